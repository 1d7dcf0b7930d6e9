//! The thirteen real own-ship NMEA recordings in `../shared/realdata/nmea/` (receivers,
//! plotters and bridge networks nobody on this project wrote), each replayed through the
//! main job with the simulated picture moving with the recorded ship:
//!
//! - every line is classified (used, ignored, rejected with a reason, annotation or blank),
//!   and none of these well-formed recordings has a line counted malformed or a bad
//!   checksum;
//! - own ship, as the product used it (its plots recording's own-ship columns), follows the
//!   recording's position fixes: median error at most 5 m, against fixes read here
//!   independently of the product (framing and fields by hand);
//! - the simulated targets around it are tracked with no false track.
//!
//! The files are read where CI has them (`../shared/realdata/` beside the checkout); a
//! missing file fails the test.

use std::path::PathBuf;
use std::process::ExitCode;

use tracker_host::own_ship::recording::RecordedTrack;
use tracker_host::own_ship::NmeaOptions;

const FILES: [&str; 13] = [
    "gpsd-bundg_zeus_9.log",
    "gpsd-hemi.log",
    "gpsd-humminbird-M37.log",
    "gpsd-neo-m8n.log",
    "gpsd-rst39.log",
    "gpsd-saab-r4.log",
    "gpsd-skytraq-PX1172RH_DS.log",
    "mayara-halo_and_0183-nmea.log",
    "radar_pi-3g-trueheading-udp10110.log",
    "radar_pi-4g-noheading-merrimac-tcp2000.log",
    "signalk-gofree-merrimac.log",
    "signalk-gps.log",
    "signalk-plaka.log",
];

mod realdata;

fn nmea_dir() -> PathBuf {
    realdata::dir().join("nmea")
}

/// A position fix as the recording states it: time of day (s, if the sentence has one),
/// latitude and longitude (degrees). Read here by hand: checksum, then RMC, GGA or GLL.
fn fixes(text: &str) -> Vec<(Option<f64>, f64, f64)> {
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        let Some(body) = line.strip_prefix('$') else {
            continue;
        };
        let Some((body, sum)) = body.rsplit_once('*') else {
            continue;
        };
        if u8::from_str_radix(sum, 16).ok() != Some(body.bytes().fold(0, |a, b| a ^ b)) {
            continue;
        }
        let f: Vec<&str> = body.split(',').collect();
        let kind = f[0].get(2..).unwrap_or("");
        let angle = |v: &str, h: &str| -> Option<f64> {
            let x: f64 = v.parse().ok()?;
            let d = (x / 100.0).trunc();
            let a = d + (x - 100.0 * d) / 60.0;
            match h {
                "N" | "E" => Some(a),
                "S" | "W" => Some(-a),
                _ => None,
            }
        };
        let tod = |t: &str| -> Option<f64> {
            let h: f64 = t.get(0..2)?.parse().ok()?;
            let m: f64 = t.get(2..4)?.parse().ok()?;
            let s: f64 = t.get(4..)?.parse().ok()?;
            Some(h * 3600.0 + m * 60.0 + s)
        };
        let get = |i: usize| f.get(i).copied().unwrap_or("");
        let fix = match kind {
            "RMC" if get(2) == "A" => angle(get(3), get(4))
                .zip(angle(get(5), get(6)))
                .map(|(la, lo)| (tod(get(1)), la, lo)),
            "GGA" if !matches!(get(6), "" | "0") => angle(get(2), get(3))
                .zip(angle(get(4), get(5)))
                .map(|(la, lo)| (tod(get(1)), la, lo)),
            "GLL" if get(6) == "A" => angle(get(1), get(2))
                .zip(angle(get(3), get(4)))
                .map(|(la, lo)| (tod(get(5)), la, lo)),
            _ => None,
        };
        out.extend(fix);
    }
    out
}

/// Metres between two latitudes/longitudes (flat earth: they are metres apart).
fn metres(a: (f64, f64), b: (f64, f64)) -> f64 {
    let north = (a.0 - b.0) * 111_120.0;
    let east = (a.1 - b.1) * 111_120.0 * a.0.to_radians().cos();
    north.hypot(east)
}

#[test]
fn every_real_recording_drives_own_ship_and_the_picture() {
    let dir = tempfile::tempdir().unwrap();
    let mut table = String::new();
    for name in FILES {
        let path = nmea_dir().join(name);
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (CI has ../shared beside the checkout)",
                path.display()
            )
        });
        let track = RecordedTrack::read(&path, &NmeaOptions::default()).unwrap();
        let origin = track.first_position();
        // Long enough to read every line of the recording.
        let duration = track.span_s() + 30.0;
        let plots = dir.path().join(format!("{name}.plots.csv"));
        let json = dir.path().join(format!("{name}.json"));
        let args = [
            "tracker-host".to_string(),
            "--link".into(),
            "inproc".into(),
            "demo".into(),
            "--plain".into(),
            "--nmea-in".into(),
            format!("file:{}", path.display()),
            "--duration".into(),
            format!("{duration}"),
            "--record-plots".into(),
            plots.display().to_string(),
            "--summary-json".into(),
            json.display().to_string(),
        ];
        let code = tracker_host::cli::run(args).expect("the demo runs");
        assert_eq!(code, ExitCode::SUCCESS, "{name}");
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let c = &summary["own_ship_nmea"];
        let n = |k: &str| {
            c[k].as_u64()
                .unwrap_or_else(|| panic!("{name}: no {k} in {c}"))
        };
        // Every line classified.
        let rejected: u64 = [
            "bad_checksum",
            "malformed",
            "void",
            "stale",
            "time_jump",
            "implausible",
            "out_of_range",
            "not_true",
            "no_variation",
        ]
        .iter()
        .map(|k| n(k))
        .sum();
        let lines = text.lines().count() as u64;
        let blank = text.lines().filter(|l| l.trim().is_empty()).count() as u64;
        // AIS sentences go to the AIS decoder, the rest to own ship's; none refused.
        let ais = &summary["ais"]["sentences"];
        let ais_lines = ais["sentences"].as_u64().unwrap_or(0);
        let ais_refused: u64 = ais["rejected"]
            .as_object()
            .map_or(0, |m| m.values().filter_map(|v| v.as_u64()).sum());
        assert_eq!(ais_refused, 0, "{name}: AIS sentences refused: {ais}");
        assert_eq!(n("lines") + ais_lines, lines, "{name}: every line read");
        assert_eq!(
            n("used") + n("ignored") + rejected + n("annotations") + blank + ais_lines,
            lines,
            "{name}: {c}"
        );
        assert_eq!(
            n("malformed"),
            0,
            "{name}: well-formed lines counted malformed: {c}"
        );
        assert_eq!(n("bad_checksum"), 0, "{name}: {c}");
        assert!(n("used") > 0, "{name}: {c}");
        // No false track in the simulated picture around the recorded ship.
        assert_eq!(summary["false_tracks"], 0, "{name}: {summary}");
        // Own ship as the product used it, against the recording's fixes.
        let recorded = fixes(&text);
        assert!(!recorded.is_empty(), "{name}");
        let csv = std::fs::read_to_string(&plots).unwrap();
        let mut errors = Vec::new();
        let mut seen_scans = std::collections::BTreeSet::new();
        for row in csv.lines().skip(1) {
            let f: Vec<&str> = row.split(',').collect();
            if !seen_scans.insert(f[0].to_string()) {
                continue;
            }
            let t: f64 = f[1].parse().unwrap();
            let (e, nn): (f64, f64) = (f[4].parse().unwrap(), f[5].parse().unwrap());
            let (lat, lon) = origin.to_lat_lon([e, nn]);
            let tod = t.rem_euclid(86_400.0);
            // The fix nearest in time (within 1.5 s) of the scan, if the recording has one
            // then; recordings without times (the HALO network's GLL) are compared with their
            // last fix at their last scan.
            let nearest = recorded
                .iter()
                .filter_map(|&(ft, la, lo)| ft.map(|ft| (ft, la, lo)))
                .map(|(ft, la, lo)| {
                    let dt = (ft - tod + 43_200.0).rem_euclid(86_400.0) - 43_200.0;
                    (dt.abs(), la, lo)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .filter(|x| x.0 <= 1.5);
            if let Some((_, la, lo)) = nearest {
                errors.push(metres((lat, lon), (la, lo)));
            }
        }
        if errors.is_empty() {
            // No timed fix: the last scan against the last fix.
            let last = csv.lines().last().unwrap();
            let f: Vec<&str> = last.split(',').collect();
            let (lat, lon) = origin.to_lat_lon([f[4].parse().unwrap(), f[5].parse().unwrap()]);
            let fix = recorded.last().unwrap();
            errors.push(metres((lat, lon), (fix.1, fix.2)));
        }
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        table += &format!(
            "{name}: {} lines, {} used, {} ignored, {rejected} rejected, {ais_lines} AIS; own ship vs fixes: median {median:.1} m, max {:.1} m over {} scans\n",
            lines,
            n("used"),
            n("ignored"),
            errors.last().unwrap(),
            errors.len()
        );
        assert!(median <= 5.0, "{name}: median own-ship error {median:.1} m");
    }
    eprintln!("{table}");
}

/// A recording with no time in it (the HALO network's `GLL`s without one) drives a demo
/// whose clock is not UTC: shown without the `Z`, and sent to plotters on this computer's
/// clock rather than as midnight of a day it never said (a new user's trial saw
/// `00:00:00Z` and an `RMC` of today's date). A timed one is UTC.
#[test]
fn a_recording_without_a_time_gives_no_utc() {
    for (name, timed) in [
        ("mayara-halo_and_0183-nmea.log", false),
        ("gpsd-hemi.log", true),
    ] {
        let path = nmea_dir().join(name);
        assert_eq!(
            RecordedTrack::read(&path, &NmeaOptions::default())
                .unwrap()
                .timed,
            timed,
            "{name}"
        );
        let mut options = tracker_host::app::demo::DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            4,
            1,
            10.0,
            tracker_core::filter::FilterKind::KalmanCv,
        );
        options.own_ship.nmea_in = Some(tracker_host::nmea::input::InSpec::File(path));
        // As the command line does: a recording's times before a date are today's.
        options.own_ship.nmea.provisional_day = tracker_host::app::today();
        // Its plots and truth recorded read back with the same clock (an untimed run's was
        // written from the computer's date, then replayed as UTC).
        let dir = tempfile::tempdir().unwrap();
        let (plots, truth) = (dir.path().join("p.csv"), dir.path().join("t.csv"));
        options.outputs.record_plots = Some(plots.clone());
        options.outputs.record_truth = Some(truth.clone());
        let client =
            tracker_host::link::Client::new(Box::new(tracker_host::link::InprocTransport::new()));
        let mut run = tracker_host::app::demo::start(client, &options).unwrap();
        let report = run.step().unwrap().expect("a scan");
        assert_eq!(report.time_is_utc, timed, "{name}");
        assert_eq!(
            report.time_label().ends_with('Z'),
            timed,
            "{name}: {}",
            report.time_label()
        );
        assert_eq!(report.utc_s().is_some(), timed, "{name}");
        let first_s = report.time_s;
        while run.step().unwrap().is_some() {}
        run.finish().unwrap();
        let replay = tracker_host::source::plots_file::PlotsFileSource::open(&plots).unwrap();
        assert_eq!(
            tracker_host::source::PlotSource::time_is_utc(&replay),
            timed,
            "{name}: plots replayed"
        );
        let t0 = |p: &std::path::Path| {
            let text = std::fs::read_to_string(p).unwrap();
            let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
            let col = header.iter().position(|c| *c == "t_s").unwrap();
            let row = text.lines().nth(1).expect("a row").to_string();
            row.split(',').nth(col).unwrap().parse::<f64>().unwrap()
        };
        let expected = if timed { first_s } else { 0.0 };
        assert_eq!(t0(&plots), expected, "{name}: plots");
        assert_eq!(t0(&truth), expected, "{name}: truth");
    }
}

/// A stray sentence of another date (a valid 1994 `RMC`, the textbook example, before the
/// first fix of a 2015 log and every ten lines after): set apart, counted as time jumps,
/// and the run is the clean log's, scan for scan. Before, it took the stray fix as the
/// origin and the start, and the run would have lasted 21 years (a new user's trial filled
/// a disk with it).
#[test]
fn a_stray_sentence_of_another_date_does_not_move_the_run() {
    let clean = nmea_dir().join("gpsd-neo-m8n.log");
    let text = std::fs::read_to_string(&clean).unwrap();
    let stray = "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A";
    let doctored: String = text
        .lines()
        .enumerate()
        .flat_map(|(i, l)| (i % 10 == 0).then_some(stray).into_iter().chain([l]))
        .map(|l| format!("{l}\n"))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stray.log");
    std::fs::write(&path, doctored).unwrap();
    let options = NmeaOptions::default();
    let a = RecordedTrack::read(&clean, &options).unwrap();
    let b = RecordedTrack::read(&path, &options).unwrap();
    assert_eq!(a.set_apart, 0);
    assert!(b.set_apart > 0);
    assert_eq!(a.fixes, b.fixes);
    // The demo on each, to the end of the recording.
    let run = |path: PathBuf| {
        let mut options = tracker_host::app::demo::DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            4,
            1,
            10.0,
            tracker_core::filter::FilterKind::KalmanCv,
        );
        options.duration_from_recording = true;
        options.own_ship.nmea_in = Some(tracker_host::nmea::input::InSpec::File(path));
        let client =
            tracker_host::link::Client::new(Box::new(tracker_host::link::InprocTransport::new()));
        let mut run = tracker_host::app::demo::start(client, &options).unwrap();
        let mut scans = Vec::new();
        while let Some(r) = run.step().unwrap() {
            assert!(scans.len() < 1000, "a run that does not end");
            scans.push((r.time_s, r.own.position_m, r.own.quality.dead_reckoning_s));
        }
        scans
    };
    let (a, b) = (run(clean), run(path));
    assert!(!a.is_empty());
    assert_eq!(a, b);
}
