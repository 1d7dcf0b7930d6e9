//! `tracker-host replay`: a single-target filter over recorded measurements.
//!
//! Contract (stable; external tools check it):
//! - input: CSV with a header holding `t,x,y` (s, m; other columns ignored), t strictly
//!   increasing, spacing free;
//! - output: CSV with header `t,x,y,vx,vy,px,py,ex,ey` (and `manoeuvre`, 0 or 1, for the
//!   GRNN filter), one row per input row, in order.
//!   `x,y,vx,vy` are the estimate after the measurement at t, `px,py` the prediction for t
//!   made before it, `ex,ey` the innovation. The first row is the initial state: position =
//!   first measurement, every derivative 0, prediction = the measurement, innovation 0;
//! - bad input or options: an error naming the line or option, a non-zero exit, and no
//!   output file (the output is written to a temporary file and renamed at the end).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use clap::{Args, ValueEnum};
use tracker_core::filter::alpha_beta::AlphaBetaGains;
use tracker_core::filter::alpha_beta_gamma::AbgGains;
use tracker_core::filter::alpha_beta_gamma_eta::AbgeGains;
use tracker_core::filter::grnn::{GrnnConfig, GrnnDetector};
use tracker_core::filter::grnn_residual::ResidualConfig;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::{self, Filter, FilterConfig, FilterKind, Interval};
use tracker_core::scalar::{Fix, Real, Scalar};

/// What `replay --filter` names: one of the tracking filters ([`FilterKind`]), or paper
/// 004's target-tracking EKF fed by its dead-reckoning EKF (`ttkf`: polar `--input`,
/// own-ship sensors in `--nav`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplayFilter {
    /// A tracking filter over `t,x,y` measurements.
    Track(FilterKind),
    /// The DRKF + TTKF over polar fixes.
    Ttkf,
}

impl ReplayFilter {
    /// Every name `--filter` accepts.
    pub fn names() -> Vec<&'static str> {
        FilterKind::ALL
            .iter()
            .map(|k| k.name())
            .chain(["ttkf"])
            .collect()
    }
}

impl std::str::FromStr for ReplayFilter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "ttkf" {
            return Ok(ReplayFilter::Ttkf);
        }
        s.parse::<FilterKind>()
            .map(ReplayFilter::Track)
            .map_err(|_| format!("`{s}`: expected one of {}", Self::names().join(", ")))
    }
}

/// The number type a replay computes in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ScalarKind {
    /// Double precision (the host's reference).
    #[default]
    F64,
    /// Single precision (what the MCU runs).
    F32,
    /// Fixed point I18F14 with I2F30 gains (g-h family and SSWT only).
    Fixed,
}

impl ScalarKind {
    /// The name on the command line: `f64`, `f32`, `fixed`.
    pub fn name(self) -> &'static str {
        match self {
            ScalarKind::F64 => "f64",
            ScalarKind::F32 => "f32",
            ScalarKind::Fixed => "fixed",
        }
    }
}

/// Process-noise model names on the command line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum QModelArg {
    /// Q = q·I (the thesis).
    #[default]
    Identity,
    /// Discrete white-noise acceleration (CV) / discrete Wiener process acceleration (CA).
    Dwna,
    /// Continuous white-noise acceleration (CV) / continuous white-noise jerk (CA).
    Cwna,
}

/// The GRNN's manoeuvre detector on the command line (paper 003 §4's two concepts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum GrnnDetectorArg {
    /// The plots' residuals against the stable filter (the first concept; the default).
    #[default]
    Residual,
    /// The manoeuvre and stable filters' outputs compared (the second concept).
    Difference,
}

/// Gain options, shared by every filter (each takes the ones that apply to it).
#[derive(Clone, Debug, Default, Args)]
pub struct GainArgs {
    /// Position gain α (g). With α-β alone: Benedict–Bordner β = α²/(2−α).
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Velocity gain β (h).
    #[arg(long)]
    pub beta: Option<f64>,
    /// Acceleration gain γ (Brookner's k: the update adds 2γ/T²·ε).
    #[arg(long)]
    pub gamma: Option<f64>,
    /// Jerk gain η (Brookner's l: the update adds 6η/T³·ε).
    #[arg(long)]
    pub eta: Option<f64>,
    /// Fading-memory parameter ξ in [0, 1]: critically damped gains, all poles at ξ.
    #[arg(long)]
    pub xi: Option<f64>,
    /// α-β gain schedule: `least-squares` (thesis eq. 2-3/2-4), or `thesis` with --alpha
    /// (the thesis as run: α fixed, β from eq. 2-4's schedule).
    #[arg(long, value_name = "SCHEDULE")]
    pub alpha_schedule: Option<String>,
    /// α-β-γ with --xi: `seed-literal` runs paper 000 as it ran (Table 2's gains through
    /// its eq. 1-4); `printed-eq6` takes its eq. 6 to the letter (unstable at ξ = 0.9).
    #[arg(long, value_name = "GAINS")]
    pub gains: Option<String>,
    /// SSWT window size M (2..8).
    #[arg(long)]
    pub window: Option<usize>,
    /// Kalman process noise intensity q.
    #[arg(long)]
    pub q: Option<f64>,
    /// Kalman process noise model.
    #[arg(long, value_enum, default_value_t = QModelArg::Identity)]
    pub q_model: QModelArg,
    /// Kalman measurement noise variance per axis r, m².
    #[arg(long)]
    pub r: Option<f64>,
    /// Kalman initial variance of each derivative (position starts at r), default 1e4.
    #[arg(long)]
    pub p0: Option<f64>,
    /// GRNN kernel width σ, m/s (default: from the measured noise).
    #[arg(long)]
    pub sigma: Option<f64>,
    /// GRNN manoeuvre filter's teaching sequence, scans (default 10).
    #[arg(long)]
    pub short: Option<usize>,
    /// GRNN stable filter's teaching sequence, scans (default 45).
    #[arg(long)]
    pub long: Option<usize>,
    /// GRNN manoeuvre detector.
    #[arg(long, value_enum)]
    pub detector: Option<GrnnDetectorArg>,
    /// GRNN detector onset threshold (default 2.1 residual, 1.75 difference).
    #[arg(long)]
    pub onset: Option<f64>,
    /// GRNN detector release threshold (default 1.3 residual, 1.5 difference).
    #[arg(long)]
    pub release: Option<f64>,
}

fn unused(args: &GainArgs, filter: FilterKind, allowed: &[&str]) -> anyhow::Result<()> {
    let given = [
        ("--alpha", args.alpha.is_some()),
        ("--beta", args.beta.is_some()),
        ("--gamma", args.gamma.is_some()),
        ("--eta", args.eta.is_some()),
        ("--xi", args.xi.is_some()),
        ("--alpha-schedule", args.alpha_schedule.is_some()),
        ("--gains", args.gains.is_some()),
        ("--window", args.window.is_some()),
        ("--q", args.q.is_some()),
        ("--r", args.r.is_some()),
        ("--p0", args.p0.is_some()),
        ("--sigma", args.sigma.is_some()),
        ("--short", args.short.is_some()),
        ("--long", args.long.is_some()),
        ("--detector", args.detector.is_some()),
        ("--onset", args.onset.is_some()),
        ("--release", args.release.is_some()),
    ];
    for (name, set) in given {
        if set && !allowed.contains(&name) {
            bail!("option {name} does not apply to --filter {filter}");
        }
    }
    Ok(())
}

/// "missing options --q Q, --r R": the options of `wanted` (each `--name VALUE` and
/// whether it was given) not given, all told at once rather than one a try.
fn missing(wanted: &[(&str, bool)]) -> anyhow::Error {
    let names: Vec<&str> = wanted
        .iter()
        .filter(|(_, given)| !given)
        .map(|(name, _)| *name)
        .collect();
    match names.as_slice() {
        [one] => anyhow!("missing option {one}"),
        many => anyhow!("missing options {}", many.join(", ")),
    }
}

/// An α-β design's gains out of range, in words: the option, its value, the range.
fn alpha_beta_out_of_range(design: &AlphaBetaGains) -> anyhow::Error {
    match *design {
        AlphaBetaGains::BenedictBordner { alpha } | AlphaBetaGains::ThesisFixedAlpha { alpha } => {
            anyhow!("option --alpha: α = {alpha} out of range (0, 1]")
        }
        AlphaBetaGains::FadingMemory { xi } => {
            anyhow!("option --xi: ξ = {xi} out of range [0, 1]")
        }
        AlphaBetaGains::Fixed { alpha, beta } => anyhow!(
            "options --alpha, --beta: α = {alpha}, β = {beta} unstable (need α ≥ 0, β ≥ 0, 2α + β < 4)"
        ),
        AlphaBetaGains::LeastSquares => anyhow!("the least-squares schedule was refused"),
    }
}

/// ξ out of range, or explicit gains (`names`: α, β, …) outside [0, 2].
fn xi_or_gains_out_of_range(xi: Option<f64>, gains: &[f64], names: &[&str]) -> anyhow::Error {
    match xi {
        Some(xi) => anyhow!("option --xi: ξ = {xi} out of range [0, 1]"),
        None => {
            let given: Vec<String> = names
                .iter()
                .zip(gains)
                .map(|(n, g)| format!("{n} = {g}"))
                .collect();
            anyhow!(
                "gain options: {} out of range (each within [0, 2])",
                given.join(", ")
            )
        }
    }
}

/// The filter `config` describes, in words: its name and the parameters that matter, e.g.
/// `kalman-cv (q = 0.1, cwna model, r = 25 m², p0 = 10000)`.
pub fn describe(config: &FilterConfig) -> String {
    let alpha_beta = |g: &AlphaBetaGains| match *g {
        AlphaBetaGains::Fixed { alpha, beta } => format!("α = {alpha}, β = {beta}"),
        AlphaBetaGains::BenedictBordner { alpha } => {
            format!(
                "α = {alpha}, Benedict–Bordner β = {:.4}",
                alpha * alpha / (2.0 - alpha)
            )
        }
        AlphaBetaGains::LeastSquares => "least-squares gain schedule".to_string(),
        AlphaBetaGains::ThesisFixedAlpha { alpha } => {
            format!("α = {alpha}, β from the least-squares schedule (thesis)")
        }
        AlphaBetaGains::FadingMemory { xi } => format!("ξ = {xi}"),
    };
    let q_model = |m: QModel| match m {
        QModel::Identity => "identity",
        QModel::Discrete => "dwna",
        QModel::Continuous => "cwna",
    };
    let details = match config {
        FilterConfig::AlphaBeta(g) => alpha_beta(g),
        FilterConfig::AlphaBetaGamma(g) => match *g {
            AbgGains::Explicit { alpha, beta, gamma } => {
                format!("α = {alpha}, β = {beta}, γ = {gamma}")
            }
            AbgGains::FadingMemory { xi } => format!("ξ = {xi}"),
            AbgGains::SeedLiteral { xi } => format!("ξ = {xi}, paper 000's gains as it ran"),
            AbgGains::PrintedEq6 { xi } => format!("ξ = {xi}, paper 000's eq. 6 as printed"),
        },
        FilterConfig::AlphaBetaGammaEta(g) => match *g {
            AbgeGains::Explicit {
                alpha,
                beta,
                gamma,
                eta,
            } => format!("α = {alpha}, β = {beta}, γ = {gamma}, η = {eta}"),
            AbgeGains::FadingMemory { xi } => format!("ξ = {xi}"),
        },
        FilterConfig::Sswt(c) => format!(
            "window {}, starting with {}",
            c.window,
            alpha_beta(&c.start)
        ),
        FilterConfig::KalmanCv(c) | FilterConfig::KalmanCa(c) => format!(
            "q = {}, {} model, r = {} m², p0 = {}",
            c.q,
            q_model(c.q_model),
            c.r,
            c.p0_derivative
        ),
        FilterConfig::Grnn(c) => {
            let sigma = c
                .sigma_mps
                .map_or("σ from the measured noise".to_string(), |s| {
                    format!("σ = {s} m/s")
                });
            let detector = match &c.detector {
                GrnnDetector::Residual(r) => format!(
                    "residual detector, onset {}, release {}",
                    r.onset, r.release
                ),
                GrnnDetector::Difference => format!(
                    "difference detector, onset {}, release {}",
                    c.onset, c.release
                ),
            };
            format!("{sigma}, short {}, long {}, {detector}", c.short, c.long)
        }
        FilterConfig::Imm(c) => format!("q CV = {}, r = {} m²", c.q_cv, c.r),
    };
    format!("{} ({details})", config.kind())
}

fn alpha_beta_design(a: &GainArgs) -> anyhow::Result<AlphaBetaGains> {
    let design = match (a.alpha_schedule.as_deref(), a.xi, a.alpha, a.beta) {
        (Some("least-squares"), None, None, None) => AlphaBetaGains::LeastSquares,
        (Some("thesis"), None, Some(alpha), None) => AlphaBetaGains::ThesisFixedAlpha { alpha },
        (Some("thesis"), _, None, _) => bail!("option --alpha-schedule thesis needs --alpha"),
        (Some(other), None, None, None) => bail!(
            "option --alpha-schedule: unknown schedule `{other}` (expected least-squares, or thesis with --alpha)"
        ),
        (None, Some(xi), None, None) => AlphaBetaGains::FadingMemory { xi },
        (None, None, Some(alpha), Some(beta)) => AlphaBetaGains::Fixed { alpha, beta },
        (None, None, Some(alpha), None) => AlphaBetaGains::BenedictBordner { alpha },
        (None, None, None, Some(_)) => bail!("option --beta needs --alpha"),
        (None, None, None, None) => bail!(
            "missing gain: give --xi X, --alpha A [--beta B], or --alpha-schedule least-squares"
        ),
        _ => bail!("options --alpha-schedule, --xi and --alpha/--beta exclude each other"),
    };
    design
        .validate()
        .map_err(|_| alpha_beta_out_of_range(&design))?;
    Ok(design)
}

/// The filter configuration `--filter` and the gain options describe, refusing options
/// that do not apply and missing gains.
///
/// # Errors
/// An option the filter does not take, a missing gain, gains out of range: each named.
pub fn config_from_args(kind: FilterKind, a: &GainArgs) -> anyhow::Result<FilterConfig> {
    let spec = match kind {
        FilterKind::AlphaBeta => {
            unused(a, kind, &["--alpha", "--beta", "--xi", "--alpha-schedule"])?;
            FilterConfig::AlphaBeta(alpha_beta_design(a)?)
        }
        FilterKind::AlphaBetaGamma => {
            unused(
                a,
                kind,
                &["--alpha", "--beta", "--gamma", "--xi", "--gains"],
            )?;
            let g = match (a.gains.as_deref(), a.xi, a.alpha, a.beta, a.gamma) {
                (None, Some(xi), None, None, None) => AbgGains::FadingMemory { xi },
                (Some("seed-literal"), Some(xi), None, None, None) => AbgGains::SeedLiteral { xi },
                (Some("printed-eq6"), Some(xi), None, None, None) => AbgGains::PrintedEq6 { xi },
                (Some(g @ ("seed-literal" | "printed-eq6")), None, ..) => {
                    bail!("option --gains {g} needs --xi")
                }
                (Some(other), ..) => bail!(
                    "option --gains: unknown value `{other}` (expected seed-literal or printed-eq6)"
                ),
                (None, None, Some(alpha), Some(beta), Some(gamma)) => {
                    AbgGains::Explicit { alpha, beta, gamma }
                }
                (None, None, None, None, None) => {
                    bail!("missing gain: give --xi X or --alpha A --beta B --gamma G")
                }
                (None, None, alpha, beta, gamma) => {
                    return Err(missing(&[
                        ("--alpha A", alpha.is_some()),
                        ("--beta B", beta.is_some()),
                        ("--gamma G", gamma.is_some()),
                    ])
                    .context("explicit gains need all three (or --xi X alone)"));
                }
                _ => bail!("options: give either --xi X or all of --alpha, --beta, --gamma"),
            };
            g.validate().map_err(|_| {
                let [alpha, beta, gamma] = g.gains();
                xi_or_gains_out_of_range(a.xi, &[alpha, beta, gamma], &["α", "β", "γ"])
            })?;
            FilterConfig::AlphaBetaGamma(g)
        }
        FilterKind::AlphaBetaGammaEta => {
            unused(a, kind, &["--alpha", "--beta", "--gamma", "--eta", "--xi"])?;
            let g = match (a.xi, a.alpha, a.beta, a.gamma, a.eta) {
                (Some(xi), None, None, None, None) => AbgeGains::FadingMemory { xi },
                (None, Some(alpha), Some(beta), Some(gamma), Some(eta)) => AbgeGains::Explicit {
                    alpha,
                    beta,
                    gamma,
                    eta,
                },
                (None, None, None, None, None) => {
                    bail!("missing gain: give --xi X or --alpha --beta --gamma --eta")
                }
                (None, alpha, beta, gamma, eta) => {
                    return Err(missing(&[
                        ("--alpha A", alpha.is_some()),
                        ("--beta B", beta.is_some()),
                        ("--gamma G", gamma.is_some()),
                        ("--eta E", eta.is_some()),
                    ])
                    .context("explicit gains need all four (or --xi X alone)"));
                }
                _ => bail!("options: give either --xi X or all of --alpha, --beta, --gamma, --eta"),
            };
            g.validate()
                .map_err(|_| xi_or_gains_out_of_range(a.xi, &g.gains(), &["α", "β", "γ", "η"]))?;
            FilterConfig::AlphaBetaGammaEta(g)
        }
        FilterKind::Sswt => {
            unused(
                a,
                kind,
                &["--alpha", "--beta", "--xi", "--alpha-schedule", "--window"],
            )?;
            let window = a
                .window
                .ok_or_else(|| anyhow!("missing option --window M (2..8)"))?;
            let cfg = SswtConfig {
                window,
                start: alpha_beta_design(a)?,
            };
            cfg.build::<f64>()
                .map_err(|_| anyhow!("option --window {window}: must be 2..8"))?;
            FilterConfig::Sswt(cfg)
        }
        FilterKind::Grnn => {
            unused(
                a,
                kind,
                &[
                    "--sigma",
                    "--short",
                    "--long",
                    "--detector",
                    "--onset",
                    "--release",
                ],
            )?;
            let d = GrnnConfig::default();
            let detector = match a.detector.unwrap_or_default() {
                GrnnDetectorArg::Residual => {
                    let r = ResidualConfig::default();
                    GrnnDetector::Residual(ResidualConfig {
                        onset: a.onset.unwrap_or(r.onset),
                        release: a.release.unwrap_or(r.release),
                        ..r
                    })
                }
                GrnnDetectorArg::Difference => GrnnDetector::Difference,
            };
            let difference = detector == GrnnDetector::Difference;
            let cfg = GrnnConfig {
                sigma_mps: a.sigma,
                short: a.short.unwrap_or(d.short),
                long: a.long.unwrap_or(d.long),
                onset: a.onset.filter(|_| difference).unwrap_or(d.onset),
                release: a.release.filter(|_| difference).unwrap_or(d.release),
                detector,
                ..d
            };
            cfg.validate().map_err(|_| {
                anyhow!(
                    "GRNN options: need σ > 0, 2 ≤ --short ≤ --long ≤ {}, 0 < --onset, 0 < --release (≤ --onset with --detector difference)",
                    tracker_core::filter::grnn::MAX_MODELS
                )
            })?;
            FilterConfig::Grnn(cfg)
        }
        FilterKind::Imm => {
            // The product's IMM for plots of variance --r; --q replaces the CV model's q.
            unused(a, kind, &["--q", "--r"])?;
            let r = a.r.ok_or_else(|| anyhow!("missing option --r R"))?;
            if !(r.is_finite() && r > 0.0) {
                bail!("option --r {r}: need r > 0");
            }
            let FilterConfig::Imm(mut cfg) = FilterConfig::tracking(kind, r.sqrt() as f32, 20.0)
            else {
                bail!("the IMM's configuration is not an IMM's");
            };
            cfg.r = r;
            if let Some(q) = a.q {
                cfg.q_cv = q;
            }
            cfg.validate()
                .map_err(|_| anyhow!("options --q/--r: need q ≥ 0, r > 0"))?;
            FilterConfig::Imm(cfg)
        }
        FilterKind::KalmanCv | FilterKind::KalmanCa => {
            unused(a, kind, &["--q", "--r", "--p0"])?;
            let (Some(q), Some(r)) = (a.q, a.r) else {
                return Err(missing(&[
                    ("--q Q", a.q.is_some()),
                    ("--r R", a.r.is_some()),
                ]));
            };
            let q_model = match a.q_model {
                QModelArg::Identity => QModel::Identity,
                QModelArg::Dwna => QModel::Discrete,
                QModelArg::Cwna => QModel::Continuous,
            };
            let mut cfg = KalmanConfig::new(q, q_model, r);
            if let Some(p0) = a.p0 {
                cfg.p0_derivative = p0;
            }
            cfg.validate().map_err(|_| {
                anyhow!(
                    "options --q {q} --r {r} --p0 {}: need q ≥ 0, r > 0, p0 > 0",
                    cfg.p0_derivative
                )
            })?;
            if kind == FilterKind::KalmanCv {
                FilterConfig::KalmanCv(cfg)
            } else {
                FilterConfig::KalmanCa(cfg)
            }
        }
    };
    Ok(spec)
}

/// One measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimedPosition {
    /// Time, s.
    pub t: f64,
    /// East, m.
    pub x: f64,
    /// North, m.
    pub y: f64,
}

/// One output row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateRow {
    /// Time, s.
    pub t: f64,
    /// Estimated position, m.
    pub x: f64,
    /// Estimated position, m.
    pub y: f64,
    /// Estimated velocity, m/s.
    pub vx: f64,
    /// Estimated velocity, m/s.
    pub vy: f64,
    /// Prediction for t made before the measurement, m.
    pub px: f64,
    /// Prediction for t made before the measurement, m.
    pub py: f64,
    /// Innovation, m.
    pub ex: f64,
    /// Innovation, m.
    pub ey: f64,
    /// A manoeuvre is declared (filters with a detector).
    pub manoeuvre: bool,
}

/// Reads a measurement CSV: header with `t,x,y` (any order, extra columns ignored).
///
/// # Errors
/// The file does not open, or as [`parse_measurements`].
pub fn read_measurements(path: &Path) -> anyhow::Result<Vec<TimedPosition>> {
    let file = fs::File::open(path).with_context(|| format!("opening {}", path.display()))?;
    parse_measurements(file, &path.display().to_string())
}

/// Parses measurements from any reader; `name` labels errors.
///
/// # Errors
/// A header without `t`, `x` or `y`, a value that is not a finite number, a time that does not increase, no row: each naming the line.
pub fn parse_measurements<R: std::io::Read>(
    reader: R,
    name: &str,
) -> anyhow::Result<Vec<TimedPosition>> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(reader);
    let headers = rdr
        .headers()
        .with_context(|| format!("{name}: reading the header"))?
        .clone();
    let col = |c: &str| {
        headers
            .iter()
            .position(|h| h == c)
            .ok_or_else(|| anyhow!("{name}: the header has no `{c}` column (need t,x,y)"))
    };
    let (ti, xi, yi) = (col("t")?, col("x")?, col("y")?);
    // A column twice would silently read the first; refuse it instead.
    for c in ["t", "x", "y"] {
        if headers.iter().filter(|h| *h == c).count() > 1 {
            bail!("{name}: line 1: column `{c}` appears twice");
        }
    }
    let mut out: Vec<TimedPosition> = Vec::new();
    for (i, rec) in rdr.records().enumerate() {
        let line = i + 2;
        let rec = rec.with_context(|| format!("{name} line {line}"))?;
        let field = |idx: usize, c: &str| -> anyhow::Result<f64> {
            let s = rec
                .get(idx)
                .ok_or_else(|| anyhow!("{name} line {line}: no `{c}` value"))?;
            let v: f64 = s
                .parse()
                .map_err(|_| anyhow!("{name} line {line}: `{c}` = `{s}` is not a number"))?;
            if !v.is_finite() {
                bail!("{name} line {line}: `{c}` = `{s}` is not finite");
            }
            Ok(v)
        };
        let m = TimedPosition {
            t: field(ti, "t")?,
            x: field(xi, "x")?,
            y: field(yi, "y")?,
        };
        if let Some(prev) = out.last() {
            if m.t <= prev.t {
                bail!(
                    "{name} line {line}: t = {} does not increase (previous {})",
                    m.t,
                    prev.t
                );
            }
        }
        out.push(m);
    }
    if out.is_empty() {
        bail!("{name}: no measurements");
    }
    Ok(out)
}

/// Runs one filter over the measurements.
fn drive<S: Scalar, F: Filter<S>>(
    mut f: F,
    input: &[TimedPosition],
) -> anyhow::Result<Vec<EstimateRow>> {
    let mut out = Vec::with_capacity(input.len());
    let mut prev_t = None;
    for (i, m) in input.iter().enumerate() {
        let line = i + 2;
        let z = filter::Measurement::new([S::of(m.x), S::of(m.y)])
            .map_err(|e| anyhow!("input line {line}: {e}"))?;
        let (p, e) = match prev_t {
            None => {
                f.start(z);
                (z.position_m(), [S::ZERO; 2])
            }
            Some(t0) => {
                let dt = Interval::new(S::of(m.t - t0))
                    .map_err(|e| anyhow!("input line {line}: {e} (in {})", S::NAME))?;
                (f.predict(dt), f.update(z))
            }
        };
        prev_t = Some(m.t);
        let est = f.estimate();
        out.push(EstimateRow {
            t: m.t,
            x: est.position_m[0].to_f64(),
            y: est.position_m[1].to_f64(),
            vx: est.velocity_mps[0].to_f64(),
            vy: est.velocity_mps[1].to_f64(),
            px: p[0].to_f64(),
            py: p[1].to_f64(),
            ex: e[0].to_f64(),
            ey: e[1].to_f64(),
            manoeuvre: f.manoeuvring(),
        });
    }
    Ok(out)
}

/// The g-h family and SSWT, in any scalar; `None` for the Kalman filters.
fn run_gh<S: Scalar>(
    spec: &FilterConfig,
    input: &[TimedPosition],
) -> Option<anyhow::Result<Vec<EstimateRow>>> {
    let bad = |e| anyhow!("filter parameters: {e}");
    Some(match spec {
        FilterConfig::AlphaBeta(g) => g.build::<S>().map_err(bad).and_then(|f| drive(f, input)),
        FilterConfig::AlphaBetaGamma(g) => {
            g.build::<S>().map_err(bad).and_then(|f| drive(f, input))
        }
        FilterConfig::AlphaBetaGammaEta(g) => {
            g.build::<S>().map_err(bad).and_then(|f| drive(f, input))
        }
        FilterConfig::Sswt(c) => c.build::<S>().map_err(bad).and_then(|f| drive(f, input)),
        FilterConfig::KalmanCv(_)
        | FilterConfig::KalmanCa(_)
        | FilterConfig::Grnn(_)
        | FilterConfig::Imm(_) => return None,
    })
}

fn run_real<S: Real>(
    spec: &FilterConfig,
    input: &[TimedPosition],
) -> anyhow::Result<Vec<EstimateRow>> {
    let bad = |e| anyhow!("filter parameters: {e}");
    match spec {
        FilterConfig::KalmanCv(c) => c.build_cv::<S>().map_err(bad).and_then(|f| drive(f, input)),
        FilterConfig::KalmanCa(c) => c.build_ca::<S>().map_err(bad).and_then(|f| drive(f, input)),
        FilterConfig::Grnn(c) => c.build::<S>().map_err(bad).and_then(|f| drive(f, input)),
        FilterConfig::Imm(c) => c.build::<S>().map_err(bad).and_then(|f| drive(f, input)),
        other => {
            run_gh::<S>(other, input).unwrap_or_else(|| unreachable!("all g-h filters handled"))
        }
    }
}

/// Runs `spec` over `input` in `scalar`.
///
/// # Errors
/// Fixed point asked of a Kalman or GRNN filter; a gain the filter refuses; a measurement or interval the filter cannot take (naming the line).
pub fn run(
    spec: &FilterConfig,
    scalar: ScalarKind,
    input: &[TimedPosition],
) -> anyhow::Result<Vec<EstimateRow>> {
    match scalar {
        ScalarKind::F64 => run_real::<f64>(spec, input),
        ScalarKind::F32 => run_real::<f32>(spec, input),
        ScalarKind::Fixed => {
            // The state word holds ±131,072 m: beyond, its arithmetic saturates (as the MCU's
            // must, never wrapping), and a replay would write the saturated values as if they
            // were estimates.
            let limit = FIXED_POSITION_LIMIT_M;
            if let Some((i, p)) = input
                .iter()
                .enumerate()
                .find(|(_, p)| p.x.abs() > limit || p.y.abs() > limit)
            {
                bail!(
                    "input line {}: option --scalar fixed: ({}, {}) m is beyond the fixed-point \
                     state's ±{limit:.0} m (I18F14); use --scalar f32 or f64, or positions \
                     relative to a nearer origin",
                    i + 2,
                    p.x,
                    p.y
                );
            }
            run_gh::<Fix>(spec, input).unwrap_or_else(|| {
                bail!("option --scalar fixed: the Kalman and GRNN filters run in f32 or f64 only")
            })
        }
    }
}

/// The largest position `--scalar fixed` takes, m: the `I18F14` state word's range
/// (±131,072 m) less room for the prediction and the innovation.
pub const FIXED_POSITION_LIMIT_M: f64 = 100_000.0;

/// Writes the output CSV atomically: a temporary file beside `path`, renamed when complete.
/// With `manoeuvre_column` a last column `manoeuvre` (0 or 1) is written, for filters with a
/// manoeuvre detector.
///
/// # Errors
/// The file cannot be written or renamed (the temporary file is removed).
pub fn write_estimates(
    path: &Path,
    rows: &[EstimateRow],
    manoeuvre_column: bool,
) -> anyhow::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| anyhow!("--output {}: not a file name", path.display()))?;
    let tmp: PathBuf = dir.join(format!(".{}.partial", name.to_string_lossy()));
    let result = (|| -> anyhow::Result<()> {
        let mut w = std::io::BufWriter::new(fs::File::create(&tmp)?);
        let extra = if manoeuvre_column { ",manoeuvre" } else { "" };
        writeln!(w, "t,x,y,vx,vy,px,py,ex,ey{extra}")?;
        for r in rows {
            write!(
                w,
                "{},{},{},{},{},{},{},{},{}",
                r.t, r.x, r.y, r.vx, r.vy, r.px, r.py, r.ex, r.ey
            )?;
            if manoeuvre_column {
                write!(w, ",{}", u8::from(r.manoeuvre))?;
            }
            writeln!(w)?;
        }
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        fs::rename(&tmp, path)?;
        Ok(())
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> GainArgs {
        GainArgs::default()
    }

    #[test]
    fn options_map_to_designs() {
        let mut a = args();
        a.alpha = Some(0.7);
        assert_eq!(
            config_from_args(FilterKind::AlphaBeta, &a).unwrap(),
            FilterConfig::AlphaBeta(AlphaBetaGains::BenedictBordner { alpha: 0.7 })
        );
        let mut a = args();
        a.xi = Some(0.9);
        a.gains = Some("seed-literal".into());
        assert_eq!(
            config_from_args(FilterKind::AlphaBetaGamma, &a).unwrap(),
            FilterConfig::AlphaBetaGamma(AbgGains::SeedLiteral { xi: 0.9 })
        );
    }

    #[test]
    fn bad_options_are_named() {
        let err = |k, a: &GainArgs| config_from_args(k, a).unwrap_err().to_string();
        assert!(err(FilterKind::AlphaBeta, &args()).contains("missing gain"));
        let mut a = args();
        a.window = Some(3);
        a.xi = Some(0.5);
        assert!(err(FilterKind::AlphaBeta, &a).contains("--window"));
        assert!(err(FilterKind::Sswt, &{
            let mut a = args();
            a.xi = Some(0.5);
            a
        })
        .contains("--window"));
        assert!(err(FilterKind::KalmanCv, &args()).contains("--q"));
        let mut a = args();
        a.xi = Some(1.5);
        assert!(err(FilterKind::AlphaBetaGammaEta, &a).contains("out of range"));
    }

    #[test]
    fn csv_errors_name_the_line() {
        let e = |s: &str| {
            parse_measurements(s.as_bytes(), "in.csv")
                .unwrap_err()
                .to_string()
        };
        assert!(e("t,x\n0,1\n").contains("no `y` column"));
        assert!(e("t,x,y\n0,1,2\n1,abc,3\n").contains("line 3"));
        assert!(e("t,x,y\n0,1,2\n0,1,3\n").contains("does not increase"));
        assert!(e("t,x,y\n0,NaN,2\n").contains("not finite"));
        assert!(e("t,x,y\n").contains("no measurements"));
        assert!(e("t,x,y,x\n0,1,2,3\n").contains("`x` appears twice"));
        let ok = parse_measurements("x,extra,t,y\n1,q,0,2\n3,r,1.5,4\n".as_bytes(), "in").unwrap();
        assert_eq!(
            ok[1],
            TimedPosition {
                t: 1.5,
                x: 3.0,
                y: 4.0
            }
        );
    }

    #[test]
    fn first_row_is_the_initial_state_and_fixed_kalman_is_refused() {
        let input = [
            TimedPosition {
                t: 0.0,
                x: 10.0,
                y: 20.0,
            },
            TimedPosition {
                t: 2.0,
                x: 12.0,
                y: 21.0,
            },
        ];
        let spec = FilterConfig::KalmanCv(KalmanConfig::new(1.0, QModel::Identity, 4.0));
        let rows = run(&spec, ScalarKind::F64, &input).unwrap();
        assert_eq!(
            (rows[0].x, rows[0].y, rows[0].vx, rows[0].vy),
            (10.0, 20.0, 0.0, 0.0)
        );
        assert_eq!((rows[1].px, rows[1].py), (10.0, 20.0));
        assert!(run(&spec, ScalarKind::Fixed, &input).is_err());
        // Beyond the fixed-point state's range: refused, not saturated.
        let far = [TimedPosition {
            t: 0.0,
            x: 150_000.0,
            y: 0.0,
        }];
        let ab = FilterConfig::AlphaBeta(AlphaBetaGains::Fixed {
            alpha: 0.5,
            beta: 0.2,
        });
        let e = run(&ab, ScalarKind::Fixed, &far).unwrap_err().to_string();
        assert!(e.contains("beyond the fixed-point"), "{e}");
        assert!(run(&ab, ScalarKind::F32, &far).is_ok());
    }
}
