//! The turn study in `tracker-host compare`: the IMM against the CV Kalman, α-β-γ and GRNN
//! filters (each as the product tracks with it, [`FilterConfig::tracking`]) on a ship's
//! turn at a radar's real plot noise, by Monte Carlo.
//!
//! The ship: 10 m/s on 000° for 5 minutes, a 60° turn to starboard at ω °/s (60/ω s), then
//! straight for 3 minutes; plots every 2.5 s with Gaussian noise of σ m on each axis. Scored:
//! RMS position and velocity error over the turn and the minute after it, RMS course error
//! during the turn and over the minute after, and the **vector delay**: the time from the
//! turn's end until the course error stays under 5° (for 10 scans), its 95th percentile over
//! the runs, and the share of runs where that took a minute or less.

use tracker_core::filter::{FilterConfig, FilterKind};

use super::replay::{self, ScalarKind, TimedPosition};

const SCAN_S: f64 = 2.5;
const SPEED_MPS: f64 = 10.0;
const TURN_DEG: f64 = 60.0;
const BEFORE_S: f64 = 300.0;
const AFTER_S: f64 = 180.0;
/// The window after the turn that the errors are scored over, s.
const SCORED_AFTER_S: f64 = 60.0;

/// Turn rates studied, °/s (the real Solent hovercraft turns at up to 6.8°/s).
pub const RATES_DEG_S: [f64; 4] = [1.0, 3.0, 5.0, 7.0];
/// Plot noise studied, m per axis (a radar's 20–40 m).
pub const SIGMAS_M: [f64; 3] = [20.0, 30.0, 40.0];
/// The filters compared.
pub const FILTERS: [FilterKind; 4] = [
    FilterKind::Imm,
    FilterKind::KalmanCv,
    FilterKind::AlphaBetaGamma,
    FilterKind::Grnn,
];

/// One filter's scores at one turn rate and noise.
#[derive(Clone, Debug)]
pub struct TurnScore {
    /// The filter.
    pub filter: FilterKind,
    /// Turn rate, °/s.
    pub rate_deg_s: f64,
    /// Plot noise, m.
    pub sigma_m: f64,
    /// RMS position error over the turn and the minute after, m.
    pub rms_position_m: f64,
    /// RMS velocity error over the same scans, m/s.
    pub rms_velocity_mps: f64,
    /// RMS course error during the turn, degrees.
    pub rms_course_turn_deg: f64,
    /// RMS course error over the minute after the turn, degrees.
    pub rms_course_after_deg: f64,
    /// Mean time from the turn's end until the course error stays under 5°, s.
    pub vector_delay_s: f64,
    /// Its 95th percentile over the runs, s.
    pub vector_delay_p95_s: f64,
    /// Share of runs whose course error was back under 5° (to stay) within a minute.
    pub settled_within_minute: f64,
}

/// One run: the true velocity and position per scan, the plots, and the first scan after the
/// turn.
struct Run {
    velocity: Vec<[f64; 2]>,
    position: Vec<[f64; 2]>,
    plots: Vec<TimedPosition>,
    turn_end: usize,
}

fn run_of(seed: u64, rate_deg_s: f64, sigma_m: f64) -> Run {
    let mut rng = fastrand::Rng::with_seed(seed);
    let turn_s = TURN_DEG / rate_deg_s;
    let scans = ((BEFORE_S + turn_s + AFTER_S) / SCAN_S).ceil() as usize;
    let (mut x, mut y) = (0.0f64, 0.0f64);
    let mut truth = Vec::with_capacity(scans);
    let mut position = Vec::with_capacity(scans);
    let mut plots = Vec::with_capacity(scans);
    // Integrated in small steps: the turn starts and ends between scans.
    let steps = 25;
    let h = SCAN_S / f64::from(steps);
    let course_at = |t: f64| (rate_deg_s * (t - BEFORE_S).clamp(0.0, turn_s)).to_radians();
    for k in 0..scans {
        let t = k as f64 * SCAN_S;
        if k > 0 {
            for i in 0..steps {
                let c = course_at(t - SCAN_S + (f64::from(i) + 0.5) * h);
                x += SPEED_MPS * c.sin() * h;
                y += SPEED_MPS * c.cos() * h;
            }
        }
        let c = course_at(t);
        truth.push([SPEED_MPS * c.sin(), SPEED_MPS * c.cos()]);
        position.push([x, y]);
        plots.push(TimedPosition {
            t,
            x: x + sigma_m * super::noise::normal(&mut rng),
            y: y + sigma_m * super::noise::normal(&mut rng),
        });
    }
    Run {
        velocity: truth,
        position,
        plots,
        turn_end: ((BEFORE_S + turn_s) / SCAN_S).ceil() as usize,
    }
}

/// Runs the study: `runs` Monte Carlo runs per filter, rate and noise, in f32 as on the MCU.
///
/// # Errors
/// A filter refusing its configuration (a bug, not a run-time condition).
pub fn run(runs: u64) -> anyhow::Result<Vec<TurnScore>> {
    let mut out = Vec::new();
    for &sigma_m in &SIGMAS_M {
        for &rate in &RATES_DEG_S {
            for &kind in &FILTERS {
                out.push(score(kind, rate, sigma_m, runs)?);
            }
        }
    }
    Ok(out)
}

/// One row of the study: `runs` Monte Carlo runs of `kind` (as the product runs it) on the
/// turn at `rate` °/s with `sigma_m` of plot noise, in f32.
///
/// # Errors
/// The filter refusing its configuration (a bug, not a run-time condition).
pub fn score(kind: FilterKind, rate: f64, sigma_m: f64, runs: u64) -> anyhow::Result<TurnScore> {
    let spec = FilterConfig::tracking(kind, sigma_m as f32, 20.0);
    let (mut sq_p, mut sq_v, mut n) = (0.0, 0.0, 0usize);
    let (mut sq_ct, mut nt, mut sq_ca, mut na) = (0.0, 0usize, 0.0, 0usize);
    let (mut delay_sum, mut settled) = (0.0, 0usize);
    let mut delays = Vec::with_capacity(runs as usize);
    for seed in 0..runs {
        let r = run_of(seed, rate, sigma_m);
        let (truth, end) = (&r.velocity, r.turn_end);
        let rows = replay::run(&spec, ScalarKind::F32, &r.plots)?;
        let start = (BEFORE_S / SCAN_S) as usize;
        let after = end + (SCORED_AFTER_S / SCAN_S) as usize;
        let course_err = |k: usize| {
            let r = &rows[k];
            let d = (r.vx.atan2(r.vy) - truth[k][0].atan2(truth[k][1])).to_degrees();
            (d + 180.0).rem_euclid(360.0) - 180.0
        };
        for k in start..after.min(rows.len()) {
            let (e, p) = (&rows[k], r.position[k]);
            sq_p += (e.x - p[0]).powi(2) + (e.y - p[1]).powi(2);
            sq_v += (e.vx - truth[k][0]).powi(2) + (e.vy - truth[k][1]).powi(2);
            n += 1;
            let c = course_err(k).powi(2);
            if k < end {
                sq_ct += c;
                nt += 1;
            } else {
                sq_ca += c;
                na += 1;
            }
        }
        let last = rows.len();
        let back = (end..last)
            .find(|&k| (k..last.min(k + 10)).all(|j| course_err(j).abs() < 5.0))
            .unwrap_or(last);
        let delay_s = (back - end) as f64 * SCAN_S;
        delay_sum += delay_s;
        delays.push(delay_s);
        if delay_s <= SCORED_AFTER_S {
            settled += 1;
        }
    }
    let rms = |s: f64, n: usize| (s / n.max(1) as f64).sqrt();
    delays.sort_by(f64::total_cmp);
    let p95 = delays
        .get(((delays.len() as f64 - 1.0) * 0.95).round() as usize)
        .copied()
        .unwrap_or(0.0);
    Ok(TurnScore {
        filter: kind,
        rate_deg_s: rate,
        sigma_m,
        rms_position_m: rms(sq_p, n),
        rms_velocity_mps: rms(sq_v, n),
        rms_course_turn_deg: rms(sq_ct, nt),
        rms_course_after_deg: rms(sq_ca, na),
        vector_delay_s: delay_sum / runs.max(1) as f64,
        vector_delay_p95_s: p95,
        settled_within_minute: settled as f64 / runs.max(1) as f64,
    })
}

/// The study as text.
pub fn report(runs: u64, scores: &[TurnScore]) -> String {
    let mut s = format!(
        "\nTurn study: {runs} Monte Carlo runs per row, f32; a ship at 10 m/s turning 60° at the rate given, \
         plots every 2.5 s; errors over the turn and the minute after it\n\n\
         {:>5} {:>6}  {:<18} {:>8} {:>9} {:>11} {:>12} {:>10} {:>9} {:>9}\n",
        "σ m", "ω °/s", "filter", "pos m", "vel m/s", "course° in", "course° after", "delay s", "95th s", "≤ 60 s"
    );
    for t in scores {
        s += &format!(
            "{:>5.0} {:>6.0}  {:<18} {:>8.1} {:>9.2} {:>11.1} {:>12.1} {:>10.1} {:>9.1} {:>8.0} %\n",
            t.sigma_m,
            t.rate_deg_s,
            t.filter.name(),
            t.rms_position_m,
            t.rms_velocity_mps,
            t.rms_course_turn_deg,
            t.rms_course_after_deg,
            t.vector_delay_s,
            t.vector_delay_p95_s,
            t.settled_within_minute * 100.0
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_imm_brings_the_course_back_within_a_minute_of_a_turn_at_thirty_metres() {
        // Issue #18's target: 60° at 3°/s, 30 m plots; the course error back under 5° (to
        // stay) within a minute. Stated over 1000 runs (docs/tracking.md): 98 %, 95th
        // percentile 52.5 s. Over these 200: at least 95 % and the 95th within the minute,
        // and sooner than the CV Kalman filter.
        let imm = score(FilterKind::Imm, 3.0, 30.0, 200).unwrap();
        assert!(imm.settled_within_minute >= 0.95, "{imm:?}");
        assert!(imm.vector_delay_p95_s <= 60.0, "{imm:?}");
        let cv = score(FilterKind::KalmanCv, 3.0, 30.0, 200).unwrap();
        assert!(imm.vector_delay_s < cv.vector_delay_s, "{imm:?} {cv:?}");
    }

    #[test]
    fn the_truth_turns_sixty_degrees_and_the_positions_follow_it() {
        let r = run_of(1, 3.0, 0.0);
        let course = |v: [f64; 2]| v[0].atan2(v[1]).to_degrees();
        assert!(course(r.velocity[0]).abs() < 1e-9);
        assert!((course(r.velocity[r.turn_end]) - 60.0).abs() < 1e-9);
        // Before the turn, due north at 10 m/s; noise-free plots are the true positions.
        assert!((r.position[10][1] - 250.0).abs() < 1e-9);
        for (p, q) in r.plots.iter().zip(&r.position) {
            assert_eq!([p.x, p.y], *q);
        }
        // The turn's chord: 60° of a circle of radius v/ω, about 191 m across.
        let radius = 10.0 / 3f64.to_radians();
        let k0 = (300.0 / 2.5) as usize;
        let (a, b) = (r.position[k0], r.position[r.turn_end]);
        let chord = (b[0] - a[0]).hypot(b[1] - a[1]);
        assert!(
            chord > radius * 0.9 && chord < radius * 1.1 + 25.0,
            "{chord}"
        );
    }
}
