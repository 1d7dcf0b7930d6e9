//! NMEA 0183 with the bridge, in the main job: own ship from the simulated bridge sensors as
//! sentences through the dead-reckoning filter, recorded and replayed with the same result;
//! damaged sentences rejected and counted; every confirmed target out to a chart plotter
//! as `TTM` and `TLL` over UDP, read back with the `nmea` crate.

use std::net::UdpSocket;

use tracker_core::filter::FilterKind;
use tracker_core::icd::TrackState;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::app::run::Run;
use tracker_host::app::{Outputs, OwnShipOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::nmea::{InSpec, OutSpec};

const SCANS: usize = 120;

fn demo(own_ship: OwnShipOptions, outputs: Outputs) -> Run {
    let options = DemoOptions {
        own_ship,
        outputs,
        ..DemoOptions::new(ScenarioKind::OpenSea, 20, 3, 300.0, FilterKind::KalmanCv)
    };
    demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap()
}

fn run(
    d: &mut Run,
    plotter: Option<&UdpSocket>,
    heard: &mut Vec<String>,
) -> Vec<(Vec<TrackState>, [f32; 2])> {
    let mut buf = [0u8; 512];
    (0..SCANS)
        .map(|_| {
            let v = d.step().unwrap().unwrap();
            // Read as a plotter would, scan by scan (a socket buffer holds a few hundred).
            while let Some(Ok(n)) = plotter.map(|p| p.recv(&mut buf)) {
                heard.push(String::from_utf8_lossy(&buf[..n]).into_owned());
            }
            (v.tracks, v.own.position_m)
        })
        .collect()
}

#[test]
fn a_recorded_run_replays_scan_for_scan_and_targets_reach_the_plotter() {
    let dir = tempfile::tempdir().unwrap();
    let recording = dir.path().join("own-ship.nmea");
    let plotter = UdpSocket::bind("127.0.0.1:0").unwrap();
    plotter.set_nonblocking(true).unwrap();
    let mut live = demo(
        OwnShipOptions {
            nmea_record: Some(recording.clone()),
            ..OwnShipOptions::default()
        },
        Outputs {
            nmea_out: Some(OutSpec::Udp(plotter.local_addr().unwrap().to_string())),
            ..Outputs::default()
        },
    );
    let mut heard = Vec::new();
    let live_run = run(&mut live, Some(&plotter), &mut heard);
    let counts = live.nmea_counts().unwrap();
    assert_eq!(counts.used, 5 * SCANS as u64, "{counts}");
    assert_eq!(counts.rejected(), 0, "{counts}");
    let s = live.summary().unwrap();
    assert!(
        s.targets_confirmed >= 19 && s.false_tracks == 0,
        "{}",
        s.report()
    );

    // The plotter got a TTM and a TLL per target per scan, all well formed.
    let (mut ttm, mut tll) = (0, 0);
    for line in &heard {
        let line = line.trim();
        match nmea::parse_str(line) {
            Ok(nmea::ParseResult::TTM(d)) => {
                ttm += 1;
                assert!(d.target_distance.unwrap() > 0.0 && d.time_of_data.is_some());
            }
            // TLL has no parser in the crate; its frame and checksum are still checked.
            Ok(nmea::ParseResult::Unsupported(nmea::SentenceType::TLL)) => {
                assert!(nmea::parse_nmea_sentence(line).is_ok() && line.starts_with("$RATLL,"));
                tll += 1;
            }
            other => panic!("{line}: {other:?}"),
        }
    }
    assert!(ttm > 20 * 60 && ttm == tll, "TTM {ttm}, TLL {tll}");

    // Replaying the recording gives the same own ship and the same tracks, scan for scan.
    // The frame the recording was made in (by default a recording's first fix would be the
    // origin: the same place to 10⁻⁵ minute).
    let replay_options = OwnShipOptions {
        nmea_in: Some(InSpec::File(recording.clone())),
        origin: Some(tracker_host::origin::Origin::default()),
        ..OwnShipOptions::default()
    };
    let mut replay = demo(replay_options.clone(), Outputs::default());
    let replay_run = run(&mut replay, None, &mut Vec::new());
    // Own ship, from the same sentences through the same filter, is the same; the picture
    // moves with the recording's fixes (latitude and longitude to 10⁻⁵ minute, 2 cm), so
    // the tracks are the same tracks within centimetres.
    for (k, (a, b)) in live_run.iter().zip(&replay_run).enumerate() {
        assert_eq!(a.1, b.1, "own ship, scan {k}");
        assert_eq!(a.0.len(), b.0.len(), "scan {k}");
        for (x, y) in a.0.iter().zip(&b.0) {
            assert_eq!((x.track, x.status), (y.track, y.status), "scan {k}");
            let d = (x.position_m[0] - y.position_m[0]).hypot(x.position_m[1] - y.position_m[1]);
            assert!(d < 0.5, "scan {k}: track {} {d} m apart", x.track);
        }
    }
    assert_eq!(replay.nmea_counts(), Some(counts));

    // A damaged recording: a broken checksum, a void fix, a stale fix and noise are
    // rejected and counted; the run goes on and tracks as well.
    let text = std::fs::read_to_string(&recording).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    // Line 100 is a GGA: one more digit in its body, the old checksum kept.
    lines[100] = lines[100].replace('*', "0*");
    lines.insert(
        200,
        tracker_host::nmea::sentence("GPRMC,000100.00,V,,,,,,,010126,,,N"),
    );
    lines.insert(300, lines[10].clone());
    lines.insert(400, "\u{1}garbage on the line".to_string());
    std::fs::write(&recording, lines.join("\r\n") + "\r\n").unwrap();
    let mut damaged = demo(replay_options, Outputs::default());
    let damaged_run = run(&mut damaged, None, &mut Vec::new());
    let c = damaged.nmea_counts().unwrap();
    assert_eq!(c.used, 5 * SCANS as u64 - 1, "{c}");
    assert_eq!(
        (c.bad_checksum, c.void, c.stale, c.malformed),
        (1, 1, 1, 1),
        "{c}"
    );
    let s = damaged.summary().unwrap();
    assert!(
        s.targets_confirmed >= 19 && s.false_tracks == 0,
        "{}",
        s.report()
    );
    assert_eq!(damaged_run.len(), SCANS);
}

/// A recording that crosses midnight, steps back in time once, has a corrupt time field and
/// loses its GPS for a minute: own ship follows the recorded ship through all of it, the
/// step back and the corrupt line are counted and skipped, and the outage is dead reckoned
/// with its alarm, which clears when the fixes return.
#[test]
fn midnight_a_step_back_a_corrupt_time_and_an_outage() {
    use tracker_host::nmea::bridge::own_ship_sentences;
    use tracker_host::origin::Origin;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("night.nmea");
    let origin = Origin::default();
    // 2026-01-01 23:58:00 UTC, north at 5 m/s, a sentence set a second for 5 minutes.
    let t0 = 1_767_225_600.0 + 86_400.0 - 120.0;
    let truth = |k: f64| [0.0, 5.0 * k];
    let mut text = String::new();
    for k in 0..300 {
        let k = f64::from(k);
        if (180.0..240.0).contains(&k) {
            continue; // no GPS for a minute (00:01:00–00:02:00)
        }
        let lines = own_ship_sentences(truth(k), [0.0, 5.0], &origin, t0 + k);
        for (i, l) in lines.iter().enumerate() {
            if k == 60.0 && i == 0 {
                // A corrupt time field, the old checksum kept.
                text += &l.replacen("GPGGA,2359", "GPGGA,2X59", 1);
                continue;
            }
            text += l;
        }
        if k == 150.0 {
            // A step back: the sentence of 10 s ago again.
            text += &own_ship_sentences(truth(k - 10.0), [0.0, 5.0], &origin, t0 + k - 10.0)[0];
        }
    }
    std::fs::write(&path, text).unwrap();
    let options = DemoOptions {
        own_ship: OwnShipOptions {
            nmea_in: Some(InSpec::File(path)),
            origin: Some(origin),
            ..OwnShipOptions::default()
        },
        duration_from_recording: true,
        ..DemoOptions::new(ScenarioKind::OpenSea, 10, 4, 300.0, FilterKind::KalmanCv)
    };
    let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let (mut dr_alarms, mut scans) = (0, 0);
    while let Some(r) = run.step().unwrap() {
        scans += 1;
        let k = r.time_s - t0;
        let want = truth(k);
        let err = (f64::from(r.own.position_m[0]) - want[0])
            .hypot(f64::from(r.own.position_m[1]) - want[1]);
        assert!(err < 5.0, "t {k:.1} s: own ship {err:.1} m off");
        let alarms = r.own.alarms();
        if (192.0..240.0).contains(&k) {
            // More than 10 s without a fix: dead reckoning, with its age.
            assert!(
                alarms.iter().any(|a| a.contains("dead reckoning")),
                "t {k}: {alarms:?}"
            );
            dr_alarms += 1;
        }
        if !(180.0..242.5).contains(&k) {
            assert!(alarms.is_empty(), "t {k}: {alarms:?}");
        }
    }
    assert!(scans >= 119, "the run goes on past midnight: {scans} scans");
    assert!(dr_alarms >= 18);
    let c = run.nmea_counts().unwrap();
    assert_eq!((c.bad_checksum, c.stale), (1, 1), "{c}");
    assert_eq!(c.malformed, 0, "{c}");
}

/// A recording with a 2.5-hour GPS outage plays through: own ship is dead reckoned, then
/// marked unknown, and when the fixes return the filter starts again there (the first fix
/// after the gap waits for a second to confirm the jump in time) and own ship follows.
#[test]
fn a_two_and_a_half_hour_outage_plays_through() {
    use tracker_host::nmea::bridge::own_ship_sentences;
    use tracker_host::origin::Origin;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("outage.nmea");
    let origin = Origin::default();
    let t0 = 1_767_225_600.0 + 8.0 * 3600.0;
    let gap = 2.5 * 3600.0;
    let truth = |k: f64| [0.0, 4.0 * k];
    let mut text = String::new();
    for k in (0..120).chain((gap as i32)..(gap as i32 + 120)) {
        let k = f64::from(k);
        for l in own_ship_sentences(truth(k), [0.0, 4.0], &origin, t0 + k) {
            text += &l;
        }
    }
    std::fs::write(&path, text).unwrap();
    let options = DemoOptions {
        own_ship: OwnShipOptions {
            nmea_in: Some(InSpec::File(path)),
            origin: Some(origin),
            ..OwnShipOptions::default()
        },
        duration_from_recording: true,
        ..DemoOptions::new(ScenarioKind::OpenSea, 5, 2, 60.0, FilterKind::KalmanCv)
    };
    let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let (mut unknown, mut after, mut scans) = (0, 0, 0);
    while let Some(r) = run.step().unwrap() {
        scans += 1;
        let k = r.time_s - t0;
        assert!(r.own.position_m.iter().all(|v| v.is_finite()), "t {k}");
        if (1000.0..gap).contains(&k) {
            assert!(!r.own.quality.motion_known, "t {k}: {:?}", r.own.quality);
            unknown += 1;
        }
        if k > gap + 10.0 {
            let want = truth(k);
            let err = (f64::from(r.own.position_m[1]) - want[1]).abs();
            assert!(err < 10.0, "t {k}: own ship {err:.1} m off");
            assert!(r.own.alarms().is_empty(), "t {k}: {:?}", r.own.alarms());
            after += 1;
        }
    }
    assert!(
        scans > 3600 && unknown > 3000 && after > 40,
        "{scans} {unknown} {after}"
    );
    let c = run.nmea_counts().unwrap();
    assert!(c.time_jump >= 1, "{c}");
    let events = run.report("inproc").events;
    assert!(events.iter().any(|e| e.contains("restarted")), "{events:?}");
}
