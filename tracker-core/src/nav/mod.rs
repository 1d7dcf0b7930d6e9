//! Own-ship navigation and per-target tracking Kalman filters of the ECDIS paper
//! (Baziw, `004_be25d15b4854a4f6.txt`): a dead-reckoning filter ([`drkf`], 11 states) whose
//! estimates feed one target-tracking filter per target ([`ttkf`], 12 states), serially
//! (the paper's Fig. 3, "DRTTKF").
//!
//! ## Discretisation
//!
//! Both filters are continuous models `ẋ = Fx + Gw` (eq. 4b) with first-order Gauss–Markov
//! states (eq. 1). The transition Φ = e^{FΔ} and the process noise
//! Q_k = ∫₀^Δ e^{Fu} G Gᵀ e^{Fᵀu} du (eq. 6) are computed for the actual interval with Van
//! Loan's method ([`van_loan`]), not a first-order shortcut. The models split into small
//! independent blocks (one per axis, one per Gauss–Markov error state), so Van Loan runs on a
//! 4×4 (own ship, per axis) or 3×3 block, never on the whole state: the structure that keeps
//! the filters cheap on the MCU. Scalar Gauss–Markov states use the closed form of eq. 2:
//! a = e^{−βΔ}, Q = σ²(1 − e^{−2βΔ}).
//!
//! ## Updates
//!
//! Measurements are linearised about the predicted state (the EKF of the paper), then applied
//! one scalar at a time with the residual corrected for the state already moved
//! (`z − h(x̂⁻) − H(x̂ − x̂⁻)`): exactly the batch update for independent measurement errors,
//! with no matrix inverse and a measurement vector of any size (eq. 7b "adjusted dynamically").
//! Covariances use the Joseph form. Angle residuals are wrapped to ±π.

pub mod algebra;
#[cfg(feature = "reference")]
pub mod coupled;
pub mod drkf;
pub mod ttkf;

#[cfg(feature = "reference")]
pub use algebra::Dense;
use algebra::Discretised;
pub use algebra::{Algebra, Structured};

use nalgebra::{RealField, SMatrix, SVector};

/// An f64 constant in the filter's scalar.
pub(crate) fn c<T: RealField + Copy>(v: f64) -> T {
    nalgebra::convert(v)
}

/// A first-order Gauss–Markov process (eq. 1): `ȧ = −βa + √(2σ²β)·w`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussMarkov {
    /// Standard deviation σ of the process.
    pub sigma: f64,
    /// Inverse time constant β, 1/s (0: a random constant).
    pub beta_per_s: f64,
}

impl GaussMarkov {
    /// A process of variance `variance` and inverse time constant `beta_per_s`.
    pub fn with_variance(variance: f64, beta_per_s: f64) -> Self {
        GaussMarkov {
            sigma: libm::sqrt(variance.max(0.0)),
            beta_per_s,
        }
    }

    /// Eq. 2a: the transition over Δ s, a = e^{−βΔ}.
    pub fn a(&self, dt_s: f64) -> f64 {
        libm::exp(-self.beta_per_s * dt_s)
    }

    /// Eq. 2b: the driving-noise standard deviation over Δ s, b = σ·√(1 − e^{−2βΔ}).
    pub fn b(&self, dt_s: f64) -> f64 {
        self.sigma * libm::sqrt(1.0 - libm::exp(-2.0 * self.beta_per_s * dt_s))
    }

    /// α of eq. 4d: the gain on unit white noise, √(2σ²β).
    pub fn alpha(&self) -> f64 {
        libm::sqrt(2.0 * self.sigma * self.sigma * self.beta_per_s)
    }

    pub(crate) fn is_valid(&self) -> bool {
        self.sigma.is_finite()
            && self.sigma >= 0.0
            && self.beta_per_s.is_finite()
            && self.beta_per_s >= 0.0
    }
}

/// Van Loan's method (1978): for `ẋ = Fx + w` with white `w` of spectral density `qc`, the
/// transition Φ = e^{FΔ} and the process noise Q = ∫₀^Δ e^{Fu} qc e^{Fᵀu} du over `dt_s`.
///
/// `M` must be 2·`N` (Rust cannot write 2N in a type yet); `None` otherwise.
pub fn van_loan<T: RealField + Copy, const N: usize, const M: usize>(
    f: &SMatrix<T, N, N>,
    qc: &SMatrix<T, N, N>,
    dt_s: T,
) -> Option<(SMatrix<T, N, N>, SMatrix<T, N, N>)> {
    if M != 2 * N {
        return None;
    }
    // A = [[−F, qc], [0, Fᵀ]]·Δ; e^A = [[·, Φ⁻¹Q], [0, Φᵀ]].
    let mut a = SMatrix::<T, M, M>::zeros();
    a.fixed_view_mut::<N, N>(0, 0).copy_from(&(-f * dt_s));
    a.fixed_view_mut::<N, N>(0, N).copy_from(&(qc * dt_s));
    a.fixed_view_mut::<N, N>(N, N)
        .copy_from(&(f.transpose() * dt_s));
    let e = expm(&a);
    let phi: SMatrix<T, N, N> = e.fixed_view::<N, N>(N, N).transpose();
    let q = phi * e.fixed_view::<N, N>(0, N);
    // Symmetric by construction; rounding is folded back.
    let q = (q + q.transpose()) * nalgebra::convert::<f64, T>(0.5);
    Some((phi, q))
}

/// e^A by scaling and squaring with a Taylor series (Moler & Van Loan's "method 3").
///
/// Not nalgebra's `exp`: it solves its Padé system with an LU decomposition and unwraps the
/// result, a panic path the firmware must not have; and the matrices here (Van Loan's, of the
/// Markov models) have small norms and a nilpotent part, where the Taylor series converges in a
/// few terms. The tests check it against nalgebra's `exp`.
pub fn expm<T: RealField + Copy, const M: usize>(a: &SMatrix<T, M, M>) -> SMatrix<T, M, M> {
    // Scale so that ‖A/2^s‖₁ ≤ 1/2.
    let norm = (0..M)
        .map(|j| a.column(j).iter().fold(T::zero(), |acc, v| acc + v.abs()))
        .fold(T::zero(), |m, v| if v > m { v } else { m });
    let half: T = nalgebra::convert(0.5);
    let mut squarings = 0u32;
    let mut scale = T::one();
    while norm * scale > half && squarings < 64 {
        scale *= half;
        squarings += 1;
    }
    let x = a * scale;
    // Taylor to the 16th power: the remainder is below 2⁻¹⁶/16! relative, far below f64's ε.
    let mut term = SMatrix::<T, M, M>::identity();
    let mut sum = term;
    for k in 1..=16u32 {
        term = term * x * (T::one() / nalgebra::convert::<f64, T>(f64::from(k)));
        sum += term;
    }
    for _ in 0..squarings {
        sum = sum * sum;
    }
    sum
}

/// Φ and Q of one interval.
pub type Transition<T, const N: usize> = (SMatrix<T, N, N>, SMatrix<T, N, N>);

/// x ← Φx, P ← ΦPΦᵀ + Q over `dt_s` (> 0, at most a day) with `A`'s arithmetic. The model's
/// discretisation is kept in `cache` and reused while the interval repeats (sensors at a
/// fixed rate); `discretise` makes it for a new interval.
pub(crate) fn predict_cached<T, const N: usize, A, D>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    cache: &mut Option<(T, D)>,
    dt_s: f64,
    discretise: impl FnOnce(T) -> Option<D>,
) -> Result<(), crate::filter::FilterError>
where
    T: RealField + Copy,
    A: Algebra,
    D: Discretised<T, N>,
{
    use crate::filter::FilterError;
    FilterError::check(dt_s.is_finite() && dt_s > 0.0 && dt_s <= 86_400.0)?;
    let dt: T = nalgebra::convert(dt_s);
    let model = match cache {
        Some((d, model)) if *d == dt => model,
        _ => {
            let model = discretise(dt).ok_or(FilterError::BadParameter)?;
            &mut cache.insert((dt, model)).1
        }
    };
    A::propagate(x, p, model);
    Ok(())
}

/// `a` wrapped to (−π, π]. Residuals of two angles in (−π, π] need one step; only a wild
/// input pays for the remainder (a software call on the M4F).
pub(crate) fn wrap_pi<T: RealField + Copy>(a: T) -> T {
    let (pi, two_pi) = (T::pi(), T::two_pi());
    let three_pi = pi + two_pi;
    let mut w = if a >= three_pi || a <= -three_pi {
        a % two_pi
    } else {
        a
    };
    if w > pi {
        w -= two_pi;
    } else if w <= -pi {
        w += two_pi;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix4;

    #[test]
    fn gauss_markov_discretisation_is_eq_2() {
        let g = GaussMarkov::with_variance(0.25, 0.5);
        assert!((g.a(2.0) - (-1.0f64).exp()).abs() < 1e-12);
        assert!((g.b(2.0) - 0.5 * (1.0 - (-2.0f64).exp()).sqrt()).abs() < 1e-12);
        assert!((g.alpha() - (2.0 * 0.25 * 0.5f64).sqrt()).abs() < 1e-12);
    }

    /// Φ and Q by brute force: Φ by many small Euler steps of e^{FΔ}, Q by the midpoint rule.
    fn integrate(f: &Matrix4<f64>, qc: &Matrix4<f64>, dt: f64) -> (Matrix4<f64>, Matrix4<f64>) {
        let n = 20_000;
        let h = dt / n as f64;
        let step =
            Matrix4::identity() + f * h + f * f * (h * h / 2.0) + f * f * f * (h * h * h / 6.0);
        let half = Matrix4::identity() + f * (h / 2.0) + f * f * (h * h / 8.0);
        let (mut phi, mut q) = (Matrix4::identity(), Matrix4::zeros());
        let mut e = half; // e^{F(u + h/2)} at u = 0
        for _ in 0..n {
            q += e * qc * e.transpose() * h;
            e = step * e;
            phi = step * phi;
        }
        (phi, q)
    }

    #[test]
    fn van_loan_matches_numerical_integration() {
        // One axis of the dead-reckoning model: position, current, velocity, acceleration.
        let (bc, bv) = (0.17, 1.0);
        let f = Matrix4::new(
            0.0, 1.0, 1.0, 0.0, //
            0.0, -bc, 0.0, 0.0, //
            0.0, 0.0, 0.0, 1.0, //
            0.0, 0.0, 0.0, -bv,
        );
        let mut qc = Matrix4::zeros();
        qc[(1, 1)] = 2.0 * 0.3 * bc;
        qc[(3, 3)] = 2.0 * 0.25 * bv;
        for dt in [0.1, 1.0, 3.0, 10.0] {
            let (phi, q) = van_loan::<f64, 4, 8>(&f, &qc, dt).unwrap();
            let (phi_n, q_n) = integrate(&f, &qc, dt);
            assert!(
                (phi - phi_n).abs().max() < 1e-9,
                "Φ at {dt}: {}",
                (phi - phi_n).abs().max()
            );
            let scale = q_n.abs().max();
            assert!(
                (q - q_n).abs().max() < 1e-6 * scale,
                "Q at {dt}: {}",
                (q - q_n).abs().max()
            );
            // Eq. 5's printed Φ: e^{−βΔ} on the Markov states, Δ and Δ²/2 … for a pure
            // integrator chain; with β_v the acceleration term is (βΔ − 1 + e^{−βΔ})/β².
            assert!((phi[(1, 1)] - (-bc * dt).exp()).abs() < 1e-12);
            assert!((phi[(0, 2)] - dt).abs() < 1e-12);
        }
        assert!(van_loan::<f64, 4, 7>(&f, &qc, 1.0).is_none());
    }

    #[test]
    fn expm_matches_nalgebra() {
        let a = nalgebra::Matrix3::new(-0.3, 1.0, 0.2, 0.0, -2.0, 4.0, 0.5, 0.0, 0.1) * 3.0;
        let ours = expm(&a);
        let theirs = a.exp();
        assert!((ours - theirs).abs().max() < 1e-10 * theirs.abs().max());
        assert_eq!(
            expm(&nalgebra::Matrix2::<f64>::zeros()),
            nalgebra::Matrix2::identity()
        );
    }

    #[test]
    fn angles_wrap() {
        let pi = core::f64::consts::PI;
        assert!((wrap_pi(3.0 * pi / 2.0) + pi / 2.0).abs() < 1e-12);
        assert!((wrap_pi(-3.0 * pi / 2.0) - pi / 2.0).abs() < 1e-12);
        assert!((wrap_pi(0.1f64) - 0.1).abs() < 1e-15);
        assert!((wrap_pi(2.9 * pi) - 0.9 * pi).abs() < 1e-12);
        assert!((wrap_pi(-2.9 * pi) + 0.9 * pi).abs() < 1e-12);
        assert!((wrap_pi(-3.0 * pi) - pi).abs() < 1e-12);
        assert!((wrap_pi(101.5 * pi) + 0.5 * pi).abs() < 1e-9);
        assert_eq!(wrap_pi(-pi), pi);
    }
}
