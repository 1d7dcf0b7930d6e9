//! The host and the device recover from each other's restarts: a restarted host re-attaches
//! to the live track table (handshake, full track report) and tracks on as if nothing
//! happened; a reset device is noticed (new boot id), reported, configured again, and its
//! targets are re-acquired.

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::app::run::Run;
use tracker_host::link::{Client, InprocTransport};
use tracker_host::session::ScanReport;

fn start(client: Client) -> Run {
    let options = DemoOptions::new(ScenarioKind::OpenSea, 40, 8, 600.0, FilterKind::KalmanCv);
    demo::start(client, &options).unwrap()
}

fn step(run: &mut Run) -> ScanReport {
    run.step().unwrap().expect("a scan")
}

#[test]
fn a_restarted_host_reattaches_to_the_live_table() {
    let mut steady = start(Client::new(Box::new(InprocTransport::new())));
    let mut restarted = start(Client::new(Box::new(InprocTransport::new())));
    let mut last = Vec::new();
    for _ in 0..60 {
        step(&mut steady);
        last = step(&mut restarted).tracks;
    }
    let reported = restarted.session_mut().restart_host().unwrap();
    assert_eq!(reported, last, "the full track report is the live table");
    for _ in 0..60 {
        let a = step(&mut steady);
        let b = step(&mut restarted);
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
    }
    assert!(restarted
        .session()
        .events()
        .iter()
        .any(|e| e.contains("host restarted")));
}

#[test]
fn a_reset_device_is_noticed_and_tracking_resumes() {
    let transport = InprocTransport::new();
    let power = transport.reset_handle();
    let mut demo = start(Client::new(Box::new(transport)));
    for _ in 0..60 {
        step(&mut demo);
    }
    power.reset();
    let mut view = demo
        .step()
        .expect("the scan after the reset goes through")
        .unwrap();
    assert!(
        demo.session()
            .events()
            .iter()
            .any(|e| e.contains("firmware reset detected")),
        "{:?}",
        demo.session().events()
    );
    for _ in 0..20 {
        view = step(&mut demo);
    }
    // Re-acquired: most targets in view are tracked again within 20 scans.
    let confirmed = view.targets.len();
    assert!(
        confirmed >= 30,
        "{confirmed} targets tracked after the reset"
    );
}
