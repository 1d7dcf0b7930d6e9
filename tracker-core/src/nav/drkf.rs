//! The dead-reckoning Kalman filter (DRKF) of `004_be25d15b4854a4f6.txt` §2: own-ship
//! position and velocity from whatever of GPS, Loran-C, speedlog and gyro is available.
//!
//! States (eq. 4a), in the paper's order: x position, x current, x vessel velocity (through
//! the water), x acceleration; the same four for y; Loran-C x and y errors; speedlog error.
//! Current, acceleration, Loran-C and speedlog errors are first-order Gauss–Markov (eq. 1).
//! Axes: x east, y north, metres and seconds.
//!
//! Measurements (eq. 7a–7d): GPS position and velocity over ground, Loran-C position (with
//! its Markov error), the speedlog's speed (ground-lock: over ground, current included, eq.
//! 7c; bottom-lock: through the water, eq. 7d), and the gyro bearing. The bearing's H (H82,
//! H86 of eq. 7b) is that of the course over ground, atan2(v_x + c_x, v_y + c_y), and is
//! used as printed. Any subset may arrive; none is an error.

use core::marker::PhantomData;

use nalgebra::{Matrix1, Matrix4, RealField, SMatrix, SVector};

use super::algebra::{
    chain_add, chain_columns, chain_rows, chain_scatter, chain_state, Block, Row,
};
use super::{
    c, predict_cached, van_loan, wrap_pi, Algebra, Discretised, GaussMarkov, Structured, Transition,
};
use crate::filter::FilterError;

/// Number of states.
pub const STATES: usize = 11;
/// State indices (eq. 4a, zero-based).
pub mod ix {
    /// x position, m.
    pub const X: usize = 0;
    /// x current, m/s.
    pub const CX: usize = 1;
    /// x vessel velocity through the water, m/s.
    pub const VX: usize = 2;
    /// x acceleration, m/s².
    pub const AX: usize = 3;
    /// y position, m.
    pub const Y: usize = 4;
    /// y current, m/s.
    pub const CY: usize = 5;
    /// y vessel velocity through the water, m/s.
    pub const VY: usize = 6;
    /// y acceleration, m/s².
    pub const AY: usize = 7;
    /// Loran-C x error, m.
    pub const LX: usize = 8;
    /// Loran-C y error, m.
    pub const LY: usize = 9;
    /// Speedlog error, m/s.
    pub const SL: usize = 10;
}

/// Each axis's [position, current, velocity, acceleration] chain (eq. 4c: upper triangular).
const AXES: [[usize; 4]; 2] = [
    [ix::X, ix::CX, ix::VX, ix::AX],
    [ix::Y, ix::CY, ix::VY, ix::AY],
];

/// Φ (eq. 5) and Q (eq. 6) over one interval, as the model has them: one 4×4 block for
/// both axes and eq. 2's scalars for the Loran-C and speedlog errors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blocks<T: RealField + Copy> {
    axis: (Matrix4<T>, Matrix4<T>),
    /// (a, b²) of the Loran-C error (both axes) and of the speedlog error.
    loran: (Matrix1<T>, Matrix1<T>),
    speedlog: (Matrix1<T>, Matrix1<T>),
}

impl<T: RealField + Copy> Blocks<T> {
    /// Van Loan on one axis's 4×4 block, eq. 2 on the scalar states.
    pub(crate) fn new(cfg: &DrkfConfig, dt: T) -> Option<Self> {
        let (bc, bv) = (
            c::<T>(cfg.current.beta_per_s),
            c::<T>(cfg.acceleration.beta_per_s),
        );
        let (o, z) = (T::one(), T::zero());
        let f = Matrix4::new(z, o, o, z, z, -bc, z, z, z, z, z, o, z, z, z, -bv);
        let mut qc = Matrix4::zeros();
        qc[(1, 1)] = c(cfg.current.alpha() * cfg.current.alpha());
        qc[(3, 3)] = c(cfg.acceleration.alpha() * cfg.acceleration.alpha());
        let axis = van_loan::<T, 4, 8>(&f, &qc, dt)?;
        let dt64 = nalgebra::try_convert::<T, f64>(dt)?;
        let scalar = |g: &GaussMarkov| {
            (
                Matrix1::new(c(g.a(dt64))),
                Matrix1::new(c(g.b(dt64) * g.b(dt64))),
            )
        };
        Some(Blocks {
            axis,
            loran: scalar(&cfg.loran),
            speedlog: scalar(&cfg.speedlog),
        })
    }

    fn scalars(&self) -> [([usize; 1], &Block<T, 1>); 3] {
        [
            ([ix::LX], &self.loran),
            ([ix::LY], &self.loran),
            ([ix::SL], &self.speedlog),
        ]
    }
}

/// A·v for an axis's Φ (eq. 5): position integrates current and velocity, velocity
/// integrates acceleration, current and acceleration decay. The zeros and ones are exact in
/// Van Loan's result too (F's first column is zero and its current row has only −β_c).
#[inline(always)]
fn axis_phi<T: RealField + Copy>(a: &Matrix4<T>) -> impl Fn([T; 4]) -> [T; 4] + '_ {
    move |[p, cur, v, acc]| {
        [
            p + a[(0, 1)] * cur + a[(0, 2)] * v + a[(0, 3)] * acc,
            a[(1, 1)] * cur,
            v + a[(2, 3)] * acc,
            a[(3, 3)] * acc,
        ]
    }
}

#[inline(always)]
fn scalar_phi<T: RealField + Copy>(a: &Matrix1<T>) -> impl Fn([T; 1]) -> [T; 1] + '_ {
    move |[v]| [a[(0, 0)] * v]
}

impl<T: RealField + Copy> Blocks<T> {
    /// Propagates the DRKF's states, the first [`STATES`] of an `M`-state filter.
    #[inline(always)]
    pub(crate) fn propagate_leading<const M: usize>(
        &self,
        x: &mut SVector<T, M>,
        p: &mut SMatrix<T, M, M>,
    ) {
        let (phi, q) = &self.axis;
        for chain in AXES {
            chain_rows(p, chain, axis_phi(phi));
        }
        for (chain, (a, _)) in self.scalars() {
            chain_rows(p, chain, scalar_phi(a));
        }
        for chain in AXES {
            chain_columns(p, chain, axis_phi(phi));
            chain_add(p, chain, q);
            chain_state(x, chain, axis_phi(phi));
        }
        for (chain, (a, b2)) in self.scalars() {
            chain_columns(p, chain, scalar_phi(a));
            chain_add(p, chain, b2);
            chain_state(x, chain, scalar_phi(a));
        }
    }

    /// Scatters Φ and Q into the leading block of `M`-state matrices.
    pub(crate) fn scatter_leading<const M: usize>(
        &self,
        phi: &mut SMatrix<T, M, M>,
        q: &mut SMatrix<T, M, M>,
    ) {
        for chain in AXES {
            chain_scatter(phi, chain, &self.axis.0);
            chain_scatter(q, chain, &self.axis.1);
        }
        for (chain, (a, b2)) in self.scalars() {
            chain_scatter(phi, chain, a);
            chain_scatter(q, chain, b2);
        }
    }
}

impl<T: RealField + Copy> Discretised<T, STATES> for Blocks<T> {
    fn propagate_blocks(&self, x: &mut SVector<T, STATES>, p: &mut SMatrix<T, STATES, STATES>) {
        self.propagate_leading(x, p);
    }

    fn dense(&self) -> Transition<T, STATES> {
        let mut phi = SMatrix::<T, STATES, STATES>::zeros();
        let mut q = SMatrix::<T, STATES, STATES>::zeros();
        self.scatter_leading(&mut phi, &mut q);
        (phi, q)
    }
}

/// What the speedlog measures (eq. 7c, 7d).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpeedlogMode {
    /// Speed over ground, current included (eq. 7c; the paper's "ground-lock": measured
    /// against the sea floor, a Doppler log's bottom track).
    OverGround,
    /// Speed through the water (eq. 7d; the paper's "bottom-lock": measured against a
    /// layer of water, as a ship's or yacht's log, `VHW`, reads).
    ThroughWater,
}

/// What the gyro's bearing measures (eq. 7b).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroMode {
    /// The course over ground, atan2(v_x + c_x, v_y + c_y): eq. 7b's H as printed (the
    /// paper's experiments).
    CourseOverGround,
    /// The heading: the direction of the hull's velocity through the water,
    /// atan2(v_x, v_y). What a gyro or a `HDT` reads: a ship crabbing in a current or set
    /// by the wind heads one way and makes good another, and the current states take the
    /// difference, so own ship's course over ground stays the GNSS's.
    HeadingThroughWater,
}

/// DRKF parameters: the models of Table I and the sensors' noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrkfConfig {
    /// Ocean current, per axis.
    pub current: GaussMarkov,
    /// Vessel acceleration, per axis.
    pub acceleration: GaussMarkov,
    /// Loran-C position error, per axis.
    pub loran: GaussMarkov,
    /// Speedlog error.
    pub speedlog: GaussMarkov,
    /// GPS position noise variance per axis, m² (R1, R2).
    pub gps_position_var: f64,
    /// GPS velocity noise variance per axis, m²/s² (R3, R4).
    pub gps_velocity_var: f64,
    /// Loran-C white noise variance per axis, m² (on top of its Markov error).
    pub loran_var: f64,
    /// Speedlog white noise variance, m²/s².
    pub speedlog_var: f64,
    /// Gyro bearing noise variance, rad².
    pub gyro_var: f64,
    /// Speedlog mode.
    pub speedlog_mode: SpeedlogMode,
    /// Gyro mode.
    pub gyro_mode: GyroMode,
}

impl DrkfConfig {
    /// Table I, test 1 of the paper (β_L-C 0.25, β_S-L 0.5, acceleration σ 0.5 β 1, bearing
    /// 1°); the Loran-C white noise and the speedlog white noise are not given: 25 m² and
    /// 0.01 m²/s² (our choice).
    pub fn table_1(test: usize) -> Option<Self> {
        // (σc², βc, GPS pos var, GPS vel var, Loran var, speedlog Markov var)
        let row = match test {
            1 => (0.3, 0.17, 1600.0, 0.25, 500.0, 0.5),
            2 => (0.7, 0.33, 800.0, 0.25, 500.0, 0.5),
            3 => (0.25, 0.17, 800.0, 0.5, 1100.0, 0.025),
            4 => (0.0025, 0.17, 800.0, 0.5, 1100.0, 0.0025),
            5 => (0.1, 0.125, 1600.0, 0.5, 1100.0, 0.025),
            _ => return None,
        };
        Some(DrkfConfig {
            current: GaussMarkov::with_variance(row.0, row.1),
            acceleration: GaussMarkov::with_variance(0.25, 1.0),
            loran: GaussMarkov::with_variance(row.4, 0.25),
            speedlog: GaussMarkov::with_variance(row.5, 0.5),
            gps_position_var: row.2,
            gps_velocity_var: row.3,
            loran_var: 25.0,
            speedlog_var: 0.01,
            gyro_var: (1.0f64).to_radians() * (1.0f64).to_radians(),
            speedlog_mode: SpeedlogMode::OverGround,
            gyro_mode: GyroMode::CourseOverGround,
        })
    }

    fn validate(&self) -> Result<(), FilterError> {
        let var = |v: f64| v.is_finite() && v > 0.0;
        FilterError::check(
            self.current.is_valid()
                && self.acceleration.is_valid()
                && self.loran.is_valid()
                && self.speedlog.is_valid()
                && var(self.gps_position_var)
                && var(self.gps_velocity_var)
                && var(self.loran_var)
                && var(self.speedlog_var)
                && var(self.gyro_var),
        )
    }
}

/// One second's own-ship sensor data; `None`: not available (normal, not an error).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NavFix {
    /// GPS position (east, north), m.
    pub gps_position_m: Option<[f64; 2]>,
    /// GPS velocity over ground (east, north), m/s.
    pub gps_velocity_mps: Option<[f64; 2]>,
    /// Loran-C position (east, north), m.
    pub loran_position_m: Option<[f64; 2]>,
    /// Speedlog speed, m/s.
    pub speedlog_mps: Option<f64>,
    /// Gyro bearing, radians true.
    pub gyro_rad: Option<f64>,
}

/// Below this speed the speedlog and gyro rows are singular and skipped, m/s.
const MIN_SPEED_MPS: f64 = 0.2;

/// The sensors' noise variances (eq. 7's R) in the filter's scalar, converted once: on the
/// M4F an f64 → f32 conversion is a software call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SensorNoise<T> {
    gps_position: T,
    gps_velocity: T,
    loran: T,
    speedlog: T,
    gyro: T,
}

impl<T: RealField + Copy> SensorNoise<T> {
    pub(crate) fn new(cfg: &DrkfConfig) -> Self {
        SensorNoise {
            gps_position: c(cfg.gps_position_var),
            gps_velocity: c(cfg.gps_velocity_var),
            loran: c(cfg.loran_var),
            speedlog: c(cfg.speedlog_var),
            gyro: c(cfg.gyro_var),
        }
    }
}

/// The dead-reckoning filter in scalar `T` (f32 on the MCU, f64 on the host), with `A`'s
/// covariance arithmetic ([`Structured`] unless a benchmark asks for the dense reference).
#[derive(Clone, Debug)]
pub struct Drkf<T: RealField + Copy, A: Algebra = Structured> {
    config: DrkfConfig,
    x: SVector<T, STATES>,
    p: SMatrix<T, STATES, STATES>,
    /// Φ and Q of the last interval, reused while the interval repeats (sensors at 1 s).
    cached: Option<(T, Blocks<T>)>,
    noise: SensorNoise<T>,
    last_nis: T,
    algebra: PhantomData<A>,
}

impl<T: RealField + Copy> Drkf<T> {
    /// A filter at `position_m` with velocity `velocity_mps` (through the water, no current
    /// assumed), with standard deviations `position_sd_m` and `velocity_sd_mps`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] for a configuration out of range or a non-finite start.
    pub fn new(
        config: DrkfConfig,
        position_m: [f64; 2],
        velocity_mps: [f64; 2],
        position_sd_m: f64,
        velocity_sd_mps: f64,
    ) -> Result<Self, FilterError> {
        Self::with_algebra(
            config,
            position_m,
            velocity_mps,
            position_sd_m,
            velocity_sd_mps,
        )
    }
}

impl<T: RealField + Copy, A: Algebra> Drkf<T, A> {
    /// As [`Drkf::new`], with `A`'s covariance arithmetic.
    ///
    /// # Errors
    /// As [`Drkf::new`].
    pub fn with_algebra(
        config: DrkfConfig,
        position_m: [f64; 2],
        velocity_mps: [f64; 2],
        position_sd_m: f64,
        velocity_sd_mps: f64,
    ) -> Result<Self, FilterError> {
        config.validate()?;
        let finite = position_m
            .iter()
            .chain(&velocity_mps)
            .all(|v| v.is_finite());
        FilterError::check(finite && position_sd_m > 0.0 && velocity_sd_mps > 0.0)?;
        let mut x = SVector::<T, STATES>::zeros();
        x[ix::X] = c(position_m[0]);
        x[ix::Y] = c(position_m[1]);
        x[ix::VX] = c(velocity_mps[0]);
        x[ix::VY] = c(velocity_mps[1]);
        let mut p = SMatrix::<T, STATES, STATES>::zeros();
        let var = |g: &GaussMarkov| c::<T>(g.sigma * g.sigma);
        for (i, v) in [
            (ix::X, c(position_sd_m * position_sd_m)),
            (ix::Y, c(position_sd_m * position_sd_m)),
            (ix::VX, c(velocity_sd_mps * velocity_sd_mps)),
            (ix::VY, c(velocity_sd_mps * velocity_sd_mps)),
            (ix::CX, var(&config.current)),
            (ix::CY, var(&config.current)),
            (ix::AX, var(&config.acceleration)),
            (ix::AY, var(&config.acceleration)),
            (ix::LX, var(&config.loran)),
            (ix::LY, var(&config.loran)),
            (ix::SL, var(&config.speedlog)),
        ] {
            p[(i, i)] = v;
        }
        Ok(Drkf {
            config,
            x,
            p,
            cached: None,
            noise: SensorNoise::new(&config),
            last_nis: T::zero(),
            algebra: PhantomData,
        })
    }

    /// Φ and Q over `dt` s: Van Loan on one axis's 4×4 block, eq. 2 on the scalar states.
    pub fn transition(&self, dt: T) -> Option<Transition<T, STATES>> {
        Blocks::new(&self.config, dt).map(|b| b.dense())
    }

    /// Propagates the state and covariance over `dt_s` (> 0, at most a day).
    ///
    /// # Errors
    /// [`FilterError::BadInterval`] for a step outside (0, 1 day].
    pub fn predict(&mut self, dt_s: f64) -> Result<(), FilterError> {
        let config = self.config;
        predict_cached::<T, STATES, A, _>(&mut self.x, &mut self.p, &mut self.cached, dt_s, |dt| {
            Blocks::new(&config, dt)
        })
    }

    /// Applies what of `fix` is there. Returns the number of scalar measurements used.
    /// Non-finite values are refused whole, before any change.
    ///
    /// # Errors
    /// [`FilterError::NonFinite`] when a value of `fix` is not finite (nothing changes).
    pub fn update(&mut self, fix: &NavFix) -> Result<usize, FilterError> {
        let mut rows = heapless::Vec::new();
        sensor_rows(&self.config, &self.noise, &self.x, fix, &mut rows)?;
        let (used, nis) = A::update(&mut self.x, &mut self.p, &rows);
        self.last_nis = nis;
        Ok(used)
    }

    /// Switches the speedlog between ground-lock and bottom-lock (the log reports which).
    pub fn set_speedlog_mode(&mut self, mode: SpeedlogMode) {
        self.config.speedlog_mode = mode;
    }

    /// The configuration.
    pub fn config(&self) -> &DrkfConfig {
        &self.config
    }

    /// The state (eq. 4a order).
    pub fn state(&self) -> &SVector<T, STATES> {
        &self.x
    }

    /// The covariance.
    pub fn covariance(&self) -> &SMatrix<T, STATES, STATES> {
        &self.p
    }

    /// NIS (Σ ν²/S) of the last update.
    pub fn last_nis(&self) -> T {
        self.last_nis
    }

    /// Position (east, north), m.
    pub fn position_m(&self) -> [T; 2] {
        [self.x[ix::X], self.x[ix::Y]]
    }

    /// Velocity over ground (vessel + current), m/s.
    pub fn velocity_over_ground_mps(&self) -> [T; 2] {
        [
            self.x[ix::CX] + self.x[ix::VX],
            self.x[ix::CY] + self.x[ix::VY],
        ]
    }

    /// Covariance of (x, y, v_x over ground, v_y over ground): J P Jᵀ. The TTKF's R for its
    /// own-ship measurements (eq. 9a).
    pub fn own_ship_covariance(&self) -> SMatrix<T, 4, 4> {
        let mut j = SMatrix::<T, 4, STATES>::zeros();
        j[(0, ix::X)] = T::one();
        j[(1, ix::Y)] = T::one();
        j[(2, ix::CX)] = T::one();
        j[(2, ix::VX)] = T::one();
        j[(3, ix::CY)] = T::one();
        j[(3, ix::VY)] = T::one();
        j * self.p * j.transpose()
    }
}

/// Eq. 7a–7d: the scalar measurements in `fix`, linearised at `x`, appended to `rows` (of which the first
/// [`STATES`] are the DRKF's, so a coupled filter shares them). Non-finite values are refused
/// whole.
pub(crate) fn sensor_rows<T: RealField + Copy, const N: usize>(
    cfg: &DrkfConfig,
    noise: &SensorNoise<T>,
    x: &SVector<T, N>,
    fix: &NavFix,
    rows: &mut heapless::Vec<Row<T>, 8>,
) -> Result<(), FilterError> {
    FilterError::check(N >= STATES)?;
    let pairs = [
        fix.gps_position_m,
        fix.gps_velocity_mps,
        fix.loran_position_m,
    ];
    let finite = pairs.iter().flatten().flatten().all(|v| v.is_finite())
        && fix.speedlog_mps.is_none_or(f64::is_finite)
        && fix.gyro_rad.is_none_or(f64::is_finite);
    FilterError::check(finite)?;
    let o = T::one();
    let mut push = |residual: T, h: &[(usize, T)], r: T| {
        let _ = rows.push(Row::new(residual, r, h));
    };
    // The linear rows of eq. 7a: each measures the sum of one or two states.
    let mut sum_of = |z: f64, states: &[usize], r: T| {
        let mut h = [(0, o); 2];
        for (entry, &i) in h.iter_mut().zip(states) {
            entry.0 = i;
        }
        let residual = states.iter().fold(c::<T>(z), |acc, &i| acc - x[i]);
        push(residual, h.get(..states.len()).unwrap_or(&[]), r);
    };
    if let Some([e, n]) = fix.gps_position_m {
        sum_of(e, &[ix::X], noise.gps_position);
        sum_of(n, &[ix::Y], noise.gps_position);
    }
    if let Some([e, n]) = fix.gps_velocity_mps {
        sum_of(e, &[ix::CX, ix::VX], noise.gps_velocity);
        sum_of(n, &[ix::CY, ix::VY], noise.gps_velocity);
    }
    if let Some([e, n]) = fix.loran_position_m {
        sum_of(e, &[ix::X, ix::LX], noise.loran);
        sum_of(n, &[ix::Y, ix::LY], noise.loran);
    }
    let (gx, gy) = (x[ix::CX] + x[ix::VX], x[ix::CY] + x[ix::VY]);
    let ground2 = gx * gx + gy * gy;
    let min2: T = c(MIN_SPEED_MPS * MIN_SPEED_MPS);
    if let Some(s) = fix.speedlog_mps {
        match cfg.speedlog_mode {
            SpeedlogMode::OverGround if ground2 > min2 => {
                let r = ground2.sqrt();
                // Eq. 7c: H72 on x2 and x3, H76 on x6 and x7.
                let (hx, hy) = (gx / r, gy / r);
                let h = [
                    (ix::CX, hx),
                    (ix::VX, hx),
                    (ix::CY, hy),
                    (ix::VY, hy),
                    (ix::SL, o),
                ];
                push(c::<T>(s) - r - x[ix::SL], &h, noise.speedlog);
            }
            SpeedlogMode::ThroughWater => {
                let (vx, vy) = (x[ix::VX], x[ix::VY]);
                let r2 = vx * vx + vy * vy;
                if r2 > min2 {
                    let r = r2.sqrt();
                    let h = [(ix::VX, vx / r), (ix::VY, vy / r), (ix::SL, o)];
                    push(c::<T>(s) - r - x[ix::SL], &h, noise.speedlog);
                }
            }
            SpeedlogMode::OverGround => {}
        }
    }
    if let Some(b) = fix.gyro_rad {
        match cfg.gyro_mode {
            GyroMode::CourseOverGround if ground2 > min2 => {
                // Eq. 7b: H82 = (x6+x7)/|v|², H86 = (x2+x3)/|v|², as printed.
                let (h82, h86) = (gy / ground2, gx / ground2);
                let h = [(ix::CX, h82), (ix::VX, h82), (ix::CY, -h86), (ix::VY, -h86)];
                push(wrap_pi(c::<T>(b) - gx.atan2(gy)), &h, noise.gyro);
            }
            GyroMode::HeadingThroughWater => {
                // Eq. 7b's row on the velocity through the water alone.
                let (vx, vy) = (x[ix::VX], x[ix::VY]);
                let water2 = vx * vx + vy * vy;
                if water2 > min2 {
                    let h = [(ix::VX, vy / water2), (ix::VY, -vx / water2)];
                    push(wrap_pi(c::<T>(b) - vx.atan2(vy)), &h, noise.gyro);
                }
            }
            GyroMode::CourseOverGround => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filter() -> Drkf<f64> {
        Drkf::new(
            DrkfConfig::table_1(1).unwrap(),
            [0.0, 0.0],
            [5.0, 5.0],
            50.0,
            2.0,
        )
        .unwrap()
    }

    #[test]
    fn transition_is_eq_5_for_the_integrator_entries() {
        let f = filter();
        let (phi, q) = f.transition(1.0).unwrap();
        assert!((phi[(ix::X, ix::CX)] - 0.17f64.mul_add(-0.5, 1.0)).abs() < 0.01);
        assert!((phi[(ix::X, ix::VX)] - 1.0).abs() < 1e-12);
        assert!((phi[(ix::CX, ix::CX)] - (-0.17f64).exp()).abs() < 1e-12);
        assert!((phi[(ix::LX, ix::LX)] - (-0.25f64).exp()).abs() < 1e-12);
        assert!((q[(ix::SL, ix::SL)] - 0.5 * (1.0 - (-1.0f64).exp())).abs() < 1e-12);
        // The two axes are the same block and independent.
        assert_eq!(phi[(ix::X, ix::VX)], phi[(ix::Y, ix::VY)]);
        assert_eq!(q[(ix::X, ix::Y)], 0.0);
    }

    #[test]
    #[cfg(feature = "reference")]
    fn structured_arithmetic_is_the_dense_filter() {
        // Every sensor, then dead reckoning, bottom lock, and an uneven interval.
        let cfg = DrkfConfig::table_1(2).unwrap();
        let mut s = Drkf::<f64>::new(cfg, [10.0, -5.0], [4.0, 6.0], 50.0, 2.0).unwrap();
        let mut d =
            Drkf::<f64, crate::nav::Dense>::with_algebra(cfg, [10.0, -5.0], [4.0, 6.0], 50.0, 2.0)
                .unwrap();
        for k in 0..120 {
            let t = f64::from(k);
            let all = k < 40;
            let fix = NavFix {
                gps_position_m: all.then_some([4.0 * t + 3.0, 6.0 * t - 2.0]),
                gps_velocity_mps: all.then_some([4.1, 5.9]),
                loran_position_m: all.then_some([4.0 * t - 20.0, 6.0 * t + 15.0]),
                speedlog_mps: Some(7.3),
                gyro_rad: Some(0.6),
            };
            if k == 80 {
                s.set_speedlog_mode(SpeedlogMode::ThroughWater);
                d.set_speedlog_mode(SpeedlogMode::ThroughWater);
            }
            let dt = if k % 7 == 3 { 1.7 } else { 1.0 };
            s.predict(dt).unwrap();
            d.predict(dt).unwrap();
            assert_eq!(s.update(&fix).unwrap(), d.update(&fix).unwrap());
            let scale = d.covariance().abs().max();
            assert!(
                (s.covariance() - d.covariance()).abs().max() < 1e-9 * scale,
                "P at {k}"
            );
            assert!((s.state() - d.state()).abs().max() < 1e-9, "x at {k}");
            assert!((s.last_nis() - d.last_nis()).abs() < 1e-9);
        }
    }

    #[test]
    fn covariance_grows_dead_reckoning_and_collapses_when_gps_returns() {
        let mut f = filter();
        let (mut x, mut v) = ([0.0, 0.0], [5.0, 5.0]);
        let fix = |x: [f64; 2], v: [f64; 2], gps: bool| NavFix {
            gps_position_m: gps.then_some(x),
            gps_velocity_mps: gps.then_some(v),
            loran_position_m: None,
            speedlog_mps: Some((v[0] * v[0] + v[1] * v[1]).sqrt()),
            gyro_rad: Some(v[0].atan2(v[1])),
        };
        let mut sd = std::vec::Vec::new();
        for k in 0..600 {
            f.predict(1.0).unwrap();
            x = [x[0] + v[0], x[1] + v[1]];
            let gps = !(200..400).contains(&k);
            f.update(&fix(x, v, gps)).unwrap();
            sd.push(f.covariance()[(ix::X, ix::X)].sqrt());
            v = [v[0], v[1]];
        }
        assert!(sd[199] < 25.0, "with GPS {}", sd[199]);
        assert!(
            sd[399] > 2.0 * sd[199],
            "dead reckoning {} vs {}",
            sd[399],
            sd[199]
        );
        assert!(
            sd[250] < sd[300] && sd[300] < sd[399],
            "grows while dead reckoning"
        );
        assert!(
            sd[420] < 0.6 * sd[399],
            "collapses when GPS returns: {} -> {}",
            sd[399],
            sd[420]
        );
        let e = f.position_m();
        assert!((e[0] - x[0]).abs() < 30.0 && (e[1] - x[1]).abs() < 30.0);
    }

    #[test]
    fn a_heading_through_the_water_leaves_the_course_over_ground_to_gps() {
        // Making good 045° at 5 m/s heading 065°: as printed (eq. 7b on the course over
        // ground) the gyro turns the course towards itself; as a heading, the current states
        // take the 20° and the course over ground is the GPS's.
        let run = |mode: GyroMode| {
            let mut cfg = DrkfConfig::table_1(1).unwrap();
            cfg.gps_velocity_var = 0.01;
            cfg.gyro_var = 0.5f64.to_radians().powi(2);
            cfg.current = GaussMarkov::with_variance(1.0, 1.0 / 60.0);
            cfg.gyro_mode = mode;
            let v = [
                5.0 * 45f64.to_radians().sin(),
                5.0 * 45f64.to_radians().cos(),
            ];
            let mut f = Drkf::<f64>::new(cfg, [0.0, 0.0], v, 50.0, 2.0).unwrap();
            for k in 1..=120 {
                f.predict(1.0).unwrap();
                let t = f64::from(k);
                f.update(&NavFix {
                    gps_position_m: Some([v[0] * t, v[1] * t]),
                    gps_velocity_mps: Some(v),
                    gyro_rad: Some(65f64.to_radians()),
                    ..NavFix::default()
                })
                .unwrap();
            }
            let [e, n] = f.velocity_over_ground_mps();
            let x = f.state();
            (
                e.atan2(n).to_degrees(),
                x[ix::VX].atan2(x[ix::VY]).to_degrees(),
            )
        };
        let (cog, water) = run(GyroMode::HeadingThroughWater);
        assert!((cog - 45.0).abs() < 0.2, "COG {cog}");
        assert!((water - 65.0).abs() < 1.0, "through the water {water}");
        let (cog, _) = run(GyroMode::CourseOverGround);
        assert!(cog > 46.0, "as printed, the gyro turns the course: {cog}");
    }

    #[test]
    fn missing_sensors_are_normal_and_bad_values_are_refused() {
        let mut f = filter();
        f.predict(1.0).unwrap();
        assert_eq!(f.update(&NavFix::default()).unwrap(), 0);
        let before = f.state().clone_owned();
        let bad = NavFix {
            gps_position_m: Some([f64::NAN, 0.0]),
            ..NavFix::default()
        };
        assert!(f.update(&bad).is_err());
        assert_eq!(*f.state(), before);
        assert!(f.predict(0.0).is_err() && f.predict(f64::INFINITY).is_err());
    }
}
