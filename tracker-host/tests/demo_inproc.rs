//! The main job in-process (no MCU): crossing targets are not swapped, clutter makes no
//! confirmed false tracks, every filter the demo offers tracks the picture.

use tracker_core::sim::ScenarioKind;
use tracker_host::demo::{Demo, DemoFilter, DemoOptions};
use tracker_host::link::{Client, InprocTransport};

fn run(scenario: ScenarioKind, seed: u64, filter: DemoFilter) -> tracker_host::evaluate::Summary {
    let options = DemoOptions {
        scenario,
        targets: 40,
        seed,
        speedup: None,
        duration_s: 600.0,
        filter,
    };
    let mut demo = Demo::new(Client::new(Box::new(InprocTransport::new())), options).unwrap();
    demo.run(|_| {}).unwrap()
}

#[test]
fn crossing_targets_keep_their_tracks() {
    for seed in 1..=4 {
        let s = run(ScenarioKind::Crossing, seed, DemoFilter::KalmanCv);
        assert_eq!(s.swaps, 0, "seed {seed}: {}", s.report());
        assert_eq!(s.false_tracks, 0, "seed {seed}: {}", s.report());
        assert_eq!(s.targets_confirmed, 40, "seed {seed}: {}", s.report());
    }
}

#[test]
fn every_demo_filter_tracks_the_picture() {
    for filter in [
        DemoFilter::KalmanCv,
        DemoFilter::KalmanCa,
        DemoFilter::AlphaBeta,
        DemoFilter::AlphaBetaGamma,
        DemoFilter::Sswt,
        DemoFilter::Grnn,
    ] {
        let s = run(ScenarioKind::OpenSea, 2, filter);
        assert!(s.targets_confirmed >= 38, "{filter:?}: {}", s.report());
        assert!(s.false_tracks <= 2, "{filter:?}: {}", s.report());
        assert!(s.rms_position_m < 60.0, "{filter:?}: {}", s.report());
    }
}
