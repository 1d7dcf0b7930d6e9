//! The binary as a shell user meets it: its output piped into a reader that stops early
//! (`tracker-host demo --plain | head -1`) ends the run quietly, never with a panic; an
//! output path that cannot be written is refused before the run, not after it; the
//! summary's events read plainly; Ctrl-C ends a run with its summary.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Duration;

#[test]
fn a_closed_pipe_is_not_a_panic() {
    let mut child = spawn_piped(&["--link", "inproc", "demo", "--plain", "--duration", "120"]);
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

/// The binary with `args`, its standard output and error piped to the test.
fn spawn_piped(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Reads `from` up to and including the first line that `wanted` takes; fails as `what`
/// when the stream ends first.
fn read_until(from: &mut impl BufRead, wanted: impl Fn(&str) -> bool, what: &str) {
    let mut line = String::new();
    while !wanted(&line) {
        line.clear();
        assert_ne!(from.read_line(&mut line).unwrap(), 0, "{what}");
    }
}

/// Sends `child` SIGINT, as Ctrl-C in its terminal would.
fn ctrl_c(child: &std::process::Child) {
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
}

/// A ten-minute demo paced at `speedup` (`more` arguments added), stopped by Ctrl-C once
/// it has printed the line of scan `after`: ends successfully with its summary, within
/// `within` of the Ctrl-C.
fn paced_demo_ends_on_ctrl_c(speedup: &str, after: u32, more: &[&str], within: Duration) {
    let mut args = vec![
        "--link",
        "inproc",
        "demo",
        "--plain",
        "--speedup",
        speedup,
        "--duration",
        "600",
    ];
    args.extend_from_slice(more);
    let mut child = spawn_piped(&args);
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let line = format!("scan {after:>4}");
    read_until(
        &mut out,
        // demo's headers start `SIM ` (its picture is a simulation's).
        |l| l.trim_start_matches("SIM ").starts_with(&line),
        &format!("ended before {line}"),
    );
    let started = std::time::Instant::now();
    ctrl_c(&child);
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut out, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    assert!(rest.contains("== summary"), "{rest}");
    assert!(started.elapsed() < within, "{:?}", started.elapsed());
}

#[test]
fn ctrl_c_ends_a_run_with_its_summary() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    // Paced at real time: ten minutes, stopped after its first scans.
    let json_arg = json.display().to_string();
    paced_demo_ends_on_ctrl_c(
        "1",
        2,
        &["--summary-json", &json_arg],
        Duration::from_secs(60),
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let scans = summary["scans"].as_u64().unwrap();
    assert!((2..100).contains(&scans), "{scans} scans");
}

/// Paced as slowly as allowed (a scan every 2,500 s), Ctrl-C ends the wait for the next
/// scan at once (a new user's trial at 10⁻⁹ was still waiting 8 minutes after it); slower
/// than allowed is refused (at 10⁻³⁰⁰ the wait's length overflowed the clock: a panic).
#[test]
fn ctrl_c_ends_a_slowly_paced_run_at_once_and_absurd_pacing_is_refused() {
    paced_demo_ends_on_ctrl_c("0.001", 0, &[], Duration::from_secs(10));
    for absurd in ["1e-9", "1e-300", "1e9", "0", "nan"] {
        let out = spawn_piped(&["--link", "inproc", "demo", "--speedup", absurd])
            .wait_with_output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{absurd}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("expected a number from"),
            "{absurd}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{absurd}: {stderr}");
    }
}

#[test]
fn ctrl_c_while_waiting_for_the_first_fix_ends_the_run_with_its_summary() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    // A free port: bound, read, let go; nothing is ever sent to it.
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let nmea_in = format!("udp:{port}");
    let mut child = spawn_piped(&[
        "--link",
        "inproc",
        "demo",
        "--plain",
        "--nmea-in",
        &nmea_in,
        "--summary-json",
        &json.display().to_string(),
    ]);
    let mut err = BufReader::new(child.stderr.take().unwrap());
    read_until(&mut err, |l| l.contains("first fix"), "no wait for a fix");
    let started = std::time::Instant::now();
    ctrl_c(&child);
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{:?}", out.status);
    // Not the whole 30 s wait.
    assert!(started.elapsed() < std::time::Duration::from_secs(10));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("== summary"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(summary["scans"], 0);
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

#[test]
fn a_ship_without_a_name_is_paired_by_its_mmsi_once() {
    // Own ship and one ship 550 m north and 1 km east, both north at 6 kn for 4 minutes,
    // as AIS reports every 5 s (the `--ais-truth` format).
    let dir = tempfile::tempdir().unwrap();
    let mut csv =
        String::from("Time,MMSI,Latitude_degrees,Longitude_degrees,COG_degrees,SOG_knots\n");
    for i in 0..48 {
        let (m, s) = (i * 5 / 60, i * 5 % 60);
        let lat = 50.7 + f64::from(i * 5) * 6.0 * 0.514 / 111_000.0;
        csv += &format!("2016-01-12 13:{m:02}:{s:02}.000,235000001,{lat},-1.1,0,6\n");
        csv += &format!(
            "2016-01-12 13:{m:02}:{s:02}.000,235000002,{},-1.085,0,6\n",
            lat + 0.005
        );
    }
    std::fs::write(dir.path().join("truth.csv"), csv).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args([
            "--link",
            "inproc",
            "demo",
            "--ais-truth",
            "truth.csv",
            "--own-mmsi",
            "235000001",
            "--summary-json",
            "s.json",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("s.json")).unwrap()).unwrap();
    let events: Vec<&str> = summary["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e.as_str())
        .filter(|e| e.contains("paired with"))
        .collect();
    assert!(!events.is_empty(), "{summary}");
    for e in events {
        assert!(e.ends_with("paired with AIS 235000002"), "{e}");
    }
}

#[test]
fn without_a_firmware_to_run_the_default_link_falls_back_to_in_process() {
    // The default link is QEMU where it is installed; with no firmware to start (here no
    // cargo to build it) the run goes on in-process and says so, and its summary names the
    // link it ran on. (Without QEMU it is in-process from the start.)
    let dir = tempfile::tempdir().unwrap();
    let summary = dir.path().join("s.json");
    let out = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args(["demo", "--plain", "--duration", "5", "--summary-json"])
        .arg(&summary)
        .env("CARGO", "/bin/false")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    assert_eq!(json["link"], "inproc", "{stderr}");
}
