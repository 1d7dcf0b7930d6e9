//! The coupled filter the paper's DRTTKF is measured against (§3, eq. 10): one EKF over the
//! own ship's 11 dead-reckoning states and six per target, 11 + 6n states in all, fed the
//! same sensors and radar plots.
//!
//! It exists to be compared with, not to be run at sea: its cost grows as (11 + 6n)³ where
//! the DRTTKF's grows as n, and a 64 KiB MCU holds it for a handful of targets only. It
//! shares the DRKF's and TTKF's models, rows and discretisations, so the two differ only in
//! the coupling.

use core::marker::PhantomData;

use nalgebra::{RealField, SMatrix, SVector};

use super::algebra::{chain_add, chain_columns, chain_rows, chain_scatter, chain_state};
use super::drkf::{self, Drkf, DrkfConfig, NavFix, SensorNoise};
use super::ttkf::{self, chain_phi, TtkfConfig};
use super::{predict_cached, Algebra, Discretised, Structured, Transition};
use crate::filter::FilterError;

/// States per target: x, y position, velocity and acceleration (the TTKF's eq. 8a target
/// half, same order).
pub const TARGET_STATES: usize = 6;

/// The [position, velocity, acceleration] chains (x, y) of target `t` in an `N`-state filter.
fn target_chains(t: usize) -> [[usize; 3]; 2] {
    let b = drkf::STATES + TARGET_STATES * t;
    [[b, b + 2, b + 4], [b + 1, b + 3, b + 5]]
}

/// Φ and Q over one interval: the DRKF's blocks, then one target chain block per axis and
/// target.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Blocks<T: RealField + Copy> {
    own: drkf::Blocks<T>,
    targets: ttkf::Blocks<T>,
}

impl<T: RealField + Copy, const N: usize> Discretised<T, N> for Blocks<T> {
    fn propagate_blocks(&self, x: &mut SVector<T, N>, p: &mut SMatrix<T, N, N>) {
        // Left (row) and right (column) products commute, so block by block is ΦPΦᵀ.
        self.own.propagate_leading(x, p);
        let (phi, q) = self.targets.target();
        for t in 0..targets(N) {
            for chain in target_chains(t) {
                chain_rows(p, chain, chain_phi(phi));
                chain_columns(p, chain, chain_phi(phi));
                chain_add(p, chain, q);
                chain_state(x, chain, chain_phi(phi));
            }
        }
    }

    fn dense(&self) -> Transition<T, N> {
        let mut phi = SMatrix::<T, N, N>::zeros();
        let mut q = SMatrix::<T, N, N>::zeros();
        self.own.scatter_leading(&mut phi, &mut q);
        let (phi3, q3) = self.targets.target();
        for t in 0..targets(N) {
            for chain in target_chains(t) {
                chain_scatter(&mut phi, chain, phi3);
                chain_scatter(&mut q, chain, q3);
            }
        }
        (phi, q)
    }
}

/// Targets an `n`-state coupled filter holds.
const fn targets(n: usize) -> usize {
    n.saturating_sub(drkf::STATES) / TARGET_STATES
}

/// The coupled (11 + 6n)-state filter in scalar `T`, `N` = 11 + 6n states.
#[derive(Clone, Debug)]
pub struct Coupled<T: RealField + Copy, const N: usize, A: Algebra = Structured> {
    own: DrkfConfig,
    target: TtkfConfig,
    x: SVector<T, N>,
    p: SMatrix<T, N, N>,
    cached: Option<(T, Blocks<T>)>,
    noise: SensorNoise<T>,
    radar_noise: [T; 3],
    algebra: PhantomData<A>,
}

impl<T: RealField + Copy, const N: usize, A: Algebra> Coupled<T, N, A> {
    /// Targets held: n of N = 11 + 6n.
    pub const TARGETS: usize = targets(N);

    /// Starts from the dead-reckoning filter `own` (its state and covariance) with one target
    /// per (range m, bearing rad true) in `plots`; `N` must be 11 + 6·`plots.len()`. The
    /// target model and radar noise are the TTKF's (`target`; its own-ship fields unused).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when `N` does not match the plots or the configuration is out of range.
    pub fn new<B: Algebra>(
        own: &Drkf<T, B>,
        target: TtkfConfig,
        plots: &[(f64, f64)],
    ) -> Result<Self, FilterError> {
        FilterError::check(
            N >= drkf::STATES
                && (N - drkf::STATES).is_multiple_of(TARGET_STATES)
                && plots.len() == Self::TARGETS,
        )?;
        target.validate()?;
        let mut x = SVector::<T, N>::zeros();
        let mut p = SMatrix::<T, N, N>::zeros();
        x.fixed_rows_mut::<{ drkf::STATES }>(0)
            .copy_from(own.state());
        p.fixed_view_mut::<{ drkf::STATES }, { drkf::STATES }>(0, 0)
            .copy_from(own.covariance());
        for (t, &(range_m, bearing_rad)) in plots.iter().enumerate() {
            FilterError::check(range_m.is_finite() && range_m > 0.0 && bearing_rad.is_finite())?;
            ttkf::acquire(
                &target,
                &mut x,
                &mut p,
                [drkf::ix::X, drkf::ix::Y],
                target_chains(t),
                range_m,
                bearing_rad,
            );
        }
        Ok(Coupled {
            own: *own.config(),
            target,
            x,
            p,
            cached: None,
            noise: SensorNoise::new(own.config()),
            radar_noise: ttkf::radar_noise(&target),
            algebra: PhantomData,
        })
    }

    /// Propagates every state over `dt_s` (> 0, at most a day).
    ///
    /// # Errors
    /// [`FilterError::BadInterval`] for a step outside (0, 1 day].
    pub fn predict(&mut self, dt_s: f64) -> Result<(), FilterError> {
        let (own, target) = (self.own, self.target);
        predict_cached::<T, N, A, _>(&mut self.x, &mut self.p, &mut self.cached, dt_s, |dt| {
            Some(Blocks {
                own: drkf::Blocks::new(&own, dt)?,
                targets: ttkf::Blocks::new(&target, dt)?,
            })
        })
    }

    /// The own-ship sensors (eq. 7a–7d), as [`Drkf::update`]. Returns the rows used.
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] when a value of `fix` is not finite (nothing changes).
    pub fn update_nav(&mut self, fix: &NavFix) -> Result<usize, FilterError> {
        let mut rows = heapless::Vec::new();
        drkf::sensor_rows(&self.own, &self.noise, &self.x, fix, &mut rows)?;
        Ok(A::update(&mut self.x, &mut self.p, &rows).0)
    }

    /// A radar plot of target `t` (eq. 9a z5–z6). Returns the NIS of the two.
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] for a non-finite plot, [`FilterError::BadParameter`] for a target index out of range.
    pub fn update_radar(
        &mut self,
        t: usize,
        range_m: f64,
        bearing_rad: f64,
    ) -> Result<T, FilterError> {
        FilterError::check(t < Self::TARGETS)?;
        let [cx, cy] = target_chains(t);
        let rows = ttkf::radar_rows(
            &self.x,
            [drkf::ix::X, drkf::ix::Y],
            [cx[0], cy[0]],
            self.radar_noise,
            range_m,
            bearing_rad,
        )?;
        Ok(A::update(&mut self.x, &mut self.p, &rows).1)
    }

    /// The state: the DRKF's 11 (eq. 4a order), then six per target.
    pub fn state(&self) -> &SVector<T, N> {
        &self.x
    }

    /// The covariance.
    pub fn covariance(&self) -> &SMatrix<T, N, N> {
        &self.p
    }

    /// Target `t`'s position, m (`None` past the last target).
    pub fn target_position_m(&self, t: usize) -> Option<[T; 2]> {
        (t < Self::TARGETS).then(|| {
            let [cx, cy] = target_chains(t);
            [self.x[cx[0].min(N - 1)], self.x[cy[0].min(N - 1)]]
        })
    }

    /// Target `t`'s velocity over ground, m/s.
    pub fn target_velocity_mps(&self, t: usize) -> Option<[T; 2]> {
        (t < Self::TARGETS).then(|| {
            let [cx, cy] = target_chains(t);
            [self.x[cx[1].min(N - 1)], self.x[cy[1].min(N - 1)]]
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nav::ttkf::{OwnShipEstimate, Ttkf};
    use crate::nav::{Dense, GaussMarkov};

    fn ttkf_config() -> TtkfConfig {
        TtkfConfig {
            own_acceleration: GaussMarkov::with_variance(0.01, 0.1),
            target_acceleration: GaussMarkov::with_variance(0.01, 0.1),
            range_var_m2: 400.0,
            bearing_var_rad2: 0.5f64.to_radians().powi(2),
            initial_speed_sd_mps: 10.0,
            glint_sd_m: 0.0,
        }
    }

    fn drkf() -> Drkf<f64> {
        Drkf::new(
            DrkfConfig::table_1(1).unwrap(),
            [0.0, 0.0],
            [0.0, 5.0],
            20.0,
            1.0,
        )
        .unwrap()
    }

    /// Own ship north at 5 m/s; target t from (3000, 3000 + 1000 t) heading west at 6 m/s.
    fn truth(t: usize, s: f64) -> ([f64; 2], [f64; 2]) {
        (
            [0.0, 5.0 * s],
            [3000.0 - 6.0 * s, 3000.0 + 1000.0 * t as f64],
        )
    }

    fn polar(own: [f64; 2], target: [f64; 2]) -> (f64, f64) {
        let (dx, dy) = (target[0] - own[0], target[1] - own[1]);
        ((dx * dx + dy * dy).sqrt(), dx.atan2(dy))
    }

    fn fix(s: f64) -> NavFix {
        NavFix {
            gps_position_m: Some([0.0, 5.0 * s]),
            gps_velocity_mps: Some([0.0, 5.0]),
            speedlog_mps: Some(5.0),
            gyro_rad: Some(0.0),
            ..NavFix::default()
        }
    }

    #[test]
    fn coupled_and_decoupled_filters_track_alike_and_structure_changes_nothing() {
        const N: usize = drkf::STATES + 2 * TARGET_STATES;
        let plots: [(f64, f64); 2] = core::array::from_fn(|t| {
            let (o, p) = truth(t, 0.0);
            polar(o, p)
        });
        let dr = drkf();
        let mut coupled = Coupled::<f64, N>::new(&dr, ttkf_config(), &plots).unwrap();
        let mut dense = Coupled::<f64, N, Dense>::new(&dr, ttkf_config(), &plots).unwrap();
        // The DRTTKF: the same DRKF feeding one TTKF per target.
        let mut own = dr.clone();
        let handoff = |d: &Drkf<f64>| OwnShipEstimate {
            position_m: d.position_m(),
            velocity_mps: d.velocity_over_ground_mps(),
            covariance: d.own_ship_covariance(),
        };
        let mut tracks: [Ttkf<f64>; 2] = core::array::from_fn(|t| {
            Ttkf::new(ttkf_config(), &handoff(&own), plots[t].0, plots[t].1).unwrap()
        });
        for k in 1..=300 {
            let s = f64::from(k);
            coupled.predict(1.0).unwrap();
            dense.predict(1.0).unwrap();
            coupled.update_nav(&fix(s)).unwrap();
            dense.update_nav(&fix(s)).unwrap();
            own.predict(1.0).unwrap();
            own.update(&fix(s)).unwrap();
            for (t, track) in tracks.iter_mut().enumerate() {
                track.predict(1.0).unwrap();
                track.update_own_ship(&handoff(&own)).unwrap();
                if k % 3 == 0 {
                    let (o, p) = truth(t, s);
                    let (r, b) = polar(o, p);
                    coupled.update_radar(t, r, b).unwrap();
                    dense.update_radar(t, r, b).unwrap();
                    track.update_radar(r, b).unwrap();
                }
            }
            let scale = dense.covariance().abs().max();
            assert!((coupled.covariance() - dense.covariance()).abs().max() < 1e-9 * scale);
        }
        for (t, track) in tracks.iter().enumerate() {
            let (_, p) = truth(t, 300.0);
            let c = coupled.target_position_m(t).unwrap();
            let d = track.target_position_m();
            let v = coupled.target_velocity_mps(t).unwrap();
            assert!(
                (c[0] - p[0]).hypot(c[1] - p[1]) < 15.0,
                "coupled {c:?} vs {p:?}"
            );
            assert!(
                (d[0] - p[0]).hypot(d[1] - p[1]) < 15.0,
                "DRTTKF {d:?} vs {p:?}"
            );
            assert!((v[0] + 6.0).abs() < 0.3 && v[1].abs() < 0.3, "{v:?}");
        }
    }

    #[test]
    fn sizes_that_are_not_11_plus_6n_are_refused() {
        let dr = drkf();
        assert!(Coupled::<f64, 12>::new(&dr, ttkf_config(), &[]).is_err());
        assert!(Coupled::<f64, 17>::new(&dr, ttkf_config(), &[]).is_err());
        assert!(Coupled::<f64, 17>::new(&dr, ttkf_config(), &[(1000.0, 0.1)]).is_ok());
        let mut c = Coupled::<f64, 17>::new(&dr, ttkf_config(), &[(1000.0, 0.1)]).unwrap();
        assert!(c.update_radar(1, 1000.0, 0.1).is_err());
        assert!(c.target_position_m(1).is_none());
    }
}
