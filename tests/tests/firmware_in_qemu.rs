//! End-to-end: the host against the firmware running in QEMU (mps2-an386, Cortex-M4F).
//!
//! Without qemu-system-arm these tests say so and pass, unless TRACKER_REQUIRE_QEMU is set
//! (the test command sets it, so CI cannot skip them silently).

use std::process::ExitCode;

use tracker_host::{bench_mcu, cli, qemu};

fn qemu_or_skip(test: &str) -> bool {
    if qemu::qemu_available() {
        return true;
    }
    assert!(
        std::env::var_os("TRACKER_REQUIRE_QEMU").is_none(),
        "{test}: qemu-system-arm is required (TRACKER_REQUIRE_QEMU is set) but not installed"
    );
    eprintln!("{test}: skipped, qemu-system-arm is not installed");
    false
}

#[test]
fn link_check_passes_against_the_firmware() {
    if !qemu_or_skip("link_check_passes_against_the_firmware") {
        return;
    }
    let code = cli::run([
        "tracker-host",
        "--link",
        "qemu",
        "link-check",
        "--frames",
        "1000",
    ])
    .expect("link-check runs");
    assert_eq!(code, ExitCode::SUCCESS);
}

#[test]
fn bench_counts_are_deterministic_and_within_budget() {
    if !qemu_or_skip("bench_counts_are_deterministic_and_within_budget") {
        return;
    }
    let first = bench_mcu::run(None).expect("bench runs");
    let second = bench_mcu::run(None).expect("bench runs again");
    assert_eq!(first, second, "instruction counts must repeat exactly");
    let row = |name: &str| {
        first
            .iter()
            .find(|r| r.name == name)
            .unwrap_or_else(|| panic!("no {name} row"))
    };
    // Budgets for the link path (decode + CRC + dispatch + encode the reply), per frame.
    assert!(row("link-hello").instructions_per_call < 8_000.0);
    assert!(row("link-echo-16B").instructions_per_call < 12_000.0);
    // Per byte of a full frame: COBS, CRC and postcard each way.
    assert!(row("link-echo-1000B").instructions_per_call < 120.0 * 1000.0);
    assert!(row("link-hello").ram_bytes <= 4 * 1024);
}
