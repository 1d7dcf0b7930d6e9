//! The main job in-process (no MCU): crossing targets are not swapped, clutter makes no
//! confirmed false tracks, every filter the demo offers tracks the picture.

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::score::Summary;

fn run(scenario: ScenarioKind, seed: u64, filter: FilterKind) -> Summary {
    let options = DemoOptions::new(scenario, 40, seed, 600.0, filter);
    let mut demo = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    demo.run_to_end(None, |_| {}).unwrap();
    demo.summary().unwrap()
}

#[test]
fn crossing_targets_keep_their_tracks() {
    for seed in 1..=4 {
        let s = run(ScenarioKind::Crossing, seed, FilterKind::KalmanCv);
        assert_eq!(s.track_swaps, 0, "seed {seed}: {}", s.report());
        assert_eq!(s.false_tracks, 0, "seed {seed}: {}", s.report());
        assert_eq!(s.targets_confirmed, 40, "seed {seed}: {}", s.report());
    }
}

#[test]
fn every_filter_tracks_the_picture() {
    for filter in FilterKind::ALL {
        let s = run(ScenarioKind::OpenSea, 2, filter);
        assert!(s.targets_confirmed >= 38, "{filter}: {}", s.report());
        assert!(s.false_tracks <= 2, "{filter}: {}", s.report());
        assert!(s.rms_position_m < 60.0, "{filter}: {}", s.report());
    }
}
