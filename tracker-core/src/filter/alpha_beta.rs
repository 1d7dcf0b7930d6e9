//! α-β filter (thesis `002`, eq. 2-1 to 2-4).
//!
//! Position and velocity per axis; gains by one of four designs:
//!
//! - fixed (α, β), as the thesis's Tables 2-2/2-3 runs with α = 0.3, 0.7, 1;
//! - Benedict–Bordner (eq. 2-2): β = α²/(2 − α), the optimal steady-state pair;
//! - the least-squares schedule (eq. 2-3/2-4): α(k) = 2(2k−1)/(k(k+1)),
//!   β(k) = 6/(k(k+1)), k the measurement number. With k counted from the first
//!   measurement (k = 1) this is Brookner's growing-memory least-squares filter with
//!   n = k − 1: at k = 2 it gives (1, 1), the line through two points, and at every scan
//!   the estimate is the least-squares line through every measurement so far (tested).
//!   The thesis states k > 2; we start at k = 2, where the formula is already exact;
//! - fading memory / critically damped from ξ: g = 1 − ξ², h = (1 − ξ)², both poles at ξ.

use super::gh::{GhFilter, Schedule};
use super::FilterError;
use crate::scalar::Scalar;

/// An α-β filter.
pub type AlphaBeta<S> = GhFilter<S, 2>;

/// How the α-β gains are chosen.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AlphaBetaGains {
    /// Fixed α and β.
    Fixed {
        /// Position gain g.
        alpha: f64,
        /// Velocity gain h.
        beta: f64,
    },
    /// α given, β = α²/(2 − α) (thesis eq. 2-2).
    BenedictBordner {
        /// Position gain g.
        alpha: f64,
    },
    /// The growing-memory least-squares schedule (thesis eq. 2-3/2-4).
    LeastSquares,
    /// The thesis as run in Examples I–II: α fixed, β from eq. 2-4's schedule 6/(k(k+1)).
    ThesisFixedAlpha {
        /// Position gain g.
        alpha: f64,
    },
    /// Critically damped: both closed-loop poles at ξ.
    FadingMemory {
        /// ξ in [0, 1]: 0 follows the measurements, 1 ignores them.
        xi: f64,
    },
}

impl AlphaBetaGains {
    /// The constant (α, β) of this design, or `None` for the least-squares schedule.
    pub fn constant(&self) -> Option<[f64; 2]> {
        match *self {
            AlphaBetaGains::Fixed { alpha, beta } => Some([alpha, beta]),
            AlphaBetaGains::BenedictBordner { alpha } => {
                Some([alpha, alpha * alpha / (2.0 - alpha)])
            }
            AlphaBetaGains::LeastSquares | AlphaBetaGains::ThesisFixedAlpha { .. } => None,
            AlphaBetaGains::FadingMemory { xi } => Some([1.0 - xi * xi, (1.0 - xi) * (1.0 - xi)]),
        }
    }

    /// Checks the design is defined and the filter stable (Jury: 0 < α, 0 < β,
    /// 2α + β < 4; α = 1, β = 0 and ξ up to 1 are allowed as limits).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when a gain is not finite or the filter would be unstable.
    pub fn validate(&self) -> Result<(), FilterError> {
        let ok = match *self {
            AlphaBetaGains::LeastSquares => true,
            AlphaBetaGains::FadingMemory { xi } => (0.0..=1.0).contains(&xi),
            AlphaBetaGains::BenedictBordner { alpha }
            | AlphaBetaGains::ThesisFixedAlpha { alpha } => alpha > 0.0 && alpha <= 1.0,
            AlphaBetaGains::Fixed { alpha, beta } => {
                alpha.is_finite()
                    && beta.is_finite()
                    && alpha >= 0.0
                    && beta >= 0.0
                    && 2.0 * alpha + beta < 4.0
            }
        };
        FilterError::check(ok)
    }

    /// A filter with these gains in scalar `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`AlphaBetaGains::validate`].
    pub fn build<S: Scalar>(&self) -> Result<AlphaBeta<S>, FilterError> {
        self.validate()?;
        Ok(GhFilter::with_schedule(match (self, self.constant()) {
            (_, Some(g)) => Schedule::Constant(g.map(S::gain_from_f64)),
            (AlphaBetaGains::ThesisFixedAlpha { alpha }, None) => {
                Schedule::FixedAlphaLeastSquaresBeta(S::gain_from_f64(*alpha))
            }
            (_, None) => Schedule::LeastSquares,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::gh::pole_mismatch;
    use crate::filter::testing::{polynomial, run};
    use crate::filter::{Filter, Interval, Measurement};
    use crate::scalar::Fix;

    #[test]
    fn fading_memory_puts_both_poles_at_xi() {
        for xi in [0.0, 0.3, 0.64, 0.9, 0.99] {
            let g = AlphaBetaGains::FadingMemory { xi }.constant().unwrap();
            assert!(pole_mismatch(g, xi) < 1e-12, "xi {xi}");
        }
    }

    #[test]
    fn benedict_bordner_relation() {
        let [a, b] = AlphaBetaGains::BenedictBordner { alpha: 0.5 }
            .constant()
            .unwrap();
        assert_eq!(a, 0.5);
        assert!((b - 0.25 / 1.5).abs() < 1e-15);
    }

    #[test]
    fn no_steady_state_error_on_constant_velocity() {
        let samples = polynomial(&[100.0, 7.0], &[-50.0, -3.0], 200, 2.5);
        for design in [
            AlphaBetaGains::Fixed {
                alpha: 0.3,
                beta: 0.05,
            },
            AlphaBetaGains::BenedictBordner { alpha: 0.7 },
            AlphaBetaGains::LeastSquares,
            AlphaBetaGains::FadingMemory { xi: 0.8 },
        ] {
            let est = run(&mut design.build::<f64>().unwrap(), &samples);
            let (_, z) = samples[199];
            let e = est[199];
            assert!((e.position_m[0] - z[0]).abs() < 1e-6, "{design:?}");
            assert!((e.velocity_mps[1] + 3.0).abs() < 1e-6, "{design:?}");
        }
    }

    #[test]
    fn thesis_schedule_keeps_alpha_and_fades_beta() {
        let mut f = AlphaBetaGains::ThesisFixedAlpha { alpha: 0.3 }
            .build::<f64>()
            .unwrap();
        f.start(Measurement::new([0.0, 0.0]).unwrap());
        for k in 2..6u32 {
            let [a, b] = f.gains();
            assert_eq!(a, 0.3);
            assert!(
                (b - 6.0 / f64::from(k * (k + 1))).abs() < 1e-12,
                "k {k}: β {b}"
            );
            f.predict(Interval::new(1.0).unwrap());
            f.update(Measurement::new([1.0, 1.0]).unwrap());
        }
        assert!(AlphaBetaGains::ThesisFixedAlpha { alpha: 1.5 }
            .validate()
            .is_err());
    }

    #[test]
    fn unstable_or_undefined_gains_are_refused() {
        for bad in [
            AlphaBetaGains::Fixed {
                alpha: 1.5,
                beta: 1.5,
            },
            AlphaBetaGains::Fixed {
                alpha: f64::NAN,
                beta: 0.1,
            },
            AlphaBetaGains::FadingMemory { xi: 1.2 },
            AlphaBetaGains::BenedictBordner { alpha: 2.0 },
        ] {
            assert_eq!(
                bad.build::<f32>().err(),
                Some(FilterError::BadParameter),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn f32_and_fixed_agree_with_f64() {
        let mut noise = crate::filter::testing::Noise::new(3);
        let samples: std::vec::Vec<_> = polynomial(&[20_000.0, 8.0], &[-30_000.0, 5.0], 2000, 3.0)
            .into_iter()
            .map(|(t, z)| (t, [z[0] + noise.gauss(20.0), z[1] + noise.gauss(20.0)]))
            .collect();
        let design = AlphaBetaGains::FadingMemory { xi: 0.8 };
        let r = run(&mut design.build::<f64>().unwrap(), &samples);
        let s = run(&mut design.build::<f32>().unwrap(), &samples);
        let x = run(&mut design.build::<Fix>().unwrap(), &samples);
        let worst = |o: &[crate::filter::Estimate<f64>]| {
            o.iter()
                .zip(&r)
                .map(|(a, b)| {
                    (a.position_m[0] - b.position_m[0])
                        .abs()
                        .max((a.position_m[1] - b.position_m[1]).abs())
                })
                .fold(0.0, f64::max)
        };
        // Stated bounds: f32 within 2 cm (its resolution at 30 km is 2 mm), fixed within
        // 2 mm (I18F14 rounding accumulated through the filter's memory).
        assert!(worst(&s) < 0.02, "f32 {}", worst(&s));
        assert!(worst(&x) < 0.002, "fixed {}", worst(&x));
    }
}
