//! `tracker-host reproduce`: the seed papers' experiments rerun with our filters, each
//! printed beside the paper's figure, with the parameters we had to choose, plotted the way
//! the papers plot them, and with our best filter on the same metric ("beyond the paper").
//!
//! One module per paper. Every experiment is deterministic (seeded noise), so the report is
//! the same on every run and a committed copy (`docs/reproduce/report.md`) can be checked for
//! staleness by a test.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context};

mod abg_2drms;
mod abge_sweep;
mod drttkf;
mod grnn;
pub mod plot;
mod thesis;

/// One experiment: its name on the command line, and what it reproduces.
pub struct Experiment {
    /// Name for `reproduce NAME`.
    pub name: &'static str,
    /// The paper and what of it.
    pub what: &'static str,
    run: fn(&Path) -> anyhow::Result<String>,
}

/// Every experiment, in report order.
pub const EXPERIMENTS: [Experiment; 5] = [
    Experiment {
        name: "abg-2drms",
        what: "000_1d4538ac71ce8a6a.txt: α-β-γ at ξ = 0.9, 2drms of smoothing and prediction",
        run: abg_2drms::run,
    },
    Experiment {
        name: "abge-sweep",
        what: "001_13aaa989b195c0a5.txt: α-β-γ against α-β-γ-η, ξ swept, total errors",
        run: abge_sweep::run,
    },
    Experiment {
        name: "thesis",
        what: "002_d593f8d961ebadf3.txt: α-β, Kalman and SSWT on Models I–III (Tables 2-2 to 2-14)",
        run: thesis::run,
    },
    Experiment {
        name: "grnn",
        what: "003_59e231011a82eeef.txt: the GRNN filter against CV Kalman and α-β on a manoeuvre",
        run: grnn::run,
    },
    Experiment {
        name: "drttkf",
        what: "004_be25d15b4854a4f6.txt: the dead-reckoning and target-tracking EKFs, Tables I–III and eq. 10",
        run: drttkf::run,
    },
];

/// Runs the experiments named (`all` or none: every one), writes `out/report.md` and the
/// plots beside it, and returns the report.
///
/// # Errors
/// An unknown experiment name, an experiment failing, the report or a plot not written.
pub fn run(names: &[String], out: &Path) -> anyhow::Result<String> {
    let chosen: Vec<&Experiment> = if names.is_empty() || names.iter().any(|n| n == "all") {
        EXPERIMENTS.iter().collect()
    } else {
        let mut chosen = Vec::new();
        for n in names {
            match EXPERIMENTS.iter().find(|e| e.name == n) {
                Some(e) => chosen.push(e),
                None => bail!(
                    "unknown experiment '{n}': choose all or {}",
                    EXPERIMENTS.map(|e| e.name).join(", ")
                ),
            }
        }
        chosen
    };
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut report = String::from(
        "# The seed papers, reproduced\n\n\
         Written by `tracker-host reproduce --out DIR` (this copy: `docs/reproduce/`); every \
         number below is measured by that command, deterministically (seeded noise), except \
         the columns headed *paper*, which are copied from the papers. Plots are SVG (PNG \
         beside each).\n\n",
    );
    for e in &chosen {
        let _ = writeln!(report, "- [{}](#{}): {}", e.name, e.name, e.what);
    }
    for e in chosen {
        let body = (e.run)(out).with_context(|| format!("experiment {}", e.name))?;
        let _ = write!(report, "\n<a id=\"{}\"></a>\n\n{body}", e.name);
    }
    std::fs::write(out.join("report.md"), &report)
        .with_context(|| format!("writing {}", out.join("report.md").display()))?;
    Ok(report)
}

/// `12345.6` → `12,345.6` (figures in the report as the papers print them).
pub(crate) fn grouped(v: f64, decimals: usize) -> String {
    let s = format!("{:.*}", decimals, v.abs());
    let (int, frac) = s.split_once('.').map_or((s.as_str(), ""), |(i, f)| (i, f));
    let mut out = String::new();
    for (i, c) in int.chars().enumerate() {
        if i > 0 && (int.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    let sign = if v < 0.0 { "-" } else { "" };
    if frac.is_empty() {
        format!("{sign}{out}")
    } else {
        format!("{sign}{out}.{frac}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grouping() {
        assert_eq!(grouped(19592.204, 2), "19,592.20");
        assert_eq!(grouped(0.5, 1), "0.5");
        assert_eq!(grouped(-1234567.0, 0), "-1,234,567");
        assert_eq!(grouped(999.0, 0), "999");
    }

    #[test]
    fn unknown_experiment_is_refused() {
        let dir = std::env::temp_dir().join("tracker-reproduce-unknown");
        let e = run(&["nope".into()], &dir).unwrap_err();
        assert!(e.to_string().contains("unknown experiment 'nope'"), "{e}");
    }
}

/// Small versions of each experiment, with bounds that hold by a margin.
#[cfg(test)]
mod experiment_tests {
    use super::*;

    #[test]
    fn paper_000_without_noise_gives_zero_and_with_noise_a_positive_radius() {
        let (s1, p1, s2, p2) = abg_2drms::case_figures();
        assert!(s1 < 1e-6 && p1 < 1e-6, "{s1} {p1}");
        assert!(s2 > 1.0 && p2 > s2, "{s2} {p2}");
    }

    #[test]
    fn paper_001_abge_beats_abg_and_the_optimum_is_inside() {
        let truth = abge_sweep::truth();
        let sweep = abge_sweep::sweep(&truth, 4, 5).unwrap();
        let (xi3, e3) = abge_sweep::Sweep::best(&sweep.abg);
        let (xi4, e4) = abge_sweep::Sweep::best(&sweep.abge);
        assert!(e4 < 0.98 * e3, "α-β-γ-η {e4} vs α-β-γ {e3}");
        for xi in [xi3, xi4] {
            assert!(xi > 0.5 && xi < 0.9, "optimal ξ {xi}");
        }
    }

    #[test]
    fn thesis_kalman_beats_alpha_beta_on_model_ii() {
        use thesis::{error, Model, Setting};
        let kalman = error(Model::II, Setting::Kalman(1.0), 10).unwrap();
        for alpha in [None, Some(0.3), Some(0.7), Some(1.0)] {
            let ab = error(Model::II, Setting::AlphaBeta(alpha), 10).unwrap();
            assert!(kalman < 0.5 * ab, "Kalman {kalman} vs α-β {alpha:?} {ab}");
        }
    }
}
