//! Switched slide-window tracker, SSWT (thesis `002`, §2.3.1, eq. 2-14, Table 2-6,
//! Fig. 2-9).
//!
//! The thesis's own proposal for non-linear targets: run an α-β filter for the first
//! M + 1 scans, then switch to a slide-window predictor that extrapolates the straight
//! line through the last M *filtered* positions one scan ahead,
//! `x_p(k+1) = Σ w_m·x_F(k−M+m)`, and filters with `x_F = x_p + a·(x_m − x_p)`, a = α.
//!
//! ## The weights
//!
//! The weights are the least-squares straight-line extrapolation one scan ahead over M
//! equally spaced points: `w_m = 1/M + 6(m − (M+1)/2) / (M(M − 1))`, m = 1..M (oldest
//! first). This reproduces Table 2-6 for M = 2 (−1, 2), 3 (−2/3, 1/3, 4/3) and
//! 4 (−0.5, 0, 0.5, 1). The table's M = 5 row (−0.35, −0.2, 0.25, 0.5, 0.8) is not the
//! least-squares line (which gives −0.4, −0.1, 0.2, 0.5, 0.8). The printed row still
//! extrapolates a straight line exactly (Σ w_m = 1, Σ w_m·m = 6) but passes more noise:
//! its noise gain Σ w_m² is 1.115 against the least-squares minimum of 1.100. We use the
//! least-squares weights; [`TABLE_2_6_M5`] keeps the printed row for reproduction.
//!
//! ## Uneven scan intervals
//!
//! The window stores each filtered position with its time, and the prediction is the
//! least-squares line through those (time, position) pairs evaluated at the prediction
//! time. With equal intervals that is exactly the weights above; with uneven ones it is
//! still the best straight line, where fixed weights would bend it. The velocity estimate
//! is that line's slope.
//!
//! Equal intervals are the common case and take a fast path: the weights above (and the
//! slope's, per scan) are constants of M, computed once, applied to the positions relative
//! to the newest (so every weight is below 1 in magnitude and fits the fixed-point gain
//! format). The general fit runs only when the window holds uneven intervals.

use super::alpha_beta::{AlphaBeta, AlphaBetaGains};
use super::{Estimate, Filter, FilterError, Interval, Measurement, Vec2};
use crate::scalar::Scalar;

/// Longest window supported.
pub const MAX_WINDOW: usize = 8;

/// Table 2-6's printed M = 5 weights (not least squares; see the module docs).
pub const TABLE_2_6_M5: [f64; 5] = [-0.35, -0.2, 0.25, 0.5, 0.8];

/// Least-squares one-step extrapolation weights for `m` equally spaced points, oldest
/// first; `out` must hold `m` values.
pub fn uniform_weights(m: usize, out: &mut [f64]) {
    let mf = m as f64;
    for (i, w) in out.iter_mut().take(m).enumerate() {
        let idx = (i + 1) as f64;
        *w = 1.0 / mf + 6.0 * (idx - (mf + 1.0) / 2.0) / (mf * (mf - 1.0));
    }
}

/// SSWT parameters.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SswtConfig {
    /// Window size M, 2..=[`MAX_WINDOW`].
    pub window: usize,
    /// The α-β filter of the first M + 1 scans; its α is also the slide-window filter's a.
    pub start: AlphaBetaGains,
}

impl SswtConfig {
    /// A tracker with this configuration in scalar `S`.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] for a window outside 2..=[`MAX_WINDOW`] or a start filter out of range.
    pub fn build<S: Scalar>(&self) -> Result<Sswt<S>, FilterError> {
        if !(2..=MAX_WINDOW).contains(&self.window) {
            return Err(FilterError::BadParameter);
        }
        let alpha = match self.start.constant() {
            Some([a, _]) => a,
            // The least-squares schedule has no single α for the window phase: use its
            // value at the switch (k = M + 1).
            None => {
                let k = (self.window + 1) as f64;
                2.0 * (2.0 * k - 1.0) / (k * (k + 1.0))
            }
        };
        // Weights of (x_i − x_newest), i = 1..M−1 oldest first: one-step prediction and
        // slope per scan, for equal intervals.
        let m = self.window as f64;
        let mut w_predict = [S::gain_from_f64(0.0); MAX_WINDOW];
        let mut w_slope = [S::gain_from_f64(0.0); MAX_WINDOW];
        for i in 0..self.window - 1 {
            let centred = (i + 1) as f64 - (m + 1.0) / 2.0;
            w_predict[i] = S::gain_from_f64(1.0 / m + 6.0 * centred / (m * (m - 1.0)));
            w_slope[i] = S::gain_from_f64(12.0 * centred / (m * (m * m - 1.0)));
        }
        Ok(Sswt {
            window: self.window,
            a: S::gain_from_f64(alpha),
            w_predict,
            w_slope,
            run: 0,
            run_s: S::ZERO,
            start: self.start.build()?,
            times: [S::ZERO; MAX_WINDOW],
            positions: [[S::ZERO; 2]; MAX_WINDOW],
            len: 0,
            pending_s: S::ZERO,
            prediction: [S::ZERO; 2],
            innovation: [S::ZERO; 2],
            velocity: [S::ZERO; 2],
            velocity_per_s: S::ZERO,
            measurements: 0,
        })
    }
}

/// The switched slide-window tracker.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sswt<S: Scalar> {
    window: usize,
    a: S::Gain,
    /// Equal-interval weights of (x_i − x_newest) for the one-step prediction.
    w_predict: [S::Gain; MAX_WINDOW],
    /// Equal-interval weights of (x_i − x_newest) for the slope, per scan.
    w_slope: [S::Gain; MAX_WINDOW],
    /// Equal intervals in a row ending at the newest entry, and their length.
    run: usize,
    run_s: S,
    start: AlphaBeta<S>,
    /// Times of the window's filtered positions relative to the newest (≤ 0), oldest first.
    times: [S; MAX_WINDOW],
    /// The window's filtered positions, oldest first.
    positions: [Vec2<S>; MAX_WINDOW],
    len: usize,
    /// Time from the newest window entry to the prediction.
    pending_s: S,
    prediction: Vec2<S>,
    innovation: Vec2<S>,
    /// Velocity as a displacement over `velocity_per_s` seconds (divided out on demand, so
    /// the hot path has no division).
    velocity: Vec2<S>,
    velocity_per_s: S,
    measurements: u32,
}

impl<S: Scalar> Sswt<S> {
    /// True once the α-β start (M + 1 measurements) is over and the slide window predicts.
    pub fn in_window_phase(&self) -> bool {
        self.measurements as usize > self.window
    }

    /// The newest filtered position.
    fn newest(&self) -> Vec2<S> {
        let i = self.len.saturating_sub(1);
        self.positions.get(i).copied().unwrap_or([S::ZERO; 2])
    }

    /// True when the window is full and its intervals, and the next one, all equal `dt`.
    fn uniform(&self, dt: S) -> bool {
        self.len == self.window && self.run + 1 >= self.window && dt == self.run_s
    }

    /// Σ w_i·(x_i − x_newest) over the window, per axis.
    fn weighted(&self, w: &[S::Gain; MAX_WINDOW]) -> Vec2<S> {
        let mut out = [S::ZERO; 2];
        let Some((newest, older)) = self
            .positions
            .get(..self.window)
            .and_then(<[_]>::split_last)
        else {
            return out;
        };
        for (p, &wi) in older.iter().zip(w) {
            for axis in 0..2 {
                out[axis] = out[axis].add_scaled(p[axis].minus(newest[axis]), wi);
            }
        }
        out
    }

    fn push(&mut self, dt: S, z: Vec2<S>) {
        if self.len > 0 {
            if dt == self.run_s {
                self.run = (self.run + 1).min(MAX_WINDOW);
            } else {
                self.run = 1;
                self.run_s = dt;
            }
        }
        // Checked slicing throughout: the firmware must have no reachable panic.
        let mut n = self.len.min(self.window).min(MAX_WINDOW);
        if n == self.window && n >= 1 {
            // Drop the oldest: shift left by one, element by element (no slice method
            // with a length assertion left on the path).
            for i in 1..n {
                if let (Some(&t), Some(&p)) = (self.times.get(i), self.positions.get(i)) {
                    if let (Some(dt), Some(dp)) =
                        (self.times.get_mut(i - 1), self.positions.get_mut(i - 1))
                    {
                        *dt = t;
                        *dp = p;
                    }
                }
            }
            n -= 1;
        }
        for t in self.times.iter_mut().take(n) {
            *t = t.minus(dt);
        }
        if let (Some(t), Some(p)) = (self.times.get_mut(n), self.positions.get_mut(n)) {
            *t = S::ZERO;
            *p = z;
            self.len = n + 1;
        }
    }

    /// Least-squares line through the window: (value at `at`, slope) per axis.
    fn line_at(&self, at: S) -> (Vec2<S>, Vec2<S>) {
        let n = self.len.min(MAX_WINDOW);
        let count = S::of(n.max(1) as f64);
        let times = self.times.get(..n).unwrap_or(&[]);
        let positions = self.positions.get(..n).unwrap_or(&[]);
        let mut t_mean = S::ZERO;
        for &t in times {
            t_mean = t_mean.plus(t);
        }
        let t_mean = t_mean.div(count);
        let mut stt = S::ZERO;
        for &t in times {
            let d = t.minus(t_mean);
            stt = stt.plus(d.mul(d));
        }
        let mut value = [S::ZERO; 2];
        let mut slope = [S::ZERO; 2];
        for axis in 0..2 {
            let mut mean = S::ZERO;
            for p in positions {
                mean = mean.plus(p[axis]);
            }
            let mean = mean.div(count);
            let mut s = S::ZERO;
            if stt > S::ZERO {
                for (p, &t) in positions.iter().zip(times) {
                    s = s.plus(p[axis].minus(mean).rescale(t.minus(t_mean), stt));
                }
            }
            slope[axis] = s;
            value[axis] = mean.plus(s.mul(at.minus(t_mean)));
        }
        (value, slope)
    }
}

impl<S: Scalar> Filter<S> for Sswt<S> {
    fn start(&mut self, z: Measurement<S>) {
        self.start.start(z);
        let z = z.position_m();
        self.len = 0;
        self.run = 0;
        self.push(S::ZERO, z);
        self.pending_s = S::ZERO;
        self.prediction = z;
        self.innovation = [S::ZERO; 2];
        self.velocity = [S::ZERO; 2];
        self.velocity_per_s = S::of(1.0);
        self.measurements = 1;
    }

    fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let ahead = self.pending_s.plus(dt.seconds());
        if self.in_window_phase() {
            self.prediction = if self.pending_s == S::ZERO && self.uniform(dt.seconds()) {
                let newest = self.newest();
                let step = self.weighted(&self.w_predict);
                [newest[0].plus(step[0]), newest[1].plus(step[1])]
            } else {
                self.line_at(ahead).0
            };
        } else {
            self.prediction = self.start.predict(dt);
        }
        self.pending_s = ahead;
        self.prediction
    }

    fn update(&mut self, measurement: Measurement<S>) -> Vec2<S> {
        let z = measurement.position_m();
        let filtered = if self.in_window_phase() {
            let mut f = self.prediction;
            for axis in 0..2 {
                self.innovation[axis] = z[axis].minus(self.prediction[axis]);
                f[axis] = self.prediction[axis].add_scaled(self.innovation[axis], self.a);
            }
            f
        } else {
            self.innovation = self.start.update(measurement);
            self.start.estimate().position_m
        };
        self.push(self.pending_s, filtered);
        self.pending_s = S::ZERO;
        self.measurements = self.measurements.saturating_add(1);
        if !self.in_window_phase() {
            self.velocity = self.start.estimate().velocity_mps;
            self.velocity_per_s = S::of(1.0);
        } else if self.run + 1 >= self.window {
            self.velocity = self.weighted(&self.w_slope);
            self.velocity_per_s = self.run_s;
        } else {
            self.velocity = self.line_at(S::ZERO).1;
            self.velocity_per_s = S::of(1.0);
        }
        self.innovation
    }

    fn estimate(&self) -> Estimate<S> {
        Estimate {
            position_m: self.newest(),
            velocity_mps: [
                self.velocity[0].div(self.velocity_per_s),
                self.velocity[1].div(self.velocity_per_s),
            ],
        }
    }

    fn prediction(&self) -> Vec2<S> {
        self.prediction
    }

    fn innovation(&self) -> Vec2<S> {
        self.innovation
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::testing::{polynomial, run};
    use crate::scalar::Fix;

    #[test]
    fn weights_match_table_2_6_for_m_2_to_4() {
        let table: [&[f64]; 3] = [
            &[-1.0, 2.0],
            &[-2.0 / 3.0, 1.0 / 3.0, 4.0 / 3.0],
            &[-0.5, 0.0, 0.5, 1.0],
        ];
        for (m, row) in (2..=4).zip(table) {
            let mut w = [0.0; MAX_WINDOW];
            uniform_weights(m, &mut w);
            for (a, b) in w[..m].iter().zip(row) {
                assert!((a - b).abs() < 1e-12, "M={m}: {:?}", &w[..m]);
            }
        }
    }

    #[test]
    fn table_2_6_m5_row_is_not_least_squares() {
        let mut w = [0.0; 5];
        uniform_weights(5, &mut w);
        let ls = [-0.4, -0.1, 0.2, 0.5, 0.8];
        assert!(w.iter().zip(ls).all(|(a, b)| (a - b).abs() < 1e-12));
        // Both extrapolate a line exactly (Σ w = 1, Σ w·m = M + 1) ...
        let moment = |w: &[f64]| {
            w.iter()
                .enumerate()
                .map(|(i, w)| w * (i + 1) as f64)
                .sum::<f64>()
        };
        for row in [&w[..], &TABLE_2_6_M5[..]] {
            assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!((moment(row) - 6.0).abs() < 1e-12);
        }
        // ... but least squares passes the least noise.
        let noise_gain = |w: &[f64]| w.iter().map(|w| w * w).sum::<f64>();
        assert!((noise_gain(&w) - 1.100).abs() < 1e-12);
        assert!((noise_gain(&TABLE_2_6_M5) - 1.115).abs() < 1e-12);
    }

    #[test]
    fn window_prediction_uses_the_table_weights_on_even_scans() {
        // After the switch, with a = 0 the filtered points are the predictions; feed a
        // start, then check one prediction against Σ w·x by hand.
        let cfg = SswtConfig {
            window: 3,
            start: AlphaBetaGains::Fixed {
                alpha: 1.0,
                beta: 0.0,
            },
        };
        let mut f = cfg.build::<f64>().unwrap();
        let zs = [1.0, 4.0, 2.0, 7.0, 5.0];
        let m = |z: f64| Measurement::new([z, 0.0]).unwrap();
        let dt = Interval::new(2.0).unwrap();
        f.start(m(zs[0]));
        for &z in &zs[1..] {
            f.predict(dt);
            f.update(m(z));
        }
        // α = 1: the filtered positions are the measurements; the window is the last 3.
        let p = f.predict(dt);
        let expected = -2.0 / 3.0 * 2.0 + 1.0 / 3.0 * 7.0 + 4.0 / 3.0 * 5.0;
        assert!((p[0] - expected).abs() < 1e-12, "{p:?} vs {expected}");
    }

    #[test]
    fn follows_a_straight_track_exactly_even_with_uneven_scans() {
        let mut t = 0.0;
        let mut samples = std::vec::Vec::new();
        for i in 0..100 {
            samples.push((t, [100.0 + 6.0 * t, 50.0 - 2.5 * t]));
            t += [2.0, 3.0, 2.5][i % 3];
        }
        for m in 2..=5 {
            let cfg = SswtConfig {
                window: m,
                start: AlphaBetaGains::FadingMemory { xi: 0.5 },
            };
            let est = run(&mut cfg.build::<f64>().unwrap(), &samples);
            let last = est[99];
            assert!(
                (last.position_m[0] - samples[99].1[0]).abs() < 1e-6,
                "M={m}"
            );
            assert!((last.velocity_mps[1] + 2.5).abs() < 1e-6, "M={m}");
        }
    }

    #[test]
    fn fixed_and_f32_agree_with_f64() {
        let mut noise = crate::filter::testing::Noise::new(11);
        let samples: std::vec::Vec<_> = polynomial(&[-20_000.0, 9.0], &[15_000.0, -4.0], 1000, 3.0)
            .into_iter()
            .map(|(t, z)| (t, [z[0] + noise.gauss(15.0), z[1] + noise.gauss(15.0)]))
            .collect();
        let cfg = SswtConfig {
            window: 4,
            start: AlphaBetaGains::BenedictBordner { alpha: 0.5 },
        };
        let r = run(&mut cfg.build::<f64>().unwrap(), &samples);
        for (name, o, bound) in [
            ("f32", run(&mut cfg.build::<f32>().unwrap(), &samples), 0.02),
            (
                "fixed",
                run(&mut cfg.build::<Fix>().unwrap(), &samples),
                0.005,
            ),
        ] {
            let worst = o
                .iter()
                .zip(&r)
                .map(|(a, b)| (a.position_m[0] - b.position_m[0]).abs())
                .fold(0.0, f64::max);
            assert!(worst < bound, "{name}: {worst}");
        }
    }

    #[test]
    fn the_equal_interval_fast_path_is_the_general_fit() {
        let mut noise = crate::filter::testing::Noise::new(4);
        for m in 2..=MAX_WINDOW {
            let cfg = SswtConfig {
                window: m,
                start: AlphaBetaGains::FadingMemory { xi: 0.6 },
            };
            let mut f = cfg.build::<f64>().unwrap();
            let dt = Interval::new(2.5).unwrap();
            f.start(Measurement::new([0.0, 0.0]).unwrap());
            for k in 1..40 {
                let t = k as f64 * 2.5;
                f.predict(dt);
                f.update(
                    Measurement::new([7.0 * t + noise.gauss(9.0), -t + noise.gauss(9.0)]).unwrap(),
                );
                assert!(f.uniform(2.5) || k <= m, "M={m} k={k}");
                let (general, slope) = f.line_at(2.5);
                let v = f.estimate().velocity_mps;
                let fast = f.predict(dt);
                if !f.in_window_phase() {
                    f.pending_s = 0.0;
                    continue;
                }
                for axis in 0..2 {
                    assert!((fast[axis] - general[axis]).abs() < 1e-9, "M={m} k={k}");
                    if k > m + 1 {
                        assert!((v[axis] - slope[axis]).abs() < 1e-9, "M={m} k={k}");
                    }
                }
                // Undo the extra prediction: the next loop predicts again from the update.
                f.pending_s = 0.0;
            }
        }
    }

    #[test]
    fn refuses_bad_windows() {
        for m in [0, 1, MAX_WINDOW + 1] {
            let cfg = SswtConfig {
                window: m,
                start: AlphaBetaGains::LeastSquares,
            };
            assert_eq!(cfg.build::<f32>().err(), Some(FilterError::BadParameter));
        }
    }
}
