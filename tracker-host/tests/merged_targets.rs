//! Closely spaced and merged targets (issue #18): two ships inside one resolution cell give
//! one plot; once they separate, both are tracked again within a few scans, and from then
//! on no track passes from one to the other.
//!
//! The scenario is the simulator's `merging`: in every pair one ship overtakes the other on
//! a course along the line of sight, 52–158 m abeam and 0.8–1.2 m/s faster, so the two
//! share a resolution cell (one plot, the slower ship's) for a minute or more and draw
//! apart. The test runs the demo in process and, beside it, the same scenario for the truth;
//! per pair it finds the scan they separate, how many scans later both have a confirmed
//! track of their own, and which tracks follow which ship from then on. They separate on
//! the scan after the last one on which the radar detected both and gave one plot for
//! them (a scan merges the second ship into the first one's *measured* plot, σ 38 m in
//! range, so that happens for a while after they leave the cell by their true positions).
//!
//! Printed, and bounded: which ship each track comes out of the merge on. While the two
//! give one plot, which track takes it decides; weighed by the plot's own accuracy (the
//! radar's bearing is far finer than its range), it goes to the track on its side of the
//! line of sight (docs/tracking.md has the counts, ours and Stone Soup's).

use std::collections::BTreeSet;

use tracker_core::filter::FilterKind;
use tracker_core::sim::{in_one_cell, Scenario, ScenarioConfig, ScenarioKind, Truth};
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::score::Summary;

const TARGETS: usize = 16;

/// Both ships of a pair are tracked again within this many scans of separating (the 5 scans
/// a new target is confirmed within in the demo; 48 pairs took at most 3).
const REACQUIRE_SCANS: usize = 5;

/// At most this many of the 48 pairs come out of the merge with their tracks exchanged
/// (1 measured; 6 before the association weighed a plot by its own accuracy).
const MOST_EXCHANGED: usize = 2;

/// A track follows the target nearest it, if within this distance, m.
const FOLLOW_M: f32 = 150.0;

/// One pair's scans: in one cell or not, both detected in one plot or not, and the
/// confirmed or coasting track (if any) following each ship.
#[derive(Default)]
struct PairScans {
    in_cell: Vec<bool>,
    one_plot: Vec<bool>,
    a: Vec<Option<u16>>,
    b: Vec<Option<u16>>,
}

/// What became of one pair.
struct Outcome {
    merged_scans: usize,
    separated: usize,
    /// Scans from separating until both have a track.
    reacquired: usize,
    /// Tracks that followed A and B from then on.
    a_tracks: BTreeSet<u16>,
    b_tracks: BTreeSet<u16>,
    /// A's track before the merge now follows B (or B's follows A).
    exchanged: bool,
}

fn run(seed: u64) -> (Vec<Outcome>, Summary, usize) {
    let options = DemoOptions::new(
        ScenarioKind::Merging,
        TARGETS,
        seed,
        600.0,
        FilterKind::KalmanCv,
    );
    let mut demo = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let config = ScenarioConfig {
        kind: ScenarioKind::Merging,
        ..ScenarioConfig::open_sea(TARGETS, seed)
    };
    let mut truth = Scenario::new(config);
    let mut pairs: Vec<PairScans> = (0..TARGETS / 2).map(|_| PairScans::default()).collect();
    let mut in_echo = 0;
    while let Some(report) = demo.step().unwrap() {
        let scan = truth.next_scan();
        // A track whose target is hidden in another's plot is held (firm, numbered), not
        // drawn.
        for t in &report.in_echo {
            assert!(!report.targets.iter().any(|d| d.track == t.track));
            assert!(report
                .tracks
                .iter()
                .any(|s| s.track == t.track && s.status.is_firm()));
        }
        in_echo += report.in_echo.len();
        // The same scenario, scan for scan: the same plots.
        assert_eq!(report.plots.len(), scan.plots.len(), "scan {}", scan.scan);
        // Each firm track follows the target nearest it, if near enough.
        let mut follows: Vec<(u16, u16, f32)> = Vec::new();
        for t in report.tracks.iter().filter(|t| t.status.is_firm()) {
            let d = |x: &Truth| {
                libm::hypotf(
                    x.position_m[0] - t.position_m[0],
                    x.position_m[1] - t.position_m[1],
                )
            };
            if let Some(x) = scan.truth.iter().min_by(|a, b| d(a).total_cmp(&d(b))) {
                if d(x) <= FOLLOW_M {
                    follows.push((t.track, x.id, d(x)));
                }
            }
        }
        let track_of = |id: u16| {
            follows
                .iter()
                .filter(|f| f.1 == id)
                .min_by(|a, b| a.2.total_cmp(&b.2))
                .map(|f| f.0)
        };
        for (p, ships) in pairs.iter_mut().zip(scan.truth.chunks(2)) {
            let (a, b) = (ships[0], ships[1]);
            let (own, sensor) = (scan.own_position_m, &config.sensor);
            p.in_cell
                .push(in_one_cell(sensor, own, a.position_m, b.position_m));
            let own_plot = |id: u16| scan.plot_source.contains(&Some(id));
            p.one_plot
                .push(a.detected && b.detected && !(own_plot(a.id) && own_plot(b.id)));
            p.a.push(track_of(a.id));
            p.b.push(track_of(b.id));
        }
    }
    let outcomes = pairs
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let first = p.in_cell.iter().position(|&c| c).expect("they merge");
            let separated = p.one_plot.iter().rposition(|&c| c).expect("one plot") + 1;
            let both = (separated..p.a.len()).find(|&i| p.a[i].is_some() && p.b[i].is_some());
            let Some(both) = both else {
                panic!("seed {seed} pair {k}: separated at scan {separated}, never both tracked")
            };
            let a_tracks: BTreeSet<u16> = p.a[both..].iter().flatten().copied().collect();
            let b_tracks: BTreeSet<u16> = p.b[both..].iter().flatten().copied().collect();
            let before = |v: &[Option<u16>]| v[..first].iter().rev().flatten().next().copied();
            let exchanged = before(&p.a).is_some_and(|t| b_tracks.contains(&t))
                || before(&p.b).is_some_and(|t| a_tracks.contains(&t));
            Outcome {
                merged_scans: p.in_cell.iter().filter(|&&c| c).count(),
                separated,
                reacquired: both - separated,
                a_tracks,
                b_tracks,
                exchanged,
            }
        })
        .collect();
    (outcomes, demo.summary().unwrap(), in_echo)
}

#[test]
fn merged_targets_are_both_tracked_again_soon_after_they_separate() {
    let (mut worst, mut exchanged, mut pairs) = (0, Vec::new(), 0);
    for seed in 1..=6 {
        let (outcomes, s, in_echo) = run(seed);
        assert_eq!(s.false_tracks, 0, "seed {seed}: {}", s.report());
        // The default association holds the tracks of ships hidden in a neighbour's echo.
        assert!(in_echo > 0, "seed {seed}: no track held in another's echo");
        for (k, o) in outcomes.iter().enumerate() {
            assert!(
                o.merged_scans >= 24,
                "seed {seed} pair {k}: {} scans",
                o.merged_scans
            );
            assert!(
                o.reacquired <= REACQUIRE_SCANS,
                "seed {seed} pair {k}: both tracked {} scans after separating at scan {}",
                o.reacquired,
                o.separated
            );
            // Once both are tracked, no track passes from one ship to the other.
            assert!(
                o.a_tracks.is_disjoint(&o.b_tracks),
                "seed {seed} pair {k}: tracks {:?} on A and {:?} on B",
                o.a_tracks,
                o.b_tracks
            );
            worst = worst.max(o.reacquired);
            if o.exchanged {
                exchanged.push(format!(
                    "seed {seed} pair {k} (separated at scan {})",
                    o.separated
                ));
            }
            pairs += 1;
        }
    }
    eprintln!(
        "{pairs} pairs: both tracked again at most {worst} scans after separating; \
         {} came out of the merge with their tracks exchanged: {exchanged:?}",
        exchanged.len()
    );
    // Which ship each track comes out on is the plots' noise while the two give one plot;
    // the pair cost on the plot's own accuracy (docs/tracking.md) keeps most: 1 of the 48
    // exchanged, 6 on the filter's round 40 m.
    assert!(
        exchanged.len() <= MOST_EXCHANGED,
        "{} of {pairs} pairs exchanged their tracks: {exchanged:?}",
        exchanged.len()
    );
}

/// The demo's merging scenario (40 targets, 10 minutes, as `demo --scenario merging` and the
/// Stone Soup comparison run it), seeds 1–8: track swaps at most 2 in all, none on seeds 2
/// and 3 (2 measured on 2026-12-07, on seeds 4 and 6; 5 before a firm track left to a
/// tentative track as settled a plot it held far better, 2 on seed 2 and 1 on seed 3, where
/// a just-confirmed track that missed its own plot took the neighbour's at acquisition and
/// the two tracks exchanged ships; Stone Soup's 49, docs/stonesoup.md).
#[test]
fn ships_in_company_keep_their_tracks_from_acquisition() {
    let mut swaps = Vec::new();
    for seed in 1..=8 {
        let options =
            DemoOptions::new(ScenarioKind::Merging, 40, seed, 600.0, FilterKind::KalmanCv);
        let mut demo =
            demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        while demo.step().unwrap().is_some() {}
        let scores = demo.report("inproc").scores.expect("scored");
        swaps.push(scores.track_swaps);
    }
    println!("merging, 40 targets, seeds 1–8: track swaps {swaps:?}");
    assert_eq!(swaps[1], 0, "seed 2");
    assert_eq!(swaps[2], 0, "seed 3");
    assert!(swaps.iter().sum::<u32>() <= 2, "{swaps:?}");
}
