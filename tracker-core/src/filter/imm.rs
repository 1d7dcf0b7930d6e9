//! Interacting multiple model (IMM) filter: three Kalman filters, a quiet constant-velocity
//! one for straight legs, a constant-acceleration one for manoeuvres and a livelier
//! constant-velocity one for settling onto the new course after them, run side by side and
//! mixed every scan by how well each has been explaining the plots.
//!
//! The cycle is the IMM estimator of Bar-Shalom, Li & Kirubarajan, *Estimation with
//! Applications to Tracking and Navigation*, Wiley 2001, §11.6.6 (Blom & Bar-Shalom, IEEE
//! Trans. AC 33(8), 1988): (1) mixing probabilities μ_{i|j} = p_ij·μ_i / c̄_j with
//! c̄_j = Σ_i p_ij·μ_i; (2) mixed initial state and covariance for each model,
//! x̂⁰_j = Σ_i μ_{i|j}·x̂_i and P⁰_j = Σ_i μ_{i|j}·(P_i + (x̂_i − x̂⁰_j)(x̂_i − x̂⁰_j)ᵀ);
//! (3) each model's Kalman prediction and update, with its likelihood Λ_j = N(ν_j; 0, S_j);
//! (4) mode probabilities μ_j = Λ_j·c̄_j / Σ_k Λ_k·c̄_k; (5) the combined estimate
//! x̂ = Σ_j μ_j·x̂_j, which is what the track reports.
//!
//! **Why these models, not a coordinated turn.** All are linear and keep the two axes apart,
//! so the IMM is six small Kalman filters (per model, per axis: position, velocity,
//! acceleration) and no trigonometry or Jacobian: cheap on the M4F. A coordinated-turn
//! model with its turn rate estimated needs an extended Kalman filter over five coupled
//! states; at 20–40 m plots every 2.5 s a ship's turn rate is barely observable before the
//! turn is over, while the acceleration a turn causes (ω·v, 0.5 m/s² for 3°/s at 10 m/s) is
//! what the CA model estimates directly. (A CV + CT prototype, the turn rate a state and
//! the CV model's taken as zero, did worse than CV + CA on the turn study: docs/tracking.md.)
//!
//! **Why a third model, and a cycle.** With CV + CA the course comes back quickly but
//! overshoots (the CA model's acceleration outlives the turn), and the quiet CV model then
//! takes a minute to take the overshoot out: in most of the runs where the course error is
//! not back under 5° to stay within a minute of the turn's end it had first got under 5°
//! within 15 s (docs/tracking.md). The *settling* model (CV with a larger q) is what a manoeuvre
//! hands over to, and it hands over to the quiet model in turn: the modes form a cycle,
//! straight → manoeuvre → settling → straight, the Markov chain of a ship that turns and
//! then steadies on a new course. Its velocity follows the plots for the tens of seconds
//! after the turn; the quiet model can then be quieter than the CV Kalman filter's
//! (q = 0.001 m²/s³ against 0.05), which keeps a straight leg's course within a degree or
//! two at 30 m noise.
//!
//! Mode switching is a Markov chain in continuous time: a model is left after a mean
//! sojourn τ, so over a step of dt the probability of staying is p_ii = exp(−dt/τ_i); the
//! rest goes to the next model in the cycle; any scan interval works. The CV models'
//! acceleration is held at zero with zero variance.
//! Log-likelihoods are normalised before exponentiating, so f32 never underflows, and each
//! mode keeps at least [`MIN_MODE_PROBABILITY`] so neither is ever locked out.

// 3×3 matrix products read best with their indices.
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

use crate::filter::{Estimate, Filter, FilterError, Interval, Measurement, Vec2};
use crate::scalar::Real;

/// The mode probability neither model falls below.
pub const MIN_MODE_PROBABILITY: f64 = 1e-3;

/// The models, in the order of every per-model array: straight legs, manoeuvres, settling.
const CV: usize = 0;
const CA: usize = 1;
const SETTLE: usize = 2;
/// How many.
const MODELS: usize = 3;

/// The next model in the cycle: a mode is left for this one only.
const fn next(m: usize) -> usize {
    match m {
        CV => CA,
        CA => SETTLE,
        _ => CV,
    }
}

/// IMM parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImmConfig {
    /// CV model (straight legs): continuous white-noise acceleration intensity, m²/s³.
    pub q_cv: f64,
    /// CA model (manoeuvres): continuous white-noise jerk intensity, m²/s⁵.
    pub q_ca: f64,
    /// Settling model (CV, after a manoeuvre): continuous white-noise acceleration
    /// intensity, m²/s³.
    pub q_settle: f64,
    /// Measurement noise variance per axis, m².
    pub r: f64,
    /// Initial velocity variance, m²/s².
    pub p0_velocity: f64,
    /// Initial acceleration variance of the CA model, m²/s⁴.
    pub p0_acceleration: f64,
    /// Mean time in the CV model before a manoeuvre, s.
    pub sojourn_cv_s: f64,
    /// Mean time in the CA model (a manoeuvre's length), s.
    pub sojourn_ca_s: f64,
    /// Mean time in the settling model, s.
    pub sojourn_settle_s: f64,
}

impl ImmConfig {
    /// Checks every parameter is finite and in range (q ≥ 0, r > 0, variances > 0,
    /// sojourns > 0).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] otherwise.
    pub fn validate(&self) -> Result<(), FilterError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let q = |v: f64| v.is_finite() && v >= 0.0;
        let ok = q(self.q_cv)
            && q(self.q_ca)
            && q(self.q_settle)
            && pos(self.r)
            && pos(self.p0_velocity)
            && pos(self.p0_acceleration)
            && pos(self.sojourn_cv_s)
            && pos(self.sojourn_ca_s)
            && pos(self.sojourn_settle_s);
        FilterError::check(ok)
    }

    /// The filter in `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`ImmConfig::validate`].
    pub fn build<S: Real>(&self) -> Result<Imm<S>, FilterError> {
        self.validate()?;
        // Start in the chain's stationary distribution: the fraction of time in each mode,
        // which for a cycle is each mode's share of the mean sojourns.
        let tau = [self.sojourn_cv_s, self.sojourn_ca_s, self.sojourn_settle_s];
        let total: f64 = tau.iter().sum();
        let mu0 = tau.map(|t| S::of(t / total));
        Ok(Imm {
            q: [S::of(self.q_cv), S::of(self.q_ca), S::of(self.q_settle)],
            r: S::of(self.r),
            p0: [S::of(self.p0_velocity), S::of(self.p0_acceleration)],
            rate: tau.map(|t| S::of(1.0 / t)),
            mu0,
            models: [Model::ZERO; MODELS],
            mu: mu0,
            prediction: [S::ZERO; 2],
            innovation: [S::ZERO; 2],
            s: [S::ZERO; 3],
        })
    }
}

/// One model's state on one axis: [position, velocity, acceleration] and its covariance.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Axis<S> {
    x: [S; 3],
    p: [[S; 3]; 3],
}

/// One model's state on both axes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Model<S> {
    axes: [Axis<S>; 2],
}

impl<S: Real> Model<S> {
    const ZERO: Model<S> = Model {
        axes: [Axis {
            x: [S::ZERO; 3],
            p: [[S::ZERO; 3]; 3],
        }; 2],
    };
}

/// The IMM filter (CV, CA and settling CV).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Imm<S: Real> {
    q: [S; MODELS],
    r: S,
    /// Initial velocity and acceleration variances.
    p0: [S; 2],
    /// 1/τ per model, 1/s.
    rate: [S; MODELS],
    mu0: [S; MODELS],
    models: [Model<S>; MODELS],
    /// Mode probabilities: after an update, μ; after a prediction, the predicted c̄.
    mu: [S; MODELS],
    prediction: Vec2<S>,
    innovation: Vec2<S>,
    /// The combined predicted innovation covariance [s_xx, s_xy, s_yy].
    s: [S; 3],
}

impl<S: Real> Imm<S> {
    /// The mode probabilities [CV, CA, settling] (after an update; after a prediction, the
    /// predicted ones).
    pub fn mode_probabilities(&self) -> [S; MODELS] {
        self.mu
    }

    fn predict_model(&self, m: usize, a: &Axis<S>, dt: S) -> Axis<S> {
        let half = S::of(0.5);
        let t2 = dt * dt;
        let cv = m != CA;
        // F: the CV models keep acceleration at zero; CA integrates it.
        let f: [[S; 3]; 3] = if cv {
            [
                [S::of(1.0), dt, S::ZERO],
                [S::ZERO, S::of(1.0), S::ZERO],
                [S::ZERO, S::ZERO, S::ZERO],
            ]
        } else {
            [
                [S::of(1.0), dt, half * t2],
                [S::ZERO, S::of(1.0), dt],
                [S::ZERO, S::ZERO, S::of(1.0)],
            ]
        };
        let q = self.q[m];
        // Q: CWNA for CV, CWNJ for CA (as the Kalman filters' `QModel::Continuous`).
        let qm: [[S; 3]; 3] = if cv {
            let (a, b, c) = (q * t2 * dt * S::of(1.0 / 3.0), q * t2 * half, q * dt);
            [[a, b, S::ZERO], [b, c, S::ZERO], [S::ZERO; 3]]
        } else {
            let t3 = t2 * dt;
            let t4 = t2 * t2;
            let t5 = t4 * dt;
            let (a, b, c) = (
                q * t5 * S::of(0.05),
                q * t4 * S::of(0.125),
                q * t3 / S::of(6.0),
            );
            let (d, e, g) = (q * t3 * S::of(1.0 / 3.0), q * t2 * half, q * dt);
            [[a, b, c], [b, d, e], [c, e, g]]
        };
        let mut x = [S::ZERO; 3];
        for (i, xi) in x.iter_mut().enumerate() {
            *xi = f[i][0] * a.x[0] + f[i][1] * a.x[1] + f[i][2] * a.x[2];
        }
        // F P Fᵀ + Q.
        let mut fp = [[S::ZERO; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                fp[i][j] = f[i][0] * a.p[0][j] + f[i][1] * a.p[1][j] + f[i][2] * a.p[2][j];
            }
        }
        let mut p = [[S::ZERO; 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let v = fp[i][0] * f[j][0] + fp[i][1] * f[j][1] + fp[i][2] * f[j][2] + qm[i][j];
                p[i][j] = v;
                p[j][i] = v;
            }
        }
        Axis { x, p }
    }
}

/// Kalman update of one axis with H = [1, 0, 0] in Joseph's form; returns (ν, s).
fn update_axis<S: Real>(a: &mut Axis<S>, z: S, r: S) -> (S, S) {
    let s = a.p[0][0] + r;
    let nu = z - a.x[0];
    let k = [a.p[0][0] / s, a.p[1][0] / s, a.p[2][0] / s];
    for (xi, ki) in a.x.iter_mut().zip(k) {
        *xi += ki * nu;
    }
    // (I − K H) P (I − K H)ᵀ + K r Kᵀ.
    let mut ap = [[S::ZERO; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            ap[i][j] = a.p[i][j] - k[i] * a.p[0][j];
        }
    }
    for i in 0..3 {
        for j in i..3 {
            let v = ap[i][j] - ap[i][0] * k[j] + r * k[i] * k[j];
            a.p[i][j] = v;
            a.p[j][i] = v;
        }
    }
    (nu, s)
}

impl<S: Real> Filter<S> for Imm<S> {
    fn start(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        for (m, model) in self.models.iter_mut().enumerate() {
            for (axis, a) in model.axes.iter_mut().enumerate() {
                a.x = [z[axis], S::ZERO, S::ZERO];
                let acc = if m == CA { self.p0[1] } else { S::ZERO };
                a.p = [
                    [self.r, S::ZERO, S::ZERO],
                    [S::ZERO, self.p0[0], S::ZERO],
                    [S::ZERO, S::ZERO, acc],
                ];
            }
        }
        self.mu = self.mu0;
        self.prediction = z;
        self.innovation = [S::ZERO; 2];
        self.s = [self.r, S::ZERO, self.r];
    }

    fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let dt = dt.seconds();
        // (1) p_ij: stay with exp(−dt/τ_i), else on to the next model in the cycle.
        let mut stay = [S::ZERO; MODELS];
        for (st, r) in stay.iter_mut().zip(self.rate) {
            *st = (-dt * r).exp();
        }
        let pij = |i: usize, j: usize| {
            if i == j {
                stay[i]
            } else if j == next(i) {
                S::of(1.0) - stay[i]
            } else {
                S::ZERO
            }
        };
        let mut c = [S::ZERO; MODELS];
        for (j, cj) in c.iter_mut().enumerate() {
            for i in 0..MODELS {
                *cj += pij(i, j) * self.mu[i];
            }
        }
        // (2) mixing, then each model's prediction.
        let mut out = [Model::ZERO; MODELS];
        for j in 0..MODELS {
            let mut w = [S::ZERO; MODELS];
            for (i, wi) in w.iter_mut().enumerate() {
                *wi = pij(i, j) * self.mu[i] / c[j];
            }
            for axis in 0..2 {
                let mut x0 = [S::ZERO; 3];
                for (i, wi) in w.iter().enumerate() {
                    for k in 0..3 {
                        x0[k] += *wi * self.models[i].axes[axis].x[k];
                    }
                }
                let mut p0 = [[S::ZERO; 3]; 3];
                for (i, wi) in w.iter().enumerate() {
                    let xi = &self.models[i].axes[axis];
                    let d = [xi.x[0] - x0[0], xi.x[1] - x0[1], xi.x[2] - x0[2]];
                    for r in 0..3 {
                        for q in 0..3 {
                            p0[r][q] += *wi * (xi.p[r][q] + d[r] * d[q]);
                        }
                    }
                }
                out[j].axes[axis] = self.predict_model(j, &Axis { x: x0, p: p0 }, dt);
            }
        }
        self.models = out;
        self.mu = c;
        // The combined prediction and its innovation covariance (the gate's).
        let mut zp = [S::ZERO; 2];
        for (axis, z) in zp.iter_mut().enumerate() {
            for (j, m) in out.iter().enumerate() {
                *z += c[j] * m.axes[axis].x[0];
            }
        }
        let mut s = [S::ZERO; 3];
        for (j, m) in out.iter().enumerate() {
            let dx = m.axes[0].x[0] - zp[0];
            let dy = m.axes[1].x[0] - zp[1];
            s[0] += c[j] * (m.axes[0].p[0][0] + self.r + dx * dx);
            s[1] += c[j] * dx * dy;
            s[2] += c[j] * (m.axes[1].p[0][0] + self.r + dy * dy);
        }
        self.prediction = zp;
        self.s = s;
        zp
    }

    fn update(&mut self, z: Measurement<S>) -> Vec2<S> {
        let z = z.position_m();
        // (3) each model's update and log-likelihood (the 2π terms cancel in (4)).
        let mut ll = [S::ZERO; MODELS];
        for (j, m) in self.models.iter_mut().enumerate() {
            for (axis, a) in m.axes.iter_mut().enumerate() {
                let (nu, s) = update_axis(a, z[axis], self.r);
                ll[j] -= S::of(0.5) * (nu * nu / s + s.ln());
            }
        }
        // (4) μ_j ∝ Λ_j c̄_j, with the largest log-likelihood taken out first.
        let mut top = ll[0];
        for &l in &ll[1..] {
            if l > top {
                top = l;
            }
        }
        let mut mu = [S::ZERO; MODELS];
        for j in 0..MODELS {
            mu[j] = self.mu[j] * (ll[j] - top).exp();
        }
        let floor = S::of(MIN_MODE_PROBABILITY);
        let total = mu.iter().fold(S::ZERO, |a, &m| a + m);
        for m in &mut mu {
            *m /= total;
            // NaN compares false and takes the floor too.
            *m = if *m >= floor { *m } else { floor };
        }
        let total = mu.iter().fold(S::ZERO, |a, &m| a + m);
        for m in &mut mu {
            *m /= total;
        }
        self.mu = mu;
        self.innovation = [z[0] - self.prediction[0], z[1] - self.prediction[1]];
        self.innovation
    }

    fn estimate(&self) -> Estimate<S> {
        // (5) the combined estimate.
        let mu = self.mu;
        let comb = |axis: usize, k: usize| {
            let mut v = S::ZERO;
            for (j, m) in self.models.iter().enumerate() {
                v += mu[j] * m.axes[axis].x[k];
            }
            v
        };
        Estimate {
            position_m: [comb(0, 0), comb(1, 0)],
            velocity_mps: [comb(0, 1), comb(1, 1)],
        }
    }

    fn prediction(&self) -> Vec2<S> {
        self.prediction
    }

    fn innovation(&self) -> Vec2<S> {
        self.innovation
    }

    /// True while the straight-leg mode is the less probable: the target is manoeuvring or
    /// settling after a manoeuvre.
    fn manoeuvring(&self) -> bool {
        self.mu[CV] < self.mu[CA] + self.mu[SETTLE]
    }

    fn innovation_covariance(&self) -> Option<[S; 3]> {
        Some(self.s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::testing::{polynomial, run, Noise};

    fn config() -> ImmConfig {
        ImmConfig {
            q_cv: 0.05,
            q_ca: 0.01,
            q_settle: 0.1,
            r: 900.0,
            p0_velocity: 400.0,
            p0_acceleration: 1.0,
            sojourn_cv_s: 300.0,
            sojourn_ca_s: 30.0,
            sojourn_settle_s: 10.0,
        }
    }

    #[test]
    fn refuses_bad_parameters() {
        let bad = [
            ImmConfig { r: 0.0, ..config() },
            ImmConfig {
                q_ca: -1.0,
                ..config()
            },
            ImmConfig {
                sojourn_cv_s: 0.0,
                ..config()
            },
            ImmConfig {
                sojourn_settle_s: -1.0,
                ..config()
            },
            ImmConfig {
                p0_velocity: f64::NAN,
                ..config()
            },
        ];
        for c in bad {
            assert_eq!(c.build::<f32>().err(), Some(FilterError::BadParameter));
        }
    }

    #[test]
    fn a_straight_noiseless_track_is_followed_exactly_and_cv_wins() {
        let samples = polynomial(&[100.0, 8.0], &[-50.0, -3.0], 60, 2.5);
        let mut f = config().build::<f64>().unwrap();
        let out = run(&mut f, &samples);
        let last = out.last().unwrap();
        assert!((last.velocity_mps[0] - 8.0).abs() < 1e-3, "{last:?}");
        assert!((last.velocity_mps[1] + 3.0).abs() < 1e-3, "{last:?}");
        let mu = f.mode_probabilities();
        assert!(mu[0] > 0.8, "CV should explain a straight line: {mu:?}");
        assert!(!f.manoeuvring());
    }

    #[test]
    fn a_turn_raises_the_ca_mode_and_the_course_recovers() {
        // 10 m/s north, then a 90° turn to east at 3°/s (30 s), then straight; 20 m plots.
        let mut noise = Noise::new(7);
        let dt = 2.5;
        let (mut x, mut y, mut course) = (0.0f64, 0.0f64, 0.0f64);
        let mut samples = Vec::new();
        let mut peak_ca = 0.0f64;
        let mut f = config().build::<f32>().unwrap();
        let mut truth = Vec::new();
        for i in 0..120 {
            let t = i as f64 * dt;
            if (100.0..130.0).contains(&t) {
                course += 3f64.to_radians() * dt;
            }
            x += 10.0 * course.sin() * dt;
            y += 10.0 * course.cos() * dt;
            samples.push((t, [x + noise.gauss(20.0), y + noise.gauss(20.0)]));
            truth.push(course);
        }
        let mut last = None;
        let mut course_err_end = 0.0;
        for (i, &(t, z)) in samples.iter().enumerate() {
            let zs = Measurement::new([z[0] as f32, z[1] as f32]).unwrap();
            match last {
                None => f.start(zs),
                Some(t0) => {
                    f.predict(Interval::new((t - t0) as f32).unwrap());
                    f.update(zs);
                }
            }
            last = Some(t);
            peak_ca = peak_ca.max(f64::from(f.mode_probabilities()[1]));
            let e = f.estimate();
            let est = f64::from(e.velocity_mps[0]).atan2(f64::from(e.velocity_mps[1]));
            let d = (est - truth[i] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            course_err_end = d.abs().to_degrees();
        }
        assert!(
            peak_ca > 0.5,
            "the turn should raise the CA mode: {peak_ca}"
        );
        assert!(
            course_err_end < 5.0,
            "course error at the end {course_err_end}°"
        );
        assert!(f.mode_probabilities()[0] > 0.5, "back to CV after the turn");
    }

    #[test]
    fn coasting_keeps_probabilities_summing_to_one_and_the_gate_grows() {
        let mut f = config().build::<f32>().unwrap();
        f.start(Measurement::new([0.0, 0.0]).unwrap());
        let dt = Interval::new(2.5).unwrap();
        f.predict(dt);
        f.update(Measurement::new([20.0, 5.0]).unwrap());
        f.predict(dt);
        let s1 = f.innovation_covariance().unwrap()[0];
        f.predict(dt);
        let s2 = f.innovation_covariance().unwrap()[0];
        assert!(s2 > s1);
        let mu = f.mode_probabilities();
        assert!((mu[0] + mu[1] + mu[2] - 1.0).abs() < 1e-5, "{mu:?}");
    }
}
