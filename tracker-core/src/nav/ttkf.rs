//! The target-tracking Kalman filter (TTKF) of `004_be25d15b4854a4f6.txt` §2.2: one per
//! target, fed by the dead-reckoning filter's own-ship estimate and the radar's range and
//! azimuth to the target.
//!
//! States (eq. 8a): own-ship x, y position, velocity over ground and acceleration, then the
//! target's; both accelerations first-order Gauss–Markov (eq. 8b). Measurements (eq. 9a–9c):
//! the DRKF's position and velocity over ground, with the DRKF's covariance as their R, and
//! the radar range and azimuth (true bearing, from north through east). Own-ship data and
//! radar arrive at their own rates; [`Ttkf::predict`] takes any interval.

use core::marker::PhantomData;

use nalgebra::{Matrix3, Matrix4, RealField, SMatrix, SVector, Vector4};

use super::algebra::{
    chain_add, chain_columns, chain_rows, chain_scatter, chain_state, Block, Row,
};
use super::{
    c, predict_cached, van_loan, wrap_pi, Algebra, Discretised, GaussMarkov, Structured, Transition,
};
use crate::filter::FilterError;

/// Number of states.
pub const STATES: usize = 12;

/// State indices (eq. 8a, zero-based).
pub mod ix {
    /// Own-ship x position, m.
    pub const OX: usize = 0;
    /// Own-ship y position, m.
    pub const OY: usize = 1;
    /// Own-ship x velocity over ground, m/s.
    pub const OVX: usize = 2;
    /// Own-ship y velocity over ground, m/s.
    pub const OVY: usize = 3;
    /// Own-ship x acceleration, m/s².
    pub const OAX: usize = 4;
    /// Own-ship y acceleration, m/s².
    pub const OAY: usize = 5;
    /// Target x position, m.
    pub const TX: usize = 6;
    /// Target y position, m.
    pub const TY: usize = 7;
    /// Target x velocity over ground, m/s.
    pub const TVX: usize = 8;
    /// Target y velocity over ground, m/s.
    pub const TVY: usize = 9;
    /// Target x acceleration, m/s².
    pub const TAX: usize = 10;
    /// Target y acceleration, m/s².
    pub const TAY: usize = 11;
}

/// The four [position, velocity, acceleration] chains of eq. 8c: own ship x and y, target
/// x and y.
const CHAINS: [[usize; 3]; 4] = [
    [ix::OX, ix::OVX, ix::OAX],
    [ix::OY, ix::OVY, ix::OAY],
    [ix::TX, ix::TVX, ix::TAX],
    [ix::TY, ix::TVY, ix::TAY],
];

/// Φ (eq. 8c) and Q (eq. 6) over one interval, as the model has them: one 3×3 block for the
/// own ship's chains (both axes alike) and one for the target's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocks<T: RealField + Copy> {
    own: (Matrix3<T>, Matrix3<T>),
    target: (Matrix3<T>, Matrix3<T>),
}

impl<T: RealField + Copy> Blocks<T> {
    /// Van Loan on each chain's 3×3 model.
    pub(crate) fn new(config: &TtkfConfig, dt: T) -> Option<Self> {
        let chain = |g: &GaussMarkov| {
            let (o, z, b) = (T::one(), T::zero(), c::<T>(g.beta_per_s));
            let f = Matrix3::new(z, o, z, z, z, o, z, z, -b);
            let mut qc = Matrix3::zeros();
            qc[(2, 2)] = c(g.alpha() * g.alpha());
            van_loan::<T, 3, 6>(&f, &qc, dt)
        };
        Some(Blocks {
            own: chain(&config.own_acceleration)?,
            target: chain(&config.target_acceleration)?,
        })
    }

    /// The target's chain block (Φ, Q).
    #[cfg(feature = "reference")]
    pub(crate) fn target(&self) -> &(Matrix3<T>, Matrix3<T>) {
        &self.target
    }

    fn chains(&self) -> [([usize; 3], &Block<T, 3>); 4] {
        [
            (CHAINS[0], &self.own),
            (CHAINS[1], &self.own),
            (CHAINS[2], &self.target),
            (CHAINS[3], &self.target),
        ]
    }
}

/// A·v for a chain's Φ (eq. 8c): upper triangular with a unit diagonal but for the
/// acceleration's e^{−βΔ}; its zeros and ones are exact in Van Loan's result too, since F's
/// first column and last row are those of the chain.
#[inline(always)]
pub(crate) fn chain_phi<T: RealField + Copy>(a: &Matrix3<T>) -> impl Fn([T; 3]) -> [T; 3] + '_ {
    move |[p, v, acc]| {
        [
            p + a[(0, 1)] * v + a[(0, 2)] * acc,
            v + a[(1, 2)] * acc,
            a[(2, 2)] * acc,
        ]
    }
}

impl<T: RealField + Copy> Discretised<T, STATES> for Blocks<T> {
    fn propagate_blocks(&self, x: &mut SVector<T, STATES>, p: &mut SMatrix<T, STATES, STATES>) {
        for (chain, (phi, _)) in self.chains() {
            chain_rows(p, chain, chain_phi(phi));
        }
        for (chain, (phi, q)) in self.chains() {
            chain_columns(p, chain, chain_phi(phi));
            chain_add(p, chain, q);
            chain_state(x, chain, chain_phi(phi));
        }
    }

    fn dense(&self) -> Transition<T, STATES> {
        let mut phi = SMatrix::<T, STATES, STATES>::zeros();
        let mut q = SMatrix::<T, STATES, STATES>::zeros();
        for (chain, (phi3, q3)) in self.chains() {
            chain_scatter(&mut phi, chain, phi3);
            chain_scatter(&mut q, chain, q3);
        }
        (phi, q)
    }
}

/// TTKF parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TtkfConfig {
    /// Own-ship acceleration model.
    pub own_acceleration: GaussMarkov,
    /// Target acceleration model.
    pub target_acceleration: GaussMarkov,
    /// Radar range noise variance, m².
    pub range_var_m2: f64,
    /// Radar azimuth noise variance, rad².
    pub bearing_var_rad2: f64,
    /// Prior standard deviation of the target's velocity at acquisition, m/s.
    pub initial_speed_sd_mps: f64,
    /// Wander of the echo point over the target's extent (glint), σ per axis, m (0: a point
    /// target). It adds to the range variance and, as a cross-range distance, σ²/r² to the
    /// azimuth's: at short range it, not the beam, dominates the azimuth error.
    pub glint_sd_m: f64,
}

impl TtkfConfig {
    pub(crate) fn validate(&self) -> Result<(), FilterError> {
        let var = |v: f64| v.is_finite() && v > 0.0;
        FilterError::check(
            self.own_acceleration.is_valid()
                && self.target_acceleration.is_valid()
                && var(self.range_var_m2)
                && var(self.bearing_var_rad2)
                && var(self.initial_speed_sd_mps)
                && self.glint_sd_m.is_finite()
                && self.glint_sd_m >= 0.0,
        )
    }
}

/// Own-ship estimate handed from the DRKF: position, velocity over ground and their 4×4
/// covariance (x, y, v_x, v_y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OwnShipEstimate<T: RealField + Copy> {
    /// Position (east, north), m.
    pub position_m: [T; 2],
    /// Velocity over ground, m/s.
    pub velocity_mps: [T; 2],
    /// Covariance of (x, y, v_x, v_y).
    pub covariance: SMatrix<T, 4, 4>,
}

/// The tracking filter in scalar `T` (f32 on the MCU, f64 on the host), with `A`'s
/// covariance arithmetic ([`Structured`] unless a benchmark asks for the dense reference).
#[derive(Clone, Debug)]
pub struct Ttkf<T: RealField + Copy, A: Algebra = Structured> {
    config: TtkfConfig,
    x: SVector<T, STATES>,
    p: SMatrix<T, STATES, STATES>,
    /// Φ and Q of the last interval, reused while the interval repeats.
    cached: Option<(T, Blocks<T>)>,
    /// Range, azimuth and glint variances in `T`, converted once.
    radar_noise: [T; 3],
    last_nis: T,
    algebra: PhantomData<A>,
}

impl<T: RealField + Copy> Ttkf<T> {
    /// Starts on a target at `range_m`, `bearing_rad` (true) from `own`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] for a configuration out of range or a range that is not positive and finite.
    pub fn new(
        config: TtkfConfig,
        own: &OwnShipEstimate<T>,
        range_m: f64,
        bearing_rad: f64,
    ) -> Result<Self, FilterError> {
        Self::with_algebra(config, own, range_m, bearing_rad)
    }
}

impl<T: RealField + Copy, A: Algebra> Ttkf<T, A> {
    /// As [`Ttkf::new`], with `A`'s covariance arithmetic.
    ///
    /// # Errors
    /// As [`Ttkf::new`].
    pub fn with_algebra(
        config: TtkfConfig,
        own: &OwnShipEstimate<T>,
        range_m: f64,
        bearing_rad: f64,
    ) -> Result<Self, FilterError> {
        config.validate()?;
        FilterError::check(range_m.is_finite() && range_m > 0.0 && bearing_rad.is_finite())?;
        let mut x = SVector::<T, STATES>::zeros();
        x[ix::OX] = own.position_m[0];
        x[ix::OY] = own.position_m[1];
        x[ix::OVX] = own.velocity_mps[0];
        x[ix::OVY] = own.velocity_mps[1];
        let mut p = SMatrix::<T, STATES, STATES>::zeros();
        p.fixed_view_mut::<2, 2>(0, 0)
            .copy_from(&own.covariance.fixed_view::<2, 2>(0, 0));
        p.fixed_view_mut::<2, 2>(2, 2)
            .copy_from(&own.covariance.fixed_view::<2, 2>(2, 2));
        p.fixed_view_mut::<2, 2>(0, 2)
            .copy_from(&own.covariance.fixed_view::<2, 2>(0, 2));
        p.fixed_view_mut::<2, 2>(2, 0)
            .copy_from(&own.covariance.fixed_view::<2, 2>(2, 0));
        let ga = |g: &GaussMarkov| c::<T>(g.sigma * g.sigma);
        p[(ix::OAX, ix::OAX)] = ga(&config.own_acceleration);
        p[(ix::OAY, ix::OAY)] = ga(&config.own_acceleration);
        acquire(
            &config,
            &mut x,
            &mut p,
            [ix::OX, ix::OY],
            [CHAINS[2], CHAINS[3]],
            range_m,
            bearing_rad,
        );
        Ok(Ttkf {
            config,
            x,
            p,
            cached: None,
            radar_noise: radar_noise(&config),
            last_nis: T::zero(),
            algebra: PhantomData,
        })
    }

    /// Φ (eq. 8c) and Q (eq. 6) over `dt`: Van Loan on each [position, velocity,
    /// acceleration] chain (3×3), scattered into the state order.
    pub fn transition(&self, dt: T) -> Option<Transition<T, STATES>> {
        Blocks::new(&self.config, dt).map(|b| b.dense())
    }

    /// Propagates over `dt_s` (> 0, at most a day).
    ///
    /// # Errors
    /// [`FilterError::BadInterval`] for a step outside (0, 1 day].
    pub fn predict(&mut self, dt_s: f64) -> Result<(), FilterError> {
        let config = self.config;
        predict_cached::<T, STATES, A, _>(&mut self.x, &mut self.p, &mut self.cached, dt_s, |dt| {
            Blocks::new(&config, dt)
        })
    }

    /// Eq. 9a z1–z4: the DRKF's estimate with its covariance as R. The errors are correlated,
    /// so they are whitened first (R = LLᵀ, z' = L⁻¹z, H' = L⁻¹H) and then applied one by one.
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] for a non-finite estimate, [`FilterError::BadParameter`] when its covariance is not positive definite (nothing changes).
    pub fn update_own_ship(&mut self, own: &OwnShipEstimate<T>) -> Result<(), FilterError> {
        let z = Vector4::new(
            own.position_m[0],
            own.position_m[1],
            own.velocity_mps[0],
            own.velocity_mps[1],
        );
        FilterError::check(z.iter().chain(own.covariance.iter()).all(|v| v.is_finite()))?;
        let chol = nalgebra::Cholesky::new(own.covariance).ok_or(FilterError::BadParameter)?;
        let w = lower_inverse(&chol.l()).ok_or(FilterError::BadParameter)?;
        let idx = [ix::OX, ix::OY, ix::OVX, ix::OVY];
        let residual = Vector4::from_fn(|r, _| z[r] - self.x[idx[r]]);
        // Whitened row r: (L⁻¹)_r· on the four own-ship states (L⁻¹ is lower triangular).
        let rows: [Row<T>; 4] = core::array::from_fn(|r| {
            let entries: [(usize, T); 4] = core::array::from_fn(|k| (idx[k], w[(r, k)]));
            Row::new(
                w.row(r).dot(&residual.transpose()),
                T::one(),
                &entries[..=r],
            )
        });
        A::update(&mut self.x, &mut self.p, &rows);
        Ok(())
    }

    /// Eq. 9a z5–z6: radar range, m, and azimuth, radians true (residual wrapped), with the
    /// H of eq. 9b–9c at the predicted state. Returns the NIS of the two.
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] for a non-finite or non-positive range or bearing (nothing changes).
    pub fn update_radar(&mut self, range_m: f64, bearing_rad: f64) -> Result<T, FilterError> {
        let rows = radar_rows(
            &self.x,
            [ix::OX, ix::OY],
            [ix::TX, ix::TY],
            self.radar_noise,
            range_m,
            bearing_rad,
        )?;
        let (_, nis) = A::update(&mut self.x, &mut self.p, &rows);
        self.last_nis = nis;
        Ok(nis)
    }

    /// The state (eq. 8a order).
    pub fn state(&self) -> &SVector<T, STATES> {
        &self.x
    }

    /// The covariance.
    pub fn covariance(&self) -> &SMatrix<T, STATES, STATES> {
        &self.p
    }

    /// Target position, m.
    pub fn target_position_m(&self) -> [T; 2] {
        [self.x[ix::TX], self.x[ix::TY]]
    }

    /// Target velocity over ground, m/s.
    pub fn target_velocity_mps(&self) -> [T; 2] {
        [self.x[ix::TVX], self.x[ix::TVY]]
    }

    /// Own-ship position, m.
    pub fn own_position_m(&self) -> [T; 2] {
        [self.x[ix::OX], self.x[ix::OY]]
    }

    /// Own-ship velocity over ground, m/s.
    pub fn own_velocity_mps(&self) -> [T; 2] {
        [self.x[ix::OVX], self.x[ix::OVY]]
    }
}

/// The radar's range, azimuth and glint variances in `T`.
pub(crate) fn radar_noise<T: RealField + Copy>(config: &TtkfConfig) -> [T; 3] {
    [
        c(config.range_var_m2),
        c(config.bearing_var_rad2),
        c(config.glint_sd_m * config.glint_sd_m),
    ]
}

/// Puts a new target at `range_m`, `bearing_rad` (true) from the own-ship position at
/// indices `own` into the state and covariance, on the [position, velocity, acceleration]
/// chains `chains` (x, y): position from the plot, with the own ship's position covariance plus
/// the plot's error ellipse; velocity unknown (`initial_speed_sd_mps`), acceleration at its
/// Markov variance.
pub(crate) fn acquire<T: RealField + Copy, const N: usize>(
    config: &TtkfConfig,
    x: &mut SVector<T, N>,
    p: &mut SMatrix<T, N, N>,
    own: [usize; 2],
    chains: [[usize; 3]; 2],
    range_m: f64,
    bearing_rad: f64,
) {
    let (sin, cos) = (libm::sin(bearing_rad), libm::cos(bearing_rad));
    let glint = config.glint_sd_m * config.glint_sd_m;
    // The plot's error ellipse: range along the line of sight u = (sin, cos), range × azimuth
    // across it, glint both ways.
    let along = config.range_var_m2 + glint;
    let across = range_m * range_m * config.bearing_var_rad2 + glint;
    let cross = (along - across) * sin * cos;
    let ellipse = [
        [along * sin * sin + across * cos * cos, cross],
        [cross, along * cos * cos + across * sin * sin],
    ];
    let own = own.map(|i| i.min(N - 1));
    let pos = [chains[0][0], chains[1][0]].map(|i| i.min(N - 1));
    // Target = own ship + the plot: it inherits the own-ship position's covariance with
    // everything, and adds the plot's ellipse.
    for j in (0..N).filter(|j| !pos.contains(j)) {
        for (&t, &o) in pos.iter().zip(&own) {
            let v = p[(o, j)];
            p[(t, j)] = v;
            p[(j, t)] = v;
        }
    }
    for (i, (&ti, &oi)) in pos.iter().zip(&own).enumerate() {
        x[ti] = x[oi] + c(range_m * [sin, cos][i]);
        for (k, (&tk, &ok)) in pos.iter().zip(&own).enumerate() {
            p[(ti, tk)] = p[(oi, ok)] + c(ellipse[i][k]);
        }
    }
    let v0 = config.initial_speed_sd_mps * config.initial_speed_sd_mps;
    let g = &config.target_acceleration;
    for chain in chains {
        let [_, vel, acc] = chain.map(|i| i.min(N - 1));
        p[(vel, vel)] = c(v0);
        p[(acc, acc)] = c(g.sigma * g.sigma);
    }
}

/// Eq. 9a z5–z6 with eq. 9b–9c's H at `x`: range, m, and azimuth, radians true (residual
/// wrapped), of the target whose position is at state indices `target`, seen from the own
/// ship's at `own`.
pub(crate) fn radar_rows<T: RealField + Copy, const N: usize>(
    x: &SVector<T, N>,
    own: [usize; 2],
    target: [usize; 2],
    [range_var, bearing_var, glint_var]: [T; 3],
    range_m: f64,
    bearing_rad: f64,
) -> Result<[Row<T>; 2], FilterError> {
    FilterError::check(range_m.is_finite() && range_m >= 0.0 && bearing_rad.is_finite())?;
    let dx = x[target[0].min(N - 1)] - x[own[0].min(N - 1)];
    let dy = x[target[1].min(N - 1)] - x[own[1].min(N - 1)];
    let r2 = dx * dx + dy * dy;
    let r = r2.sqrt();
    if r <= c(1.0) || !r.is_finite() {
        return Err(FilterError::BadParameter);
    }
    let (h51, h52, h61, h62) = (dx / r, dy / r, dx / r2, dy / r2);
    Ok([
        Row::new(
            c::<T>(range_m) - r,
            range_var + glint_var,
            &[
                (own[0], -h51),
                (own[1], -h52),
                (target[0], h51),
                (target[1], h52),
            ],
        ),
        Row::new(
            wrap_pi(c::<T>(bearing_rad) - dx.atan2(dy)),
            bearing_var + glint_var / r2,
            &[
                (own[0], -h62),
                (own[1], h61),
                (target[0], h62),
                (target[1], -h61),
            ],
        ),
    ])
}

/// L⁻¹ of a lower-triangular 4×4 L by forward substitution; `None` unless its diagonal is
/// positive and finite.
fn lower_inverse<T: RealField + Copy>(l: &Matrix4<T>) -> Option<Matrix4<T>> {
    let mut w = Matrix4::zeros();
    for r in 0..4 {
        let d = l[(r, r)];
        if d <= T::zero() || !d.is_finite() {
            return None;
        }
        for col in 0..=r {
            let mut acc = if col == r { T::one() } else { T::zero() };
            for k in col..r {
                acc -= l[(r, k)] * w[(k, col)];
            }
            w[(r, col)] = acc / d;
        }
    }
    Some(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config() -> TtkfConfig {
        TtkfConfig {
            own_acceleration: GaussMarkov::with_variance(0.01, 0.1),
            target_acceleration: GaussMarkov::with_variance(0.01, 0.1),
            range_var_m2: 20.0 * 20.0,
            bearing_var_rad2: 0.5f64.to_radians().powi(2),
            initial_speed_sd_mps: 10.0,
            glint_sd_m: 0.0,
        }
    }

    fn own(t: f64) -> OwnShipEstimate<f64> {
        let mut cov = SMatrix::<f64, 4, 4>::identity() * 0.01;
        cov[(0, 0)] = 4.0;
        cov[(1, 1)] = 4.0;
        OwnShipEstimate {
            position_m: [0.0, 5.0 * t],
            velocity_mps: [0.0, 5.0],
            covariance: cov,
        }
    }

    #[test]
    fn tracks_a_crossing_target_at_multiple_rates() {
        // Target from 5 km at 045° heading 270° at 8 m/s; own ship north at 5 m/s.
        let target = |t: f64| [3535.5 - 8.0 * t, 3535.5];
        let polar = |t: f64| {
            let o = own(t).position_m;
            let p = target(t);
            let (dx, dy) = (p[0] - o[0], p[1] - o[1]);
            ((dx * dx + dy * dy).sqrt(), dx.atan2(dy))
        };
        let (r0, b0) = polar(0.0);
        let mut f = Ttkf::new(config(), &own(0.0), r0, b0).unwrap();
        let mut t = 0.0;
        // Own ship every 1 s, radar every 2.5 s.
        for k in 1..=480 {
            let dt = 0.5;
            t = f64::from(k) * dt;
            f.predict(dt).unwrap();
            if k % 2 == 0 {
                f.update_own_ship(&own(t)).unwrap();
            }
            if k % 5 == 0 {
                let (r, b) = polar(t);
                f.update_radar(r, b).unwrap();
            }
        }
        let v = f.target_velocity_mps();
        assert!((v[0] + 8.0).abs() < 0.3 && v[1].abs() < 0.3, "{v:?}");
        let p = f.target_position_m();
        let tp = target(t);
        assert!((p[0] - tp[0]).abs() < 5.0 && (p[1] - tp[1]).abs() < 5.0);
        // Symmetric, positive definite.
        let cov = f.covariance();
        assert!((cov - cov.transpose()).abs().max() < 1e-9);
        assert!(nalgebra::Cholesky::new(*cov).is_some());
    }

    #[test]
    #[cfg(feature = "reference")]
    fn structured_arithmetic_is_the_dense_filter() {
        let mut s = Ttkf::<f64>::new(config(), &own(0.0), 5000.0, 0.8).unwrap();
        let mut d =
            Ttkf::<f64, crate::nav::Dense>::with_algebra(config(), &own(0.0), 5000.0, 0.8).unwrap();
        for k in 1..=200 {
            let t = f64::from(k);
            let dt = if k % 9 == 4 { 0.6 } else { 1.0 };
            s.predict(dt).unwrap();
            d.predict(dt).unwrap();
            let mut o = own(t);
            o.covariance[(0, 2)] = 0.05;
            o.covariance[(2, 0)] = 0.05;
            s.update_own_ship(&o).unwrap();
            d.update_own_ship(&o).unwrap();
            if k % 3 == 0 {
                let (r, b) = (5000.0 - 3.0 * t, 0.8 + 0.001 * t);
                let (ns, nd) = (s.update_radar(r, b).unwrap(), d.update_radar(r, b).unwrap());
                assert!((ns - nd).abs() < 1e-9);
            }
            let scale = d.covariance().abs().max();
            assert!(
                (s.covariance() - d.covariance()).abs().max() < 1e-9 * scale,
                "P at {k}"
            );
            assert!((s.state() - d.state()).abs().max() < 1e-8, "x at {k}");
        }
    }

    #[test]
    fn azimuth_residuals_wrap_across_north() {
        let mut f = Ttkf::new(config(), &own(0.0), 1000.0, 359.9f64.to_radians()).unwrap();
        f.predict(1.0).unwrap();
        let nis = f.update_radar(1000.0, 0.1f64.to_radians()).unwrap();
        assert!(
            nis < 10.0,
            "a 0.2° step across north, not 359.8°: NIS {nis}"
        );
    }

    #[test]
    fn bad_input_is_refused_without_change() {
        let mut f = Ttkf::new(config(), &own(0.0), 1000.0, 0.5).unwrap();
        let before = f.state().clone_owned();
        assert!(f.update_radar(f64::NAN, 0.0).is_err());
        let mut o = own(0.0);
        o.covariance[(0, 0)] = -1.0;
        assert!(f.update_own_ship(&o).is_err());
        assert_eq!(*f.state(), before);
        assert!(Ttkf::new(config(), &own(0.0), 0.0, 0.0).is_err());
    }
}
