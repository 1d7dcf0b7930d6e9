//! The target-tracking Kalman filter (TTKF) of `004_be25d15b4854a4f6.txt` §2.2: one per
//! target, fed by the dead-reckoning filter's own-ship estimate and the radar's range and
//! azimuth to the target.
//!
//! States (eq. 8a): own-ship x, y position, velocity over ground and acceleration, then the
//! target's; both accelerations first-order Gauss–Markov (eq. 8b). Measurements (eq. 9a–9c):
//! the DRKF's position and velocity over ground, with the DRKF's covariance as their R, and
//! the radar range and azimuth (true bearing, from north through east). Own-ship data and
//! radar arrive at their own rates; [`Ttkf::predict`] takes any interval.

use nalgebra::{Matrix3, RealField, SMatrix, SVector, Vector4};

use super::{
    c, predict_with, sequential_update, van_loan, wrap_pi, GaussMarkov, Scalar, Transition,
    TransitionCache,
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
}

impl TtkfConfig {
    fn validate(&self) -> Result<(), FilterError> {
        let var = |v: f64| v.is_finite() && v > 0.0;
        FilterError::check(
            self.own_acceleration.is_valid()
                && self.target_acceleration.is_valid()
                && var(self.range_var_m2)
                && var(self.bearing_var_rad2)
                && var(self.initial_speed_sd_mps),
        )
    }
}

/// Own-ship estimate handed from the DRKF: position, velocity over ground and their 4×4
/// covariance (x, y, v_x, v_y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OwnShip<T: RealField + Copy> {
    /// Position (east, north), m.
    pub position_m: [T; 2],
    /// Velocity over ground, m/s.
    pub velocity_mps: [T; 2],
    /// Covariance of (x, y, v_x, v_y).
    pub covariance: SMatrix<T, 4, 4>,
}

/// The tracking filter in scalar `T`.
#[derive(Clone, Debug)]
pub struct Ttkf<T: RealField + Copy> {
    config: TtkfConfig,
    x: SVector<T, STATES>,
    p: SMatrix<T, STATES, STATES>,
    cached: TransitionCache<T, STATES>,
    last_nis: T,
}

impl<T: RealField + Copy> Ttkf<T> {
    /// Starts on a target at `range_m`, `bearing_rad` (true) from `own`.
    pub fn new(
        config: TtkfConfig,
        own: &OwnShip<T>,
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
        let (s, co) = (libm::sin(bearing_rad), libm::cos(bearing_rad));
        x[ix::TX] = own.position_m[0] + c(range_m * s);
        x[ix::TY] = own.position_m[1] + c(range_m * co);
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
        p[(ix::TAX, ix::TAX)] = ga(&config.target_acceleration);
        p[(ix::TAY, ix::TAY)] = ga(&config.target_acceleration);
        // Target position: the radar's error ellipse, taken round (its larger axis), plus
        // the own-ship position's.
        let pos_var = config
            .range_var_m2
            .max(range_m * range_m * config.bearing_var_rad2);
        for (t, o) in [(ix::TX, ix::OX), (ix::TY, ix::OY)] {
            p[(t, t)] = p[(o, o)] + c(pos_var);
        }
        let v0 = c::<T>(config.initial_speed_sd_mps * config.initial_speed_sd_mps);
        p[(ix::TVX, ix::TVX)] = v0;
        p[(ix::TVY, ix::TVY)] = v0;
        Ok(Ttkf {
            config,
            x,
            p,
            cached: None,
            last_nis: T::zero(),
        })
    }

    /// Φ (eq. 8c) and Q (eq. 6) over `dt`: Van Loan on each [position, velocity,
    /// acceleration] chain (3×3), scattered into the state order.
    pub fn transition(&self, dt: T) -> Option<Transition<T, STATES>> {
        transition(&self.config, dt)
    }

    /// Propagates over `dt_s` (> 0, at most a day).
    pub fn predict(&mut self, dt_s: f64) -> Result<(), FilterError> {
        let config = self.config;
        predict_with(&mut self.x, &mut self.p, &mut self.cached, dt_s, |dt| {
            transition(&config, dt)
        })
    }

    /// Eq. 9a z1–z4: the DRKF's estimate with its covariance as R. The errors are correlated,
    /// so they are whitened first (R = LLᵀ, z' = L⁻¹z, H' = L⁻¹H) and then applied one by one.
    pub fn update_own_ship(&mut self, own: &OwnShip<T>) -> Result<(), FilterError> {
        let z = Vector4::new(
            own.position_m[0],
            own.position_m[1],
            own.velocity_mps[0],
            own.velocity_mps[1],
        );
        FilterError::check(z.iter().chain(own.covariance.iter()).all(|v| v.is_finite()))?;
        let chol = nalgebra::Cholesky::new(own.covariance).ok_or(FilterError::BadParameter)?;
        let l = chol.l();
        let idx = [ix::OX, ix::OY, ix::OVX, ix::OVY];
        // Residuals and H rows (unit rows) before whitening.
        let mut residual = Vector4::zeros();
        let mut h = SMatrix::<T, 4, STATES>::zeros();
        for (r, &i) in idx.iter().enumerate() {
            residual[r] = z[r] - self.x[i];
            h[(r, i)] = T::one();
        }
        // Forward substitution with L (no inverse, no panic path).
        let mut wr = Vector4::zeros();
        let mut wh = SMatrix::<T, 4, STATES>::zeros();
        for r in 0..4 {
            let mut acc = residual[r];
            let mut acc_h = h.row(r).clone_owned();
            for k in 0..r {
                acc -= l[(r, k)] * wr[k];
                acc_h -= wh.row(k) * l[(r, k)];
            }
            let d = l[(r, r)];
            if d <= T::zero() || !d.is_finite() {
                return Err(FilterError::BadParameter);
            }
            wr[r] = acc / d;
            wh.set_row(r, &(acc_h / d));
        }
        let rows: [Scalar<T, STATES>; 4] = core::array::from_fn(|r| Scalar {
            residual: wr[r],
            h: wh.row(r).transpose(),
            r: T::one(),
        });
        sequential_update(&mut self.x, &mut self.p, &rows);
        Ok(())
    }

    /// Eq. 9a z5–z6: radar range, m, and azimuth, radians true (residual wrapped), with the
    /// H of eq. 9b–9c at the predicted state. Returns the NIS of the two.
    pub fn update_radar(&mut self, range_m: f64, bearing_rad: f64) -> Result<T, FilterError> {
        FilterError::check(range_m.is_finite() && range_m >= 0.0 && bearing_rad.is_finite())?;
        let dx = self.x[ix::TX] - self.x[ix::OX];
        let dy = self.x[ix::TY] - self.x[ix::OY];
        let r2 = dx * dx + dy * dy;
        let r = r2.sqrt();
        if r <= c(1.0) || !r.is_finite() {
            return Err(FilterError::BadParameter);
        }
        let (h51, h52, h61, h62) = (dx / r, dy / r, dx / r2, dy / r2);
        let mut hr = SVector::<T, STATES>::zeros();
        hr[ix::OX] = -h51;
        hr[ix::OY] = -h52;
        hr[ix::TX] = h51;
        hr[ix::TY] = h52;
        let mut hb = SVector::<T, STATES>::zeros();
        hb[ix::OX] = -h62;
        hb[ix::OY] = h61;
        hb[ix::TX] = h62;
        hb[ix::TY] = -h61;
        let rows = [
            Scalar {
                residual: c::<T>(range_m) - r,
                h: hr,
                r: c(self.config.range_var_m2),
            },
            Scalar {
                residual: wrap_pi(c::<T>(bearing_rad) - dx.atan2(dy)),
                h: hb,
                r: c(self.config.bearing_var_rad2),
            },
        ];
        let (_, nis) = sequential_update(&mut self.x, &mut self.p, &rows);
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

/// Φ (eq. 8c) and Q (eq. 6) over `dt`: Van Loan on each [position, velocity,
/// acceleration] chain (3×3), scattered into the state order.
fn transition<T: RealField + Copy>(config: &TtkfConfig, dt: T) -> Option<Transition<T, STATES>> {
    let mut phi = SMatrix::<T, STATES, STATES>::zeros();
    let mut q = SMatrix::<T, STATES, STATES>::zeros();
    for (g, axes) in [
        (
            &config.own_acceleration,
            [[ix::OX, ix::OVX, ix::OAX], [ix::OY, ix::OVY, ix::OAY]],
        ),
        (
            &config.target_acceleration,
            [[ix::TX, ix::TVX, ix::TAX], [ix::TY, ix::TVY, ix::TAY]],
        ),
    ] {
        let (o, z, b) = (T::one(), T::zero(), c::<T>(g.beta_per_s));
        let f = Matrix3::new(z, o, z, z, z, o, z, z, -b);
        let mut qc = Matrix3::zeros();
        qc[(2, 2)] = c(g.alpha() * g.alpha());
        let (phi3, q3) = van_loan::<T, 3, 6>(&f, &qc, dt)?;
        for idx in axes {
            for (r, &i) in idx.iter().enumerate() {
                for (k, &j) in idx.iter().enumerate() {
                    phi[(i, j)] = phi3[(r, k)];
                    q[(i, j)] = q3[(r, k)];
                }
            }
        }
    }
    Some((phi, q))
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
        }
    }

    fn own(t: f64) -> OwnShip<f64> {
        let mut cov = SMatrix::<f64, 4, 4>::identity() * 0.01;
        cov[(0, 0)] = 4.0;
        cov[(1, 1)] = 4.0;
        OwnShip {
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
