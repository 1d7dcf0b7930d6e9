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

pub mod drkf;
pub mod ttkf;

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

/// The last interval's Φ and Q, reused while the interval repeats (sensors at a fixed rate).
pub(crate) type TransitionCache<T, const N: usize> =
    Option<(T, SMatrix<T, N, N>, SMatrix<T, N, N>)>;

/// x ← Φx, P ← ΦPΦᵀ + Q over `dt_s` (> 0, at most a day), Φ and Q from `cache` or, for a new
/// interval, from `transition`.
pub(crate) fn predict_with<T: RealField + Copy, const N: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    cache: &mut TransitionCache<T, N>,
    dt_s: f64,
    transition: impl FnOnce(T) -> Option<Transition<T, N>>,
) -> Result<(), crate::filter::FilterError> {
    use crate::filter::FilterError;
    FilterError::check(dt_s.is_finite() && dt_s > 0.0 && dt_s <= 86_400.0)?;
    let dt: T = nalgebra::convert(dt_s);
    let (phi, q) = match cache {
        Some((d, phi, q)) if *d == dt => (*phi, *q),
        _ => {
            let (phi, q) = transition(dt).ok_or(FilterError::BadParameter)?;
            *cache = Some((dt, phi, q));
            (phi, q)
        }
    };
    *x = phi * *x;
    *p = phi * *p * phi.transpose() + q;
    Ok(())
}

/// One scalar measurement, linearised about the predicted state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Scalar<T: RealField + Copy, const N: usize> {
    /// z − h(x̂⁻), wrapped when an angle.
    pub residual: T,
    /// ∂h/∂x at x̂⁻.
    pub h: SVector<T, N>,
    /// Measurement noise variance.
    pub r: T,
}

/// Applies `rows` one at a time (Joseph form), each against the state as moved by the ones
/// before. Rows whose innovation variance is not positive and finite are skipped. Returns the
/// rows used and, for the NIS, Σ innovation²/S over them.
pub(crate) fn sequential_update<T: RealField + Copy, const N: usize>(
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    rows: &[Scalar<T, N>],
) -> (usize, T) {
    let x_pred = *x;
    let mut used = 0;
    let mut nis = T::zero();
    for row in rows {
        let innovation = row.residual - row.h.dot(&(*x - x_pred));
        let ph = *p * row.h;
        let s = row.h.dot(&ph) + row.r;
        if s <= T::zero() || !s.is_finite() || !innovation.is_finite() {
            continue;
        }
        let k = ph / s;
        *x += k * innovation;
        // Joseph: (I − khᵀ)P(I − khᵀ)ᵀ + k r kᵀ, with rank-one products only.
        let a = *p - k * ph.transpose();
        let ah = a * row.h;
        *p = a - ah * k.transpose() + k * k.transpose() * row.r;
        *p = (*p + p.transpose()) * nalgebra::convert::<f64, T>(0.5);
        used += 1;
        nis += innovation * innovation / s;
    }
    (used, nis)
}

/// `a` wrapped to (−π, π].
pub(crate) fn wrap_pi<T: RealField + Copy>(a: T) -> T {
    let two_pi = T::two_pi();
    let mut w = a % two_pi;
    if w > T::pi() {
        w -= two_pi;
    } else if w <= -T::pi() {
        w += two_pi;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix4};

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
    fn sequential_update_equals_the_batch_update() {
        let mut p = Matrix2::new(4.0, 1.0, 1.0, 3.0);
        let mut x = nalgebra::Vector2::new(1.0, -1.0);
        let rows = [
            Scalar {
                residual: 0.5,
                h: nalgebra::Vector2::new(1.0, 0.0),
                r: 2.0,
            },
            Scalar {
                residual: -0.3,
                h: nalgebra::Vector2::new(1.0, 1.0),
                r: 1.0,
            },
        ];
        // Batch: H 2×2, R diag.
        let h = Matrix2::new(1.0, 0.0, 1.0, 1.0);
        let r = Matrix2::new(2.0, 0.0, 0.0, 1.0);
        let s = h * p * h.transpose() + r;
        let k = p * h.transpose() * s.try_inverse().unwrap();
        let xb = x + k * nalgebra::Vector2::new(0.5, -0.3);
        let pb = (Matrix2::identity() - k * h) * p;
        let (used, _) = sequential_update(&mut x, &mut p, &rows);
        assert_eq!(used, 2);
        assert!((x - xb).abs().max() < 1e-12 && (p - pb).abs().max() < 1e-12);
    }

    #[test]
    fn angles_wrap() {
        let pi = core::f64::consts::PI;
        assert!((wrap_pi(3.0 * pi / 2.0) + pi / 2.0).abs() < 1e-12);
        assert!((wrap_pi(-3.0 * pi / 2.0) - pi / 2.0).abs() < 1e-12);
        assert!((wrap_pi(0.1f64) - 0.1).abs() < 1e-15);
    }
}
