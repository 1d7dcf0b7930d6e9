//! The host and the device recover from each other's restarts: a restarted host re-attaches
//! to the live track table (handshake, full track report) and tracks on as if nothing
//! happened; a reset device is noticed (new boot id), reported, configured again, and its
//! targets are re-acquired.

use tracker_core::sim::ScenarioKind;
use tracker_host::demo::{Demo, DemoFilter, DemoOptions};
use tracker_host::link::{Client, InprocTransport};

fn options() -> DemoOptions {
    DemoOptions {
        scenario: ScenarioKind::OpenSea,
        targets: 40,
        seed: 8,
        speedup: None,
        duration_s: 600.0,
        filter: DemoFilter::KalmanCv,
    }
}

#[test]
fn a_restarted_host_reattaches_to_the_live_table() {
    let mut steady = Demo::new(Client::new(Box::new(InprocTransport::new())), options()).unwrap();
    let mut restarted =
        Demo::new(Client::new(Box::new(InprocTransport::new())), options()).unwrap();
    let mut last = Vec::new();
    for _ in 0..60 {
        steady.step().unwrap();
        last = restarted.step().unwrap().tracks;
    }
    let reported = restarted.restart_host().unwrap();
    assert_eq!(reported, last, "the full track report is the live table");
    for _ in 0..60 {
        let a = steady.step().unwrap();
        let b = restarted.step().unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.sim.scan);
    }
    assert!(restarted
        .events()
        .iter()
        .any(|e| e.contains("host restarted")));
}

#[test]
fn a_reset_device_is_noticed_and_tracking_resumes() {
    let transport = InprocTransport::new();
    let power = transport.reset_handle();
    let mut demo = Demo::new(Client::new(Box::new(transport)), options()).unwrap();
    for _ in 0..60 {
        demo.step().unwrap();
    }
    power.reset();
    let mut view = demo.step().expect("the scan after the reset goes through");
    assert!(
        demo.events()
            .iter()
            .any(|e| e.contains("firmware reset detected")),
        "{:?}",
        demo.events()
    );
    for _ in 0..20 {
        view = demo.step().unwrap();
    }
    // Re-acquired: most targets in view are tracked again within 20 scans.
    let confirmed = view.targets.len();
    assert!(
        confirmed >= 30,
        "{confirmed} targets tracked after the reset"
    );
}
