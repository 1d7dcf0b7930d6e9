//! End-to-end: the host against the firmware running in QEMU (mps2-an386, Cortex-M4F).
//!
//! Without qemu-system-arm these tests say so and pass, unless TRACKER_REQUIRE_QEMU is set
//! (the test command sets it, so CI cannot skip them silently).

use std::process::ExitCode;

use tracker_core::filter::FilterKind;
use tracker_host::cli;
use tracker_host::lab::bench_mcu;
use tracker_host::link::qemu;

/// The instructions of bench row `name` (infinite when there is no such row).
fn growth_of(rows: &[bench_mcu::BenchRow], name: &str) -> f64 {
    rows.iter()
        .find(|r| r.name == name)
        .map_or(f64::INFINITY, |r| r.instructions_per_call)
}

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
    let first = bench_mcu::run(&[]).expect("bench runs");
    let second = bench_mcu::run(&[]).expect("bench runs again");
    assert_eq!(first, second, "instruction counts must repeat exactly");
    let row = |name: &str| {
        first
            .iter()
            .find(|r| r.name == name)
            .unwrap_or_else(|| panic!("no {name} row"))
    };
    // The link path (decode + CRC + dispatch + encode the reply), per frame, held where it
    // was measured: the frame's bytes handed over one at a time (1,736 / 1,755 / 37,546),
    // and in one slice as a DMA buffer hands them over (1,686 / 1,327 / 15,267). The
    // 1,000-byte echo takes about 2,020 bytes on the wire, both ways: in one slice that is
    // within the 15 a byte; see the README for a byte at a time and the small
    // frames' floor.
    assert!(row("link-hello").instructions_per_call < 1_900.0);
    assert!(row("link-echo-16B").instructions_per_call < 1_900.0);
    assert!(row("link-echo-1000B").instructions_per_call < 40_000.0);
    assert!(row("link-echo-1000B-dma").instructions_per_call < 15.0 * 2_020.0);
    assert!(row("link-hello-dma").instructions_per_call < 1_800.0);
    assert!(row("link-echo-16B-dma").instructions_per_call < 1_450.0);
    assert!(row("link-echo-1000B-dma").instructions_per_call < 16_000.0);
    // The device object holds the link buffers and the whole track table (72 slots, each
    // able to hold any filter, the GRNN the largest; measured 45,288 B): it must leave at
    // least 19 KiB of the 64 KiB RAM budget for the stack, nearly twice the deepest the
    // bench measured (`stack-peak`).
    assert!(row("link-hello").ram_bytes <= 45 * 1024);
}

#[test]
fn filter_costs_are_within_budget() {
    if !qemu_or_skip("filter_costs_are_within_budget") {
        return;
    }
    let rows = bench_mcu::run(&[]).expect("bench runs");
    let cost = |name: &str, scalar: &str| {
        rows.iter()
            .find(|r| r.name == name && r.scalar == scalar)
            .unwrap_or_else(|| panic!("no {name}/{scalar} row"))
            .instructions_per_call
    };
    // Instructions per 2-D scan (predict + update, call included). The CV Kalman meets the
    // issue's budget (≤ 120, Joseph form). The g-h filters meet the 30 / 45 in the
    // form the track table runs them (`*-fixed-scan`: per track of a 64-track scan, the
    // interval compared once a scan, measured 27.6 / 43.8); the general filter called once
    // per track (46 / 61) keeps its bounds so a regression fails. See the README.
    assert!(cost("kalman-cv", "f32") <= 120.0);
    assert!(cost("alpha-beta-fixed-scan", "f32") <= 30.0);
    assert!(cost("alpha-beta-gamma-fixed-scan", "f32") <= 45.0);
    assert!(cost("alpha-beta-gamma-eta-fixed-scan", "f32") <= 62.0);
    assert!(cost("alpha-beta", "f32") <= 55.0);
    assert!(cost("alpha-beta-gamma", "f32") <= 66.0);
    assert!(cost("alpha-beta-gamma-eta", "f32") <= 85.0);
    assert!(cost("kalman-ca", "f32") <= 300.0);
    assert!(cost("sswt", "f32") <= 450.0);
    // Fixed point within 1.5× of f32 (the budget).
    for name in [
        "alpha-beta",
        "alpha-beta-gamma",
        "alpha-beta-gamma-eta",
        "sswt",
        "alpha-beta-fixed-scan",
        "alpha-beta-gamma-fixed-scan",
        "alpha-beta-gamma-eta-fixed-scan",
    ] {
        let (fixed, float) = (cost(name, "fixed"), cost(name, "f32"));
        assert!(fixed <= 1.5 * float, "{name}: fixed {fixed} vs f32 {float}");
    }
    // RAM per filter instance and per track slot.
    let filters = [
        "alpha-beta",
        "alpha-beta-gamma",
        "alpha-beta-gamma-eta",
        "alpha-beta-fixed-scan",
        "alpha-beta-gamma-fixed-scan",
        "alpha-beta-gamma-eta-fixed-scan",
        "sswt",
        "kalman-cv",
        "kalman-ca",
        "grnn",
        "imm",
    ];
    for r in rows
        .iter()
        .filter(|r| filters.contains(&r.name.as_str()) || r.name.starts_with("track-slot"))
    {
        assert!(
            r.ram_bytes <= 512,
            "{} {}: {} B",
            r.name,
            r.scalar,
            r.ram_bytes
        );
    }
    // Paper 004's filters (f32, on the MCU): the structure (block-diagonal Φ, sparse H, the
    // Joseph update as rank-one terms) against the plain dense filter, same numbers.
    let ratio = |name: &str| cost(name, "dense") / cost(name, "structured");
    for (name, at_least) in [
        ("ttkf-second-own-ship", 9.5),
        ("ttkf-radar", 10.0),
        ("drkf-second-gyro-log", 8.0),
        ("drkf-predict", 8.0),
        ("ttkf-predict", 6.0),
    ] {
        assert!(ratio(name) >= at_least, "{name}: {:.1}×", ratio(name));
    }
    assert!(cost("ttkf-second-own-ship", "structured") <= 12_500.0);
    assert!(cost("drkf-second-gyro-log", "structured") <= 7_000.0);
    // One DRKF feeding four TTKFs against the coupled 35-state filter, both dense (eq. 10's
    // comparison): the coupled one costs several times more, and far more than the
    // structured DRTTKF.
    let coupled = cost("coupled-second-4-targets", "dense");
    assert!(coupled >= 5.0 * cost("drttkf-second-4-targets", "dense"));
    assert!(coupled >= 40.0 * cost("drttkf-second-4-targets", "structured"));
    // RAM per tracked target (one TTKF) and for the dead-reckoning filter.
    let ram = |name: &str| {
        rows.iter()
            .find(|r| r.name == name && r.scalar == "structured")
            .map(|r| r.ram_bytes)
            .unwrap_or(usize::MAX)
    };
    assert!(ram("ttkf-second-own-ship") <= 1024);
    assert!(ram("drkf-second-gyro-log") <= 1024);
    // The device's whole tracking state (72 tracks, a scan's plots, assignments; measured
    // 42,184 B) fits in 42 KiB of the 64 KiB RAM budget.
    let scan = rows
        .iter()
        .find(|r| r.name == "scan-40-targets-200-plots")
        .expect("scan row");
    assert!(scan.ram_bytes <= 42 * 1024, "{} B", scan.ram_bytes);
    // The stack the bench's deepest row took, the bench's own code included (measured
    // 10,232 B): within 12 KiB, which the firmware's 20,224 B left for its stack
    // (`scripts/size`) hold with 7,936 B to spare; and more than `main`'s own frame (1.6 KiB), so
    // that a painting that measured nothing fails.
    let stack = rows
        .iter()
        .find(|r| r.name == "stack-peak")
        .expect("stack-peak row");
    assert!(
        (2 * 1024..=12 * 1024).contains(&stack.ram_bytes),
        "{} B",
        stack.ram_bytes
    );
    // The budget for the device's tracking work (measured 77,996 with a table of
    // 72, which the bench's 160 clutter plots a scan keep full; 71,840 with 64, 70,724 before
    // the track score; 123,368 before slots that never move), and the same with the lists
    // read from their frames (measured 96,800; 90,410 with 64).
    assert!(
        scan.instructions_per_call <= 80_000.0,
        "{}",
        scan.instructions_per_call
    );
    assert!(growth_of(&rows, "scan-40-targets-200-plots-read-from-frames") <= 100_000.0);
    // The growth rows: with the gate bucketed, a plot costs about 120 instructions whatever
    // the tracks, not one gate test per track (measured 17,716 / 36,226 at 16 tracks,
    // 50,626 / 73,948 at 64 with the slot sets in 32-bit words; 17,712 / 36,426 and
    // 50,560 / 74,074 with them in one u64; 17,138 / 35,846 and 48,292 / 71,808 before the
    // track score, which costs about 35 instructions a track a scan).
    let growth = |name: &str| {
        rows.iter()
            .find(|r| r.name == name)
            .map_or(f64::INFINITY, |r| r.instructions_per_call)
    };
    assert!(growth("scan-16-tracks-50-plots") <= 19_000.0);
    assert!(growth("scan-16-tracks-250-plots") <= 38_000.0);
    assert!(growth("scan-64-tracks-50-plots") <= 52_500.0);
    assert!(growth("scan-64-tracks-250-plots") <= 76_500.0);
    // The device's scan with 64 g-h tracks, which the table runs in their fixed-scan form
    // (measured 46,380 / 47,298; 45,796 / 46,706 in protocol 6; 46,132 / 47,054 before the
    // slot sets in 32-bit words, 43,872 / 44,774 before the track score; the general
    // filters cost about 4,200 more a scan, so these bounds fail if the table stops using
    // it).
    assert!(growth("scan-64-tracks-64-plots-alpha-beta") <= 47_800.0);
    assert!(growth("scan-64-tracks-64-plots-alpha-beta-gamma") <= 48_800.0);
    // Plot extraction per 1,024-sample spoke (bench-radar): its RAM (measured 19,208 B with
    // the echoes and the CFAR's near-side factors), and its cost held where it was measured
    // (291,418; 281,327 since the near side past the blanking), so a change that slows it
    // shows here.
    let extract = rows
        .iter()
        .find(|r| r.name == "extract-spoke-1024")
        .expect("extraction row");
    assert!(extract.ram_bytes <= 19 * 1024, "{} B", extract.ram_bytes);
    // Configuring the extractor once (the CFAR's factors solved in software f64): measured
    // 25,633,360 instructions, 0.15 s at 168 MHz; held there.
    let configure = rows
        .iter()
        .find(|r| r.name == "extract-configure")
        .expect("configuration row");
    assert!(
        configure.instructions_per_call <= 28_000_000.0,
        "{}",
        configure.instructions_per_call
    );
    assert!(
        extract.instructions_per_call <= 315_000.0,
        "{}",
        extract.instructions_per_call
    );
}

/// The main job, 40 targets with clutter and P_d = 0.9 for 10 simulated minutes, on the
/// firmware in QEMU and in-process: the same tracks scan for scan (f32 on both, same seed),
/// and the scores within the bounds the README states.
#[test]
fn demo_on_the_firmware_tracks_like_inproc_and_meets_its_bounds() {
    use tracker_host::app::demo::{self, DemoOptions};
    use tracker_host::link::{self, Client, LinkSpec};
    if !qemu_or_skip("demo_on_the_firmware_tracks_like_inproc_and_meets_its_bounds") {
        return;
    }
    let options = DemoOptions::new(
        tracker_core::sim::ScenarioKind::OpenSea,
        40,
        1,
        600.0,
        FilterKind::KalmanCv,
    );
    let open = |spec: LinkSpec| {
        let transport = link::open(&spec, &qemu::QemuOptions::default()).expect("link opens");
        demo::start(Client::new(transport), &options).expect("demo starts")
    };
    let mut on_mcu = open(LinkSpec::Qemu);
    let mut in_process = open(LinkSpec::Inproc);
    for _ in 0..240 {
        let a = on_mcu.step().expect("scan on the firmware").unwrap();
        let b = in_process.step().expect("scan in process").unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
    }
    let s = on_mcu.summary().unwrap();
    assert_eq!(s, in_process.summary().unwrap());
    assert_eq!(s.targets_confirmed, 40, "{}", s.report());
    assert_eq!(s.confirmed_within_5_scans, 40, "{}", s.report());
    assert_eq!(s.track_swaps, 0, "{}", s.report());
    assert_eq!(s.false_tracks, 0, "{}", s.report());
    assert!(
        s.cpa_error_p95_m.is_some_and(|e| e < 1000.0),
        "{}",
        s.report()
    );
    assert!(
        s.tcpa_error_p95_s.is_some_and(|e| e < 600.0),
        "{}",
        s.report()
    );
}

/// Unresolved plots over the link (protocol 7's `HIDDEN_PLOT`): the merging scenario with
/// `two-stage-unresolved` tracks the same on the firmware as in process, scan for scan, and
/// the host did name hidden targets.
#[test]
fn hidden_targets_coast_the_same_on_the_firmware() {
    use tracker_host::app::demo::{self, DemoOptions};
    use tracker_host::link::{self, Client, LinkSpec};
    use tracker_host::session::associate::Association;
    if !qemu_or_skip("hidden_targets_coast_the_same_on_the_firmware") {
        return;
    }
    let mut options = DemoOptions::new(
        tracker_core::sim::ScenarioKind::Merging,
        40,
        2,
        300.0,
        FilterKind::KalmanCv,
    );
    options.association = Association::TwoStageUnresolved;
    let open = |spec: LinkSpec| {
        let transport = link::open(&spec, &qemu::QemuOptions::default()).expect("link opens");
        demo::start(Client::new(transport), &options).expect("demo starts")
    };
    let mut on_mcu = open(LinkSpec::Qemu);
    let mut in_process = open(LinkSpec::Inproc);
    let mut hidden = 0;
    for _ in 0..120 {
        let a = on_mcu.step().expect("scan on the firmware").unwrap();
        let b = in_process.step().expect("scan in process").unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
        hidden += a.association.hidden;
    }
    assert!(
        hidden > 0,
        "no target was hidden: the test no longer tests it"
    );
}

/// The noisy-link guarantee against the firmware: at a 10⁻³ byte error rate both ways, the
/// tracks over QEMU are those of the clean in-process run, scan for scan.
#[test]
fn a_noisy_link_to_the_firmware_changes_no_track() {
    use tracker_host::app::demo::{self, DemoOptions};
    use tracker_host::link::faults::{FaultRates, FaultyTransport};
    use tracker_host::link::{self, Client, LinkSpec};
    if !qemu_or_skip("a_noisy_link_to_the_firmware_changes_no_track") {
        return;
    }
    let options = DemoOptions::new(
        tracker_core::sim::ScenarioKind::OpenSea,
        40,
        6,
        300.0,
        FilterKind::KalmanCv,
    );
    let qemu = link::open(&LinkSpec::Qemu, &qemu::QemuOptions::default()).expect("qemu");
    let noisy = FaultyTransport::new(qemu, FaultRates::byte_errors(1e-3), 5);
    let mut client = Client::new(Box::new(noisy));
    client.timeout = std::time::Duration::from_millis(300);
    client.retries = 50;
    let mut on_mcu = demo::start(client, &options).expect("demo over a noisy link");
    let inproc = link::open(&LinkSpec::Inproc, &qemu::QemuOptions::default()).unwrap();
    let mut clean = demo::start(Client::new(inproc), &options).unwrap();
    for _ in 0..120 {
        let a = on_mcu.step().expect("scan over the noisy link").unwrap();
        let b = clean.step().unwrap().unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
    }
    let s = on_mcu.session().link_stats();
    assert!(s.frames_damaged > 0 && s.retries > 0, "{s:?}");
}

/// Recorded plots in, over the firmware: a demo run recorded in-process and tracked again
/// from its plots file on the firmware in QEMU gives the same tracks, scan for scan, and the
/// same scored summary.
#[test]
fn a_recorded_demo_tracks_the_same_on_the_firmware() {
    if !qemu_or_skip("a_recorded_demo_tracks_the_same_on_the_firmware") {
        return;
    }
    let dir = std::env::temp_dir().join(format!("tracker-e2e-track-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = |n: &str| dir.join(n).to_str().unwrap().to_string();
    let run = |args: &[&str]| {
        cli::run(std::iter::once("tracker-host").chain(args.iter().copied())).expect("runs")
    };
    let code = run(&[
        "--link",
        "inproc",
        "demo",
        "--plain",
        "--targets",
        "40",
        "--seed",
        "1",
        "--duration",
        "150",
        "--record-plots",
        &f("plots.csv"),
        "--record-truth",
        &f("truth.csv"),
        "--record-tracks",
        &f("demo-tracks.csv"),
        "--summary-json",
        &f("demo.json"),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let code = run(&[
        "--link",
        "qemu",
        "track",
        "--plain",
        "--plots",
        &f("plots.csv"),
        "--truth",
        &f("truth.csv"),
        "--record-tracks",
        &f("qemu-tracks.csv"),
        "--summary-json",
        &f("qemu.json"),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let read = |n: &str| std::fs::read_to_string(dir.join(n)).unwrap();
    let (a, b) = (read("demo-tracks.csv"), read("qemu-tracks.csv"));
    assert!(a.lines().count() > 60 * 30);
    assert_eq!(a, b, "tracks differ");
    // The scores: all but the host's times, the link's counts and the command lines.
    let scores = |n: &str| {
        let mut v: serde_json::Value = serde_json::from_str(&read(n)).unwrap();
        v.as_object_mut()
            .unwrap()
            .retain(|k, _| !k.starts_with("host_ms") && !k.starts_with("link") && k != "command");
        v
    };
    assert_eq!(scores("demo.json"), scores("qemu.json"));
    let _ = std::fs::remove_dir_all(&dir);
}
