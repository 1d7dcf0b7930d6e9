//! Single-target tracking filters, one per file, behind one small trait.
//!
//! Every filter tracks a target's position in a plane: east and north in metres, time
//! steps in seconds. A scan is `predict(dt)` then `update(z)`; a missed detection is
//! `predict(dt)` alone (the track coasts). The first measurement starts the filter with
//! position = measurement and every derivative zero, so results compare across filters
//! and across tools.
//!
//! | file | filter | source |
//! |---|---|---|
//! | [`gh`] | the g-h-k-l engine the next three share | Brookner's notation |
//! | [`gh_fixed_scan`] | the same engine for scans at a fixed interval: what the track table runs for constant gains | – |
//! | [`alpha_beta`] | α-β: fixed, Benedict–Bordner, least-squares schedule, fading memory | thesis eq. 2-1 to 2-4 |
//! | [`alpha_beta_gamma`] | α-β-γ, critically damped, and the paper as printed | `000` eq. 1-7 |
//! | [`alpha_beta_gamma_eta`] | α-β-γ-η (constant jerk), critically damped | `001` eq. 1-8 |
//! | [`sswt`] | switched slide-window tracker | thesis §2.3.1, eq. 2-14 |
//! | [`kalman`] | Kalman, constant velocity and constant acceleration | thesis eq. 2-6 to 2-13 |
//! | [`grnn`] | GRNN neural filter with a manoeuvre detector | `003` §3–4 |
//! | [`grnn_residual`] | the GRNN's manoeuvre detector on the paper's first concept: the plots' residuals against the stable filter | `003` §4 |
//! | [`imm`] | interacting multiple model: CV, CA and settling-CV Kalman in a cycle | Bar-Shalom, Li & Kirubarajan 2001, §11.6.6 |
//!
//! [`config`] holds the one list of them ([`FilterKind`]) and their configurations
//! ([`FilterConfig`]), which the command line, the wire and the track table all use.
//!
//! Bad input never reaches a filter: measurements and intervals are validated once, where
//! they enter, into [`Measurement`] and [`Interval`]; a NaN or a non-positive step is
//! refused there with a [`FilterError`], and the filters' hot paths need no checks.

pub mod alpha_beta;
pub mod alpha_beta_gamma;
pub mod alpha_beta_gamma_eta;
pub mod config;
pub mod gh;
pub mod gh_fixed_scan;
pub mod grnn;
pub mod grnn_residual;
pub mod imm;
pub mod kalman;
pub mod sswt;

use crate::scalar::Scalar;

pub use config::{FilterConfig, FilterKind};

/// A position or velocity in the local plane: `[east, north]`.
pub type Vec2<S> = [S; 2];

/// What a filter knows about its target after the last update.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<S> {
    /// Position `[east, north]`, metres.
    pub position_m: Vec2<S>,
    /// Velocity `[east, north]`, m/s.
    pub velocity_mps: Vec2<S>,
}

/// Why a filter refused an input. The filter's state is unchanged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FilterError {
    /// A measurement was NaN, infinite, or beyond [`MAX_POSITION_M`].
    NonFinite,
    /// The time step was outside [`MIN_INTERVAL_S`, `MAX_INTERVAL_S`] (or not a number).
    BadInterval,
    /// A gain or parameter is outside the range where the filter is defined or stable.
    BadParameter,
}

impl core::fmt::Display for FilterError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            FilterError::NonFinite => "measurement is not finite or beyond ±10,000 km",
            FilterError::BadInterval => "time step is not between 1 ms and 1 day",
            FilterError::BadParameter => "parameter out of range",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FilterError {}

impl FilterError {
    /// `Ok` when a parameter check passed, [`FilterError::BadParameter`] otherwise.
    pub(crate) fn check(ok: bool) -> Result<(), FilterError> {
        if ok {
            Ok(())
        } else {
            Err(FilterError::BadParameter)
        }
    }
}

/// Largest coordinate a measurement may have, m: 10,000 km, beyond any radar picture,
/// so that no sequence of valid inputs can overflow `f32` arithmetic.
pub const MAX_POSITION_M: f64 = 1.0e7;

/// Shortest time step, s: nothing a radar does happens faster.
pub const MIN_INTERVAL_S: f64 = 1.0e-3;

/// Longest time step, s: a day.
pub const MAX_INTERVAL_S: f64 = 86_400.0;

/// A measured position `[east, north]` in metres, known to be finite and within
/// [`MAX_POSITION_M`].
///
/// Validated once where data enters (a CSV line, a plot off the link), so the filters'
/// hot paths carry no checks and cannot be handed a NaN.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement<S>(Vec2<S>);

impl<S: Scalar> Measurement<S> {
    /// Accepts a finite position within [`MAX_POSITION_M`].
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] for NaN, an infinity or a coordinate beyond [`MAX_POSITION_M`].
    #[inline]
    pub fn new(position_m: Vec2<S>) -> Result<Self, FilterError> {
        let max = S::of(MAX_POSITION_M);
        let min = S::of(-MAX_POSITION_M);
        // Both bounds are finite, so NaN and the infinities fail one of the comparisons.
        let ok = |v: S| v <= max && v >= min;
        if ok(position_m[0]) && ok(position_m[1]) {
            Ok(Measurement(position_m))
        } else {
            Err(FilterError::NonFinite)
        }
    }

    /// The position, metres.
    #[inline]
    pub fn position_m(&self) -> Vec2<S> {
        self.0
    }
}

/// A time step in seconds, known to lie in [`MIN_INTERVAL_S`, `MAX_INTERVAL_S`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval<S>(S);

impl<S: Scalar> Interval<S> {
    /// Accepts a step from 1 ms to a day.
    ///
    /// # Errors
    /// [`FilterError::BadInterval`] for a step outside [`MIN_INTERVAL_S`, `MAX_INTERVAL_S`] (or NaN).
    #[inline]
    pub fn new(seconds: S) -> Result<Self, FilterError> {
        if seconds >= S::of(MIN_INTERVAL_S) && seconds <= S::of(MAX_INTERVAL_S) {
            Ok(Interval(seconds))
        } else {
            Err(FilterError::BadInterval)
        }
    }

    /// The step, seconds.
    #[inline]
    pub fn seconds(&self) -> S {
        self.0
    }
}

/// A single-target tracking filter.
///
/// Inputs arrive validated ([`Measurement`], [`Interval`]), so no call can fail or leave
/// the state invalid.
pub trait Filter<S: Scalar> {
    /// (Re)starts on a first measurement: position = `z`, every derivative zero.
    fn start(&mut self, z: Measurement<S>);
    /// Predicts `dt` past the last update (or prediction); returns the predicted position.
    fn predict(&mut self, dt: Interval<S>) -> Vec2<S>;
    /// Corrects the prediction with a measured position; returns the innovation
    /// `z − prediction`.
    fn update(&mut self, z: Measurement<S>) -> Vec2<S>;
    /// Position and velocity now.
    fn estimate(&self) -> Estimate<S>;
    /// The last predicted position.
    fn prediction(&self) -> Vec2<S>;
    /// The last innovation.
    fn innovation(&self) -> Vec2<S>;
    /// True while the filter has declared a manoeuvre (only filters with a detector do).
    fn manoeuvring(&self) -> bool {
        false
    }
    /// The covariance `[s_xx, s_xy, s_yy]` (m²) of the innovation the next update will see,
    /// S = H·P⁻·Hᵀ + R after the last prediction (thesis eq. 2-9), for the filters that
    /// carry a covariance; `None` for those that do not (the g-h family, the SSWT, the
    /// GRNN), whose gates are sized from a model of their errors instead.
    fn innovation_covariance(&self) -> Option<[S; 3]> {
        None
    }
}

#[cfg(test)]
pub(crate) mod testing {
    //! Helpers shared by the filters' tests.
    use super::*;

    /// Runs `f` over `(t, [x, y])` samples; returns estimates after each update.
    pub fn run<S: Scalar, F: Filter<S>>(
        f: &mut F,
        samples: &[(f64, [f64; 2])],
    ) -> std::vec::Vec<Estimate<f64>> {
        let mut out = std::vec::Vec::new();
        let mut last_t = None;
        for &(t, z) in samples {
            let zs = Measurement::new([S::of(z[0]), S::of(z[1])]).unwrap();
            match last_t {
                None => f.start(zs),
                Some(t0) => {
                    f.predict(Interval::new(S::of(t - t0)).unwrap());
                    f.update(zs);
                }
            }
            last_t = Some(t);
            let e = f.estimate();
            out.push(Estimate {
                position_m: e.position_m.map(S::to_f64),
                velocity_mps: e.velocity_mps.map(S::to_f64),
            });
        }
        out
    }

    /// Samples of a polynomial trajectory `x(t) = Σ c_i t^i` on both axes.
    pub fn polynomial(cx: &[f64], cy: &[f64], n: usize, dt: f64) -> std::vec::Vec<(f64, [f64; 2])> {
        let eval = |c: &[f64], t: f64| c.iter().rev().fold(0.0, |acc, &ci| acc * t + ci);
        (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                (t, [eval(cx, t), eval(cy, t)])
            })
            .collect()
    }

    /// Deterministic Gaussian noise for tests.
    pub struct Noise(rand_pcg::Pcg32);

    impl Noise {
        pub fn new(seed: u64) -> Self {
            use rand_core::SeedableRng;
            Noise(rand_pcg::Pcg32::seed_from_u64(seed))
        }
        pub fn gauss(&mut self, sigma: f64) -> f64 {
            use rand_distr::Distribution;
            rand_distr::Normal::new(0.0, sigma).map_or(0.0, |n| n.sample(&mut self.0))
        }
    }
}
