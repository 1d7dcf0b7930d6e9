//! `demo --video` against the plot-level demo on the same scenario (40 targets, 10 minutes,
//! seed 1): the ships seen through the synthetic radar's spokes and the plot extractor
//! instead of the IMO plot model. The plots: detection probability within 10 % of the plot
//! model's 0.9, no more false plots a scan than its 10. The tracking: every target
//! confirmed, no false track, no swap, as the plot-level demo; confirmation within 5 scans
//! for at least 90 % of as many targets; RMS position and velocity errors and OSPA no worse
//! than 10 % above (measured 2026-12-07: 14.6 m, 1.24 m/s and 19.0 m against 21.2 m,
//! 1.48 m/s and 27.4 m; the OSPA was 35.3 m while the CFAR took the first cells' near side
//! from the blanked samples, 29.1 m before the synthetic radar's sea control, 24.9 m before
//! a near echo grew as the radar equation has it, 24.1 m before a pass across the bow was
//! painted from one state, docs/radar.md). Untracked target-scans, where the plot-level
//! demo has none, are bounded at 6 (none now; 4 before that change, one target at 10 km
//! whose Swerling I echo drew under 0.43 of its mean amplitude six rotations in a row, a
//! chance of about 1 in 5 in a run; seeds 1–8 have 22 against the plot level's 4: the bound
//! leaves room for the draws to fall otherwise). There were 22 before the sea control (a target passing own ship inside
//! 660 m, in clutter saturating the 4 bits) and 7 before the near echo's growth (3 of them
//! that target at 452–482 m, its echo held down with the clutter).

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::score::Summary;

fn run(video: bool) -> (Summary, Option<tracker_host::source::radar::RadarCounts>) {
    let options = DemoOptions {
        video,
        ..DemoOptions::new(ScenarioKind::OpenSea, 40, 1, 600.0, FilterKind::KalmanCv)
    };
    let mut d = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    while d.step().unwrap().is_some() {}
    let report = d.report("inproc");
    (report.scores.expect("scored"), report.radar)
}

#[test]
fn spokes_to_tracks_tracks_like_the_plot_level_demo() {
    let (plots, _) = run(false);
    let (video, radar) = run(true);
    let p = radar.and_then(|r| r.plot_scores).expect("plot scores");
    println!("plot level: {}", plots.report());
    println!("video:      {}", video.report());
    println!("video plots: {p}");
    assert!((p.pd() - 0.9).abs() <= 0.09, "{p}");
    assert!(p.false_per_scan() <= 10.0, "{p}");
    assert_eq!(p.spokes, 240 * 2048);
    assert_eq!(video.targets_confirmed, plots.targets_confirmed);
    assert_eq!(video.false_tracks, plots.false_tracks);
    assert_eq!(video.track_swaps, plots.track_swaps);
    assert!(video.confirmed_within_5_scans * 10 >= plots.confirmed_within_5_scans * 9);
    assert!(video.rms_velocity_mps <= 1.1 * plots.rms_velocity_mps);
    assert!(video.rms_position_m <= 1.1 * plots.rms_position_m);
    assert!(
        video.untracked_target_scans <= 6,
        "untracked {}",
        video.untracked_target_scans
    );
    assert!(
        video.ospa_mean_m <= 1.1 * plots.ospa_mean_m,
        "OSPA {} against {}",
        video.ospa_mean_m,
        plots.ospa_mean_m
    );
}
