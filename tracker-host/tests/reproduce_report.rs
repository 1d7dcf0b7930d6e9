//! The committed report (`docs/reproduce/report.md`) must be what `tracker-host reproduce`
//! writes now: every experiment is deterministic, so any difference means the code changed
//! and the report was not regenerated.

use std::path::Path;

#[test]
fn committed_report_is_current() {
    let dir = std::env::temp_dir().join(format!("tracker-reproduce-{}", std::process::id()));
    let fresh = tracker_host::lab::reproduce::run(&[], &dir).unwrap();
    let committed_path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reproduce/report.md");
    let committed = std::fs::read_to_string(&committed_path).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&dir);
    if fresh != committed {
        let line = fresh
            .lines()
            .zip(committed.lines())
            .position(|(a, b)| a != b)
            .map_or(
                fresh.lines().count().min(committed.lines().count()) + 1,
                |i| i + 1,
            );
        panic!(
            "docs/reproduce/report.md is stale (first difference at line {line}); regenerate it with\n  \
             cargo run --release -p tracker-host -- reproduce --out docs/reproduce"
        );
    }
}
