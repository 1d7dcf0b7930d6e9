//! Two ships in one resolution cell give one echo. The track of the one hidden in the
//! other's echo is held (the default association, `two-stage-unresolved`) and not drawn:
//! it keeps its number, is held while the shared echo is not seen at all, and is drawn
//! again under its number when its ship is seen apart.

use tracker_core::filter::FilterKind;
use tracker_core::icd::Plot;
use tracker_host::link::{Client, InprocTransport};
use tracker_host::own_ship::OwnShip;
use tracker_host::session::{ScanReport, Session, SessionConfig};
use tracker_host::source::RadarScan;

const PERIOD_S: f64 = 2.5;

fn plot([e, n]: [f64; 2]) -> Plot {
    Plot {
        range_m: e.hypot(n) as f32,
        bearing_rad: e.atan2(n).rem_euclid(std::f64::consts::TAU) as f32,
    }
}

/// Ships A and B 2 km north-east of a stopped own ship, both steaming east at 5 m/s
/// (no alarm: their CPA is behind them), B 25 m north of A.
fn parallel(time_s: f64) -> [[f64; 2]; 2] {
    let a = [1500.0 + 5.0 * time_s, 1500.0];
    [a, [a[0], a[1] + 25.0]]
}

/// What the radar gives on a scan.
#[derive(Clone, Copy)]
enum Seen {
    /// Both, apart.
    Both,
    /// One echo for the two (A's).
    Merged,
    /// One echo for the two, measured where B is.
    MergedAtB,
    /// Nothing.
    Neither,
}

struct Scans {
    session: Session,
    scan: u32,
    scene: fn(f64) -> [[f64; 2]; 2],
}

impl Scans {
    fn new(scene: fn(f64) -> [[f64; 2]; 2]) -> Self {
        let config = SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 10.0);
        let client = Client::new(Box::new(InprocTransport::new()));
        Scans {
            session: Session::start(client, config).unwrap(),
            scan: 0,
            scene,
        }
    }

    fn next(&mut self, seen: Seen) -> ScanReport {
        self.scan += 1;
        let time_s = PERIOD_S * f64::from(self.scan);
        let [a, b] = (self.scene)(time_s);
        let plots = match seen {
            Seen::Both => vec![plot(a), plot(b)],
            Seen::Merged => vec![plot(a)],
            Seen::MergedAtB => vec![plot(b)],
            Seen::Neither => Vec::new(),
        };
        let radar = RadarScan {
            scan: self.scan,
            time_s,
            plots,
        };
        self.session
            .scan(&radar, &OwnShip::at([0.0, 0.0], [0.0, 0.0]))
            .unwrap()
    }
}

/// The numbers of the targets drawn.
fn drawn_numbers(r: &ScanReport) -> Vec<u8> {
    r.targets.iter().filter_map(|t| t.number).collect()
}

#[test]
fn a_ship_hidden_in_anothers_echo_is_held_undrawn_and_comes_back_under_its_number() {
    let mut s = Scans::new(parallel);
    let mut r = s.next(Seen::Both);
    for _ in 0..30 {
        r = s.next(Seen::Both);
    }
    let before = drawn_numbers(&r);
    assert_eq!(before.len(), 2, "both tracked apart: {before:?}");
    assert!(r.in_echo.is_empty());
    // One echo: B's track is held, not drawn, with its number.
    r = s.next(Seen::Merged);
    assert_eq!(r.targets.len(), 1, "{:?}", drawn_numbers(&r));
    assert_eq!(r.in_echo.len(), 1);
    let b = r.in_echo[0].number.expect("held with its number");
    assert!(before.contains(&b) && !drawn_numbers(&r).contains(&b));
    // Not drawn while the shared echo is not seen either, nor when its plot goes to B's
    // track: the echo keeps the one symbol it had (A's), not the two swapping.
    for seen in [Seen::Merged, Seen::Neither, Seen::MergedAtB, Seen::Merged] {
        r = s.next(seen);
        assert_eq!(
            r.in_echo
                .iter()
                .filter_map(|t| t.number)
                .collect::<Vec<_>>(),
            [b]
        );
        assert!(!drawn_numbers(&r).contains(&b));
    }
    // Seen apart: drawn again under its number.
    r = s.next(Seen::Both);
    assert!(r.in_echo.is_empty());
    let mut after = drawn_numbers(&r);
    after.sort_unstable();
    let mut before = before;
    before.sort_unstable();
    assert_eq!(after, before);
}

/// B steams straight at own ship (CPA 0, TCPA under 12 min: alarmed); A crosses its bow
/// 2.6 km out (CPA 2.6 km: no alarm) and is 25 m east of B on scan 31.
fn crossing(time_s: f64) -> [[f64; 2]; 2] {
    let meet_s = 31.0 * PERIOD_S;
    let b = [0.0, 3000.0 - 5.0 * time_s];
    let a = [25.0 + 5.0 * (time_s - meet_s), 3000.0 - 5.0 * meet_s];
    [a, b]
}

/// A and B both steam at own ship, 25 m apart: both alarmed.
fn both_closing(time_s: f64) -> [[f64; 2]; 2] {
    let b = [0.0, 3000.0 - 5.0 * time_s];
    [[25.0, b[1]], b]
}

#[test]
fn a_hidden_target_whose_alarm_is_raised_is_drawn_unless_the_echo_it_is_in_alarms_too() {
    for (scene, drawn) in [(crossing as fn(f64) -> _, true), (both_closing, false)] {
        let mut s = Scans::new(scene);
        let mut r = s.next(Seen::Both);
        for _ in 1..30 {
            r = s.next(Seen::Both);
        }
        let limits = tracker_host::session::target::AlarmLimits::default();
        let b = r
            .targets
            .iter()
            .find(|t| t.position_m[0].abs() < 12.0)
            .expect("B tracked");
        assert!(b.dangerous(&limits), "B alarms");
        let b = b.number;
        r = s.next(Seen::Merged);
        let in_echo: Vec<_> = r.in_echo.iter().map(|t| t.number).collect();
        let shown = r.targets.iter().any(|t| t.number == b);
        assert_eq!(
            (shown, in_echo.contains(&b)),
            (drawn, !drawn),
            "drawn {drawn}"
        );
    }
}

/// The tracks recording marks a held track (`held` 1), and no other.
#[test]
fn the_tracks_recording_marks_the_held_track() {
    use tracker_host::record::TracksRecorder;
    use tracker_host::sink::ScanSink;
    use tracker_host::source::SourceScan;

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracks.csv");
    let mut recorder = TracksRecorder::create(&path).unwrap();
    let mut s = Scans::new(parallel);
    let mut held_rows = 0;
    let seen = std::iter::repeat_n(Seen::Both, 31)
        .chain(std::iter::repeat_n(Seen::Merged, 4))
        .chain(std::iter::once(Seen::Both));
    for seen in seen {
        let r = s.next(seen);
        let source = SourceScan {
            radar: RadarScan {
                scan: r.scan,
                time_s: r.time_s,
                plots: Vec::new(),
            },
            own_ship: None,
            truth: None,
            echoes: None,
            heading_sensor_rad: None,
            placed_heading_rad: None,
        };
        recorder.scan(&source, &r).unwrap();
        held_rows += r.in_echo.len();
    }
    recorder.finish().unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines = text.lines();
    assert!(lines.next().unwrap().ends_with(",held"));
    let marked = lines.filter(|l| l.ends_with(",1")).count();
    assert_eq!(held_rows, 4, "held on the four merged scans");
    assert_eq!(marked, held_rows, "{text}");
}
