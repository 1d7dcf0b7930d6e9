//! Constant-acceleration Kalman filter: per axis state (position, velocity, acceleration).
//!
//! One 3×3 covariance serves both axes (see [`super`]); the algebra is nalgebra's
//! statically sized matrices, no heap.

use nalgebra::{Matrix3, Vector3};

use super::{KalmanConfig, QModel};
use crate::filter::{Estimate, Filter, FilterError, Interval, Measurement, Vec2};
use crate::scalar::Real;

/// The constant-acceleration Kalman filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanCa<S: Real> {
    q: S,
    q_model: QModel,
    r: S,
    p0_derivative: S,
    /// Per axis: [position, velocity, acceleration].
    x: [Vector3<S>; 2],
    /// The covariance each axis shares.
    p: Matrix3<S>,
    prediction: Vec2<S>,
    innovation: Vec2<S>,
}

impl KalmanConfig {
    /// A constant-acceleration filter in `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`KalmanConfig::validate`].
    pub fn build_ca<S: Real>(&self) -> Result<KalmanCa<S>, FilterError> {
        self.validate()?;
        let mut f = KalmanCa {
            q: S::of(self.q),
            q_model: self.q_model,
            r: S::of(self.r),
            p0_derivative: S::of(self.p0_derivative),
            x: [Vector3::zeros(); 2],
            p: Matrix3::zeros(),
            prediction: [S::ZERO; 2],
            innovation: [S::ZERO; 2],
        };
        f.p = f.initial_covariance();
        Ok(f)
    }
}

impl<S: Real> KalmanCa<S> {
    fn initial_covariance(&self) -> Matrix3<S> {
        Matrix3::from_diagonal(&Vector3::new(
            self.r,
            self.p0_derivative,
            self.p0_derivative,
        ))
    }

    /// The covariance of each axis.
    pub fn covariance(&self) -> Matrix3<S> {
        self.p
    }

    /// The measurement noise variance per axis, m².
    pub fn measurement_variance(&self) -> S {
        self.r
    }

    /// Acceleration `[east, north]`, m/s².
    pub fn acceleration(&self) -> Vec2<S> {
        [self.x[0][2], self.x[1][2]]
    }

    fn process_noise(&self, dt: S) -> Matrix3<S> {
        let c = |v: f64| S::of(v);
        let (t, t2) = (dt, dt * dt);
        let (t3, t4) = (t2 * t, t2 * t2);
        let q = self.q;
        match self.q_model {
            QModel::Identity => Matrix3::identity() * q,
            QModel::Discrete => {
                let g = Vector3::new(t2 * c(0.5), t, c(1.0));
                g * g.transpose() * q
            }
            QModel::Continuous => {
                Matrix3::new(
                    t4 * t * c(1.0 / 20.0),
                    t4 * c(1.0 / 8.0),
                    t3 * c(1.0 / 6.0),
                    t4 * c(1.0 / 8.0),
                    t3 * c(1.0 / 3.0),
                    t2 * c(0.5),
                    t3 * c(1.0 / 6.0),
                    t2 * c(0.5),
                    t,
                ) * q
            }
        }
    }
}

impl<S: Real> Filter<S> for KalmanCa<S> {
    fn start(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        self.x = [
            Vector3::new(z[0], S::ZERO, S::ZERO),
            Vector3::new(z[1], S::ZERO, S::ZERO),
        ];
        self.p = self.initial_covariance();
        self.prediction = z;
        self.innovation = [S::ZERO; 2];
    }

    #[inline]
    fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let dt = dt.seconds();
        let zero = S::ZERO;
        let one = S::of(1.0);
        let f = Matrix3::new(
            one,
            dt,
            dt * dt * S::of(0.5),
            zero,
            one,
            dt,
            zero,
            zero,
            one,
        );
        for x in &mut self.x {
            *x = f * *x;
        }
        self.p = f * self.p * f.transpose() + self.process_noise(dt);
        self.prediction = [self.x[0][0], self.x[1][0]];
        self.prediction
    }

    #[inline]
    fn update(&mut self, z: Measurement<S>) -> Vec2<S> {
        let z = z.position_m();
        let s = self.p[(0, 0)] + self.r;
        let k: Vector3<S> = self.p.column(0) / s;
        for (axis, x) in self.x.iter_mut().enumerate() {
            let e = z[axis] - x[0];
            self.innovation[axis] = e;
            *x += k * e;
        }
        // Joseph form with H = [1, 0, 0]; 1 − k0 as r/s, without the cancellation of
        // 1 − (almost 1) when the prediction is far less certain than the plot.
        let mut ikh = Matrix3::identity();
        ikh.set_column(0, &Vector3::new(self.r / s, -k[1], -k[2]));
        self.p = ikh * self.p * ikh.transpose() + k * k.transpose() * self.r;
        self.innovation
    }

    fn estimate(&self) -> Estimate<S> {
        Estimate {
            position_m: [self.x[0][0], self.x[1][0]],
            velocity_mps: [self.x[0][1], self.x[1][1]],
        }
    }

    fn prediction(&self) -> Vec2<S> {
        self.prediction
    }

    fn innovation(&self) -> Vec2<S> {
        self.innovation
    }

    fn innovation_covariance(&self) -> Option<[S; 3]> {
        let s = self.p[(0, 0)] + self.r;
        Some([s, S::ZERO, s])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::testing::{polynomial, run, Noise};
    use nalgebra::{SMatrix, SVector};

    #[test]
    fn matches_the_dense_six_state_filter() {
        let cfg = KalmanConfig::new(0.01, QModel::Continuous, 100.0);
        let mut noise = Noise::new(9);
        let samples: std::vec::Vec<_> =
            polynomial(&[0.0, 5.0, 0.02], &[100.0, -3.0, 0.0], 200, 3.0)
                .into_iter()
                .map(|(t, z)| (t, [z[0] + noise.gauss(10.0), z[1] + noise.gauss(10.0)]))
                .collect();
        let est = run(&mut cfg.build_ca::<f64>().unwrap(), &samples);
        // Dense 6-state (x, vx, ax, y, vy, ay).
        let mut x = SVector::<f64, 6>::zeros();
        x[0] = samples[0].1[0];
        x[3] = samples[0].1[1];
        let mut p = SMatrix::<f64, 6, 6>::from_diagonal(&SVector::<f64, 6>::from_column_slice(&[
            100.0, 1e4, 1e4, 100.0, 1e4, 1e4,
        ]));
        let mut h = SMatrix::<f64, 2, 6>::zeros();
        h[(0, 0)] = 1.0;
        h[(1, 3)] = 1.0;
        let r = nalgebra::Matrix2::identity() * 100.0;
        for i in 1..samples.len() {
            let t = samples[i].0 - samples[i - 1].0;
            let f1 = Matrix3::new(1.0, t, t * t / 2.0, 0.0, 1.0, t, 0.0, 0.0, 1.0);
            let q1 = Matrix3::new(
                t.powi(5) / 20.0,
                t.powi(4) / 8.0,
                t.powi(3) / 6.0,
                t.powi(4) / 8.0,
                t.powi(3) / 3.0,
                t * t / 2.0,
                t.powi(3) / 6.0,
                t * t / 2.0,
                t,
            ) * 0.01;
            let mut f = SMatrix::<f64, 6, 6>::zeros();
            let mut q = SMatrix::<f64, 6, 6>::zeros();
            for b in [0, 3] {
                f.fixed_view_mut::<3, 3>(b, b).copy_from(&f1);
                q.fixed_view_mut::<3, 3>(b, b).copy_from(&q1);
            }
            x = f * x;
            p = f * p * f.transpose() + q;
            let s = h * p * h.transpose() + r;
            let k = p * h.transpose() * s.try_inverse().unwrap();
            x += k * (nalgebra::Vector2::new(samples[i].1[0], samples[i].1[1]) - h * x);
            let ikh = SMatrix::<f64, 6, 6>::identity() - k * h;
            p = ikh * p * ikh.transpose() + k * r * k.transpose();
            let e = est[i];
            let err = (e.position_m[0] - x[0]).abs()
                + (e.velocity_mps[0] - x[1]).abs()
                + (e.position_m[1] - x[3]).abs()
                + (e.velocity_mps[1] - x[4]).abs();
            assert!(err < 1e-7, "step {i}: {err}");
        }
    }

    #[test]
    fn no_steady_state_error_on_constant_acceleration() {
        let samples = polynomial(&[0.0, 2.0, 0.05], &[0.0, 0.0, -0.02], 400, 2.0);
        let mut f = KalmanConfig::new(1e-6, QModel::Discrete, 25.0)
            .build_ca::<f64>()
            .unwrap();
        let est = run(&mut f, &samples);
        let t = samples[399].0;
        assert!((est[399].velocity_mps[0] - (2.0 + 0.1 * t)).abs() < 1e-3);
        assert!((f.acceleration()[1] + 0.04).abs() < 1e-4);
    }
}
