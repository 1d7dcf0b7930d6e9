//! α-β-γ-η filter, constant jerk (`001_13aaa989b195c0a5.txt`, eq. 1-8).
//!
//! Critically damped design from ξ (Brookner's fading-memory g-h-k-l):
//! g = 1 − ξ⁴, h = (1/6)(1 − ξ)²(11 + 14ξ + 11ξ²), k = (1 − ξ)³(1 + ξ),
//! l = (1/6)(1 − ξ)⁴, which puts all four closed-loop poles at ξ (tested). The paper's
//! printed formulas lost their exponents in extraction; these are the ones that place the
//! poles, and they are what we run.

use super::gh::{GhFilter, Schedule};
use super::FilterError;
use crate::scalar::Scalar;

/// An α-β-γ-η filter.
pub type AlphaBetaGammaEta<S> = GhFilter<S, 4>;

/// How the α-β-γ-η gains are chosen.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AbgeGains {
    /// Explicit Brookner gains g, h, k, l.
    Explicit {
        /// Position gain g (α).
        alpha: f64,
        /// Velocity gain h (β).
        beta: f64,
        /// Acceleration gain k (γ).
        gamma: f64,
        /// Jerk gain l (η).
        eta: f64,
    },
    /// Critically damped from ξ: all poles at ξ.
    FadingMemory {
        /// ξ in [0, 1].
        xi: f64,
    },
}

impl AbgeGains {
    /// Brookner's (g, h, k, l).
    pub fn gains(&self) -> [f64; 4] {
        match *self {
            AbgeGains::Explicit {
                alpha,
                beta,
                gamma,
                eta,
            } => [alpha, beta, gamma, eta],
            AbgeGains::FadingMemory { xi } => {
                let m = 1.0 - xi;
                [
                    1.0 - xi * xi * xi * xi,
                    m * m * (11.0 + 14.0 * xi + 11.0 * xi * xi) / 6.0,
                    m * m * m * (1.0 + xi),
                    m * m * m * m / 6.0,
                ]
            }
        }
    }

    /// Checks parameters are finite and in range.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when a gain or ξ is not finite or out of range.
    pub fn validate(&self) -> Result<(), FilterError> {
        let ok = match *self {
            AbgeGains::Explicit { .. } => self
                .gains()
                .iter()
                .all(|g| g.is_finite() && (0.0..=2.0).contains(g)),
            AbgeGains::FadingMemory { xi } => (0.0..=1.0).contains(&xi),
        };
        FilterError::check(ok)
    }

    /// A filter with these gains in scalar `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`AbgeGains::validate`].
    pub fn build<S: Scalar>(&self) -> Result<AlphaBetaGammaEta<S>, FilterError> {
        self.validate()?;
        Ok(GhFilter::with_schedule(Schedule::Constant(
            self.gains().map(S::gain_from_f64),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::gh::pole_mismatch;
    use crate::filter::testing::{polynomial, run};

    #[test]
    fn all_four_poles_at_xi() {
        for xi in [0.0, 0.3, 0.74, 0.9, 0.95] {
            assert!(
                pole_mismatch(AbgeGains::FadingMemory { xi }.gains(), xi) < 1e-12,
                "xi {xi}"
            );
        }
    }

    #[test]
    fn no_steady_state_error_on_constant_jerk() {
        let samples = polynomial(
            &[0.0, 5.0, 0.01, 0.0001],
            &[100.0, 0.0, -0.02, 0.00005],
            800,
            3.0,
        );
        let mut f = AbgeGains::FadingMemory { xi: 0.6 }.build::<f64>().unwrap();
        let est = run(&mut f, &samples);
        let (t, z) = samples[799];
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1.0);
        assert!(rel(est[799].position_m[0], z[0]) < 1e-9);
        assert!(rel(est[799].velocity_mps[1], -0.04 * t + 0.000_15 * t * t) < 1e-9);
        let d = f.derivatives();
        assert!((d[0][3] - 0.0006).abs() < 1e-9);
    }
}
