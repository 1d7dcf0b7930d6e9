//! The GRNN filter's manoeuvre detector on the paper's first concept: the plots' residuals
//! against the stable filter (Stateczny & Kazimierski, `003_59e231011a82eeef.txt`, §4).
//!
//! The paper names two concepts and works out neither: "the first consists in comparing the
//! increments of the estimated vector obtained by means of one of the filters" (more
//! manoeuvre sensitive, but dependent on external conditions: the increments' size depends
//! on the noise), "the second compares the values of estimated parameters originating from
//! the manoeuvre and the stable filter"; either declares a manoeuvre when its value is
//! exceeded "in three successive steps". [`super::grnn`]'s first detector is the second
//! concept. This one is the first: the increment is what the newest plot adds to the stable
//! filter's estimate, measured in position, and its dependence on the conditions is taken
//! out by normalising it with its own spread, learnt while the target goes straight.
//!
//! ## The test (per scan k, interval Δt_k since the last plot)
//!
//! The stable filter (teaching sequence 45, the paper's formulas 2–3) gives the velocity
//! V_s; a *reference* position follows the plots with it, with a small gain g (the stable
//! filter's long memory, in position):
//!
//! 1. prediction  x⁻_k = x_{k−1} + V_s,k−1 · Δt_k;
//! 2. residual    r_k = z_k − x⁻_k, and the reference x_k = x⁻_k + g · r_k (g = 0.1);
//! 3. on a straight leg r_k has a mean b (the stable filter's slow velocity error, times
//!    Δt/g) and a spread s² per axis; both are learnt while no manoeuvre is declared and
//!    the test is quiet: b ← b + w_b (r − b), s² ← s² + w (|r − b|²/2 − s²), w_b = 0.05,
//!    w = 0.03 (0.2 while the filter warms up);
//! 4. statistic   z_k = |r_k − b| / (√2 · s): the residual in units of its own spread, the
//!    same at any plot noise;
//! 5. onset: z_k > 2.1 on 3 successive scans (the paper's finding that one step is not
//!    enough).
//!
//! In a turn the plots leave the stable filter's straight line by ½·a·t² and the reference
//! follows them only a tenth a scan, so the residual grows to several spreads within a few
//! scans; at 20 m noise a 60° turn at 2.9°/s is 50 m off the line 4 scans after its onset
//! and 91 m after 6.
//!
//! **End.** Once a manoeuvre is declared the stable filter is cut to the manoeuvre filter's
//! short teaching sequence (as with the first detector), so it follows the turn; the
//! manoeuvre ends when its one-step prediction fits the plots again: the residual
//! e_k = z_k − (x̂_{k−1} + V_s,k−1 · Δt_k) of the output position x̂, smoothed
//! ē_k = λ ē_{k−1} + (1 − λ) e_k (λ = 0.5) and normalised by its spread on straight legs,
//! is under 1.3 on 3 successive scans. The reference then restarts from the output position.
//!
//! The constants were chosen on `tracker-host compare` (the paper's manoeuvre: 3 s scans, a
//! 60° turn at 2.9°/s slowing from 8 to 6 m/s) over g ∈ {0.1, 0.15} and onset ∈ {2.0, 2.1,
//! 2.2} at 10 and 20 m, 200 runs, then checked over 1000 (docs/tracking.md), after a wider
//! grid in a prototype and the variants tried before this one: the residual against the
//! filter's own position (gain 0.5: it follows the turn too fast to see it at 20 m) and
//! without the mean b (the stable filter's velocity wanders by 1–2 m/s at 20 m noise, and
//! with a small gain that wander alone is tens of metres of residual).

use super::Vec2;
use crate::scalar::Real;

/// The residual detector's parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResidualConfig {
    /// Gain g with which the reference position follows the plots (0 < g ≤ 1).
    pub reference_gain: f64,
    /// Onset threshold on z (spreads).
    pub onset: f64,
    /// End threshold on the smoothed one-step residual (spreads).
    pub release: f64,
}

impl Default for ResidualConfig {
    fn default() -> Self {
        ResidualConfig {
            reference_gain: 0.1,
            onset: 2.1,
            release: 1.3,
        }
    }
}

impl ResidualConfig {
    /// True when every parameter is in range: 0 < g ≤ 1, 0 < release, 0 < onset.
    pub fn is_valid(&self) -> bool {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        positive(self.reference_gain)
            && self.reference_gain <= 1.0
            && positive(self.onset)
            && positive(self.release)
    }
}

/// Weight of the residual's mean b.
const BIAS_WEIGHT: f64 = 0.05;
/// Weight of the spreads once warm (0.2 before).
const SPREAD_WEIGHT: f64 = 0.03;
/// Smoothing λ of the one-step residual.
const ONE_STEP_LAMBDA: f64 = 0.5;

/// [`ResidualConfig`] in the filter's scalar.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualParams<S> {
    /// The reference gain g.
    pub gain: S,
    /// The onset threshold.
    pub onset: S,
    /// The end threshold.
    pub release: S,
}

impl<S: Real> ResidualParams<S> {
    /// `config` (checked by the caller, [`ResidualConfig::is_valid`]) in `S`.
    pub fn new(config: &ResidualConfig) -> Self {
        ResidualParams {
            gain: S::of(config.reference_gain),
            onset: S::of(config.onset),
            release: S::of(config.release),
        }
    }
}

/// The residual detector's state, in `S`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualDetector<S> {
    /// The reference position x_k, m.
    reference: Vec2<S>,
    /// The residual's mean on straight legs b, m.
    bias: Vec2<S>,
    /// Its spread per axis s², m².
    spread_var: S,
    /// The smoothed one-step residual ē, m.
    one_step: Vec2<S>,
    /// Its spread per axis on straight legs, m².
    one_step_var: S,
    /// This scan's residual r_k − b and statistic z_k, before the spreads learn from them.
    residual: Vec2<S>,
    started: bool,
}

impl<S: Real> Default for ResidualDetector<S> {
    fn default() -> Self {
        Self::new()
    }
}

impl<S: Real> ResidualDetector<S> {
    /// A detector before its first plot.
    pub fn new() -> Self {
        ResidualDetector {
            reference: [S::ZERO; 2],
            bias: [S::ZERO; 2],
            spread_var: S::ZERO,
            one_step: [S::ZERO; 2],
            one_step_var: S::ZERO,
            residual: [S::ZERO; 2],
            started: false,
        }
    }

    /// Steps 1–2 (reference gain `gain`) and the one-step residual for plot `z` (m), `dt_s`
    /// after the last plot,
    /// with the stable filter's velocity `stable_mps` (m/s, as it was before this plot) and
    /// the output position after the last plot `last_m` (m). Until `ready` (the stable
    /// filter has a velocity) the reference just follows the plots.
    pub fn residual(
        &mut self,
        gain: S,
        z: Vec2<S>,
        dt_s: S,
        stable_mps: Vec2<S>,
        last_m: Vec2<S>,
        ready: bool,
    ) {
        if !(ready && self.started) {
            self.reference = z;
            self.started = ready;
            self.residual = [S::ZERO; 2];
            return;
        }
        let lambda = S::of(ONE_STEP_LAMBDA);
        for a in 0..2 {
            let predicted = self.reference[a] + stable_mps[a] * dt_s;
            let r = z[a] - predicted;
            self.reference[a] = predicted + gain * r;
            self.residual[a] = r - self.bias[a];
            let e = z[a] - (last_m[a] + stable_mps[a] * dt_s);
            self.one_step[a] = lambda * self.one_step[a] + (S::of(1.0) - lambda) * e;
        }
    }

    /// Steps 3–4: the onset and end statistics of this scan's residuals, in spreads; while
    /// `steady` (no manoeuvre declared) the mean and spreads learn from them, faster until
    /// `warm`, and not from a residual already over the `onset` threshold.
    pub fn statistics(&mut self, onset: S, steady: bool, warm: bool) -> (S, S) {
        let half = S::of(0.5);
        let sq = |v: Vec2<S>| (v[0] * v[0] + v[1] * v[1]) * half;
        let m2 = sq(self.residual);
        let e2 = sq(self.one_step);
        let ratio = |v: S, var: S| {
            if var > S::ZERO {
                (v / var).sqrt()
            } else {
                S::ZERO
            }
        };
        let z = ratio(m2, self.spread_var);
        if steady && self.started && (!warm || z < onset) {
            let w = if warm {
                S::of(SPREAD_WEIGHT)
            } else {
                S::of(0.2)
            };
            let wb = if warm { S::of(BIAS_WEIGHT) } else { w };
            self.spread_var += w * (m2 - self.spread_var);
            self.one_step_var += w * (e2 - self.one_step_var);
            for a in 0..2 {
                // The residual before the mean came off: r = (r − b) + b.
                self.bias[a] += wb * self.residual[a];
            }
        }
        (
            m2.sqrt() / self.spread_var.sqrt().max(S::of(1e-9)),
            e2.sqrt() / self.one_step_var.sqrt().max(S::of(1e-9)),
        )
    }

    /// After a manoeuvre's end: the reference restarts from the output position `at_m` (m)
    /// and the mean from zero.
    pub fn restart(&mut self, at_m: Vec2<S>) {
        self.reference = at_m;
        self.bias = [S::ZERO; 2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_plots_stay_under_the_onset_and_a_plot_off_the_line_does_not() {
        let mut noise = crate::filter::testing::Noise::new(3);
        let p = ResidualParams::<f64>::new(&ResidualConfig::default());
        let mut d = ResidualDetector::<f64>::new();
        // 5 m/s each way, 3 s scans, 10 m noise; the stable velocity known.
        let v = [5.0, 5.0];
        let line = |k: usize| [15.0 * k as f64, 15.0 * k as f64];
        let mut last = line(0);
        let mut worst: f64 = 0.0;
        for k in 0..300 {
            let z = [
                line(k)[0] + noise.gauss(10.0),
                line(k)[1] + noise.gauss(10.0),
            ];
            d.residual(p.gain, z, 3.0, v, last, true);
            let (onset, release) = d.statistics(p.onset, true, k > 30);
            if k > 100 {
                worst = worst.max(onset);
                assert!(release.is_finite());
            }
            last = z;
        }
        // The spread is learnt: a straight track's statistic is a few units at most, and
        // one plot 80 m off the line (8 σ) is far over the threshold.
        assert!(worst < 4.0, "{worst}");
        let off = [line(300)[0] + 80.0, line(300)[1]];
        d.residual(p.gain, off, 3.0, v, last, true);
        let (onset, _) = d.statistics(p.onset, true, true);
        assert!(onset > 4.0, "{onset}");
    }

    #[test]
    fn bad_parameters_are_refused() {
        let ok = ResidualConfig::default();
        assert!(ok.is_valid());
        for bad in [
            ResidualConfig {
                reference_gain: 0.0,
                ..ok
            },
            ResidualConfig {
                reference_gain: 1.5,
                ..ok
            },
            ResidualConfig {
                onset: f64::NAN,
                ..ok
            },
            ResidualConfig {
                release: -1.0,
                ..ok
            },
        ] {
            assert!(!bad.is_valid(), "{bad:?}");
        }
    }
}
