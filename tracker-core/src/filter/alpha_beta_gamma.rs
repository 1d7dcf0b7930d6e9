//! α-β-γ filter, constant acceleration (`000_1d4538ac71ce8a6a.txt`, eq. 1-7).
//!
//! The canonical design is critically damped (fading memory): from ξ,
//! g = 1 − ξ³, h = 1.5(1 − ξ)²(1 + ξ), k = ½(1 − ξ)³, which puts all three closed-loop
//! poles at ξ (tested through the characteristic polynomial).
//!
//! The paper's printed formulas differ: eq. 6 prints β = 1.5(1 − ξ)³(1 + ξ), but its own
//! Table 2 (ξ = 0.9: α = 0.271, β = 0.0285, γ = 0.001) agrees with (1 − ξ)²; its
//! γ = (1 − ξ)³ (eq. 7) is 2k, and its eq. 3 then adds 2γ/T²·ε, twice the critically damped
//! acceleration gain, which moves the poles from ξ = 0.9 to 0.81 and 0.945 ± 0.087j.
//!
//! [`AbgGains::SeedLiteral`] runs the paper as it ran: Table 2's α, β, γ through eq. 1-4
//! exactly as printed. [`AbgGains::PrintedEq6`] also takes eq. 6's (1 − ξ)³ literally;
//! that filter is unstable at ξ = 0.9 (a pole pair at |z| = 1.006, tested), so the paper
//! cannot have run it: it is kept only to show why.

use super::gh::{GhFilter, Schedule};
use super::FilterError;
use crate::scalar::Scalar;

/// An α-β-γ filter.
pub type AlphaBetaGamma<S> = GhFilter<S, 3>;

/// How the α-β-γ gains are chosen.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AbgGains {
    /// Explicit Brookner gains g, h, k (the update adds 2k/T²·ε to the acceleration).
    Explicit {
        /// Position gain g (α).
        alpha: f64,
        /// Velocity gain h (β).
        beta: f64,
        /// Acceleration gain k (γ).
        gamma: f64,
    },
    /// Critically damped from ξ: all poles at ξ.
    FadingMemory {
        /// ξ in [0, 1].
        xi: f64,
    },
    /// The paper as run: Table 2's gains, α = 1 − ξ³, β = 1.5(1 − ξ)²(1 + ξ),
    /// γ = (1 − ξ)³, through eq. 3's acceleration update 2γ/T²·ε.
    SeedLiteral {
        /// ξ in [0, 1].
        xi: f64,
    },
    /// Eq. 5-7 to the letter, β = 1.5(1 − ξ)³(1 + ξ): unstable at ξ = 0.9.
    PrintedEq6 {
        /// ξ in [0, 1].
        xi: f64,
    },
}

impl AbgGains {
    /// Brookner's (g, h, k) for this design.
    pub fn gains(&self) -> [f64; 3] {
        match *self {
            AbgGains::Explicit { alpha, beta, gamma } => [alpha, beta, gamma],
            AbgGains::FadingMemory { xi } => {
                let m = 1.0 - xi;
                [
                    1.0 - xi * xi * xi,
                    1.5 * m * m * (1.0 + xi),
                    0.5 * m * m * m,
                ]
            }
            AbgGains::SeedLiteral { xi } => {
                let m = 1.0 - xi;
                [1.0 - xi * xi * xi, 1.5 * m * m * (1.0 + xi), m * m * m]
            }
            AbgGains::PrintedEq6 { xi } => {
                let m = 1.0 - xi;
                [1.0 - xi * xi * xi, 1.5 * m * m * m * (1.0 + xi), m * m * m]
            }
        }
    }

    /// The gains as the paper tabulates them: (α, β, γ) with γ = 2k.
    pub fn paper_alpha_beta_gamma(&self) -> [f64; 3] {
        let [g, h, k] = self.gains();
        [g, h, 2.0 * k]
    }

    /// Checks parameters are finite and in range.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when a gain or ξ is not finite or out of range.
    pub fn validate(&self) -> Result<(), FilterError> {
        let ok = match *self {
            AbgGains::Explicit { alpha, beta, gamma } => [alpha, beta, gamma]
                .iter()
                .all(|g| g.is_finite() && (0.0..=2.0).contains(g)),
            AbgGains::FadingMemory { xi }
            | AbgGains::SeedLiteral { xi }
            | AbgGains::PrintedEq6 { xi } => (0.0..=1.0).contains(&xi),
        };
        FilterError::check(ok)
    }

    /// A filter with these gains in scalar `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`AbgGains::validate`].
    pub fn build<S: Scalar>(&self) -> Result<AlphaBetaGamma<S>, FilterError> {
        self.validate()?;
        Ok(GhFilter::with_schedule(Schedule::Constant(
            self.gains().map(S::gain_from_f64),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::gh::{pole_mismatch, spectral_radius};
    use crate::filter::testing::{polynomial, run};
    use crate::filter::Filter;

    #[test]
    fn table_2_of_the_paper() {
        let [a, b, g] = AbgGains::FadingMemory { xi: 0.9 }.paper_alpha_beta_gamma();
        assert!((a - 0.271).abs() < 5e-4);
        assert!((b - 0.0285).abs() < 5e-5);
        assert!((g - 0.001).abs() < 5e-7);
    }

    #[test]
    fn critically_damped_poles_are_all_at_xi() {
        for xi in [0.0, 0.2, 0.5, 0.64, 0.9, 0.97] {
            assert!(
                pole_mismatch(AbgGains::FadingMemory { xi }.gains(), xi) < 1e-12,
                "xi {xi}"
            );
        }
    }

    #[test]
    fn the_papers_gains_move_the_poles() {
        // As run (Table 2 through eq. 3): poles 0.810 and 0.945 ± 0.087j, so the slowest
        // mode decays at |z| = 0.949 instead of 0.9.
        let rho = spectral_radius(AbgGains::SeedLiteral { xi: 0.9 }.gains());
        assert!((rho - 0.9488).abs() < 1e-3, "{rho}");
        assert!(pole_mismatch(AbgGains::SeedLiteral { xi: 0.9 }.gains(), 0.9) > 1e-4);
        // Eq. 6 to the letter: a pole pair at |z| = 1.006, outside the unit circle.
        let rho = spectral_radius(AbgGains::PrintedEq6 { xi: 0.9 }.gains());
        assert!((rho - 1.0059).abs() < 1e-3, "{rho}");
    }

    #[test]
    fn no_steady_state_error_on_constant_acceleration() {
        let samples = polynomial(&[5.0, 10.0, 0.3], &[0.0, -4.0, -0.05], 600, 3.0);
        let mut f = AbgGains::FadingMemory { xi: 0.7 }.build::<f64>().unwrap();
        let est = run(&mut f, &samples);
        let (t, z) = samples[599];
        assert!((est[599].position_m[0] - z[0]).abs() < 1e-6);
        assert!((est[599].velocity_mps[0] - (10.0 + 0.6 * t)).abs() < 1e-6);
        let d = f.derivatives();
        assert!((d[0][2] - 0.6).abs() < 1e-9 && (d[1][2] + 0.1).abs() < 1e-9);
        // Prediction one scan ahead is exact too.
        let p = f.predict(crate::filter::Interval::new(3.0).unwrap());
        let t1 = t + 3.0;
        assert!((p[1] - (-4.0 * t1 - 0.05 * t1 * t1)).abs() < 1e-5);
    }
}
