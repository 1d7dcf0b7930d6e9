//! The binary as a shell user meets it: its output piped into a reader that stops early
//! (`tracker-host demo --plain | head -1`) ends the run quietly, never with a panic; an
//! output path that cannot be written is refused before the run, not after it.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

#[test]
fn a_closed_pipe_is_not_a_panic() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args(["--link", "inproc", "demo", "--plain", "--duration", "120"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(!first.is_empty(), "the demo printed nothing");
    // The reader is gone: every later write meets a closed pipe.
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_ne!(out.status.code(), Some(101), "{stderr}");
}

#[test]
fn an_output_that_cannot_be_written_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let nowhere = dir.path().join("no-such-dir").join("s.json");
    for (option, path, said) in [
        (
            "--summary-json",
            nowhere.display().to_string(),
            "does not exist",
        ),
        ("--snapshot", "foo.txt".to_string(), "must end in .png"),
        (
            "--snapshot",
            nowhere.with_extension("png").display().to_string(),
            "does not exist",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
            .args(["--link", "inproc", "demo", "--plain", option, &path])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{option} {path}: {stderr}");
        assert!(out.stdout.is_empty(), "{option}: the run ran");
        assert!(stderr.contains(option) && stderr.contains(said), "{stderr}");
    }
}
