//! What a chart plotter gets: over an hour of the main job's picture, no target number is
//! shared by two live targets in any scan, a number stays with its track, and every track
//! that ends, or is still shown when the run ends, is sent once as lost (`L`); one held
//! hidden in another's echo is neither sent nor ended while hidden, and comes back under its
//! number; positions are valid in every hemisphere and across
//! the antimeridian; own ship goes out when asked.

use std::collections::{BTreeMap, BTreeSet};
use std::net::UdpSocket;

use tracker_core::filter::FilterKind;
use tracker_core::icd::TrackStatus;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::nmea::targets::TargetsOut;
use tracker_host::nmea::{NmeaOut, OutSpec};
use tracker_host::origin::Origin;

/// The fields of a sentence between the address and the checksum, after checking both.
fn fields(s: &str) -> Vec<String> {
    let s = s.trim();
    let frame = nmea::parse_nmea_sentence(s).unwrap_or_else(|e| panic!("{s}: {e:?}"));
    assert_eq!(frame.checksum, frame.calc_checksum(), "{s}: checksum");
    s[1..s.find('*').unwrap()]
        .split(',')
        .map(str::to_string)
        .collect()
}

fn sink() -> NmeaOut {
    let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
    NmeaOut::open(&OutSpec::Udp(rx.local_addr().unwrap().to_string())).unwrap()
}

/// What a plotter got over a run, checked scan by scan (numbers unique, kept, every end
/// sent once, hidden targets neither sent nor ended): scans, ends sent, target reports,
/// and targets that came back from another's echo under their number.
fn plotter_stream(
    kind: ScenarioKind,
    targets: usize,
    seed: u64,
    duration_s: f64,
) -> (u32, u64, u64, usize) {
    let options = DemoOptions::new(kind, targets, seed, duration_s, FilterKind::KalmanCv);
    let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let mut out = TargetsOut::new(sink(), Origin::default(), false);
    // Read from the stream alone: number → where it was last sent, and the scan.
    let mut shown: BTreeMap<u8, ([f64; 2], u32)> = BTreeMap::new();
    let (mut scans, mut lost_sent, mut numbered) = (0, 0, 0u64);
    // Numbers of targets hidden in another's echo, until they are sent again.
    let (mut hidden, mut came_back) = (BTreeSet::new(), 0);
    while let Some(report) = run.step().unwrap() {
        scans += 1;
        let sentences = out.scan_sentences(&report);
        let mut now: BTreeMap<u8, ([f64; 2], u32)> = BTreeMap::new();
        let mut ended: BTreeSet<u8> = BTreeSet::new();
        for pair in sentences.chunks(2) {
            let ttm = fields(&pair[0]);
            let tll = fields(&pair[1]);
            assert_eq!((ttm[0].as_str(), tll[0].as_str()), ("RATTM", "RATLL"));
            let number: u8 = ttm[1].parse().unwrap();
            assert!((1..=99).contains(&number), "{}", pair[0]);
            assert_eq!(
                (tll[1].as_str(), tll[8].as_str()),
                (ttm[1].as_str(), ttm[12].as_str())
            );
            let lat =
                tll[2][..2].parse::<f64>().unwrap() + tll[2][2..].parse::<f64>().unwrap() / 60.0;
            let lon =
                -(tll[4][..3].parse::<f64>().unwrap() + tll[4][3..].parse::<f64>().unwrap() / 60.0);
            let p = Origin::default().to_local(lat, lon);
            match ttm[12].as_str() {
                "L" => {
                    assert!(
                        shown.contains_key(&number),
                        "scan {}: L for {number}, not shown",
                        report.scan
                    );
                    assert!(
                        ended.insert(number),
                        "scan {}: L twice for {number}",
                        report.scan
                    );
                    lost_sent += 1;
                }
                "T" | "Q" => {
                    assert!(
                        now.insert(number, (p, report.scan)).is_none(),
                        "scan {}: number {number} twice",
                        report.scan
                    );
                    // The same target as when last sent: it moved as a ship moves in 2.5 s
                    // a scan (a scan or more, back from another's echo).
                    if let Some((q, at)) = shown.get(&number) {
                        let d = (p[0] - q[0]).hypot(p[1] - q[1]);
                        let scans = f64::from(report.scan.saturating_sub(*at).max(1));
                        assert!(
                            d < 400.0 * scans,
                            "scan {}: number {number} jumped {d:.0} m",
                            report.scan
                        );
                    }
                    numbered += 1;
                }
                other => panic!("status {other}"),
            }
        }
        assert!(
            ended.is_disjoint(&now.keys().copied().collect()),
            "a number ended and shown in one scan"
        );
        // A target hidden in another's echo is neither sent nor ended (not lost: told `L`
        // and sent again a few scans later, a plotter's symbol blinked), and keeps its
        // number on the plotter as last sent.
        let mut hidden_now = BTreeSet::new();
        for t in &report.in_echo {
            let n = t.number.expect("a held target keeps its number");
            assert!(
                !now.contains_key(&n) && !ended.contains(&n),
                "scan {}: {n} sent while hidden",
                report.scan
            );
            if let Some(last) = shown.get(&n) {
                now.insert(n, *last);
                hidden.insert(n);
            }
            hidden_now.insert(n);
        }
        // Every number on the plotter last scan is on it now or ended now.
        for n in shown.keys() {
            assert!(
                now.contains_key(n) || ended.contains(n),
                "scan {}: {n} vanished without L",
                report.scan
            );
        }
        // The stream agrees with the display's numbers.
        for t in report.targets.iter().chain(&report.acquiring) {
            if let Some(n) = t.number {
                assert!(now.contains_key(&n));
            }
        }
        // Back from the echo: sent again this scan under its number.
        came_back += hidden
            .iter()
            .filter(|n| !hidden_now.contains(*n) && now.get(*n).is_some_and(|x| x.1 == report.scan))
            .count();
        hidden.retain(|n| hidden_now.contains(n));
        shown = now;
    }
    // The run's end takes every target off the plotter, once each, where it was last sent.
    let before = out.counts().lost_sent;
    let mut ended = BTreeSet::new();
    for pair in out.end_sentences().chunks(2) {
        let ttm = fields(&pair[0]);
        assert_eq!(fields(&pair[1])[8], "L", "{}", pair[1]);
        assert_eq!(ttm[12], "L", "{}", pair[0]);
        let number: u8 = ttm[1].parse().unwrap();
        assert!(shown.contains_key(&number), "L for {number}, not shown");
        assert!(ended.insert(number), "L twice for {number}");
    }
    assert_eq!(ended, shown.keys().copied().collect::<BTreeSet<_>>());
    assert!(!ended.is_empty());
    assert_eq!(out.counts().lost_sent, before + ended.len() as u64);
    assert!(out.end_sentences().is_empty(), "ended once");
    assert_eq!(run.session().targets_without_number(), 0);
    (scans, lost_sent, numbered, came_back)
}

#[test]
fn an_hour_of_targets_keeps_numbers_unique_and_sends_every_end_once() {
    let (scans, lost_sent, numbered, came_back) =
        plotter_stream(ScenarioKind::Crossing, 40, 11, 3600.0);
    assert_eq!(scans, 1440);
    // Tracked targets lost (38): failed acquisitions are never numbered, so never end.
    assert!(lost_sent > 30, "{lost_sent} ends over the hour");
    assert!(numbered > 40 * 1000, "{numbered} target reports");
    assert!(came_back > 0, "no target came back from another's echo");
}

/// Ships merging in one resolution cell: targets held in another's echo stay on the
/// plotter as last sent, not told lost, and come back under their numbers; an end is
/// never sent twice for one of them.
#[test]
fn merged_targets_stay_on_the_plotter_while_hidden_and_come_back_under_their_numbers() {
    for seed in 1..=3 {
        let (_, lost_sent, _, came_back) = plotter_stream(ScenarioKind::Merging, 16, seed, 600.0);
        assert!(came_back > 0, "seed {seed}: none came back");
        assert!(lost_sent > 0, "seed {seed}");
    }
}

#[test]
fn positions_are_valid_in_every_hemisphere_and_across_the_antimeridian() {
    let target = |east: f32, north: f32| {
        let own = tracker_host::own_ship::OwnShip::at([0.0, 0.0], [0.0, 5.0]);
        let t = tracker_core::icd::TrackState {
            track: 1,
            status: TrackStatus::Confirmed,
            position_m: [east, north],
            velocity_mps: [3.0, -2.0],
            age_scans: 10,
            hit_history: 0x3ff,
        };
        tracker_host::session::target::TargetData::new(&own, &t)
    };
    for (origin, east, north, lat_ok, lon_ok) in [
        // Sydney: south and east.
        (
            Origin {
                lat_deg: -33.9,
                lon_deg: 151.2,
            },
            5000.0,
            -3000.0,
            'S',
            'E',
        ),
        // Rio: south and west.
        (
            Origin {
                lat_deg: -22.9,
                lon_deg: -43.2,
            },
            -5000.0,
            3000.0,
            'S',
            'W',
        ),
        // Fiji, just west of the antimeridian, the target 10 km east across it.
        (
            Origin {
                lat_deg: -17.0,
                lon_deg: 179.95,
            },
            10_000.0,
            0.0,
            'S',
            'W',
        ),
        // Just east of it, the target across it to the west.
        (
            Origin {
                lat_deg: 52.0,
                lon_deg: -179.95,
            },
            -10_000.0,
            0.0,
            'N',
            'E',
        ),
    ] {
        let t = tracker_host::nmea::targets::PlotterTarget {
            name: None,
            number: 1,
            status: 'T',
            data: target(east, north),
        };
        let s = tracker_host::nmea::tll(&t, &origin, [0.0, 0.0], 1_767_225_600.0 + 45_296.5)
            .expect("a place on the globe");
        let f = fields(&s);
        assert_eq!(
            (f[3].chars().next(), f[5].chars().next()),
            (Some(lat_ok), Some(lon_ok)),
            "{s}"
        );
        let lat_deg: f64 = f[2][..2].parse().unwrap();
        let lat_min: f64 = f[2][2..].parse().unwrap();
        let lon_deg: f64 = f[4][..3].parse().unwrap();
        let lon_min: f64 = f[4][3..].parse().unwrap();
        assert!(f[2].len() == 10 && lat_deg <= 90.0 && lat_min < 60.0, "{s}");
        assert!(
            f[4].len() == 11 && lon_deg <= 180.0 && lon_min < 60.0,
            "{s}"
        );
        assert_eq!(f[7], "123456.50");
        // Back to the local frame about own ship: the same place.
        let sign = |c: char| if c == 'S' || c == 'W' { -1.0 } else { 1.0 };
        let lat = sign(lat_ok) * (lat_deg + lat_min / 60.0);
        let lon = sign(lon_ok) * (lon_deg + lon_min / 60.0);
        let back = origin.to_local_near(lat, lon, [0.0, 0.0]);
        assert!(
            (back[0] - f64::from(east)).abs() < 1.0 && (back[1] - f64::from(north)).abs() < 1.0,
            "{s} {back:?}"
        );
        // TTM: bearings and courses 0.0–359.9.
        let ttm = fields(&tracker_host::nmea::ttm(&t, 0.0));
        for i in [3, 6] {
            let a: f64 = ttm[i].parse().unwrap();
            assert!((0.0..360.0).contains(&a) && ttm[i] != "360.0", "{ttm:?}");
        }
    }
    // Checked by an independent parser too (pynmea2) where it is installed.
    tracker_host_tools_check();
}

/// Runs `tools/check_nmea.py` (pynmea2, geographiclib) over sentences in every hemisphere, when
/// they are there; `scripts/setup` installs them, and the test command requires them.
fn tracker_host_tools_check() {
    let python = std::env::var("TRACKER_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/check_nmea.py");
    let have = std::process::Command::new(&python)
        .args(["-c", "import pynmea2, geographiclib"])
        .status()
        .is_ok_and(|s| s.success());
    if !have {
        assert!(
            std::env::var_os("TRACKER_REQUIRE_TOOLS").is_none(),
            "pynmea2 and geographiclib are required (TRACKER_REQUIRE_TOOLS is set): scripts/setup installs them"
        );
        eprintln!("pynmea2 or geographiclib not installed: the independent check is skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("out.nmea");
    let mut text = String::new();
    for (lat, lon) in [
        (-33.9, 151.2),
        (-22.9, -43.2),
        (-17.0, 179.95),
        (52.0, -179.95),
        (60.1, 23.5),
    ] {
        let origin = Origin {
            lat_deg: lat,
            lon_deg: lon,
        };
        // Own ship 20 km from the origin, a target 11 km from own ship.
        for (e, n) in [(10_000.0, -5_000.0), (-10_000.0, 5_000.0)] {
            let own = tracker_host::own_ship::OwnShip::at([12_000.0, -16_000.0], [1.0, 5.0]);
            let (e, n) = (e + own.position_m[0], n + own.position_m[1]);
            let t = tracker_core::icd::TrackState {
                track: 3,
                status: TrackStatus::Confirmed,
                position_m: [e, n],
                velocity_mps: [-3.0, 2.0],
                age_scans: 10,
                hit_history: 0x3ff,
            };
            let p = tracker_host::nmea::targets::PlotterTarget {
                name: None,
                number: 42,
                status: 'T',
                data: tracker_host::session::target::TargetData::new(&own, &t),
            };
            let (own_lat, own_lon) = origin.to_lat_lon([12_000.0, -16_000.0]);
            let (range_m, bearing) = (
                f64::from(p.data.range_m),
                f64::from(p.data.bearing_rad).to_degrees(),
            );
            text += &tracker_host::nmea::ttm(&p, 1_767_225_600.0);
            text += &tracker_host::nmea::tll(&p, &origin, own.position_m, 1_767_225_600.0)
                .expect("a place on the globe");
            text += &format!("# expect {own_lat:.9} {own_lon:.9} {range_m:.3} {bearing:.7}\n");
            text +=
                &tracker_host::nmea::targets::own_ship_sentences(&own, &origin, 1_767_225_600.0)
                    .concat();
        }
    }
    std::fs::write(&file, text).unwrap();
    let out = std::process::Command::new(&python)
        .arg(&script)
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The last scan of a minute of the open-sea demo (8 targets, seed 1).
fn a_minutes_last_scan() -> tracker_host::session::ScanReport {
    let options = DemoOptions::new(ScenarioKind::OpenSea, 8, 1, 60.0, FilterKind::KalmanCv);
    let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let mut last = None;
    while let Some(report) = run.step().unwrap() {
        last = Some(report);
    }
    last.expect("scans")
}

/// A source whose clock is its own (a plots file counting from 0 s) has its targets and own
/// ship sent at this host's time and date (OpenCPN draws nothing from sentences without
/// them), not at 1970's; a UTC source is sent at its own, on the bridge's UTC when a live
/// NMEA source's differs from this computer's clock.
#[test]
fn a_clock_that_is_not_utc_is_sent_as_the_time_of_sending() {
    let mut out = TargetsOut::new(sink(), Origin::default(), true);
    let mut report = a_minutes_last_scan();
    assert!(report.time_is_utc, "the simulator's clock is UTC");
    // TTM's UTC, TLL's UTC, RMC's time and date, of one scan's sentences; and the RMC.
    let times = |out: &mut TargetsOut, report: &tracker_host::session::ScanReport| {
        let sentences = out.scan_sentences(report);
        let of = |kind: &str, at: usize| -> String {
            let f = sentences
                .iter()
                .map(|s| fields(s))
                .find(|f| f[0] == kind)
                .unwrap_or_else(|| panic!("no {kind} in {sentences:?}"));
            f[at].clone()
        };
        let rmc = sentences.iter().find(|s| s.starts_with("$RARMC")).cloned();
        (
            [
                of("RATTM", 14),
                of("RATLL", 7),
                of("RARMC", 1),
                of("RARMC", 9),
            ],
            rmc.expect("RMC"),
        )
    };
    // hhmmss.ss and ddmmyy of a time.
    let utc = |t: f64| {
        let d = chrono::DateTime::from_timestamp_millis((t * 1000.0).round() as i64).unwrap();
        (
            d.format("%H%M%S").to_string(),
            d.format("%d%m%y").to_string(),
        )
    };
    // The time an RMC stands for, s since 1970, as own ship's reader takes it.
    let sent = |rmc: &str| -> f64 {
        use tracker_host::nmea::sentence::{parse, Line};
        use tracker_host::own_ship::sentences::{decode, Decoded};
        let Ok(Line::Sentence(s)) = parse(rmc) else {
            panic!("{rmc}")
        };
        let Decoded::Readings(stamp, _) = decode(&s, rmc) else {
            panic!("{rmc}")
        };
        let (Some(day), Some(time_of_day_s)) = (stamp.day, stamp.time_of_day_s) else {
            panic!("{rmc}: no time or date")
        };
        day as f64 * 86_400.0 + time_of_day_s
    };
    let (time, date) = utc(report.time_s);
    let ([ttm, tll, rmc, rmc_date], _) = times(&mut out, &report);
    assert!(
        ttm.starts_with(&time) && tll == ttm && rmc == ttm && rmc_date == date,
        "{ttm} {tll} {rmc} {rmc_date}: the scan's time is {} s",
        report.time_s
    );
    // A live NMEA source 3 h behind this computer's clock: sent on the bridge's UTC, as
    // own ship is (a plotter with the ship's GNSS would otherwise see every target 3 h off).
    report.utc_offset_s = -3.0 * 3600.0;
    let ([ttm, tll, rmc, _], rmc_line) = times(&mut out, &report);
    let bridge = report.time_s - 3.0 * 3600.0;
    assert!(
        ttm.starts_with(&utc(bridge).0) && tll == ttm && rmc == ttm,
        "{ttm} {tll} {rmc}: the bridge's time is {bridge} s"
    );
    assert!((sent(&rmc_line) - bridge).abs() < 0.006, "{rmc_line}");
    assert_eq!(report.utc_s(), Some(bridge));
    report.utc_offset_s = 0.0;
    report.time_is_utc = false;
    report.time_s = 42.0;
    let before = tracker_host::utc::now_s();
    let ([ttm, tll, rmc, rmc_date], rmc_line) = times(&mut out, &report);
    let after = tracker_host::utc::now_s();
    assert!(tll == ttm && rmc == ttm, "{ttm} {tll} {rmc}");
    // Sent to the hundredth, rounded.
    let at = sent(&rmc_line);
    assert!(
        before - 0.006 <= at && at <= after + 0.006,
        "{ttm} {rmc_date} ({at} s): sent between {before} and {after}"
    );
}

/// Before own ship's first fix (a radar with no GNSS yet) targets go as TTM alone: their
/// range and bearing are measured, their latitude and longitude are not, and a TLL would
/// put them where the frame starts.
#[test]
fn without_a_fix_targets_go_without_a_position() {
    let mut out = TargetsOut::new(sink(), Origin::default(), true);
    let mut report = a_minutes_last_scan();
    let kinds = |out: &mut TargetsOut, report: &tracker_host::session::ScanReport| {
        let mut n: BTreeMap<String, usize> = BTreeMap::new();
        for s in out.scan_sentences(report) {
            *n.entry(fields(&s)[0].clone()).or_default() += 1;
        }
        n
    };
    let fixed = kinds(&mut out, &report);
    let targets = fixed.get("RATTM").copied().unwrap_or(0);
    assert!(targets > 0, "{fixed:?}");
    assert_eq!(fixed.get("RATLL"), Some(&targets), "{fixed:?}");
    report.own.quality.no_fix_yet = true;
    let unfixed = kinds(&mut out, &report);
    assert_eq!(unfixed.get("RATTM"), Some(&targets), "{unfixed:?}");
    assert_eq!(unfixed.get("RATLL"), None, "{unfixed:?}");
    assert_eq!(
        unfixed.get("RARMC"),
        Some(&1),
        "own ship still goes, without a fix"
    );
    // Unless the operator gave own ship's position as the origin (`--origin`).
    let mut placed = TargetsOut::new(sink(), Origin::default(), true).with_origin_known(true);
    let given = kinds(&mut placed, &report);
    assert_eq!(given.get("RATLL"), Some(&targets), "{given:?}");
}

/// Through the product's own path (`--nmea-out tcp:PORT` on a run that ends, a plotter
/// connected): every number the plotter was sent as tracked or acquiring is last sent as
/// lost (`L`), so no target stays drawn as live once the tracker has stopped.
#[test]
fn a_run_that_ends_leaves_no_target_on_the_plotter() {
    use std::io::BufRead;
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut options = DemoOptions::new(ScenarioKind::Crossing, 8, 5, 120.0, FilterKind::KalmanCv);
    options.outputs.nmea_out = Some(OutSpec::Tcp(port));
    let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let plotter = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    plotter
        .set_read_timeout(Some(std::time::Duration::from_secs(10)))
        .unwrap();
    // Reads until the tracker closes the connection (the run dropped).
    let reader = std::thread::spawn(move || {
        let mut last: BTreeMap<String, String> = BTreeMap::new();
        for line in std::io::BufReader::new(plotter).lines() {
            let Ok(s) = line else { break };
            if s.starts_with("$RATTM") {
                let f = fields(&s);
                last.insert(f[1].clone(), f[12].clone());
            }
        }
        last
    });
    let mut shown_at_end = 0;
    while let Some(report) = run.step().unwrap() {
        shown_at_end = report.targets.iter().filter(|t| t.number.is_some()).count();
    }
    drop(run);
    let last = reader.join().unwrap();
    assert!(shown_at_end > 0, "targets shown at the end");
    assert!(!last.is_empty());
    for (number, status) in &last {
        assert_eq!(
            status, "L",
            "number {number} left on the plotter as {status}"
        );
    }
}
