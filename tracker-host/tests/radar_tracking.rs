//! The radar as a plot source on the five real captures in `../shared/realdata/radar/`
//! (read where CI has them, beside the checkout, or where `TRACKER_REALDATA` says): spokes
//! → plots (CFAR, echoes, point vs extended) → the session's tracks, in process.
//!
//! - Per capture: scans, plots and extended returns a scan, targets shown, and the
//!   stationary point echoes (found at the same place, within 10 m or 1 % of the range
//!   scale, in at least 80 % of the whole scans) with the speeds their settled tracks show
//!   (tracks at least [`SETTLED_SCANS`] old), and the echoes' plot scatter against the plot
//!   accuracy the tracker is given. Measured and printed (docs/radar.md); asserted as bounds
//!   on the 4G harbour, the Garmin (whose heading is the fixed one turned by own ship's yaw
//!   measured from the picture) and the HALO VelocityTrack harbour, at the values reached on
//!   these same captures (guards against going back, not a validation).
//! - Per capture, the targets shown at 5 kn or more (tracks, target-scans, those with the
//!   CPA/TCPA alarm): in the harbours nearly all false (docs/radar.md); printed, and bounded
//!   in the two dense harbours (4G, HALO VelocityTrack).
//! - The HALO capture's AIS ships under way against the plots, per range band, with the
//!   checks of time alignment, turning direction and systematic offsets.
//! - The sizes of the echoes the extractor closes, by the detections they hold: what the
//!   point/extended limits were chosen on.

use std::path::PathBuf;

use tracker_core::filter::FilterKind;
use tracker_core::geo;
use tracker_host::app::run::Run;
use tracker_host::app::track::{self, TrackInput, TrackOptions};
use tracker_host::app::{Outputs, OwnShipOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::radar::RadarSpec;
use tracker_host::session::target::AlarmLimits;
use tracker_host::session::ScanReport;
use tracker_host::source::radar::{plot_sigma_m, CaptureSurvey, RadarOptions};

mod realdata;

fn capture(name: &str) -> PathBuf {
    realdata::file(&format!("radar/{name}"))
}

/// The bytes of the gzipped capture `name`, a classic little-endian pcap: a 24-byte header,
/// then records of a 16-byte header (seconds, microseconds, length kept, length on the
/// wire) and the frame.
fn pcap_bytes(name: &str) -> Vec<u8> {
    use std::io::Read;
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(capture(name)).unwrap())
        .read_to_end(&mut bytes)
        .unwrap();
    assert_eq!(bytes[..4], [0xd4, 0xc3, 0xb2, 0xa1]);
    bytes
}

/// A GNSS's log over the Garmin capture's time: `RMC` every second from 2017-10-19
/// 16:04:50Z for two minutes, stopped at `position` (`DDMM.MMMMM,N,DDDMM.MMMMM,W`), no
/// heading.
fn garmin_gnss_log(position: &str) -> String {
    (0..120)
        .map(|k| {
            let (minute, second) = (4 + (50 + k) / 60, (50 + k) % 60);
            sentence(&format!(
                "GPRMC,16{minute:02}{second:02}.00,A,{position},0.0,,191017,,,A"
            ))
        })
        .collect()
}

/// The NMEA sentence of `body` (between `$` and `*`), with its checksum and line end.
fn sentence(body: &str) -> String {
    let sum = body.bytes().fold(0u8, |a, b| a ^ b);
    format!("${body}*{sum:02X}\r\n")
}

const KNOT_MPS: f32 = 1852.0 / 3600.0;

/// One capture tracked to its end.
struct Tracked {
    reports: Vec<ScanReport>,
    run: Run,
    /// The capture's first spoke's range, m.
    first_range_m: f32,
}

/// Own ship from the NMEA recording at `path` (`--nmea-in file:PATH`).
fn nmea_file(path: PathBuf) -> OwnShipOptions {
    OwnShipOptions {
        nmea_in: Some(tracker_host::nmea::input::InSpec::File(path)),
        ..OwnShipOptions::default()
    }
}

fn track(name: &str, heading_deg: Option<f32>) -> Tracked {
    track_with(name, heading_deg, OwnShipOptions::default())
}

/// … with own ship from `own_ship` (`--nmea-in`).
fn track_with(name: &str, heading_deg: Option<f32>, own_ship: OwnShipOptions) -> Tracked {
    track_path(capture(name), heading_deg, own_ship)
}

/// … of the capture at `path`.
fn track_path(path: PathBuf, heading_deg: Option<f32>, own_ship: OwnShipOptions) -> Tracked {
    let name = path.display().to_string();
    let mut radar = RadarOptions::new(RadarSpec::Capture(path.clone()));
    radar.fixed_heading_rad = heading_deg.map(f32::to_radians);
    let options = TrackOptions {
        input: TrackInput::Radar(radar),
        filter: FilterKind::KalmanCv,
        association: Default::default(),
        alarms: AlarmLimits::default(),
        own_ship,
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
    let first_range_m = CaptureSurvey::of(&path).unwrap().first_range_m.unwrap();
    Tracked {
        reports,
        run,
        first_range_m,
    }
}

/// A track's velocity is read once it has had this many scans: by then a CV Kalman
/// track's velocity variance is within 1 % of its steady state (0.605 against 0.603 m/s per
/// axis for 5 m plots every 2.5 s, q 0.05 m²/s³), so what it shows is what it will show.
const SETTLED_SCANS: u16 = 10;

/// The least radius within which a stationary echo's plots stay, m.
const STATIONARY_RADIUS_M: f32 = 10.0;

/// The stationary point echoes and the speeds their tracks show.
#[derive(Debug, Default)]
struct Stationary {
    /// Point plots of the last whole scan with a point plot within the radius in at least
    /// 80 % of the whole scans.
    echoes: usize,
    /// … with a settled track (at least [`SETTLED_SCANS`] old) within the radius showing
    /// under 1 kn …
    slow: usize,
    /// … showing 1 kn or more …
    fast: usize,
    /// … with a track within the radius not yet settled …
    unsettled: usize,
    /// … with no track within the radius.
    untracked: usize,
    /// The settled tracks' speeds, kn, sorted.
    speeds_kn: Vec<f32>,
    /// The echoes' plots' distances from their own mean position, every whole scan
    /// (their scatter, against the tracker's plot accuracy), m, sorted.
    scatter_m: Vec<f32>,
}

/// The stationary point echoes of `reports` (the whole scans: the first is a partial
/// rotation; a capture's cut last one is not tracked) and their tracks, found within
/// `radius_m`.
fn stationary(reports: &[ScanReport], radius_m: f32) -> Stationary {
    let mut out = Stationary::default();
    let whole = reports.get(1..).unwrap_or(&[]);
    let Some(last) = whole.last() else {
        return out;
    };
    let distance = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    for p in &last.plots_m {
        let seen: Vec<[f32; 2]> = whole
            .iter()
            .filter_map(|r| {
                r.plots_m
                    .iter()
                    .copied()
                    .min_by(|a, b| distance(*a, *p).total_cmp(&distance(*b, *p)))
                    .filter(|q| distance(*q, *p) <= radius_m)
            })
            .collect();
        if (seen.len() as f64) < 0.8 * whole.len() as f64 {
            continue;
        }
        out.echoes += 1;
        let n = seen.len() as f32;
        let mean = seen
            .iter()
            .fold([0.0, 0.0], |m, q| [m[0] + q[0] / n, m[1] + q[1] / n]);
        out.scatter_m
            .extend(seen.iter().map(|q| distance(*q, mean)));
        let track = last
            .targets
            .iter()
            .filter(|t| distance(t.position_m, *p) <= radius_m)
            .min_by(|a, b| distance(a.position_m, *p).total_cmp(&distance(b.position_m, *p)));
        match track {
            None => out.untracked += 1,
            Some(t) if t.age_scans < SETTLED_SCANS => out.unsettled += 1,
            Some(t) => {
                if t.speed_mps >= KNOT_MPS && std::env::var_os(ECHO_HISTORY).is_some() {
                    print_echo_history(reports, *p, t.track, t.speed_mps, 3.0 * radius_m);
                }
                out.speeds_kn.push(t.speed_mps / KNOT_MPS);
                if t.speed_mps < KNOT_MPS {
                    out.slow += 1;
                } else {
                    out.fast += 1;
                }
            }
        }
    }
    out.speeds_kn.sort_by(f32::total_cmp);
    out.scatter_m.sort_by(f32::total_cmp);
    out
}

/// Set (to anything) to print, for every stationary echo whose track shows 1 kn or more,
/// the echo's scans: the plots near it (`*`: started a track) and the tracks near it with
/// their status, age, hits (last scan rightmost), position from the echo, velocity and the
/// plot each took. How the echoes over 1 kn in docs/radar.md were followed.
const ECHO_HISTORY: &str = "TRACKER_ECHO_HISTORY";

/// The hit history's scans a track reports (bit 0 the last), as printed.
const HIT_HISTORY_MASK: u16 = (1 << tracker_core::track::KEEP_N) - 1;

/// Prints the scans around `at` (m, local frame: the echo's plot of the last whole scan),
/// within `within_m` of it; `track_id` is the track read there, showing `speed_mps`.
fn print_echo_history(
    reports: &[ScanReport],
    at: [f32; 2],
    track_id: u16,
    speed_mps: f32,
    within_m: f32,
) {
    let offset = |q: [f32; 2]| [q[0] - at[0], q[1] - at[1]];
    let near = |q: [f32; 2]| {
        let d = offset(q);
        d[0].hypot(d[1]) < within_m
    };
    println!(
        "echo at ({:.1}, {:.1}) m: track {track_id} shows {:.2} kn",
        at[0],
        at[1],
        speed_mps / KNOT_MPS
    );
    for r in reports {
        let plots: Vec<String> = r
            .plots_m
            .iter()
            .enumerate()
            .filter(|(_, q)| near(**q))
            .map(|(i, q)| {
                let d = offset(*q);
                let started = u16::try_from(i).is_ok_and(|i| r.association.initiate.contains(&i));
                format!(
                    "p{i} ({:.1}, {:.1}){}",
                    d[0],
                    d[1],
                    if started { "*" } else { "" }
                )
            })
            .collect();
        let tracks: Vec<String> = r
            .tracks
            .iter()
            .filter(|k| near(k.position_m))
            .map(|k| {
                let took = r
                    .association
                    .assignments
                    .iter()
                    .find(|a| a.track == k.track)
                    .and_then(|a| a.plot);
                let d = offset(k.position_m);
                format!(
                    "T{} {:?} age {} hits {:010b} at ({:.1}, {:.1}) v ({:.2}, {:.2}) took {took:?}",
                    k.track,
                    k.status,
                    k.age_scans,
                    k.hit_history & HIT_HISTORY_MASK,
                    d[0],
                    d[1],
                    k.velocity_mps[0],
                    k.velocity_mps[1]
                )
            })
            .collect();
        println!(
            "  scan {}: {} | {}",
            r.scan,
            plots.join(" "),
            tracks.join("; ")
        );
    }
}

/// A target shown at this speed or more is counted as fast: in the harbour captures
/// nothing but the odd boat under way moves, so most such targets are false, m/s (5 kn).
const FAST_MPS: f32 = 5.0 * KNOT_MPS;

/// Targets shown with their motion ([`TargetData::trend_known`]) at [`FAST_MPS`] or more
/// (their true speed, or the relative one where own ship's motion is unknown): distinct
/// tracks, target-scans, and those with the CPA/TCPA alarm raised; and the target-scans of
/// confirmed targets at that speed whose motion is not shown yet.
fn fast_targets(reports: &[ScanReport]) -> ((usize, usize, usize), usize) {
    let mut tracks = std::collections::BTreeSet::new();
    let (mut scans, mut alarmed, mut unshown) = (0, 0, 0);
    let limits = AlarmLimits::default();
    for r in reports {
        for t in &r.targets {
            let speed = if t.true_motion_known {
                t.speed_mps
            } else {
                t.rel_speed_mps
            };
            if speed < FAST_MPS {
                continue;
            }
            if !t.trend_known {
                unshown += 1;
                continue;
            }
            tracks.insert(t.track);
            scans += 1;
            if t.dangerous(&limits) {
                alarmed += 1;
            }
        }
    }
    ((tracks.len(), scans, alarmed), unshown)
}

/// The value at quantile `q` of sorted `v`, NaN for none.
fn quantile(v: &[f32], q: f64) -> f32 {
    if v.is_empty() {
        return f32::NAN;
    }
    v[((v.len() - 1) as f64 * q).round() as usize]
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
        "| capture | scans | period s | farthest plot m | point plots/scan | extended/scan | targets shown | stationary echoes (radius m) | settled tracks < 1 kn | ≥ 1 kn | tracks not settled | untracked | settled speeds, median / max kn | echo scatter, median / 95 % m (plot σ m) | tracks shown ≥ 5 kn (target-scans, with CPA alarm) + target-scans ≥ 5 kn without their motion shown yet |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, heading) in captures {
        let t = track(name, heading);
        let report = t.run.report("inproc");
        let radar = report.radar.clone().expect("a radar source counts");
        let period = t.run.scan_period_s().unwrap_or(f64::NAN);
        let range = t
            .reports
            .iter()
            .flat_map(|r| r.plots.iter().map(|p| p.range_m))
            .fold(0.0f32, f32::max);
        // An echo "sits still" when its plots stay within 10 m or 1 % of the range scale,
        // whichever is more (apart from the tracker's settings, so that changing them does
        // not change which echoes are counted).
        let sigma = plot_sigma_m(t.first_range_m);
        let radius = STATIONARY_RADIUS_M.max(0.01 * t.first_range_m);
        let s = stationary(&t.reports, radius);
        let (fast, fast_unshown) = fast_targets(&t.reports);
        println!(
            "| {name} | {} | {period:.2} | {range:.0} | {:.1} | {:.1} | {} | {} ({radius:.0}) | {} | {} | {} | {} | {:.2} / {:.2} | {:.2} / {:.2} ({sigma:.1}) | {} ({}, {}) + {fast_unshown} |",
            report.scans,
            radar.plots_per_scan(),
            radar.extended_per_scan(),
            report.targets_seen,
            s.echoes,
            s.slow,
            s.fast,
            s.unsettled,
            s.untracked,
            quantile(&s.speeds_kn, 0.5),
            quantile(&s.speeds_kn, 1.0),
            quantile(&s.scatter_m, 0.5),
            quantile(&s.scatter_m, 0.95),
            fast.0,
            fast.1,
            fast.2,
        );
        if radar.yaw_measured + radar.yaw_unmatched > 0 {
            println!(
                "|   ({name}: own ship's yaw from the picture, {} rotations measured, {} with too few plots, {:+.1}° at the end) |",
                radar.yaw_measured, radar.yaw_unmatched, radar.yaw_deg
            );
        }
        // What was achieved, as bounds that fail when it goes back (docs/radar.md): the 4G
        // harbour's stationary echoes all with a settled track under 1 kn but one at most,
        // at most one over (two before targets standing still were shown so; none before
        // the track score: two in clusters of echoes 6–8 m apart, whose tracks are
        // confirmed later and then trade plots, docs/radar.md); the
        // Garmin's (moored, swinging, no heading: its yaw measured from the
        // picture) no more than 1 over 1 kn, at least 10 under, their plots' scatter about
        // their mean under half what it was with the fixed heading alone (10.7 m median); the
        // HALO harbour's none over 1 kn, at least 9 under. The plot σ (0.25 % of the range)
        // was chosen on these captures: the bounds guard what was reached, no more.
        // Since a heading sensor heard before the first fix places the first scans' plots
        // (2026-12-06), the 4G's stationary echoes all have a settled track under 1 kn (6
        // and 1 over at 1.61 kn before).
        if name.starts_with("radar_pi-4g") {
            assert!(s.fast == 0 && s.slow == s.echoes, "{name}: {s:?}");
        }
        // A target found standing still is shown so (`session::stationary`): the settled
        // tracks' median speed on the 4G's, the Garmin's and the HALO harbour's stationary
        // echoes fell from 0.25, 0.57 and 0.30 kn to 0, and the 4G's second echo over 1 kn
        // (1.70 kn) went under.
        if name.starts_with("radar_pi-4g")
            || name.starts_with("radar_pi-garmin")
            || name.starts_with("radar_pi-halo-velocitytrack")
        {
            assert!(quantile(&s.speeds_kn, 0.5) < 0.1, "{name}: {s:?}");
        }
        // The targets shown with their motion at 5 kn or more in the two dense harbours,
        // nearly all false: 305 and 184 target-scans before the track score (a tentative
        // track confirmed only once its plots are more likely a target's than chance's
        // among the plots around it) and the trend (a target's motion shown once its
        // velocity is known); 18 and 12 with the score alone, 220 and 119 with the trend
        // alone, 12 and 6 with both: the bounds fail without either. The 4G's 12 became
        // none with protocol 6 (its gates are a few metres, and their Cholesky factor went
        // in tenths of a metre): its bound fails with the factor in tenths too.
        if name.starts_with("radar_pi-4g") {
            assert!(fast.1 <= 6, "{name}: fast targets {fast:?}");
        }
        if name.starts_with("radar_pi-halo-velocitytrack") {
            assert!(fast.1 <= 8, "{name}: fast targets {fast:?}");
        }
        if name.starts_with("radar_pi-garmin") {
            assert!(s.fast <= 1 && s.slow >= 10, "{name}: {s:?}");
            assert!(quantile(&s.scatter_m, 0.5) < 5.3, "{name}: {s:?}");
            assert!(
                radar.yaw_measured + 3 >= report.scans,
                "{name}: yaw measured on {} rotations of {}",
                radar.yaw_measured,
                report.scans
            );
        }
        if name.starts_with("radar_pi-halo-velocitytrack") {
            assert!(s.fast == 0 && s.slow >= 9, "{name}: {s:?}");
        }
        assert!(report.scans >= 3, "{name}: {} scans", report.scans);
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

/// One AIS ship under way at one whole rotation, against the plots: positions relative to
/// own ship, m (east, north).
#[derive(Clone, Copy, Debug)]
struct AisPair {
    /// The scan.
    scan: u32,
    /// The AIS position, extrapolated to the time the antenna swept its bearing.
    ais_m: [f32; 2],
    /// The same at the scan's time (the wrap).
    ais_at_scan_m: [f32; 2],
}

/// For the AIS ships under way (over 2 kn, a position under 30 s old) inside the radar's
/// reach (its farthest plot), every whole rotation: the AIS position extrapolated along its
/// course to the moment the antenna swept its bearing (the scan's time is the wrap through
/// the bow; the antenna turns clockwise, so a bearing θ from the bow was swept a fraction
/// 1 − θ/360° of a period before it) and at the scan's time.
fn ais_pairs(reports: &[ScanReport], period_s: f32) -> Vec<AisPair> {
    let mut out = Vec::new();
    // The first scan is a partial rotation (the capture starts mid-rotation; its cut last
    // one is not tracked): a ship in the part not swept has no plot.
    let whole = reports.get(1..).unwrap_or(&[]);
    for r in whole {
        let heading = r.own.heading_rad.unwrap_or(0.0);
        let reach = r.plots.iter().map(|p| p.range_m).fold(0.0f32, f32::max);
        let own = r.own.position_m;
        for a in &r.ais {
            let speed = a.velocity_mps[0].hypot(a.velocity_mps[1]);
            if speed < 2.0 * KNOT_MPS || a.range_m > reach || a.age_s > 30.0 {
                continue;
            }
            let from_bow = geo::wrap_2pi(a.bearing_rad - heading);
            let lag_s = period_s * (1.0 - from_bow / core::f32::consts::TAU);
            let at = |lag: f32| {
                [
                    a.position_m[0] - a.velocity_mps[0] * lag - own[0],
                    a.position_m[1] - a.velocity_mps[1] * lag - own[1],
                ]
            };
            out.push(AisPair {
                scan: r.scan,
                ais_m: at(lag_s),
                ais_at_scan_m: at(0.0),
            });
        }
    }
    out
}

/// The plots of scan `scan` relative to own ship, turned by `turn_rad` (clockwise) and
/// moved out in range by `range_m`, or mirrored about the bow line (the antenna turning the
/// other way) when `mirrored`.
fn plots_as(r: &ScanReport, turn_rad: f32, range_m: f32, mirrored: bool) -> Vec<[f32; 2]> {
    let heading = r.own.heading_rad.unwrap_or(0.0);
    r.plots
        .iter()
        .map(|p| {
            let mut b = p.bearing_rad + turn_rad;
            if mirrored {
                b = 2.0 * heading - b;
            }
            let range = p.range_m + range_m;
            [range * b.sin(), range * b.cos()]
        })
        .collect()
}

/// The distance from `at` to the nearest of `plots`, m.
fn nearest_m(plots: &[[f32; 2]], at: [f32; 2]) -> f32 {
    plots
        .iter()
        .map(|p| (p[0] - at[0]).hypot(p[1] - at[1]))
        .fold(f32::INFINITY, f32::min)
}

/// Distances (as a fraction of range) from each pair's AIS position to the nearest plot of
/// its scan as `plots` gives them, and the pairs' ranges, m.
fn fractions(
    reports: &[ScanReport],
    pairs: &[AisPair],
    at_sweep: bool,
    plots: impl Fn(&ScanReport) -> Vec<[f32; 2]>,
) -> Vec<(f32, f32)> {
    pairs
        .iter()
        .filter_map(|p| {
            let r = reports.iter().find(|r| r.scan == p.scan)?;
            let at = if at_sweep { p.ais_m } else { p.ais_at_scan_m };
            let range = at[0].hypot(at[1]).max(1.0);
            Some((nearest_m(&plots(r), at) / range, range))
        })
        .collect()
}

/// The mean plot-minus-AIS bearing (rad, clockwise positive) and range (m) offsets of the
/// pairs whose nearest plot lies within 5 % of range, each with its standard error and
/// standard deviation.
fn offsets(reports: &[ScanReport], pairs: &[AisPair]) -> ([f32; 3], [f32; 3], usize) {
    let mut db = Vec::new();
    let mut dr = Vec::new();
    for p in pairs {
        let Some(r) = reports.iter().find(|r| r.scan == p.scan) else {
            continue;
        };
        let plots = plots_as(r, 0.0, 0.0, false);
        let range = p.ais_m[0].hypot(p.ais_m[1]);
        let Some(q) = plots.iter().copied().min_by(|a, b| {
            let d = |x: &[f32; 2]| (x[0] - p.ais_m[0]).hypot(x[1] - p.ais_m[1]);
            d(a).total_cmp(&d(b))
        }) else {
            continue;
        };
        if (q[0] - p.ais_m[0]).hypot(q[1] - p.ais_m[1]) > 0.05 * range {
            continue;
        }
        let bearing = |x: [f32; 2]| x[0].atan2(x[1]);
        db.push(geo::wrap_pi(bearing(q) - bearing(p.ais_m)));
        dr.push(q[0].hypot(q[1]) - range);
    }
    let stats = |v: &[f32]| {
        let n = v.len().max(1) as f32;
        let mean = v.iter().sum::<f32>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / (n - 1.0).max(1.0);
        [mean, (var / n).sqrt(), var.sqrt()]
    };
    (stats(&db), stats(&dr), db.len())
}

#[test]
fn ais_ships_under_way_in_the_captures_have_a_plot_near_them() {
    for name in [
        "mayara-halo_and_0183.pcap",
        "radar_pi-4g-noheading-merrimac.pcap.gz",
    ] {
        let t = track(name, None);
        let period = t.run.scan_period_s().unwrap_or(0.0) as f32;
        let pairs = ais_pairs(&t.reports, period);
        let report = t.run.report("inproc");
        let ais = report.ais.clone().expect("AIS heard in the capture");
        println!(
            "{name}: {} AIS targets, {} ship-scans under way in range, {} radar/AIS pairs made",
            ais.table.targets,
            pairs.len(),
            ais.pairing.paired
        );
        assert!(ais.sentences.decoded() > 100, "{name}: {}", ais.sentences);
        assert_eq!(
            ais.sentences.rejected_total(),
            0,
            "{name}: {}",
            ais.sentences
        );
        if pairs.is_empty() {
            continue;
        }
        let as_extracted = |r: &ScanReport| plots_as(r, 0.0, 0.0, false);
        let d = fractions(&t.reports, &pairs, true, as_extracted);
        println!("| range band km | ship-scans | plot within 2 % of range | within 5 % | median distance m | median, % of range |");
        println!("|---|---|---|---|---|---|");
        for (lo, hi) in [
            (0.0, 5e3),
            (5e3, 10e3),
            (10e3, 15e3),
            (15e3, 30e3),
            (0.0, 30e3),
        ] {
            let mut band: Vec<(f32, f32)> = d
                .iter()
                .copied()
                .filter(|(_, r)| (lo..hi).contains(r))
                .collect();
            if band.is_empty() {
                continue;
            }
            band.sort_by(|a, b| a.0.total_cmp(&b.0));
            let within = |f: f32| band.iter().filter(|(x, _)| *x <= f).count();
            let mut metres: Vec<f32> = band.iter().map(|(x, r)| x * r).collect();
            metres.sort_by(f32::total_cmp);
            let n = band.len();
            println!(
                "| {:.0}–{:.0} | {n} | {} ({:.0} %) | {} ({:.0} %) | {:.0} | {:.1} |",
                lo / 1e3,
                hi / 1e3,
                within(0.02),
                100.0 * within(0.02) as f32 / n as f32,
                within(0.05),
                100.0 * within(0.05) as f32 / n as f32,
                quantile(&metres, 0.5),
                100.0 * band[n / 2].0,
            );
        }
        let within = |v: &[(f32, f32)], f: f32| v.iter().filter(|(x, _)| *x <= f).count();
        let within5 = |v: &[(f32, f32)]| within(v, 0.05);
        let ([db, db_se, db_sd], [dr, dr_se, dr_sd], matched) = offsets(&t.reports, &pairs);
        let at_scan = fractions(&t.reports, &pairs, false, as_extracted);
        let mirrored = fractions(&t.reports, &pairs, true, |r| plots_as(r, 0.0, 0.0, true));
        // The offsets measured on one whole rotation's pairs, taken out of the other's
        // plots (never of the rotation they were measured on).
        let scans: Vec<u32> = pairs.iter().map(|p| p.scan).collect();
        let mut crossed = Vec::new();
        for s in scans
            .iter()
            .copied()
            .collect::<std::collections::BTreeSet<u32>>()
        {
            let (others, own): (Vec<AisPair>, Vec<AisPair>) =
                pairs.iter().partition(|p| p.scan != s);
            let ([b, ..], [r, ..], _) = offsets(&t.reports, &others);
            crossed.extend(fractions(&t.reports, &own, true, |rep| {
                plots_as(rep, -b, -r, false)
            }));
        }
        println!(
            "within 5 %: {} of {}; with AIS at the scan's time instead of its sweep: {}; plots mirrored about the bow line (antenna turning the other way): {}; \
             plot − AIS offsets over the {matched} pairs within 5 %: bearing {:+.2}° ± {:.2}° (s.d. {:.2}°), range {:+.0} m ± {:.0} m (s.d. {:.0} m); \
             those offsets (measured on the other rotation) taken out: {} of {} within 5 %, {} within 2 % (against {})",
            within5(&d),
            d.len(),
            within5(&at_scan),
            within5(&mirrored),
            db.to_degrees(),
            db_se.to_degrees(),
            db_sd.to_degrees(),
            dr,
            dr_se,
            dr_sd,
            within5(&crossed),
            crossed.len(),
            within(&crossed, 0.02),
            within(&d, 0.02),
        );
        // Guards against a wrong heading, range scale, frame or turning direction (which
        // put the ships tens of per cent of their range from any plot), not measures of
        // extraction quality: the HALO's figures are printed above and in docs/radar.md.
        if name.starts_with("mayara") {
            let mut sorted: Vec<f32> = d.iter().map(|(x, _)| *x).collect();
            sorted.sort_by(f32::total_cmp);
            assert!(within5(&d) * 10 >= d.len() * 4, "{name}: {d:?}");
            assert!(sorted[sorted.len() / 2] < 0.1, "{name}: {sorted:?}");
            assert!(
                within5(&mirrored) * 2 < within5(&d),
                "{name}: turning direction"
            );
            assert!(db.to_degrees().abs() < 2.0, "{name}: bearing offset {db}");
        }
    }
}

/// The sizes of the echoes the extractor closes on each capture (every whole rotation,
/// complete echoes): those holding one CFAR detection (mostly isolated buoys, boats and
/// ships) against those holding three or more (mostly quays, pontoons and coasts, whose
/// edges the CFAR breaks into pieces), the figures the point/extended limits of
/// `ExtractorConfig::classify` were chosen on.
#[test]
fn echo_sizes_by_detections() {
    use tracker_core::radar::{Event, Extractor, ExtractorConfig, RadarPlot};
    use tracker_host::radar::SpokeSource;
    println!("| capture | echoes with 1 detection: range cells p50 / p99 | cells p50 / p99 | width ° p50 / p99 | point | echoes with 3+: range cells p10 / p50 | cells p10 / p50 | width ° p10 / p50 | extended |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in [
        "mayara-halo_and_0183.pcap",
        "radar_pi-3g-trueheading.pcap.gz",
        "radar_pi-4g-noheading-merrimac.pcap.gz",
        "radar_pi-garmin_xhd.pcap.gz",
        "radar_pi-halo-velocitytrack-away.pcap.gz",
    ] {
        let mut spokes = SpokeSource::open(&RadarSpec::Capture(capture(name))).unwrap();
        let mut extractor: Option<Extractor> = None;
        let (mut rotation, mut closed) = (0u32, Vec::<(RadarPlot, bool)>::new());
        while let Some((spoke, _)) = spokes.next_spoke().unwrap() {
            let x = extractor.get_or_insert_with(|| {
                let config = if spoke.max_sample == 15 {
                    ExtractorConfig::navico_4bit()
                } else {
                    ExtractorConfig::garmin_xhd()
                };
                Extractor::new(config).unwrap()
            });
            // Sizes do not depend on the heading: bearings from the bow will do.
            let mut s = spoke;
            s.heading_rad = s.heading_rad.or(Some(0.0));
            let whole = rotation >= 1;
            x.push(&s, |e| match e {
                Event::Wrap { .. } => rotation += 1,
                Event::Plot(p) if whole && !p.partial => closed.push((p, true)),
                Event::Extended(p) if whole && !p.partial => closed.push((p, false)),
                _ => {}
            });
        }
        fn q(mut v: Vec<f32>, p: f64) -> f32 {
            v.sort_by(f32::total_cmp);
            v.get(((v.len() as f64 * p) as usize).min(v.len().saturating_sub(1)))
                .copied()
                .unwrap_or(f32::NAN)
        }
        fn col(v: &[(RadarPlot, bool)], f: fn(&RadarPlot) -> f32) -> Vec<f32> {
            v.iter().map(|(p, _)| f(p)).collect()
        }
        fn rc(p: &RadarPlot) -> f32 {
            f32::from(p.range_cells)
        }
        fn cells(p: &RadarPlot) -> f32 {
            p.cells as f32
        }
        fn deg(p: &RadarPlot) -> f32 {
            p.angular_extent_rad.to_degrees()
        }
        let (one, many): (Vec<_>, Vec<_>) = closed
            .iter()
            .copied()
            .filter(|(p, _)| p.detections != 2)
            .partition(|(p, _)| p.detections == 1);
        let points = one.iter().filter(|(_, point)| *point).count();
        let extended = many.iter().filter(|(_, point)| !*point).count();
        println!(
            "| {name} | {:.0} / {:.0} | {:.0} / {:.0} | {:.1} / {:.1} | {points} of {} | {:.0} / {:.0} | {:.0} / {:.0} | {:.1} / {:.1} | {extended} of {} |",
            q(col(&one, rc), 0.5),
            q(col(&one, rc), 0.99),
            q(col(&one, cells), 0.5),
            q(col(&one, cells), 0.99),
            q(col(&one, deg), 0.5),
            q(col(&one, deg), 0.99),
            one.len(),
            q(col(&many, rc), 0.1),
            q(col(&many, rc), 0.5),
            q(col(&many, cells), 0.1),
            q(col(&many, cells), 0.5),
            q(col(&many, deg), 0.1),
            q(col(&many, deg), 0.5),
            many.len(),
        );
        // Most single detections are points, most many-piece echoes extended: the limits
        // sit between the two.
        assert!(
            points * 10 >= one.len() * 9,
            "{name}: {points} of {}",
            one.len()
        );
        assert!(
            extended * 10 >= many.len() * 6,
            "{name}: {extended} of {}",
            many.len()
        );
    }
}

/// The 4G capture ends part way through a rotation: that rotation is counted and not
/// tracked (its unswept sector's targets would each miss a plot), so the last scan is a
/// whole rotation, its plots and its picture all round the harbour.
#[test]
fn the_cut_last_rotation_is_counted_not_tracked() {
    let t = track("radar_pi-4g-noheading-merrimac.pcap.gz", None);
    let radar = t.run.report("inproc").radar.expect("a radar source counts");
    assert!(radar.last_rotation_cut_plots > 0, "{radar}");
    // Eighths of the circle holding echoes of half scale or more, and plots.
    let echo_sectors = |r: &ScanReport| -> usize {
        let image = r.echoes.as_ref().expect("a radar scan carries its picture");
        let mut seen = [false; 8];
        for (bearing_rad, _, _) in image.echoes(0.5) {
            seen[((bearing_rad / std::f32::consts::TAU * 8.0) as usize).min(7)] = true;
        }
        seen.iter().filter(|s| **s).count()
    };
    let plot_sectors = |r: &ScanReport| -> usize {
        let mut seen = [false; 8];
        for p in &r.plots {
            seen[((p.bearing_rad / std::f32::consts::TAU * 8.0) as usize).min(7)] = true;
        }
        seen.iter().filter(|s| **s).count()
    };
    let last = t.reports.last().expect("scans");
    assert!(
        echo_sectors(last) >= 6,
        "echoes in {} of 8",
        echo_sectors(last)
    );
    assert!(
        plot_sectors(last) >= 6,
        "plots in {} of 8",
        plot_sectors(last)
    );
}

/// Own ship from `--nmea-in` without a heading (the 4G capture's TCP NMEA, positions only)
/// and a heading sensor whose `HDG` the capture holds beside the spokes: the plots are placed
/// with that heading, and own ship shows it too, as without `--nmea-in` (a new user's trial
/// read `HDG ---` and no `HDT` to the plotter while the plots were placed with 183.8°).
#[test]
fn a_heading_in_the_capture_is_own_ships_with_nmea_in_too() {
    let name = "radar_pi-4g-noheading-merrimac.pcap.gz";
    let alone = track(name, None);
    let nmea_in = nmea_file(realdata::file(
        "nmea/radar_pi-4g-noheading-merrimac-tcp2000.log",
    ));
    let with = track_with(name, None, nmea_in);
    assert_eq!(alone.reports.len(), with.reports.len());
    let mut both = 0;
    for (a, w) in alone.reports.iter().zip(&with.reports) {
        assert_eq!(
            a.own.heading_rad.is_some(),
            w.own.heading_rad.is_some(),
            "scan {}",
            a.scan
        );
        if let (Some(x), Some(y)) = (a.own.heading_rad, w.own.heading_rad) {
            both += 1;
            assert!((x - y).abs() < 1e-4, "scan {}: {x} against {y}", a.scan);
            assert!(!w.own.quality.heading_needed, "scan {}", a.scan);
        }
    }
    assert!(
        both + 2 >= with.reports.len(),
        "a heading on {both} of {} scans",
        with.reports.len()
    );
    // The summary says where own ship came from: the capture's NMEA, counted, its sources
    // told as events (it said nothing: a new user's trial).
    let (alone, with) = (alone.run.report("inproc"), with.run.report("inproc"));
    let capture_nmea = alone.radar.as_ref().and_then(|r| r.capture_nmea.clone());
    assert!(capture_nmea.is_some_and(|c| c.used > 0));
    assert!(
        alone
            .events
            .iter()
            .any(|e| e.starts_with("the capture's NMEA: heading source")),
        "{:?}",
        alone.events
    );
    // The capture's AIS and the same recording's on --nmea-in: each message taken once,
    // the AIS table as without --nmea-in (every sentence was counted twice).
    let (a, w) = (alone.ais.unwrap(), with.ais.unwrap());
    assert_eq!(a.heard_twice, 0);
    let reports = a.sentences.decoded();
    assert_eq!(w.sentences.sentences, 2 * a.sentences.sentences);
    assert!(
        w.heard_twice * 10 >= reports * 9 && w.heard_twice <= reports,
        "{} of {reports} heard twice",
        w.heard_twice
    );
    assert_eq!(a.table, w.table);
}

/// A moored radar's given heading (`--heading-deg`, the Garmin's spokes having none) with
/// own ship from `--nmea-in` whose GNSS gives no heading: own ship shows the heading its
/// plots were placed with, as without `--nmea-in` (it showed `HDG ---` every scan). And an
/// NMEA log of another voyage beside it (the 4G's, two years older, with its transponder's
/// untimed `AIVDO`s) does not flip own ship's position between its GNSS and the
/// transponder every scan (two events a scan before).
#[test]
fn a_given_heading_is_own_ships_with_a_gnss_on_nmea_in() {
    let name = "radar_pi-garmin_xhd.pcap.gz";
    let dir = tempfile::tempdir().unwrap();
    let gnss = dir.path().join("gnss.log");
    std::fs::write(&gnss, garmin_gnss_log("5048.30720,N,00117.90400,W")).unwrap();
    let alone = track(name, Some(0.0));
    let with = track_with(name, Some(0.0), nmea_file(gnss));
    assert_eq!(alone.reports.len(), with.reports.len());
    assert!(with.reports.len() >= 30);
    for (a, w) in alone.reports.iter().zip(&with.reports) {
        assert!(!w.own.quality.no_fix_yet, "scan {}", w.scan);
        let (x, y) = (a.own.heading_rad, w.own.heading_rad);
        let (Some(x), Some(y)) = (x, y) else {
            panic!("scan {}: headings {x:?} and {y:?}", w.scan)
        };
        assert!((x - y).abs() < 1e-3, "scan {}: {x} against {y}", w.scan);
        assert_eq!(a.plots_m.len(), w.plots_m.len(), "scan {}", w.scan);
        // Shown as given, not a sensor's, either way.
        for own in [&a.own, &w.own] {
            let line = tracker_host::display::own_ship_line(own);
            assert!(line.contains("MAN"), "scan {}: {line}", w.scan);
        }
    }
    let other = track_with(
        name,
        Some(0.0),
        nmea_file(realdata::file(
            "nmea/radar_pi-4g-noheading-merrimac-tcp2000.log",
        )),
    );
    let events = other.run.report("inproc").events;
    assert!(
        !events
            .iter()
            .any(|e| e.contains("not the AIS transponder's")),
        "{events:?}"
    );
    let sources = events.iter().filter(|e| e.contains(" source: ")).count();
    assert!(sources <= 6, "{sources} events of source: {events:?}");
}

/// A capture without NMEA (the Garmin's) with own ship from an NMEA recording on
/// `--nmea-in` made far from the default origin (Sydney): the frame's origin is the
/// recording's first fix, as the README says, and the plots are tracked (a new user's trial:
/// every scan's plots refused, own ship 14,257 km from the origin).
#[test]
fn a_recordings_first_fix_is_the_origin_for_a_capture_without_one() {
    let dir = tempfile::tempdir().unwrap();
    let gnss = dir.path().join("sydney.log");
    std::fs::write(&gnss, garmin_gnss_log("3351.00000,S,15112.00000,E")).unwrap();
    let t = track_with("radar_pi-garmin_xhd.pcap.gz", Some(0.0), nmea_file(gnss));
    assert!(t.reports.len() >= 30);
    for r in &t.reports[1..] {
        let [east, north] = r.own.position_m;
        assert!(east.hypot(north) < 100.0, "scan {}: {east} {north}", r.scan);
        assert!(!r.own.quality.no_fix_yet, "scan {}", r.scan);
        assert!(!r.plots.is_empty(), "scan {}: no plots", r.scan);
        assert!(
            !r.own
                .alarms()
                .iter()
                .any(|a| a.contains("from the frame's origin")),
            "scan {}: {:?}",
            r.scan,
            r.own.alarms()
        );
    }
}

/// A heading sensor lost mid-run while the radar's own heading (flagged true in the 3G's
/// spokes) goes on: the plots stay placed, and own ship says the radar's heading is in use
/// (it took over in silence when own ship came from the capture's own NMEA). The capture's
/// NMEA heading is its `IIHDM,001,M` (magnetic, with no variation known: not used) and an
/// `APHDT` flagged `M` (refused), so the test makes the sensor: the `HDM`s of its first
/// 4.5 s (at 1.7 and 4.2 s; its scans close at 12.5–22.5 s) are rewritten as the true
/// `IIHDT,001,T` (same length and checksum), and every heading after them dropped (`HDT`,
/// `HDM`, `HDG`, `VHW`, and the transponder's own `AIVDO`).
#[test]
fn a_lost_heading_sensor_replaced_by_the_radars_is_told() {
    let bytes = pcap_bytes("radar_pi-3g-trueheading.pcap.gz");
    let u32_at = |b: &[u8], i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    let mut doctored = bytes[..24].to_vec();
    let (mut at, mut first_s, mut dropped, mut made) = (24, None, 0, 0);
    while at + 16 <= bytes.len() {
        let t_s = f64::from(u32_at(&bytes, at)) + f64::from(u32_at(&bytes, at + 4)) * 1e-6;
        let end = at + 16 + u32_at(&bytes, at + 8) as usize;
        let record = &bytes[at..end.min(bytes.len())];
        let heading = [&b"HDT,"[..], b"HDM,", b"HDG,", b"VHW,", b"VDO,"]
            .iter()
            .any(|h| record.windows(4).any(|w| w == *h));
        if heading && t_s - *first_s.get_or_insert(t_s) > 4.5 {
            dropped += 1;
        } else {
            let (hdm, hdt) = (b"$IIHDM,001,M*3D", b"$IIHDT,001,T*3D");
            let mut record = record.to_vec();
            if let Some(i) = record.windows(hdm.len()).position(|w| w == hdm) {
                record[i..i + hdt.len()].copy_from_slice(hdt);
                made += 1;
            }
            doctored.extend_from_slice(&record);
        }
        at = end;
    }
    assert!(dropped > 10, "{dropped} heading sentences dropped");
    assert_eq!(made, 2, "HDTs made");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("3g-heading-lost.pcap");
    std::fs::write(&path, &doctored).unwrap();
    let t = track_path(path, None, OwnShipOptions::default());
    let told: Vec<bool> = t
        .reports
        .iter()
        .map(|r| r.own.quality.heading_from_radar)
        .collect();
    // Lost 10 s after its last sentence (`HEADING_LOST_S`), at 14.2 s: told from then to
    // the end.
    let first_told = told.iter().position(|x| *x).expect("never told");
    assert!(first_told >= 1, "told from scan {first_told}: {told:?}");
    assert!(told[first_told..].iter().all(|x| *x), "{told:?}");
    for r in &t.reports {
        assert!(r.own.heading_rad.is_some(), "scan {}: no heading", r.scan);
        assert!(!r.own.quality.heading_lost, "scan {}: heading lost", r.scan);
        assert!(!r.own.quality.heading_needed, "scan {}", r.scan);
    }
    assert!(t.reports[first_told]
        .own
        .alarms()
        .iter()
        .any(|a| a.contains("the radar's heading in use")));
}

/// A radar's own heading (flagged true in the HALO VelocityTrack capture's spokes, its only
/// heading) that stops mid-run: held for `HEADING_LOST_S` (10 s) as a heading sensor's is,
/// then lost: own ship's heading goes, with its alarm, and the head-up plots are no longer
/// placed. (The last heading was held for ever: own ship showed it, and the next spokes were
/// placed with it, without an alarm.) A fixed heading given stands in then, with the alarm;
/// a gyro on `--nmea-in` places the spokes throughout. The test cuts the flag: from 6 s
/// after the first spoke on, every spoke header's heading field is set to 0x8000 (no
/// heading).
#[test]
fn a_radars_heading_that_stops_is_lost_not_held() {
    let mut bytes = pcap_bytes("radar_pi-halo-velocitytrack-away.pcap.gz");
    // Ethernet frames. The spoke datagrams (UDP to port 7059, 17,168 bytes)
    // come in IPv4 fragments: a spoke's heading field is at byte 8 + 8 + 536·k + 10 of the
    // datagram (UDP header, frame header, spoke k's header), never across two fragments
    // (fragments start at multiples of 8; the field at 2 past one).
    let u32_at = |b: &[u8], i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    let be16 = |b: &[u8], i: usize| u16::from_be_bytes([b[i], b[i + 1]]);
    let (mut at, mut spoke_ids, mut cut_s, mut cut) = (24, Vec::new(), None, 0);
    while at + 16 <= bytes.len() {
        let t_s = f64::from(u32_at(&bytes, at)) + f64::from(u32_at(&bytes, at + 4)) * 1e-6;
        let frame = at + 16;
        let end = frame + u32_at(&bytes, at + 8) as usize;
        at = end;
        let ip = frame + 14;
        if end > bytes.len() || bytes[frame + 12..frame + 14] != [8, 0] || bytes[ip + 9] != 17 {
            continue;
        }
        let header_len = usize::from(bytes[ip] & 0x0F) * 4;
        let (id, offset) = (
            be16(&bytes, ip + 4),
            usize::from(be16(&bytes, ip + 6) & 0x1FFF) * 8,
        );
        let payload = ip + header_len;
        if offset == 0 && be16(&bytes, payload + 2) == 7059 && be16(&bytes, payload + 4) == 17_168 {
            spoke_ids.push(id);
        }
        if !spoke_ids.contains(&id) || t_s < *cut_s.get_or_insert(t_s + 6.0) {
            continue;
        }
        for k in 0..32 {
            let field = 8 + 8 + 536 * k + 10;
            if (offset..offset + end - payload).contains(&field) {
                let i = payload + field - offset;
                bytes[i..i + 2].copy_from_slice(&0x8000u16.to_le_bytes());
                cut += 1;
            }
        }
    }
    let cut_s = cut_s.unwrap();
    assert!(cut > 10_000, "{cut} spoke headings cut");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("halo-heading-cut.pcap");
    std::fs::write(&path, &bytes).unwrap();
    // With own ship from `--nmea-in`: a GNSS giving no heading (RMC every second, stopped,
    // over the capture's time), and the same with a gyro (`HDT` after each `RMC`).
    let log = |gyro: bool| {
        let mut log = String::new();
        for k in -10..60 {
            use chrono::{Datelike, Timelike};
            let t = chrono::DateTime::from_timestamp(cut_s as i64 - 6 + k, 0).unwrap();
            let rmc = format!(
                "GPRMC,{:02}{:02}{:02}.00,A,5048.30720,N,00117.90400,W,0.0,,{:02}{:02}{:02},,,A",
                t.hour(),
                t.minute(),
                t.second(),
                t.day(),
                t.month(),
                t.year() % 100
            );
            let hdt = "HEHDT,226.1,T".to_string();
            for body in std::iter::once(rmc).chain(gyro.then_some(hdt)) {
                log.push_str(&sentence(&body));
            }
        }
        let file = dir.path().join(if gyro { "gyro.log" } else { "gnss.log" });
        std::fs::write(&file, log).unwrap();
        nmea_file(file)
    };
    let whole = track("radar_pi-halo-velocitytrack-away.pcap.gz", None);
    let alone = OwnShipOptions::default();
    let runs = [
        (None, alone.clone(), After::Lost),
        (None, log(false), After::Lost),
        // A fixed heading given stands in, with the alarm: no longer measured.
        (Some(226.0), alone, After::Fixed),
        // A gyro on `--nmea-in` places every spoke without one, every rotation (the first
        // version refused it every other rotation when it read the same as the scan
        // before, taking it for the heading the radar had reported), and no alarm.
        (None, log(true), After::Gyro),
    ];
    for (heading_deg, own_ship, after) in runs {
        let t = track_path(path.clone(), heading_deg, own_ship);
        heading_cut_at(cut_s, &whole, &t, after);
    }
}

/// What own ship is once a radar's own heading has stopped for `HEADING_LOST_S`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum After {
    /// No heading, the alarm, no plots placed.
    Lost,
    /// The fixed heading, the alarm, the plots placed.
    Fixed,
    /// The gyro's heading, no alarm, the plots placed.
    Gyro,
}

/// Checks the run `t` of the capture whose spoke headings were cut at `cut_s` against the
/// `whole` capture's.
fn heading_cut_at(cut_s: f64, whole: &Tracked, t: &Tracked, after: After) {
    assert_eq!(whole.reports.len(), t.reports.len());
    let (mut held, mut lost) = (0, 0);
    for (w, r) in whole.reports.iter().zip(&t.reports) {
        let at = format!(
            "{after:?}: scan {} at {:.1} s after the cut",
            r.scan,
            r.time_s - cut_s
        );
        assert!(
            w.own.heading_rad.is_some(),
            "{at}: the capture has no heading"
        );
        let q = r.own.quality;
        if after == After::Gyro && r.time_s > cut_s {
            // Every scan after the cut placed with the gyro's 226.1°.
            let h = r.own.heading_rad.map(f32::to_degrees);
            assert!(h.is_some_and(|h| (h - 226.1).abs() < 0.01), "{at}: {h:?}");
        }
        if after == After::Gyro || r.time_s <= cut_s + 10.0 {
            // Before the cut as the whole capture; after it, the last heading held (the
            // ship turns a little: 0.1° in 3 s), or the gyro's.
            let (Some(h), Some(whole_h)) = (r.own.heading_rad, w.own.heading_rad) else {
                panic!("{at}: no heading")
            };
            // (The gyro's 226.1° is own ship's from the start: NMEA's before the radar's.)
            let off = if r.time_s <= cut_s && after != After::Gyro {
                1e-6
            } else {
                0.01
            };
            assert!((h - whole_h).abs() < off, "{at}: {h} against {whole_h}");
            assert!(
                !q.heading_lost && !q.heading_needed && !q.heading_given,
                "{at}"
            );
            assert_eq!(r.plots.len(), w.plots.len(), "{at}");
            held += usize::from(r.time_s > cut_s);
        } else if r.time_s > cut_s + 10.0 + 3.0 {
            // A whole rotation (2.83 s) of spokes after the heading's 10 s.
            assert!(q.heading_lost, "{at}");
            assert!(
                r.own.alarms().iter().any(|a| a.contains("heading lost")),
                "{at}: {:?}",
                r.own.alarms()
            );
            if after == After::Lost {
                assert_eq!(r.own.heading_rad, None, "{at}");
                assert!(q.heading_needed, "{at}");
                assert!(r.plots.is_empty() && !w.plots.is_empty(), "{at}");
            } else {
                assert!(r.own.heading_rad.is_some() && !q.heading_needed, "{at}");
                assert!(q.heading_given, "{at}: the fixed heading shown as given");
                assert_eq!(r.plots.len(), w.plots.len(), "{at}");
            }
            lost += 1;
        }
    }
    let after_hold = if after == After::Gyro { held } else { lost };
    assert!(
        held >= 2 && after_hold >= 2,
        "{held} scans held, {lost} lost"
    );
}

/// An NMEA recording played with a capture: its times before its first date (a log of
/// `GGA` and `GLL` only has none) fall on the capture's day, not today's (the 4G's own
/// log without its `RMC`s gave own ship no fix on any scan), and a log of another voyage
/// is told to have no time near the scans (it gave no fix, and said nothing).
#[test]
fn a_recording_without_dates_falls_on_the_captures_day_and_one_apart_is_told() {
    let name = "radar_pi-4g-noheading-merrimac.pcap.gz";
    let with_log = |path: PathBuf| track_with(name, None, nmea_file(path));
    let dir = tempfile::tempdir().unwrap();
    let undated = dir.path().join("4g-without-rmc.log");
    let log = std::fs::read_to_string(realdata::file(
        "nmea/radar_pi-4g-noheading-merrimac-tcp2000.log",
    ))
    .unwrap();
    let lines: Vec<&str> = log.lines().filter(|l| !l.contains("RMC,")).collect();
    assert!(lines.iter().any(|l| l.contains("GGA,")));
    std::fs::write(&undated, lines.join("\n")).unwrap();
    let t = with_log(undated);
    let fixed = t
        .reports
        .iter()
        .filter(|r| !r.own.quality.no_fix_yet && r.own.quality.dead_reckoning_s.is_none())
        .count();
    assert!(
        fixed + 1 >= t.reports.len(),
        "a fix on {fixed} of {} scans",
        t.reports.len()
    );
    let events = t.run.report("inproc").events;
    assert!(
        !events.iter().any(|e| e.contains("has no time within")),
        "{events:?}"
    );
    // Another voyage's log (Bundg, 2018; its first sentences without a date).
    let apart = with_log(realdata::file("nmea/gpsd-bundg_zeus_9.log"));
    let events = apart.run.report("inproc").events;
    let told: Vec<&String> = events
        .iter()
        .filter(|e| e.contains("has no time within 5 min of the scan at 2015-10-18 14:20:07Z"))
        .collect();
    assert_eq!(told.len(), 1, "{events:?}");
    assert!(told[0].contains("its next at 2018-08-20"), "{told:?}");
}

/// A log of an earlier voyage (GoFree, 2014: its first sentences undated, AIS among them
/// before its first fix) played with the 4G's capture of 2015: its times fall on its own
/// first date and it is told so; its AIS is not heard in the capture's picture (a new
/// user's trial saw its ships among the capture's: its undated start had been put on the
/// capture's day, the AIS before its first time taken at the first scan); own ship is told
/// lost since the log's last fix, not dead reckoned from it.
#[test]
fn a_log_of_an_earlier_voyage_brings_no_ais_and_is_told_by_its_own_date() {
    let name = "radar_pi-4g-noheading-merrimac.pcap.gz";
    let mmsis = |t: &Tracked| -> std::collections::BTreeSet<u32> {
        t.reports
            .iter()
            .flat_map(|r| r.ais.iter().map(|a| a.mmsi))
            .collect()
    };
    let alone = mmsis(&track(name, None));
    let t = track_with(
        name,
        None,
        nmea_file(realdata::file("nmea/signalk-gofree-merrimac.log")),
    );
    let with_log = mmsis(&t);
    assert!(!alone.is_empty());
    assert_eq!(
        with_log,
        alone,
        "the log's ships: {:?}",
        with_log.difference(&alone)
    );
    let events = t.run.report("inproc").events;
    let told: Vec<&String> = events
        .iter()
        .filter(|e| e.contains("has no time within 5 min of the scan at 2015-10-18 14:20:07Z"))
        .collect();
    assert_eq!(told.len(), 1, "{events:?}");
    assert!(
        told[0].contains("its last time before it at 2014-04-16"),
        "{told:?}"
    );
    assert!(
        events
            .iter()
            .any(|e| e.contains("AIS sentences of the recording not taken")),
        "{events:?}"
    );
    for r in &t.reports {
        let q = r.own.quality;
        assert!(
            !q.motion_known && (q.no_fix_yet || q.dead_reckoning_s.is_some()),
            "{q:?}"
        );
    }
}

/// A moored radar without GNSS (the Garmin's: no NMEA, no heading in its spokes), its
/// position given (`--origin … --fixed-position`): own ship stands at the origin, stopped
/// and known, every scan; no "no fix" alarm; the plots and tracks are those of the run
/// without it (only what is told of own ship changes), and targets' true motion is known.
#[test]
fn a_moored_radar_without_gnss_stands_at_its_fixed_position() {
    let name = "radar_pi-garmin_xhd.pcap.gz";
    let unknown = track(name, Some(0.0));
    let fixed = track_with(
        name,
        Some(0.0),
        OwnShipOptions {
            origin: Some(tracker_host::origin::Origin {
                lat_deg: 50.8,
                lon_deg: -1.3,
            }),
            fixed_position: true,
            ..OwnShipOptions::default()
        },
    );
    assert_eq!(unknown.reports.len(), fixed.reports.len());
    assert!(unknown.reports.len() >= 30);
    for (u, f) in unknown.reports.iter().zip(&fixed.reports) {
        assert!(u.own.quality.no_fix_yet && !u.own.quality.motion_known);
        assert!(
            u.own.alarms().iter().any(|a| a.contains("no position fix")),
            "{:?}",
            u.own.alarms()
        );
        let q = f.own.quality;
        assert!(q.fixed_position && q.motion_known && !q.no_fix_yet, "{q:?}");
        assert_eq!(f.own.position_m, [0.0, 0.0]);
        assert_eq!(f.own.sog_kn(), Some(0.0));
        assert!(f.own.alarms().is_empty(), "{:?}", f.own.alarms());
        assert_eq!(u.plots_m, f.plots_m, "scan {}", u.scan);
        assert_eq!(u.tracks, f.tracks, "scan {}", u.scan);
        // True motion: known at the fixed position, not without it.
        assert!(f.targets.iter().all(|t| t.true_motion_known));
        assert!(u.targets.iter().all(|t| !t.true_motion_known));
    }
    assert!(!fixed.reports.last().unwrap().targets.is_empty());
    // Someone's target is shown with its motion, and the same with or without.
    let speeds = |t: &Tracked| -> Vec<(u16, u32)> {
        t.reports
            .last()
            .unwrap()
            .targets
            .iter()
            .map(|x| (x.track, (x.speed_mps * 100.0).round() as u32))
            .collect()
    };
    assert_eq!(speeds(&unknown), speeds(&fixed));
}
