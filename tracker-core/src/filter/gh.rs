//! The g-h-k-l engine shared by the α-β, α-β-γ and α-β-γ-η filters.
//!
//! Brookner's notation: with residual ε = z − x_pred,
//! x += g·ε, v += (h/T)·ε, a += (2k/T²)·ε, j += (6l/T³)·ε. The papers' α, β, γ, η are
//! g, h, k, l except where their files note otherwise.
//!
//! ## Per-scan units
//!
//! Each axis keeps its polynomial state in per-scan units,
//! `q = [x, v·T, a·T²/2, j·T³/6]`. Then the update is `q_i += G_i·ε` with the plain gains
//! `G = [g, h, k, l]`, and one scan of prediction is the binomial shift
//! `q_i ← Σ_{j ≥ i} C(j, i)·q_j` (x + vT + aT²/2 + jT³/6, and so on): adds and small
//! integer multiples only, no gain divided by T. That is what makes the fixed-point filter
//! exact and cheap. When the interval changes, `q_i` is rescaled by `(T_new/T_old)^i` once.

use super::{Estimate, Filter, Interval, Measurement, Vec2};
use crate::scalar::Scalar;

/// Binomial coefficients C(j, i) for j, i < 4.
const BINOMIAL: [[u8; 4]; 4] = [[1, 0, 0, 0], [1, 1, 0, 0], [1, 2, 1, 0], [1, 3, 3, 1]];

/// How the gains evolve from scan to scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Schedule<G, const N: usize> {
    /// The same gains every scan.
    Constant([G; N]),
    /// The growing-memory least-squares α-β gains of thesis eq. 2-3 and 2-4 (only for
    /// N = 2): α(k) = 2(2k−1)/(k(k+1)), β(k) = 6/(k(k+1)), k the measurement number.
    LeastSquares,
    /// A fixed α with eq. 2-4's β(k) = 6/(k(k+1)) (only for N = 2): the thesis's Examples I
    /// and II, which vary α and take β "from (2-4)" whatever α is. β fades to zero, so the
    /// velocity stops following: why α = 0.3 fares so badly there.
    FixedAlphaLeastSquaresBeta(G),
}

/// A g-h-k-l filter of order `N` (2: α-β, 3: α-β-γ, 4: α-β-γ-η) in scalar `S`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GhFilter<S: Scalar, const N: usize> {
    schedule: Schedule<S::Gain, N>,
    /// The gains of the next update (kept current for the least-squares schedule).
    gains: [S::Gain; N],
    /// Per axis (east, north): `[x, v·T, a·T²/2, j·T³/6][..N]`.
    q: [[S; N]; 2],
    /// The interval `q`'s derivatives are scaled to; zero before the first prediction.
    scan_s: S,
    prediction: Vec2<S>,
    innovation: Vec2<S>,
    /// Measurements taken, the first included (kept by the least-squares schedule only).
    measurements: u32,
}

impl<S: Scalar, const N: usize> GhFilter<S, N> {
    /// A filter with the given gain schedule, waiting for its first measurement.
    pub fn with_schedule(schedule: Schedule<S::Gain, N>) -> Self {
        let mut f = GhFilter {
            schedule,
            gains: [S::gain_from_ratio(0, 1); N],
            q: [[S::ZERO; N]; 2],
            scan_s: S::ZERO,
            prediction: [S::ZERO; 2],
            innovation: [S::ZERO; 2],
            measurements: 0,
        };
        f.gains = f.scheduled_gains();
        f
    }

    /// The gains the next update will use.
    pub fn gains(&self) -> [S::Gain; N] {
        self.gains
    }

    fn scheduled_gains(&self) -> [S::Gain; N] {
        match self.schedule {
            Schedule::Constant(g) => g,
            Schedule::LeastSquares => {
                let k = self.measurements.saturating_add(1).max(2);
                let den = k.saturating_mul(k + 1);
                let mut g = [S::gain_from_ratio(0, 1); N];
                if let Some(alpha) = g.get_mut(0) {
                    *alpha = S::gain_from_ratio(2 * (2 * k - 1), den);
                }
                if let Some(beta) = g.get_mut(1) {
                    *beta = S::gain_from_ratio(6, den);
                }
                g
            }
            Schedule::FixedAlphaLeastSquaresBeta(alpha) => {
                let k = self.measurements.saturating_add(1).max(2);
                let mut g = [S::gain_from_ratio(0, 1); N];
                if let Some(a) = g.get_mut(0) {
                    *a = alpha;
                }
                if let Some(beta) = g.get_mut(1) {
                    *beta = S::gain_from_ratio(6, k.saturating_mul(k + 1));
                }
                g
            }
        }
    }

    /// Rescales the per-scan derivatives to a new interval ([`rescale_derivatives`]). Off
    /// the hot path: scans usually repeat the same interval.
    #[cold]
    fn change_interval(&mut self, dt: S) {
        rescale_derivatives(&mut self.q, self.scan_s, dt);
        self.scan_s = dt;
    }

    /// The gains, when they are the same every scan (`None` for the least-squares
    /// schedules): what [`super::gh_fixed_scan::FixedScanGh`] is built from.
    pub fn constant_gains(&self) -> Option<[S::Gain; N]> {
        match self.schedule {
            Schedule::Constant(g) => Some(g),
            _ => None,
        }
    }

    /// Per-axis derivatives in physical units: `[x, v, a, j][..N]` (m, m/s, m/s², m/s³).
    pub fn derivatives(&self) -> [[f64; N]; 2] {
        let t = self.scan_s.to_f64();
        let mut out = [[0.0; N]; 2];
        for (o, q) in out.iter_mut().zip(&self.q) {
            let mut factorial_over_t = 1.0;
            for (i, (oi, qi)) in o.iter_mut().zip(q).enumerate() {
                *oi = if i == 0 {
                    qi.to_f64()
                } else if t > 0.0 {
                    factorial_over_t *= i as f64 / t;
                    qi.to_f64() * factorial_over_t
                } else {
                    0.0
                };
            }
        }
        out
    }
}

impl<S: Scalar, const N: usize> Filter<S> for GhFilter<S, N> {
    fn start(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        self.q = [[S::ZERO; N]; 2];
        for (q, zi) in self.q.iter_mut().zip(z) {
            q[0] = zi;
        }
        self.prediction = z;
        self.innovation = [S::ZERO; 2];
        self.measurements = 1;
        self.gains = self.scheduled_gains();
    }

    #[inline]
    fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let dt = dt.seconds();
        if dt != self.scan_s {
            self.change_interval(dt);
        }
        for q in &mut self.q {
            *q = shifted(q);
        }
        self.prediction = [self.q[0][0], self.q[1][0]];
        self.prediction
    }

    #[inline]
    fn update(&mut self, z: Measurement<S>) -> Vec2<S> {
        let z = z.position_m();
        let gains = self.gains;
        for (axis, (q, zi)) in self.q.iter_mut().zip(z).enumerate() {
            let e = zi.minus(q[0]);
            self.innovation[axis] = e;
            for (qi, &g) in q.iter_mut().zip(&gains) {
                *qi = qi.add_scaled(e, g);
            }
        }
        if !matches!(self.schedule, Schedule::Constant(_)) {
            self.measurements = self.measurements.saturating_add(1);
            self.gains = self.scheduled_gains();
        }
        self.innovation
    }

    fn estimate(&self) -> Estimate<S> {
        estimate_of(&self.q, self.scan_s)
    }

    fn prediction(&self) -> Vec2<S> {
        self.prediction
    }

    fn innovation(&self) -> Vec2<S> {
        self.innovation
    }
}

/// One scan of prediction of one axis in per-scan units, the binomial shift
/// `q_i ← Σ_{j ≥ i} C(j, i)·q_j`, summed from `q_i` upwards. Every g-h form predicts
/// through this one function, so they agree bit for bit.
#[inline]
pub(crate) fn shifted<S: Scalar, const N: usize>(q: &[S; N]) -> [S; N] {
    let mut out = *q;
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = q[i];
        for j in i + 1..N {
            acc = acc.plus(q[j].times(BINOMIAL[j][i]));
        }
        *o = acc;
    }
    out
}

/// Rescales both axes' per-scan derivatives from interval `from` to `to`:
/// `q_i ·= (to/from)^i`, one factor at a time. Nothing to do while `from` is zero (no
/// interval yet: the derivatives are still zero).
pub(crate) fn rescale_derivatives<S: Scalar, const N: usize>(q: &mut [[S; N]; 2], from: S, to: S) {
    if from > S::ZERO {
        for q in q {
            for (i, qi) in q.iter_mut().enumerate().skip(1) {
                for _ in 0..i {
                    *qi = qi.rescale(to, from);
                }
            }
        }
    }
}

/// The closed-loop matrix (I − K·H)·Φ of a constant-gain filter, one axis, per-scan units.
/// Position and velocity from a g-h state (per axis `[x, v·T, …]`) whose scaled terms are
/// for the interval `scan_s` (no velocity before an interval is known).
pub(crate) fn estimate_of<S: Scalar, const N: usize>(q: &[[S; N]; 2], scan_s: S) -> Estimate<S> {
    let velocity = |q: &[S; N]| match q.get(1) {
        Some(&vt) if scan_s > S::ZERO => vt.div(scan_s),
        _ => S::ZERO,
    };
    Estimate {
        position_m: [q[0][0], q[1][0]],
        velocity_mps: [velocity(&q[0]), velocity(&q[1])],
    }
}

#[cfg(test)]
fn closed_loop<const N: usize>(gains: [f64; N]) -> nalgebra::SMatrix<f64, N, N> {
    use nalgebra::SMatrix;
    let phi = SMatrix::<f64, N, N>::from_fn(|i, j| {
        f64::from(BINOMIAL[j][i]) * f64::from(u8::from(j >= i))
    });
    let mut kh = SMatrix::<f64, N, N>::zeros();
    for (i, g) in gains.iter().enumerate() {
        kh[(i, 0)] = *g;
    }
    (SMatrix::<f64, N, N>::identity() - kh) * phi
}

/// How far the characteristic polynomial of a constant-gain g-h-k-l filter's closed loop,
/// (I − K·H)·Φ for one axis in per-scan units, is from `expected` (monic, degree N),
/// compared at several z rather than through an eigen-solver, which is ill-conditioned for
/// repeated roots. Returns the largest mismatch.
#[cfg(test)]
pub(crate) fn char_poly_mismatch<const N: usize>(
    gains: [f64; N],
    expected: impl Fn(f64) -> f64,
) -> f64
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    use nalgebra::SMatrix;
    let a = closed_loop(gains);
    [-1.5, -0.3, 0.2, 0.7, 1.1, 2.0]
        .iter()
        .map(|&z| ((SMatrix::<f64, N, N>::identity() * z - a).determinant() - expected(z)).abs())
        .fold(0.0, f64::max)
}

/// The largest pole modulus of a constant-gain filter, from the growth of (I − K·H)·Φ's
/// powers (Gelfand's formula): robust for repeated and complex poles alike.
#[cfg(test)]
pub(crate) fn spectral_radius<const N: usize>(gains: [f64; N]) -> f64 {
    let a = closed_loop(gains);
    // Square 12 times: A^4096, rescaled each step to stay in range.
    let mut m = a;
    let mut log_scale = 0.0;
    for _ in 0..12 {
        m = m * m;
        let n = m.norm();
        log_scale = 2.0 * log_scale + n.ln();
        m /= n;
    }
    (log_scale / 4096.0).exp()
}

/// [`char_poly_mismatch`] against (z − ξ)^N: zero when every pole sits at ξ.
#[cfg(test)]
pub(crate) fn pole_mismatch<const N: usize>(gains: [f64; N], xi: f64) -> f64
where
    nalgebra::Const<N>: nalgebra::DimMin<nalgebra::Const<N>, Output = nalgebra::Const<N>>,
{
    char_poly_mismatch(gains, |z| (z - xi).powi(N as i32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::testing::{polynomial, run};
    use crate::filter::FilterError;
    use crate::scalar::Fix;

    #[test]
    fn a_changing_interval_keeps_a_polynomial_track_exact() {
        // Constant acceleration sampled at uneven times: after convergence the α-β-γ
        // engine follows it exactly, so the rescale between intervals is right.
        let g = [0.5, 0.4, 0.1];
        let mut f = GhFilter::<f64, 3>::with_schedule(Schedule::Constant(g));
        let mut t = 0.0;
        let mut samples = std::vec::Vec::new();
        for i in 0..400 {
            samples.push((t, [3.0 + 2.0 * t + 0.25 * t * t, -t]));
            t += if i % 3 == 0 { 2.0 } else { 3.0 };
        }
        let est = run(&mut f, &samples);
        let (tl, zl) = samples[samples.len() - 1];
        let last = est[est.len() - 1];
        assert!((last.position_m[0] - zl[0]).abs() < 1e-6);
        assert!((last.velocity_mps[0] - (2.0 + 0.5 * tl)).abs() < 1e-6);
        assert!((last.velocity_mps[1] + 1.0).abs() < 1e-6, "{:?}", last);
    }

    #[test]
    fn bad_input_is_refused_before_it_reaches_a_filter() {
        assert_eq!(
            Measurement::new([f32::NAN, 0.0]),
            Err(FilterError::NonFinite)
        );
        assert_eq!(
            Measurement::new([0.0, f32::INFINITY]),
            Err(FilterError::NonFinite)
        );
        for dt in [0.0, -1.0, f32::INFINITY, f32::NAN] {
            assert_eq!(Interval::new(dt), Err(FilterError::BadInterval), "{dt}");
        }
        assert_eq!(Interval::new(Fix::ZERO), Err(FilterError::BadInterval));
        assert_eq!(
            Interval::new(Fix::DELTA),
            Err(FilterError::BadInterval),
            "below 1 ms"
        );
        assert!(Interval::new(Fix::of(0.002)).is_ok());
        assert!(Measurement::new([Fix::MAX, Fix::MIN]).is_ok());
        assert_eq!(
            Measurement::new([2.0e7f32, 0.0]),
            Err(FilterError::NonFinite)
        );
        assert_eq!(Interval::new(90_000.0f32), Err(FilterError::BadInterval));
    }

    #[test]
    fn least_squares_schedule_is_the_batch_line_fit() {
        // Thesis eq. 2-3/2-4 with k the measurement number equal, at every scan, the
        // least-squares straight line through all measurements so far (Brookner's
        // growing-memory filter with n = k − 1).
        let mut noise = crate::filter::testing::Noise::new(7);
        let samples: std::vec::Vec<_> = polynomial(&[10.0, 3.0], &[0.0, -2.0], 60, 2.0)
            .into_iter()
            .map(|(t, z)| (t, [z[0] + noise.gauss(5.0), z[1] + noise.gauss(5.0)]))
            .collect();
        let mut f = GhFilter::<f64, 2>::with_schedule(Schedule::LeastSquares);
        let est = run(&mut f, &samples);
        for k in 2..samples.len() {
            let pts = &samples[..=k];
            let n = pts.len() as f64;
            let tm = pts.iter().map(|p| p.0).sum::<f64>() / n;
            let xm = pts.iter().map(|p| p.1[0]).sum::<f64>() / n;
            let sxx = pts.iter().map(|p| (p.0 - tm).powi(2)).sum::<f64>();
            let sxy = pts.iter().map(|p| (p.0 - tm) * (p.1[0] - xm)).sum::<f64>();
            let slope = sxy / sxx;
            let at_last = xm + slope * (pts[k].0 - tm);
            assert!((est[k].position_m[0] - at_last).abs() < 1e-9, "k={k}");
            assert!((est[k].velocity_mps[0] - slope).abs() < 1e-9, "k={k}");
        }
    }
}
