//! Constant-velocity Kalman filter: per axis state (position, velocity).
//!
//! Written out per element: one 2×2 covariance (three unique entries) serves both axes
//! (see [`super`]), so a 2-D update costs one covariance prediction, one gain, one Joseph
//! update and two state updates.

use super::{KalmanConfig, QModel};
use crate::filter::{Estimate, Filter, FilterError, Interval, Measurement, Vec2};
use crate::scalar::Real;

/// Symmetric 2×2 covariance of one axis: [[pp, pv], [pv, vv]].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cov2<S> {
    /// Position variance, m².
    pub pp: S,
    /// Position-velocity covariance, m²/s.
    pub pv: S,
    /// Velocity variance, m²/s².
    pub vv: S,
}

/// The constant-velocity Kalman filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanCv<S: Real> {
    q: S,
    q_model: QModel,
    r: S,
    p0_derivative: S,
    /// Per axis: [position, velocity].
    x: [[S; 2]; 2],
    /// The covariance each axis shares.
    p: Cov2<S>,
    prediction: Vec2<S>,
    innovation: Vec2<S>,
    gain: [S; 2],
}

impl KalmanConfig {
    /// A constant-velocity filter in `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] as [`KalmanConfig::validate`].
    pub fn build_cv<S: Real>(&self) -> Result<KalmanCv<S>, FilterError> {
        self.validate()?;
        let r = S::of(self.r);
        Ok(KalmanCv {
            q: S::of(self.q),
            q_model: self.q_model,
            r,
            p0_derivative: S::of(self.p0_derivative),
            x: [[S::ZERO; 2]; 2],
            p: Cov2 {
                pp: r,
                pv: S::ZERO,
                vv: S::of(self.p0_derivative),
            },
            prediction: [S::ZERO; 2],
            innovation: [S::ZERO; 2],
            gain: [S::ZERO; 2],
        })
    }
}

impl<S: Real> KalmanCv<S> {
    /// The covariance of each axis.
    pub fn covariance(&self) -> Cov2<S> {
        self.p
    }

    /// The gain of the last update, [position, velocity (1/s)].
    pub fn gain(&self) -> [S; 2] {
        self.gain
    }

    /// Innovation covariance of the current prediction, per axis (m²): what a gate needs.
    pub fn innovation_variance(&self) -> S {
        self.p.pp + self.r
    }

    /// Q's three entries for an interval of `dt`.
    fn process_noise(&self, dt: S) -> Cov2<S> {
        let q = self.q;
        let half = S::of(0.5);
        match self.q_model {
            QModel::Identity => Cov2 {
                pp: q,
                pv: S::ZERO,
                vv: q,
            },
            QModel::Discrete => {
                let t2 = dt * dt;
                Cov2 {
                    pp: q * t2 * t2 * S::of(0.25),
                    pv: q * t2 * dt * half,
                    vv: q * t2,
                }
            }
            QModel::Continuous => {
                let t2 = dt * dt;
                Cov2 {
                    pp: q * t2 * dt * S::of(1.0 / 3.0),
                    pv: q * t2 * half,
                    vv: q * dt,
                }
            }
        }
    }
}

impl<S: Real> Filter<S> for KalmanCv<S> {
    fn start(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        self.x = [[z[0], S::ZERO], [z[1], S::ZERO]];
        self.p = Cov2 {
            pp: self.r,
            pv: S::ZERO,
            vv: self.p0_derivative,
        };
        self.prediction = z;
        self.innovation = [S::ZERO; 2];
    }

    #[inline]
    fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let dt = dt.seconds();
        for x in &mut self.x {
            x[0] += x[1] * dt;
        }
        // P = F P Fᵀ + Q with F = [[1, T], [0, 1]].
        let q = self.process_noise(dt);
        let p = self.p;
        let pv = p.pv + dt * p.vv;
        self.p = Cov2 {
            pp: p.pp + dt * (p.pv + pv) + q.pp,
            pv: pv + q.pv,
            vv: p.vv + q.vv,
        };
        self.prediction = [self.x[0][0], self.x[1][0]];
        self.prediction
    }

    #[inline]
    fn update(&mut self, z: Measurement<S>) -> Vec2<S> {
        let z = z.position_m();
        let p = self.p;
        let s = p.pp + self.r;
        let s_inv = S::of(1.0) / s;
        let k0 = p.pp * s_inv;
        let k1 = p.pv * s_inv;
        for (axis, x) in self.x.iter_mut().enumerate() {
            let e = z[axis] - x[0];
            self.innovation[axis] = e;
            x[0] += k0 * e;
            x[1] += k1 * e;
        }
        // Joseph form, written out for H = [1, 0]:
        //   pp = (1−k0)²·pp + k0²·r
        //   pv = (1−k0)(pv − k1·pp) + k0·k1·r
        //   vv = vv − 2·k1·pv + k1²·s
        // 1 − k0 as r/s: the same number, without the cancellation of 1 − (almost 1) when
        // the prediction is far less certain than the plot.
        let m = self.r * s_inv;
        let kr = k0 * self.r;
        self.p = Cov2 {
            pp: m * m * p.pp + k0 * kr,
            pv: m * (p.pv - k1 * p.pp) + k1 * kr,
            vv: p.vv - k1 * (p.pv + p.pv - k1 * s),
        };
        self.gain = [k0, k1];
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
        let s = self.innovation_variance();
        Some([s, S::ZERO, s])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::testing::{polynomial, run, Noise};
    use nalgebra::{Matrix2x4, Matrix4, Vector2, Vector4};

    /// The textbook filter on the full 4-state (x, vx, y, vy), dense matrices, Joseph form.
    struct Dense {
        x: Vector4<f64>,
        p: Matrix4<f64>,
        cfg: KalmanConfig,
    }

    impl Dense {
        fn new(cfg: KalmanConfig, z: [f64; 2]) -> Self {
            Dense {
                x: Vector4::new(z[0], 0.0, z[1], 0.0),
                p: Matrix4::from_diagonal(&Vector4::new(
                    cfg.r,
                    cfg.p0_derivative,
                    cfg.r,
                    cfg.p0_derivative,
                )),
                cfg,
            }
        }
        fn step(&mut self, dt: f64, z: [f64; 2]) {
            let f1 = nalgebra::Matrix2::new(1.0, dt, 0.0, 1.0);
            let q = self.cfg.q;
            let q1 = match self.cfg.q_model {
                QModel::Identity => nalgebra::Matrix2::identity() * q,
                QModel::Discrete => {
                    nalgebra::Matrix2::new(
                        dt.powi(4) / 4.0,
                        dt.powi(3) / 2.0,
                        dt.powi(3) / 2.0,
                        dt * dt,
                    ) * q
                }
                QModel::Continuous => {
                    nalgebra::Matrix2::new(dt.powi(3) / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt) * q
                }
            };
            let mut f = Matrix4::zeros();
            let mut qm = Matrix4::zeros();
            f.fixed_view_mut::<2, 2>(0, 0).copy_from(&f1);
            f.fixed_view_mut::<2, 2>(2, 2).copy_from(&f1);
            qm.fixed_view_mut::<2, 2>(0, 0).copy_from(&q1);
            qm.fixed_view_mut::<2, 2>(2, 2).copy_from(&q1);
            let h = Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
            let r = nalgebra::Matrix2::identity() * self.cfg.r;
            self.x = f * self.x;
            self.p = f * self.p * f.transpose() + qm;
            let s = h * self.p * h.transpose() + r;
            let k = self.p * h.transpose() * s.try_inverse().unwrap();
            self.x += k * (Vector2::new(z[0], z[1]) - h * self.x);
            let ikh = Matrix4::identity() - k * h;
            self.p = ikh * self.p * ikh.transpose() + k * r * k.transpose();
        }
    }

    fn noisy_track(seed: u64, n: usize) -> std::vec::Vec<(f64, [f64; 2])> {
        let mut noise = Noise::new(seed);
        let mut t = 0.0;
        (0..n)
            .map(|i| {
                let turn = if i > n / 2 {
                    (i - n / 2) as f64 * 0.5
                } else {
                    0.0
                };
                let s = (
                    t,
                    [
                        1000.0 + 8.0 * t + noise.gauss(10.0),
                        -500.0 + 3.0 * t + turn * turn + noise.gauss(10.0),
                    ],
                );
                t += if i % 4 == 0 { 2.0 } else { 3.0 };
                s
            })
            .collect()
    }

    #[test]
    fn matches_the_dense_textbook_filter() {
        for q_model in [QModel::Identity, QModel::Discrete, QModel::Continuous] {
            let cfg = KalmanConfig::new(0.05, q_model, 100.0);
            let samples = noisy_track(5, 300);
            let est = run(&mut cfg.build_cv::<f64>().unwrap(), &samples);
            let mut dense = Dense::new(cfg, samples[0].1);
            for i in 1..samples.len() {
                dense.step(samples[i].0 - samples[i - 1].0, samples[i].1);
                let e = est[i];
                let d = dense.x;
                let err = (e.position_m[0] - d[0]).abs()
                    + (e.velocity_mps[0] - d[1]).abs()
                    + (e.position_m[1] - d[2]).abs()
                    + (e.velocity_mps[1] - d[3]).abs();
                assert!(err < 1e-8, "{q_model:?} step {i}: {err}");
            }
            let mut f = cfg.build_cv::<f64>().unwrap();
            run(&mut f, &samples);
            let p = f.covariance();
            for (a, b) in [
                (p.pp, dense.p[(0, 0)]),
                (p.pv, dense.p[(0, 1)]),
                (p.vv, dense.p[(1, 1)]),
                (p.pp, dense.p[(2, 2)]),
            ] {
                assert!(
                    (a - b).abs() < 1e-9 * b.abs().max(1.0),
                    "{q_model:?}: {a} vs {b}"
                );
            }
            assert!(dense.p[(0, 2)].abs() < 1e-12, "axes stay independent");
        }
    }

    #[test]
    fn steady_state_gain_is_kalatas_riccati_solution() {
        // DWNA: the discrete algebraic Riccati equation has Kalata's closed form in the
        // tracking index λ = σ_w·T²/σ_v.
        let (q, r, dt) = (0.04f64, 225.0f64, 2.5f64);
        let lambda = q.sqrt() * dt * dt / r.sqrt();
        let root = (lambda * lambda + 8.0 * lambda).sqrt();
        let alpha = -(lambda * lambda + 8.0 * lambda - (lambda + 4.0) * root) / 8.0;
        let beta = (lambda * lambda + 4.0 * lambda - lambda * root) / 4.0;
        let mut f = KalmanConfig::new(q, QModel::Discrete, r)
            .build_cv::<f64>()
            .unwrap();
        let origin = Measurement::new([0.0, 0.0]).unwrap();
        f.start(origin);
        for _ in 0..2000 {
            f.predict(Interval::new(dt).unwrap());
            f.update(origin);
        }
        let [k0, k1] = f.gain();
        assert!((k0 - alpha).abs() < 1e-10, "{k0} vs {alpha}");
        assert!((k1 - beta / dt).abs() < 1e-10, "{k1} vs {}", beta / dt);
    }

    #[test]
    fn no_steady_state_error_on_constant_velocity() {
        let samples = polynomial(&[300.0, -12.0], &[0.0, 4.0], 300, 3.0);
        let est = run(
            &mut KalmanConfig::new(0.01, QModel::Continuous, 50.0)
                .build_cv::<f32>()
                .unwrap(),
            &samples,
        );
        assert!((est[299].velocity_mps[0] + 12.0).abs() < 1e-3);
        assert!((est[299].position_m[1] - samples[299].1[1]).abs() < 1e-2);
    }

    #[test]
    fn refuses_bad_parameters() {
        assert!(KalmanConfig::new(-1.0, QModel::Identity, 1.0)
            .build_cv::<f64>()
            .is_err());
        assert!(KalmanConfig::new(1.0, QModel::Identity, 0.0)
            .build_cv::<f64>()
            .is_err());
        assert!(KalmanConfig::new(f64::NAN, QModel::Identity, 1.0)
            .build_cv::<f64>()
            .is_err());
    }
}
