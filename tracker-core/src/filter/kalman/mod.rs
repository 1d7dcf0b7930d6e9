//! Kalman filters (thesis `002`, §2.2.2, eq. 2-6 to 2-13): constant velocity ([`cv`]) and
//! constant acceleration ([`ca`]).
//!
//! Both measure position only (H picks x and y) with R = r·I, and both model the two axes
//! as independent, identical chains (F, Q, R and P0 are block diagonal with equal blocks).
//! Two consequences carry the speed:
//!
//! - the 4×4 (6×6) problem splits into two 2×2 (3×3) problems, one per axis;
//! - the covariance recursion does not depend on the measurements, so with equal P0 the two
//!   axes' covariances are equal at every step: one covariance serves both axes.
//!
//! The covariance update is Joseph's form, `P = (I − KH)P(I − KH)ᵀ + K R Kᵀ`, which stays
//! symmetric positive semi-definite under rounding where `(I − KH)P` does not. The tests
//! compare both filters against a dense textbook implementation of the full state.

pub mod ca;
pub mod cv;

use super::FilterError;

/// The process noise model: how the unmodelled motion enters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum QModel {
    /// Q = q·I per axis, as the thesis uses.
    Identity,
    /// Discrete white noise in the highest modelled derivative, constant over a scan: for
    /// CV per axis q·[[T⁴/4, T³/2], [T³/2, T²]] (DWNA); for CA q·g·gᵀ with
    /// g = [T²/2, T, 1] (DWPA).
    Discrete,
    /// Continuous white noise in the derivative above the highest modelled one: for CV per
    /// axis q·[[T³/3, T²/2], [T²/2, T]] (CWNA); for CA q·[[T⁵/20, T⁴/8, T³/6],
    /// [T⁴/8, T³/3, T²/2], [T³/6, T²/2, T]] (CWNJ).
    Continuous,
}

/// Kalman filter parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KalmanConfig {
    /// Process noise intensity (units per the model: m²/s⁴·s² for `Discrete` CV, etc.).
    pub q: f64,
    /// How `q` enters.
    pub q_model: QModel,
    /// Measurement noise variance per axis, m².
    pub r: f64,
    /// Initial variance of each derivative (velocity, and acceleration for CA); the
    /// initial position variance is `r`. Default 10⁴.
    pub p0_derivative: f64,
}

impl KalmanConfig {
    /// Default initial derivative variance: (100 m/s)², a ship at any plausible speed.
    pub const DEFAULT_P0_DERIVATIVE: f64 = 1e4;

    /// The configuration with the default initial covariance.
    pub fn new(q: f64, q_model: QModel, r: f64) -> Self {
        KalmanConfig {
            q,
            q_model,
            r,
            p0_derivative: Self::DEFAULT_P0_DERIVATIVE,
        }
    }

    /// Checks every parameter is finite and in range (q ≥ 0, r > 0, P0 > 0).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] otherwise.
    pub fn validate(&self) -> Result<(), FilterError> {
        let ok = self.q.is_finite()
            && self.q >= 0.0
            && self.r.is_finite()
            && self.r > 0.0
            && self.p0_derivative.is_finite()
            && self.p0_derivative > 0.0;
        FilterError::check(ok)
    }
}
