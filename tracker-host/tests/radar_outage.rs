//! A radar silent for longer than a track coasts (a power cut, a network down, standby):
//! the tracks from before are not believed after it. Their gates grew over the gap until
//! they took any echo; in a user trial a harbour's moored boats became targets at
//! 11–13 kn with a CPA alarm after 35 s of silence. The session loses every target, tells
//! why, and acquires again; a shorter gap (a rotation or two lost) is coasted through.

use tracker_core::filter::FilterKind;
use tracker_core::icd::Plot;
use tracker_core::track::LOST_AFTER_COASTS;
use tracker_host::link::{Client, InprocReset, InprocTransport};
use tracker_host::own_ship::OwnShip;
use tracker_host::session::{ScanReport, Session, SessionConfig};
use tracker_host::source::RadarScan;

const PERIOD_S: f64 = 2.5;

/// A ship 2 km north-east of a stopped own ship, steaming east at 5 m/s, and a buoy.
fn scene(time_s: f64) -> Vec<Plot> {
    let ship = [1500.0 + 5.0 * time_s, 1500.0];
    let buoy = [-800.0, 600.0];
    [ship, buoy]
        .iter()
        .map(|[e, n]: &[f64; 2]| Plot {
            range_m: e.hypot(*n) as f32,
            bearing_rad: e.atan2(*n).rem_euclid(std::f64::consts::TAU) as f32,
        })
        .collect()
}

struct Scans {
    session: Session,
    scan: u32,
    power: InprocReset,
}

impl Scans {
    fn new() -> Self {
        let config = SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 10.0);
        let transport = InprocTransport::new();
        let power = transport.reset_handle();
        let client = Client::new(Box::new(transport));
        Scans {
            session: Session::start(client, config).unwrap(),
            scan: 0,
            power,
        }
    }

    fn at(&mut self, time_s: f64) -> ScanReport {
        self.scan += 1;
        let radar = RadarScan {
            scan: self.scan,
            time_s,
            plots: scene(time_s),
        };
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        self.session.scan(&radar, &own).unwrap()
    }

    fn silence_events(&self) -> Vec<String> {
        self.session
            .events()
            .into_iter()
            .filter(|e| e.contains("rotations missed"))
            .collect()
    }
}

/// The ship's target (the one east of north, moving).
fn ship(r: &ScanReport) -> Option<&tracker_host::session::target::TargetData> {
    r.targets.iter().find(|t| t.speed_mps > 2.0)
}

#[test]
fn a_silence_longer_than_a_track_coasts_loses_every_target_and_acquires_again() {
    let mut s = Scans::new();
    let mut last = None;
    for k in 0..20 {
        last = Some(s.at(PERIOD_S * f64::from(k)));
    }
    let before = last.unwrap();
    assert_eq!(before.targets.len(), 2, "{:?}", before.targets);
    let number = ship(&before).expect("the ship tracked").number;
    assert!(number.is_some());

    // 35 s without a scan: 13 rotations missed.
    let t = PERIOD_S * 19.0 + 35.0;
    let after = s.at(t);
    assert!(after.targets.is_empty(), "{:?}", after.targets);
    let silence = after.silence.expect("the silence reported");
    assert_eq!(
        (silence.rotations_missed, silence.targets_lost),
        (13, 2),
        "{silence:?}"
    );
    assert_eq!(after.ended.len(), 2, "both targets told lost");
    assert!(after.ended.iter().any(|e| e.number == number));
    let said = s.silence_events();
    assert_eq!(said.len(), 1, "{said:?}");
    assert!(
        said[0].contains("35.0 s (13 rotations missed): 2 targets lost"),
        "{said:?}"
    );

    // Acquired again from the scans after it, at the ship's true speed.
    let mut again = None;
    for k in 1..12 {
        again = Some(s.at(t + PERIOD_S * f64::from(k)));
    }
    let again = again.unwrap();
    assert_eq!(again.targets.len(), 2, "{:?}", again.targets);
    let speed = ship(&again).expect("the ship tracked again").speed_mps;
    assert!((speed - 5.0).abs() < 1.0, "{speed} m/s");
    assert_eq!(s.silence_events().len(), 1);
}

#[test]
fn a_gap_shorter_than_a_track_coasts_is_coasted_through() {
    let mut s = Scans::new();
    let mut time_s = 0.0;
    let mut last = None;
    for _ in 0..20 {
        last = Some(s.at(time_s));
        time_s += PERIOD_S;
    }
    let number = ship(&last.unwrap()).unwrap().number;
    // One rotation fewer than a confirmed track coasts: nothing lost.
    time_s += PERIOD_S * f64::from(LOST_AFTER_COASTS - 1);
    let after = s.at(time_s);
    assert!(after.ended.is_empty(), "{:?}", after.ended);
    assert_eq!(after.silence, None);
    assert_eq!(ship(&after).map(|t| t.number), Some(number));
    assert!(s.silence_events().is_empty());
}

#[test]
fn the_first_scans_and_a_slow_antenna_are_not_a_silence() {
    // Before two scans there is no period to judge by; a long period is not a gap.
    let mut s = Scans::new();
    for k in 0..12 {
        let r = s.at(30.0 * f64::from(k));
        assert!(r.ended.is_empty(), "scan {k}: {:?}", r.ended);
    }
    assert!(s.silence_events().is_empty());
}

#[test]
fn a_device_reset_in_the_same_power_cut_is_noticed_and_configured_again() {
    // The cancel after a silence must not hide a reset: a fresh device holds no tracks, as
    // a cancelled one does, but runs its default configuration until configured again.
    let mut s = Scans::new();
    for k in 0..20 {
        s.at(PERIOD_S * f64::from(k));
    }
    s.power.reset();
    let t = PERIOD_S * 19.0 + 35.0;
    let after = s.at(t);
    assert_eq!(after.ended.len(), 2, "{:?}", after.ended);
    assert!(after.silence.is_some());
    let events = s.session.events();
    assert!(
        events.iter().any(|e| e.contains("firmware reset detected")),
        "{events:?}"
    );
    let mut again = None;
    for k in 1..12 {
        again = Some(s.at(t + PERIOD_S * f64::from(k)));
    }
    assert_eq!(again.unwrap().targets.len(), 2);
}
