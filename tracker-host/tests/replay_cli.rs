//! `tracker-host replay` as users (and external checks) run it: the binary, files in, files out.

use std::path::Path;
use std::process::Command;

fn replay(dir: &Path, args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .arg("replay")
        .args(args)
        .current_dir(dir)
        .output()
        .expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A target on a gentle curve, measured every 2 to 3 s with deterministic jitter.
fn write_track(path: &Path, n: usize) {
    let mut s = String::from("t,x,y,snr\n");
    let mut t = 0.0f64;
    for i in 0..n {
        let wobble = ((i * 7919) % 13) as f64 - 6.0;
        let x = 1000.0 + 8.0 * t + wobble;
        let y = -400.0 + 3.0 * t + 0.002 * t * t - wobble;
        s += &format!("{t},{x},{y},12\n");
        t += if i % 3 == 0 { 2.0 } else { 3.0 };
    }
    std::fs::write(path, s).unwrap();
}

fn read_rows(path: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,x,y,vx,vy,px,py,ex,ey"));
    lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

#[test]
fn every_filter_and_scalar_follows_the_contract() {
    let dir = tempfile::tempdir().unwrap();
    write_track(&dir.path().join("meas.csv"), 200);
    let cases: &[(&str, &[&str], &[&str])] = &[
        ("alpha-beta", &["--xi", "0.8"], &["f64", "f32", "fixed"]),
        (
            "alpha-beta",
            &["--alpha", "0.5", "--beta", "0.2"],
            &["f64", "fixed"],
        ),
        ("alpha-beta", &["--alpha", "0.7"], &["f32"]),
        (
            "alpha-beta",
            &["--alpha-schedule", "least-squares"],
            &["f64", "fixed"],
        ),
        (
            "alpha-beta-gamma",
            &["--xi", "0.9"],
            &["f64", "f32", "fixed"],
        ),
        (
            "alpha-beta-gamma",
            &["--xi", "0.9", "--gains", "seed-literal"],
            &["f64"],
        ),
        (
            "alpha-beta-gamma-eta",
            &["--xi", "0.8"],
            &["f64", "f32", "fixed"],
        ),
        (
            "sswt",
            &["--window", "4", "--alpha", "0.7"],
            &["f64", "f32", "fixed"],
        ),
        (
            "kalman-cv",
            &["--q", "0.1", "--q-model", "cwna", "--r", "25"],
            &["f64", "f32"],
        ),
        (
            "kalman-cv",
            &["--q", "0.01", "--r", "25", "--p0", "100"],
            &["f64"],
        ),
        (
            "kalman-ca",
            &["--q", "0.001", "--q-model", "dwna", "--r", "25"],
            &["f64", "f32"],
        ),
    ];
    for (filter, gains, scalars) in cases {
        let mut reference: Option<Vec<Vec<f64>>> = None;
        for scalar in *scalars {
            let mut args = vec![
                "--filter", filter, "--input", "meas.csv", "--output", "est.csv", "--scalar",
                scalar,
            ];
            args.extend_from_slice(gains);
            let (ok, err) = replay(dir.path(), &args);
            assert!(ok, "{filter} {gains:?} {scalar}: {err}");
            let rows = read_rows(&dir.path().join("est.csv"));
            assert_eq!(rows.len(), 200);
            assert_eq!(
                &rows[0][..7],
                &[0.0, 1000.0 - 6.0, -394.0, 0.0, 0.0, 994.0, -394.0]
            );
            let last = &rows[199];
            assert!(
                (last[3] - 8.0).abs() < 1.0,
                "{filter} {scalar} vx {}",
                last[3]
            );
            match &reference {
                None => reference = Some(rows),
                Some(r) => {
                    let worst = rows
                        .iter()
                        .zip(r)
                        .map(|(a, b)| (a[1] - b[1]).abs())
                        .fold(0.0, f64::max);
                    assert!(
                        worst < 0.05,
                        "{filter} {scalar} differs from f64 by {worst} m"
                    );
                }
            }
        }
    }
}

#[test]
fn bad_input_fails_clearly_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("nan.csv"), "t,x,y\n0,1,2\n1,NaN,3\n").unwrap();
    std::fs::write(d.join("back.csv"), "t,x,y\n0,1,2\n3,1,2\n2,1,2\n").unwrap();
    std::fs::write(d.join("nocol.csv"), "t,east,y\n0,1,2\n").unwrap();
    std::fs::write(d.join("text.csv"), "t,x,y\n0,1,2\n1,one,2\n").unwrap();
    write_track(&d.join("good.csv"), 10);
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--input",
                "nan.csv",
            ],
            "line 3",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--input",
                "back.csv",
            ],
            "line 4",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--input",
                "nocol.csv",
            ],
            "`x`",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--input",
                "text.csv",
            ],
            "not a number",
        ),
        (
            &["--filter", "alpha-beta", "--input", "good.csv"],
            "missing gain",
        ),
        (
            &["--filter", "kalman-cv", "--q", "1", "--input", "good.csv"],
            "--r",
        ),
        (
            &["--filter", "kalman-cv", "--input", "good.csv"],
            "missing options --q Q, --r R",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--alpha",
                "1.5",
                "--input",
                "good.csv",
            ],
            "α = 1.5 out of range (0, 1]",
        ),
        (
            &[
                "--filter",
                "alpha-beta-gamma",
                "--alpha",
                "0.5",
                "--input",
                "good.csv",
            ],
            "missing options --beta B, --gamma G",
        ),
        (
            &[
                "--filter",
                "kalman-cv",
                "--q",
                "1",
                "--r",
                "1",
                "--scalar",
                "fixed",
                "--input",
                "good.csv",
            ],
            "fixed",
        ),
        (
            &[
                "--filter", "sswt", "--alpha", "0.5", "--window", "12", "--input", "good.csv",
            ],
            "--window",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--window",
                "3",
                "--input",
                "good.csv",
            ],
            "--window",
        ),
        (
            &["--filter", "median", "--xi", "0.5", "--input", "good.csv"],
            "median",
        ),
        (
            &[
                "--filter",
                "alpha-beta",
                "--xi",
                "0.5",
                "--input",
                "missing.csv",
            ],
            "missing.csv",
        ),
    ];
    for (args, needle) in cases {
        let mut all = args.to_vec();
        all.extend_from_slice(&["--output", "out.csv"]);
        let (ok, err) = replay(d, &all);
        assert!(!ok, "{args:?} should fail");
        assert!(err.contains(needle), "{args:?}: `{needle}` not in: {err}");
        assert!(!d.join("out.csv").exists(), "{args:?} left an output file");
        assert!(!d.join(".out.csv.partial").exists());
    }
}

#[test]
fn grnn_adds_a_manoeuvre_column() {
    let dir = tempfile::tempdir().unwrap();
    write_track(&dir.path().join("meas.csv"), 200);
    for scalar in ["f64", "f32"] {
        let args = [
            "--filter", "grnn", "--short", "12", "--input", "meas.csv", "--output", "est.csv",
            "--scalar", scalar,
        ];
        let (ok, err) = replay(dir.path(), &args);
        assert!(ok, "{scalar}: {err}");
        let text = std::fs::read_to_string(dir.path().join("est.csv")).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("t,x,y,vx,vy,px,py,ex,ey,manoeuvre"));
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 200);
        assert!(rows.iter().all(|r| r[9] == 0.0 || r[9] == 1.0));
        assert!(
            (rows[199][3] - 8.0).abs() < 1.5,
            "{scalar} vx {}",
            rows[199][3]
        );
    }
    let (ok, err) = replay(
        dir.path(),
        &[
            "--filter", "grnn", "--scalar", "fixed", "--input", "meas.csv", "--output", "x.csv",
        ],
    );
    assert!(!ok && err.contains("GRNN"), "{err}");
    let (ok, err) = replay(
        dir.path(),
        &[
            "--filter", "grnn", "--short", "50", "--input", "meas.csv", "--output", "x.csv",
        ],
    );
    assert!(!ok && err.contains("--short"), "{err}");
}

#[test]
fn messages_are_plain_words_and_the_help_lists_every_schedule() {
    let dir = tempfile::tempdir().unwrap();
    write_track(&dir.path().join("meas.csv"), 60);
    for (args, said) in [
        (
            &["--filter", "grnn"][..],
            "through grnn (σ from the measured noise, short 10, long 45, residual detector",
        ),
        (
            &["--filter", "kalman-cv", "--q", "0.1", "--r", "25"],
            "through kalman-cv (q = 0.1, identity model, r = 25 m², p0 = 10000) in f64",
        ),
        (
            &["--filter", "alpha-beta", "--alpha", "0.5"],
            "through alpha-beta (α = 0.5, Benedict–Bordner β = 0.1667) in f64",
        ),
    ] {
        let mut all = args.to_vec();
        all.extend_from_slice(&["--input", "meas.csv", "--output", "est.csv"]);
        let (ok, err) = replay(dir.path(), &all);
        assert!(ok && err.contains(said), "{args:?}: {err}");
        assert!(!err.contains('{') && !err.contains("Config"), "{err}");
    }
    // The output's directory is checked before the filter runs.
    let (ok, err) = replay(
        dir.path(),
        &[
            "--filter",
            "alpha-beta",
            "--xi",
            "0.5",
            "--input",
            "meas.csv",
            "--output",
            "no-such-dir/est.csv",
        ],
    );
    assert!(
        !ok && err.contains("--output") && err.contains("does not exist"),
        "{err}"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_tracker-host"))
        .args(["replay", "--help"])
        .output()
        .expect("runs");
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("`thesis` with --alpha"), "{help}");
}
