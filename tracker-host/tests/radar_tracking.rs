//! The radar as a plot source on the five real captures in `../shared/realdata/radar/`
//! (read where CI has them, beside the checkout, or where `TRACKER_REALDATA` says): spokes
//! → plots (CFAR, blobs, point vs extended) → the session's tracks, in process.
//!
//! Per capture: scans, plots and extended returns a scan, targets shown; a table is
//! printed with the stationary point echoes (echoes found at the same place, within 10 m,
//! in at least 80 % of the scans) and how many of them have a track near them (20 m)
//! showing under 1 kn and 1 kn or more. Measured, not asserted: in the 4G harbour capture
//! many of them are boats in a row along a pontoon, whose echoes break up and join
//! differently scan to scan, and a track slides along the row (see the README).

use std::path::{Path, PathBuf};

use tracker_core::filter::FilterKind;
use tracker_host::app::run::Run;
use tracker_host::app::track::{self, TrackInput, TrackOptions};
use tracker_host::app::{Outputs, OwnShipOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::radar::RadarSpec;
use tracker_host::session::ScanReport;
use tracker_host::source::radar::RadarOptions;

fn realdata() -> PathBuf {
    std::env::var_os("TRACKER_REALDATA").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/realdata"),
        PathBuf::from,
    )
}

fn capture(name: &str) -> PathBuf {
    let p = realdata().join("radar").join(name);
    assert!(
        p.is_file(),
        "{}: missing (set TRACKER_REALDATA)",
        p.display()
    );
    p
}

const KNOT_MPS: f32 = 1852.0 / 3600.0;

/// One capture tracked to its end.
struct Tracked {
    reports: Vec<ScanReport>,
    run: Run,
}

fn track(name: &str, heading_deg: Option<f32>) -> Tracked {
    let mut radar = RadarOptions::new(RadarSpec::Capture(capture(name)));
    radar.fixed_heading_rad = heading_deg.map(f32::to_radians);
    let options = TrackOptions {
        input: TrackInput::Radar(radar),
        filter: FilterKind::KalmanCv,
        own_ship: OwnShipOptions::default(),
        outputs: Outputs::default(),
    };
    let mut run = track::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let mut reports = Vec::new();
    while let Some(r) = run.step().unwrap() {
        assert!(
            r.skipped.is_none(),
            "{name}: scan {} skipped: {:?}",
            r.scan,
            r.skipped
        );
        reports.push(r);
    }
    Tracked { reports, run }
}

/// Stationary echoes of the last scan (a plot within `radius_m` in at least `share` of the
/// scans), and how many of them have a target within 20 m showing under 1 kn, over 1 kn.
fn stationary(reports: &[ScanReport], radius_m: f32, share: f64) -> (usize, usize, usize) {
    let Some(last) = reports.last() else {
        return (0, 0, 0);
    };
    let near = |a: [f32; 2], b: [f32; 2], r: f32| (a[0] - b[0]).hypot(a[1] - b[1]) <= r;
    let mut echoes = 0;
    let mut slow = 0;
    let mut fast = 0;
    for p in &last.plots_m {
        let seen = reports
            .iter()
            .filter(|r| r.plots_m.iter().any(|q| near(*p, *q, radius_m)))
            .count();
        if (seen as f64) < share * reports.len() as f64 {
            continue;
        }
        echoes += 1;
        let target = last
            .targets
            .iter()
            .filter(|t| near(*p, t.position_m, 20.0))
            .min_by(|a, b| {
                let d = |t: &&tracker_host::session::target::TargetData| {
                    (t.position_m[0] - p[0]).hypot(t.position_m[1] - p[1])
                };
                d(a).total_cmp(&d(b))
            });
        match target {
            Some(t) if t.speed_mps < KNOT_MPS => slow += 1,
            Some(_) => fast += 1,
            None => {}
        }
    }
    (echoes, slow, fast)
}

#[test]
fn every_capture_is_tracked_to_its_end() {
    // (capture, fixed heading for a radar that sends none and no NMEA beside it)
    let captures: [(&str, Option<f32>); 5] = [
        ("mayara-halo_and_0183.pcap", None),
        ("radar_pi-3g-trueheading.pcap.gz", None),
        ("radar_pi-4g-noheading-merrimac.pcap.gz", None),
        ("radar_pi-garmin_xhd.pcap.gz", Some(0.0)),
        ("radar_pi-halo-velocitytrack-away.pcap.gz", None),
    ];
    println!(
        "| capture | scans | period s | range m | point plots/scan | extended/scan | targets shown | stationary echoes | tracked < 1 kn | tracked ≥ 1 kn |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, heading) in captures {
        let t = track(name, heading);
        let report = t.run.report("inproc");
        let radar = report.radar.clone().expect("a radar source counts");
        let (echoes, slow, fast) = stationary(&t.reports, 10.0, 0.8);
        let period = t.run.scan_period_s().unwrap_or(f64::NAN);
        let range = t
            .reports
            .iter()
            .flat_map(|r| r.plots.iter().map(|p| p.range_m))
            .fold(0.0f32, f32::max);
        println!(
            "| {name} | {} | {period:.2} | {range:.0} | {:.1} | {:.1} | {} | {echoes} | {slow} | {fast} |",
            report.scans,
            radar.plots_per_scan(),
            radar.extended_per_scan(),
            report.targets_seen,
        );
        assert!(report.scans >= 4, "{name}: {} scans", report.scans);
        // Heading: from the spokes, the capture's NMEA or the fixed heading; the 4G's first
        // few spokes come before the capture's first HDT.
        assert!(
            radar.plots_without_heading * 20 <= radar.plots,
            "{name}: plots without heading: {radar}"
        );
        assert!(radar.plots_per_scan() >= 5.0, "{name}: {radar}");
        assert!(report.targets_seen > 0, "{name}: no target tracked");
    }
}
