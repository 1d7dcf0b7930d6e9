//! The CPA/TCPA alarm limits as the navigator sets them (`--cpa-nm`, `--tcpa-min`): they
//! reach the alarms, and values that are no limits are refused before anything runs.

use std::process::Command;

fn demo(limits: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args(["--link", "inproc", "demo", "--plain", "--duration", "150"])
        .args(limits)
        .output()
        .unwrap()
}

/// Target lines with the alarm in a plain run's tables.
fn alarms(out: &std::process::Output) -> usize {
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter(|l| l.contains("ALARM CPA/TCPA"))
        .count()
}

#[test]
fn the_limits_set_are_the_limits_alarmed_on() {
    let wide = demo(&["--cpa-nm", "20", "--tcpa-min", "600"]);
    assert!(
        wide.status.success(),
        "{}",
        String::from_utf8_lossy(&wide.stderr)
    );
    let default = demo(&[]);
    let narrow = demo(&["--cpa-nm", "0.01", "--tcpa-min", "0.5"]);
    let (w, d, n) = (alarms(&wide), alarms(&default), alarms(&narrow));
    // 40 targets within 12 NM for 150 s: with a 20 NM limit every approaching target whose
    // motion is known alarms; with 0.01 NM in 30 s, none.
    assert!(w > d && d > n, "wide {w}, default {d}, narrow {n}");
    assert_eq!(n, 0);
}

#[test]
fn limits_that_are_no_limits_are_refused() {
    // A negative limit written as two words (`--cpa-nm -1`) is this refusal too, not clap's
    // "unexpected argument '-1'", which told a navigator nothing about the limit.
    for bad in [
        &["--cpa-nm=0"][..],
        &["--cpa-nm=nan"],
        &["--tcpa-min=-3"],
        &["--tcpa-min=inf"],
        &["--cpa-nm", "-1"],
        &["--tcpa-min", "-0.5"],
        // Past any radar's range, or a day: `1e308` NM overflowed to an infinite limit.
        &["--cpa-nm=1e308"],
        &["--cpa-nm=101"],
        &["--tcpa-min=1e9"],
    ] {
        let out = demo(bad);
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("limit above 0, up to"), "{bad:?}: {stderr}");
    }
}
