//! The covariance arithmetic of the navigation filters, two ways: [`Structured`] (what the
//! filters use) and [`Dense`] (the plain textbook matrices, kept as the reference the tests
//! and the MCU benchmark compare against).
//!
//! ## Where the structure is
//!
//! * Φ is block diagonal (eq. 5, eq. 8c): one small upper-triangular block per
//!   [position, velocity, …] chain and a scalar per Gauss–Markov error state, the same block
//!   on the x and the y axis. ΦPΦᵀ is then row operations on a chain's rows followed by the
//!   same on its columns: for the 12-state TTKF 2·4·12·6 multiply-adds instead of the
//!   2·12³ = 3,456 of a dense product.
//! * Q is block diagonal: added block by block.
//! * Every measurement row H touches at most five states (eq. 7b, eq. 9b–9c), so Ph is
//!   N·5 multiply-adds instead of N², and the Joseph update is three rank-one terms written
//!   entry by entry (symmetric by construction) instead of two N×N products.
//!
//! Both ways compute the same numbers up to rounding; the tests hold them to 1e-9 (f64).

use nalgebra::{RealField, SMatrix, SVector};

use super::Transition;

/// Most states one measurement row touches (the ground-lock speedlog: two currents, two
/// velocities and its own error).
pub const MAX_ROW_STATES: usize = 5;

/// One scalar measurement, linearised about the predicted state, with a sparse H row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row<T: RealField + Copy> {
    /// z − h(x̂⁻), wrapped when an angle.
    pub residual: T,
    /// Measurement noise variance.
    pub r: T,
    states: [usize; MAX_ROW_STATES],
    h: [T; MAX_ROW_STATES],
    len: usize,
}

impl<T: RealField + Copy> Row<T> {
    /// A row with ∂h/∂x given as (state index, value) pairs; pairs beyond
    /// [`MAX_ROW_STATES`] are not representable and are dropped (rows are built by the
    /// filters from their models, never from input).
    pub fn new(residual: T, r: T, entries: &[(usize, T)]) -> Self {
        let mut row = Row {
            residual,
            r,
            states: [0; MAX_ROW_STATES],
            h: [T::zero(); MAX_ROW_STATES],
            len: 0,
        };
        for (slot, &(i, v)) in entries.iter().take(MAX_ROW_STATES).enumerate() {
            if let (Some(s), Some(h)) = (row.states.get_mut(slot), row.h.get_mut(slot)) {
                *s = i;
                *h = v;
                row.len = slot + 1;
            }
        }
        row
    }

    /// The (state, ∂h/∂x) pairs, indices clamped into an `n`-state vector.
    fn entries(&self, n: usize) -> impl Iterator<Item = (usize, T)> + '_ {
        self.states
            .iter()
            .zip(self.h.iter())
            .take(self.len)
            .map(move |(&i, &v)| (i.min(n.saturating_sub(1)), v))
    }

    /// H as a dense row.
    pub fn dense<const N: usize>(&self) -> SVector<T, N> {
        let mut h = SVector::<T, N>::zeros();
        for (i, v) in self.entries(N) {
            if let Some(e) = h.get_mut(i) {
                *e += v;
            }
        }
        h
    }
}

/// One chain's (Φ, Q) block of B states.
pub type Block<T, const B: usize> = (SMatrix<T, B, B>, SMatrix<T, B, B>);

/// A model's Φ and Q over one interval, in the form the model keeps them.
pub trait Discretised<T: RealField + Copy, const N: usize> {
    /// x ← Φx, P ← ΦPΦᵀ + Q, block by block.
    fn propagate_blocks(&self, x: &mut SVector<T, N>, p: &mut SMatrix<T, N, N>);
    /// Φ and Q as full matrices.
    fn dense(&self) -> Transition<T, N>;
}

/// How a filter does its covariance arithmetic.
pub trait Algebra: Clone + Copy + core::fmt::Debug + Default {
    /// Name in benchmark tables.
    const NAME: &'static str;

    /// x ← Φx, P ← ΦPΦᵀ + Q.
    fn propagate<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        model: &impl Discretised<T, N>,
    );

    /// Applies `rows` one at a time (Joseph form), each against the state as moved by the
    /// ones before (`z − h(x̂⁻) − H(x̂ − x̂⁻)`): the batch EKF update for independent
    /// measurement errors, with no matrix inverse. Rows whose innovation variance is not
    /// positive and finite are skipped. Returns the rows used and Σ innovation²/S (the NIS).
    fn update<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        rows: &[Row<T>],
    ) -> (usize, T);
}

/// Block-diagonal Φ and Q, sparse H: the filters' arithmetic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Structured;

/// Plain dense matrices: the reference.
#[cfg(feature = "reference")]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dense;

impl Algebra for Structured {
    const NAME: &'static str = "structured";

    fn propagate<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        model: &impl Discretised<T, N>,
    ) {
        model.propagate_blocks(x, p);
    }

    fn update<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        rows: &[Row<T>],
    ) -> (usize, T) {
        let x_pred = *x;
        let mut used = 0;
        let mut nis = T::zero();
        for row in rows {
            let mut innovation = row.residual;
            let mut ph = SVector::<T, N>::zeros();
            for (m, h) in row.entries(N) {
                innovation -= h * (x[m] - x_pred[m]);
                ph.axpy(h, &p.column(m), T::one());
            }
            let hph = row
                .entries(N)
                .fold(T::zero(), |acc, (m, h)| acc + h * ph[m]);
            let s = hph + row.r;
            if s <= T::zero() || !s.is_finite() || !innovation.is_finite() {
                continue;
            }
            let k = ph / s;
            x.axpy(innovation, &k, T::one());
            // Joseph, (I − khᵀ)P(I − khᵀ)ᵀ + k r kᵀ, expanded with P symmetric:
            // P − k(Ph)ᵀ − (Ph)kᵀ + (hᵀPh + r)kkᵀ. The two middle terms are added before
            // they are subtracted and s·(kᵢkⱼ) is formed the same way round, so entry (i, j)
            // is bitwise entry (j, i): P stays symmetric with no mirroring pass.
            for j in 0..N {
                let (kj, phj) = (k[j], ph[j]);
                for i in 0..N {
                    let (ki, phi) = (k[i], ph[i]);
                    p[(i, j)] = p[(i, j)] - (ki * phj + phi * kj) + s * (ki * kj);
                }
            }
            used += 1;
            nis += innovation * innovation / s;
        }
        (used, nis)
    }
}

#[cfg(feature = "reference")]
impl Algebra for Dense {
    const NAME: &'static str = "dense";

    fn propagate<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        model: &impl Discretised<T, N>,
    ) {
        let (phi, q) = model.dense();
        *x = phi * *x;
        *p = phi * *p * phi.transpose() + q;
    }

    fn update<T: RealField + Copy, const N: usize>(
        x: &mut SVector<T, N>,
        p: &mut SMatrix<T, N, N>,
        rows: &[Row<T>],
    ) -> (usize, T) {
        let x_pred = *x;
        let mut used = 0;
        let mut nis = T::zero();
        for row in rows {
            let h = row.dense::<N>();
            let innovation = row.residual - h.dot(&(*x - x_pred));
            let ph = *p * h;
            let s = h.dot(&ph) + row.r;
            if s <= T::zero() || !s.is_finite() || !innovation.is_finite() {
                continue;
            }
            let k = ph / s;
            *x += k * innovation;
            let a = (SMatrix::<T, N, N>::identity() - k * h.transpose()) * *p;
            *p = a * (SMatrix::<T, N, N>::identity() - h * k.transpose())
                + k * k.transpose() * row.r;
            *p = (*p + p.transpose()) * nalgebra::convert::<f64, T>(0.5);
            used += 1;
            nis += innovation * innovation / s;
        }
        (used, nis)
    }
}

/// Rows `chain` of `m` ← A·(those rows), column by column, where `a` maps a chain's
/// values v to A·v (written by each model with its block's zeros and ones left out).
#[inline(always)]
pub(crate) fn chain_rows<T: RealField + Copy, const N: usize, const B: usize>(
    m: &mut SMatrix<T, N, N>,
    chain: [usize; B],
    a: impl Fn([T; B]) -> [T; B],
) {
    let chain = chain.map(|i| i.min(N - 1));
    for j in 0..N {
        let v = a(chain.map(|i| m[(i, j)]));
        for (&i, v) in chain.iter().zip(v) {
            m[(i, j)] = v;
        }
    }
}

/// Columns `chain` of `m` ← (those columns)·Aᵀ, row by row.
#[inline(always)]
pub(crate) fn chain_columns<T: RealField + Copy, const N: usize, const B: usize>(
    m: &mut SMatrix<T, N, N>,
    chain: [usize; B],
    a: impl Fn([T; B]) -> [T; B],
) {
    let chain = chain.map(|i| i.min(N - 1));
    for i in 0..N {
        let v = a(chain.map(|j| m[(i, j)]));
        for (&j, v) in chain.iter().zip(v) {
            m[(i, j)] = v;
        }
    }
}

/// x on `chain` ← A·x.
#[inline(always)]
pub(crate) fn chain_state<T: RealField + Copy, const N: usize, const B: usize>(
    x: &mut SVector<T, N>,
    chain: [usize; B],
    a: impl Fn([T; B]) -> [T; B],
) {
    let chain = chain.map(|i| i.min(N - 1));
    let v = a(chain.map(|i| x[i]));
    for (&i, v) in chain.iter().zip(v) {
        x[i] = v;
    }
}

/// A·v for a full B×B block: the reference the models' sparse versions are tested against.
#[cfg(all(test, feature = "reference"))]
pub(crate) fn full<T: RealField + Copy, const B: usize>(
    a: &SMatrix<T, B, B>,
) -> impl Fn([T; B]) -> [T; B] + '_ {
    move |v| core::array::from_fn(|r| (0..B).fold(T::zero(), |acc, k| acc + a[(r, k)] * v[k]))
}

/// P on `chain` × `chain` += the block `q`.
#[inline(always)]
pub(crate) fn chain_add<T: RealField + Copy, const N: usize, const B: usize>(
    p: &mut SMatrix<T, N, N>,
    chain: [usize; B],
    q: &SMatrix<T, B, B>,
) {
    let chain = chain.map(|i| i.min(N - 1));
    for (r, &i) in chain.iter().enumerate() {
        for (k, &j) in chain.iter().enumerate() {
            p[(i, j)] += q[(r, k)];
        }
    }
}

/// Scatters a chain's block into a full matrix.
pub(crate) fn chain_scatter<T: RealField + Copy, const N: usize, const B: usize>(
    m: &mut SMatrix<T, N, N>,
    chain: [usize; B],
    block: &SMatrix<T, B, B>,
) {
    let chain = chain.map(|i| i.min(N - 1));
    for (r, &i) in chain.iter().enumerate() {
        for (k, &j) in chain.iter().enumerate() {
            m[(i, j)] = block[(r, k)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[cfg(feature = "reference")]
    use nalgebra::{Matrix2, Matrix3, Vector2};

    #[test]
    #[cfg(feature = "reference")]
    fn sequential_update_equals_the_batch_update() {
        let p0 = Matrix2::new(4.0, 1.0, 1.0, 3.0);
        let x0 = Vector2::new(1.0, -1.0);
        let rows = [
            Row::new(0.5, 2.0, &[(0, 1.0)]),
            Row::new(-0.3, 1.0, &[(0, 1.0), (1, 1.0)]),
        ];
        // Batch: H 2×2, R diag.
        let h = Matrix2::new(1.0, 0.0, 1.0, 1.0);
        let r = Matrix2::new(2.0, 0.0, 0.0, 1.0);
        let s = h * p0 * h.transpose() + r;
        let k = p0 * h.transpose() * s.try_inverse().unwrap();
        let xb = x0 + k * Vector2::new(0.5, -0.3);
        let pb = (Matrix2::identity() - k * h) * p0;
        for structured in [true, false] {
            let (mut x, mut p) = (x0, p0);
            let (used, _) = if structured {
                Structured::update(&mut x, &mut p, &rows)
            } else {
                Dense::update(&mut x, &mut p, &rows)
            };
            assert_eq!(used, 2);
            assert!((x - xb).abs().max() < 1e-12 && (p - pb).abs().max() < 1e-12);
        }
    }

    #[test]
    #[cfg(feature = "reference")]
    fn chain_operations_are_the_dense_product() {
        // A 5-state model: one 3-chain on states (4, 0, 2), identity elsewhere.
        let a = Matrix3::new(1.0, 0.5, 0.1, -0.2, 1.0, 0.3, 0.4, 0.0, 0.8);
        let q = Matrix3::new(0.2, 0.1, 0.0, 0.1, 0.3, 0.05, 0.0, 0.05, 0.4);
        let chain = [4, 0, 2];
        let mut phi = SMatrix::<f64, 5, 5>::identity();
        let mut qf = SMatrix::<f64, 5, 5>::zeros();
        chain_scatter(&mut phi, chain, &a);
        chain_scatter(&mut qf, chain, &q);
        let m = SMatrix::<f64, 5, 5>::from_fn(|i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let mut x = SVector::<f64, 5>::from_fn(|i, _| i as f64 - 1.5);
        let want_x = phi * x;
        let want = phi * m * phi.transpose() + qf;
        let mut got = m;
        chain_rows(&mut got, chain, full(&a));
        chain_columns(&mut got, chain, full(&a));
        chain_add(&mut got, chain, &q);
        chain_state(&mut x, chain, full(&a));
        assert!((got - want).abs().max() < 1e-14);
        assert!((x - want_x).abs().max() < 1e-14);
    }

    #[test]
    fn rows_keep_at_most_five_states_and_clamp_indices() {
        let e: [(usize, f64); 6] = core::array::from_fn(|i| (i, 1.0));
        let row = Row::new(0.0, 1.0, &e);
        assert_eq!(row.dense::<8>().sum(), 5.0);
        let wild = Row::new(0.0, 1.0, &[(99, 2.0)]);
        assert_eq!(wild.dense::<3>()[2], 2.0);
    }
}
