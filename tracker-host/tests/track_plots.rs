//! Recorded plots in, tracked targets out: a demo run recorded (plots, truth, tracks,
//! summary) and tracked again from its recording with `track` gives the same tracks and the
//! same summary, scan for scan; `track` runs on a plots file that other code wrote; bad
//! files are refused with their line and column, and nothing is written.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use tracker_host::cli;

mod realdata;

fn run(args: &[&str]) -> ExitCode {
    cli::run(std::iter::once("tracker-host").chain(args.iter().copied())).expect("runs")
}

/// `track` in process with plain output, `args` after it.
fn track(args: &[&str]) -> ExitCode {
    let mut all = vec!["--link", "inproc", "track", "--plain"];
    all.extend_from_slice(args);
    run(&all)
}

fn path(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

/// The summary without what depends on the machine (host times) or the link's framing.
fn scores(json: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(json).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let o = v.as_object_mut().unwrap();
    // The command lines differ (demo, track) by design.
    o.retain(|k, _| !k.starts_with("host_ms") && !k.starts_with("link") && k != "command");
    v
}

#[test]
fn a_recorded_demo_tracks_the_same_through_track() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n| path(dir.path(), n);
    let s = |p: &PathBuf| p.to_str().unwrap().to_string();
    let (plots, truth) = (d("plots.csv"), d("truth.csv"));
    let (demo_tracks, track_tracks) = (d("demo-tracks.csv"), d("track-tracks.csv"));
    let (demo_json, track_json) = (d("demo.json"), d("track.json"));
    let code = run(&[
        "--link",
        "inproc",
        "demo",
        "--plain",
        // Ships passing inside one resolution cell: their plots' own accuracy decides which
        // track takes the one plot (recorded with the plots, so `track` weighs them alike).
        "--scenario",
        "merging",
        "--targets",
        "20",
        "--seed",
        "5",
        "--duration",
        "300",
        "--record-plots",
        &s(&plots),
        "--record-truth",
        &s(&truth),
        "--record-tracks",
        &s(&demo_tracks),
        "--summary-json",
        &s(&demo_json),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let code = track(&[
        "--plots",
        &s(&plots),
        "--truth",
        &s(&truth),
        "--record-tracks",
        &s(&track_tracks),
        "--summary-json",
        &s(&track_json),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let a = std::fs::read_to_string(&demo_tracks).unwrap();
    let b = std::fs::read_to_string(&track_tracks).unwrap();
    // About every target every scan (tracks are reported from their second plot).
    assert!(
        a.lines().count() > 120 * 19,
        "{} track rows",
        a.lines().count()
    );
    for (k, (x, y)) in a.lines().zip(b.lines()).enumerate() {
        assert_eq!(x, y, "tracks line {}", k + 1);
    }
    assert_eq!(a.lines().count(), b.lines().count());
    let (sa, sb) = (scores(&demo_json), scores(&track_json));
    assert_eq!(sa, sb);
    assert_eq!(sa["scans"], 120);
    assert!(sa["targets_confirmed"].as_u64().unwrap() >= 19, "{sa}");
    assert_eq!(sa["false_tracks"], 0, "{sa}");
}

#[test]
fn a_recorded_radar_tracks_the_same_through_track() {
    // A radar's plots are tracked at its range scale's accuracy (2 m on the HALO's 800 m,
    // 4.1 then 8.2 m on the 3G's): recorded with them (`plot_sigma_m`), tracked again they
    // give the same tracks. Taken at the file format's 40 m, the HALO's 30 targets were 1
    // (a new user's trial).
    let dir = tempfile::tempdir().unwrap();
    for capture in [
        "radar_pi-halo-velocitytrack-away.pcap.gz",
        "radar_pi-3g-trueheading.pcap.gz",
    ] {
        let d = |n: &str| dir.path().join(format!("{capture}-{n}"));
        let s = |p: &PathBuf| p.to_str().unwrap().to_string();
        let radar = format!(
            "pcap:{}",
            realdata::file(&format!("radar/{capture}")).display()
        );
        let (plots, live, again) = (d("plots.csv"), d("live.csv"), d("again.csv"));
        let code = track(&[
            "--radar",
            &radar,
            "--record-plots",
            &s(&plots),
            "--record-tracks",
            &s(&live),
        ]);
        assert_eq!(code, ExitCode::SUCCESS);
        let code = track(&["--plots", &s(&plots), "--record-tracks", &s(&again)]);
        assert_eq!(code, ExitCode::SUCCESS);
        let (a, b) = (
            std::fs::read_to_string(&live).unwrap(),
            std::fs::read_to_string(&again).unwrap(),
        );
        assert!(
            a.lines().count() > 100,
            "{capture}: {} rows",
            a.lines().count()
        );
        for (k, (x, y)) in a.lines().zip(b.lines()).enumerate() {
            assert_eq!(x, y, "{capture}: tracks line {}", k + 1);
        }
        assert_eq!(a.lines().count(), b.lines().count(), "{capture}");
        // The plots file itself round-trips, own ship's heading (from the spokes) with it.
        let replotted = d("replotted.csv");
        let code = track(&["--plots", &s(&plots), "--record-plots", &s(&replotted)]);
        assert_eq!(code, ExitCode::SUCCESS);
        let recorded = std::fs::read_to_string(&plots).unwrap();
        assert_eq!(
            recorded,
            std::fs::read_to_string(&replotted).unwrap(),
            "{capture}"
        );
        let mut rows = recorded.lines();
        let header: Vec<&str> = rows.next().unwrap().split(',').collect();
        let heading = header.iter().position(|c| *c == "heading_deg").unwrap();
        assert!(
            rows.all(|r| !r.split(',').nth(heading).unwrap().is_empty()),
            "{capture}: a row without own ship's heading"
        );
        // The operator's accuracy in place of the file's: other tracks.
        let code = track(&[
            "--plots",
            &s(&plots),
            "--plot-sigma-m",
            "40",
            "--record-tracks",
            &s(&again),
        ]);
        assert_eq!(code, ExitCode::SUCCESS);
        assert_ne!(a, std::fs::read_to_string(&again).unwrap(), "{capture}");
    }
}

#[test]
fn track_runs_on_a_plots_file_written_by_other_code() {
    // Two ships written by hand: one crossing ahead west to east, one closing from the
    // north; own ship steaming north at 5 m/s; 60 scans at 2.4–2.6 s (uneven), a scan with
    // no plot, a clutter plot now and then. No product code writes this file.
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("other.csv");
    let mut text = String::from("scan,t_s,range_m,bearing_deg,own_east_m,own_north_m\n");
    let mut t = 1000.0f64;
    for k in 0..60u32 {
        t += if k % 2 == 0 { 2.4 } else { 2.6 };
        let own = [0.0, 5.0 * (t - 1000.0)];
        let ships = [
            [-3000.0 + 6.0 * (t - 1000.0), 4000.0],
            [1500.0, 9000.0 - 4.0 * (t - 1000.0)],
        ];
        let mut rows = Vec::new();
        for (i, p) in ships.iter().enumerate() {
            if (k + i as u32) % 7 == 3 {
                continue; // missed
            }
            let (de, dn) = (p[0] - own[0], p[1] - own[1]);
            let range = de.hypot(dn) + if k % 3 == 0 { 15.0 } else { -10.0 };
            let bearing = de.atan2(dn).to_degrees().rem_euclid(360.0);
            rows.push(format!(
                "{k},{t:.3},{range:.1},{bearing:.3},{:.1},{:.1}",
                own[0], own[1]
            ));
        }
        if k % 5 == 0 {
            rows.push(format!(
                "{k},{t:.3},{:.1},{:.2},{:.1},{:.1}",
                2000.0 + 97.0 * f64::from(k),
                (37.0 * f64::from(k)) % 360.0,
                own[0],
                own[1]
            ));
        }
        if k == 30 {
            rows = vec![format!("{k},{t:.3},,,{:.1},{:.1}", own[0], own[1])];
        }
        for r in rows {
            text += &r;
            text.push('\n');
        }
    }
    std::fs::write(&plots, text).unwrap();
    let tracks = dir.path().join("tracks.csv");
    let code = track(&[
        "--plots",
        plots.to_str().unwrap(),
        "--record-tracks",
        tracks.to_str().unwrap(),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    // Both ships confirmed at the end, near where they are, moving as they move.
    let out = std::fs::read_to_string(&tracks).unwrap();
    let last: Vec<Vec<&str>> = out
        .lines()
        .filter(|l| l.starts_with("59,"))
        .map(|l| l.split(',').collect())
        .collect();
    let t_end = t - 1000.0;
    let truth = [
        ([-3000.0 + 6.0 * t_end, 4000.0], [6.0, 0.0]),
        ([1500.0, 9000.0 - 4.0 * t_end], [0.0, -4.0]),
    ];
    for (p, v) in truth {
        let found = last.iter().any(|f| {
            let n = |i: usize| f[i].parse::<f64>().unwrap();
            matches!(f[3], "confirmed" | "coasting")
                && (n(4) - p[0]).hypot(n(5) - p[1]) < 100.0
                && (n(6) - v[0]).hypot(n(7) - v[1]) < 1.5
        });
        assert!(found, "no confirmed track near {p:?} {v:?} in\n{last:?}");
    }
}

/// `text` written as a plots file, tracked with `track --plots` and recorded again with
/// `--record-plots`: the recording's `columns`, row by row.
fn recorded_again(text: &str, columns: &[&str]) -> Vec<Vec<String>> {
    let dir = tempfile::tempdir().unwrap();
    let (plots, again) = (path(dir.path(), "plots.csv"), path(dir.path(), "again.csv"));
    std::fs::write(&plots, text).unwrap();
    let code = track(&[
        "--plots",
        plots.to_str().unwrap(),
        "--record-plots",
        again.to_str().unwrap(),
    ]);
    assert_eq!(code, ExitCode::SUCCESS);
    let written = std::fs::read_to_string(&again).unwrap();
    let mut rows = written.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let at: Vec<usize> = columns
        .iter()
        .map(|c| header.iter().position(|h| h == c).unwrap())
        .collect();
    rows.map(|r| {
        let cells: Vec<&str> = r.split(',').collect();
        at.iter().map(|i| cells[*i].to_string()).collect()
    })
    .collect()
}

/// Scans recorded without a fix (`own_fix` 0) are tracked again without one: own ship
/// stood, its motion unknown, and so written again (it read as a fix at 0 kn before); a
/// position given (`M`) stays given, stopped; a fix is a fix.
#[test]
fn scans_without_a_fix_stay_without_one_tracked_again() {
    let mut text =
        "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m,own_vx_mps,own_vy_mps,own_fix\n"
            .to_string();
    for k in 0..10 {
        // No fix for four scans (own ship stood at the origin), a position given for two,
        // then a fix moving north. The velocity given beside no fix, or a position given,
        // is not taken.
        let (north, vy, fix) = match k {
            0..4 => (0.0, 3.0, "0"),
            4..6 => (0.0, 3.0, "M"),
            _ => (5.0 * f64::from(k - 6) * 2.5, 5.0, "1"),
        };
        let t = 1_000.0 + 2.5 * f64::from(k);
        text.push_str(&format!("{k},{t},1500,45,0,{north},0,{vy},{fix}\n"));
    }
    let rows = recorded_again(&text, &["own_fix", "own_vy_mps"]);
    assert_eq!(rows.len(), 10, "{rows:?}");
    for (k, row) in rows.iter().enumerate() {
        let expected = match k {
            0..4 => ["0", "0"],
            4..6 => ["M", "0"],
            _ => ["1", "5"],
        };
        assert_eq!(row, &expected, "scan {k}: {rows:?}");
    }
}

/// Without velocity columns own ship's velocity comes from successive positions with a
/// fix: the first fix after scans without one (own ship at the origin) takes the scan after
/// it, not the jump from the origin (400 m/s here).
#[test]
fn a_velocity_from_positions_is_taken_between_fixes_only() {
    let mut text = "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m,own_fix\n".to_string();
    for k in 0..7 {
        let (north, fix) = if k < 2 {
            (0.0, 0)
        } else {
            (1000.0 + 5.0 * 2.5 * f64::from(k - 2), 1)
        };
        let t = 1_000.0 + 2.5 * f64::from(k);
        text.push_str(&format!("{k},{t},1500,45,0,{north},{fix}\n"));
    }
    let rows = recorded_again(&text, &["own_vy_mps"]);
    assert_eq!(rows.len(), 7, "{rows:?}");
    for (k, row) in rows.iter().enumerate() {
        let v: f64 = row[0].parse().unwrap();
        let expected = if k < 2 { 0.0 } else { 5.0 };
        assert!((v - expected).abs() < 1e-3, "scan {k}: {v} m/s, {rows:?}");
    }
}

#[test]
fn bad_plots_files_are_refused_with_their_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let good = "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m\n0,0,1000,10,0,0\n";
    let sigma =
        "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m,range_sigma_m,bearing_sigma_deg\n";
    let head = "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m";
    let cases = [
        (
            "scan,t_s,range_m,bearing_deg,own_east_m\n0,0,1,1,0\n",
            "missing column `own_north_m`",
        ),
        (
            "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m,range_m\n0,0,1,1,0,0,1\n",
            "column 7: column `range_m` appears twice",
        ),
        (
            "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m,speed\n0,0,1,1,0,0,1\n",
            "unknown column `speed`",
        ),
        (
            &format!("{good}1,2.5,1000,360,0,0\n"),
            "line 3, column 4 (bearing_deg)",
        ),
        (
            &format!("{good}1,2.5,x,10,0,0\n"),
            "line 3, column 3 (range_m): `x`",
        ),
        (
            &format!("{good}1,0,1000,10,0,0\n"),
            "line 3, column 2 (t_s)",
        ),
        (
            &format!("{good}1,2.5,1000,10,0,0\n0,5,1000,10,0,0\n"),
            "line 4, column 1 (scan)",
        ),
        (
            &format!("{good}1,2.5,1000,,0,0\n"),
            "line 3, column 4 (bearing_deg): empty beside a range",
        ),
        (&format!("{good}1,2.5,1000,10,0\n"), "line 3"),
        (
            &format!("{good}1,2.5,1000,10,NaN,0\n"),
            "line 3, column 5 (own_east_m)",
        ),
        // The plots' accuracy: both columns or neither, positive, one for a scan's plots.
        (
            &format!("{sigma}0,0,1000,10,0,0,37.6,\n"),
            "line 2, column 8 (bearing_sigma_deg): empty beside a range_sigma_m",
        ),
        (
            &format!("{sigma}0,0,1000,10,0,0,-1,0.1\n"),
            "line 2, column 7 (range_sigma_m): -1",
        ),
        (
            &format!("{sigma}0,0,1000,10,0,0,37.6,0.1\n0,0,2000,10,0,0,37.6,0.2\n"),
            "line 3, column 7 (range_sigma_m): every plot of scan 0 must have the same accuracy",
        ),
        // The filters' accuracy: positive, one for a scan.
        (
            &format!("{head},plot_sigma_m\n0,0,1000,10,0,0,0\n"),
            "line 2, column 7 (plot_sigma_m): 0: must be over 0 m",
        ),
        (
            &format!("{head},plot_sigma_m\n0,0,1000,10,0,0,2\n0,0,900,10,0,0,4\n"),
            "line 3, column 7 (plot_sigma_m): every row of scan 0 must have the same plot_sigma_m",
        ),
        (
            &format!("{head},own_fix\n0,0,1000,10,0,0,2\n"),
            "line 2, column 7 (own_fix): `2`: must be 1, 0 or M",
        ),
        (
            &format!("{head},own_fix\n0,0,1000,10,0,0,1\n0,0,900,10,0,0,yes\n"),
            "line 3, column 7 (own_fix): `yes`: must be 1, 0 or M",
        ),
        (
            &format!("{head},own_fix\n0,0,1000,10,0,0,1\n0,0,900,10,0,0,0\n"),
            "line 3, column 7 (own_fix): every row of scan 0 must have the same own_fix",
        ),
    ];
    for (i, (text, expected)) in cases.iter().enumerate() {
        let plots = dir.path().join(format!("bad{i}.csv"));
        let tracks = dir.path().join(format!("tracks{i}.csv"));
        std::fs::write(&plots, text).unwrap();
        let err = cli::run([
            "tracker-host",
            "--link",
            "inproc",
            "track",
            "--plain",
            "--plots",
            plots.to_str().unwrap(),
            "--record-tracks",
            tracks.to_str().unwrap(),
        ])
        .expect_err("a bad file fails");
        let msg = format!("{err:#}");
        assert!(
            msg.contains(expected),
            "case {i}: `{msg}` lacks `{expected}`"
        );
        assert!(msg.contains(&format!("bad{i}.csv")), "{msg}");
        assert!(!tracks.exists(), "case {i}: output written");
    }
}

#[test]
fn a_plots_files_own_epoch_is_not_shown_as_utc() {
    use tracker_host::source::plots_file::PlotsFileSource;
    use tracker_host::source::PlotSource;
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str, t0: f64| {
        let p = path(dir.path(), name);
        let rows: String = (0..3)
            .map(|k| format!("{k},{},1500,45,0,0\n", t0 + 2.5 * f64::from(k)))
            .collect();
        std::fs::write(
            &p,
            format!("scan,t_s,range_m,bearing_deg,own_east_m,own_north_m\n{rows}"),
        )
        .unwrap();
        PlotsFileSource::open(&p).unwrap()
    };
    // Seconds from the recording's start; seconds since 1970.
    assert!(!file("elapsed.csv", 0.0).time_is_utc());
    assert!(file("utc.csv", 1.7e9).time_is_utc());
}
