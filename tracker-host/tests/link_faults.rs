//! The main job over a damaged link: at a 10⁻³ byte error rate (flips, losses, repeats, both
//! ways) for a 40-target, 30-minute scenario, every damaged frame is caught, retries with the
//! request id neither lose nor repeat a request, and the tracks are those of the clean run,
//! scan for scan.

use std::time::Duration;

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::app::run::Run;
use tracker_host::link::faults::{FaultRates, FaultyTransport};
use tracker_host::link::{Client, InprocTransport, Transport};

fn demo(transport: Box<dyn Transport>) -> Run {
    let options = DemoOptions::new(ScenarioKind::OpenSea, 40, 4, 1800.0, FilterKind::KalmanCv);
    let mut client = Client::new(transport);
    // In-process the answer is there at once: a short wait is enough to call it lost.
    client.timeout = Duration::from_millis(20);
    client.retries = 50;
    demo::start(client, &options).unwrap()
}

#[test]
fn a_noisy_link_changes_no_track() {
    let mut clean = demo(Box::new(InprocTransport::new()));
    let noisy_link = FaultyTransport::new(
        Box::new(InprocTransport::new()),
        FaultRates::byte_errors(1e-3),
        99,
    );
    let mut noisy = demo(Box::new(noisy_link));
    for _ in 0..720 {
        let a = clean.step().unwrap().unwrap();
        let b = noisy.step().unwrap().unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
    }
    let s = noisy.session().link_stats();
    assert!(s.frames_damaged > 10, "{s:?}");
    assert!(s.retries > 10, "{s:?}");
    assert_eq!(clean.summary(), noisy.summary());
    eprintln!("noisy link: {s:?}");
}
