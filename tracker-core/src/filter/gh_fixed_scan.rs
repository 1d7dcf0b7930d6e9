//! The g-h-k-l engine specialised for scans at a fixed interval: the form the track table
//! runs for the α-β, α-β-γ and α-β-γ-η filters with constant gains.
//!
//! [`GhFilter`] predicts when a scan's plots arrive and updates when its assignments do, and
//! on every call checks whether the interval changed and whether the gains follow a schedule.
//! A radar's scans come at one interval, and the track table closes every track at the end
//! of a scan. So [`FixedScanGh`] closes a scan (an update, or a coast on a scan without a
//! plot) and predicts the next scan's position at the same interval in the same pass. When
//! the next scan comes that interval later, its prediction is already made: the caller
//! compares the interval once for all its filters (the track table does, once a scan) and
//! calls [`FixedScanGh::predict`] only when it changed. Its gains are constant, checked once
//! when it is built ([`FixedScanGh::from_filter`]); the least-squares schedules stay with
//! [`GhFilter`].
//!
//! Its arithmetic is [`GhFilter`]'s, operation for operation (the same binomial shift and
//! derivative rescale, the same update), only done at other times, so its estimates and
//! predictions are [`GhFilter`]'s bit for bit (tested, f32, f64 and fixed point). It keeps
//! no innovation: nothing downstream of the track table reads one.
//!
//! ## The calls, against [`GhFilter`]'s
//!
//! | here | [`GhFilter`] |
//! |---|---|
//! | `start(z)`: state z, `prediction()` z | `start(z)` |
//! | `predict(dt)`: the position `dt` past the state; skippable when `dt == interval()` right after `update`, `coast` or `predict(interval())` | `predict(dt)` |
//! | `update(z)` | `update(z)` after `predict` |
//! | `coast()` | nothing (the next `predict` goes on from the prediction) |
//! | `update_in_place(z)` | `update(z)` without `predict` |
//!
//! A scan that is predicted must be closed (`update` or `coast`) before the next `predict`.

use super::gh::{rescale_derivatives, shifted, GhFilter};
use super::{Estimate, Interval, Measurement, Vec2};
use crate::scalar::Scalar;

/// A constant-gain g-h filter of order `N` (2: α-β, 3: α-β-γ, 4: α-β-γ-η) that predicts the
/// next scan as it closes one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedScanGh<S: Scalar, const N: usize> {
    gains: [S::Gain; N],
    /// Per axis (east, north): `[x, v·T, a·T²/2, j·T³/6][..N]` at the last scan closed (the
    /// estimate after an update, the prediction after a coast) or at the start.
    q: [[S; N]; 2],
    /// The interval `q`'s derivatives are scaled to, and the one `prediction` was made for
    /// after a close; zero until the first prediction.
    scan_s: S,
    /// The position the next update or coast takes as the prior: `scan_s` past `q` after a
    /// close, `dt` past it after `predict(dt)`, `q`'s own position after `start`.
    prediction: Vec2<S>,
}

/// The α-β filter as the track table runs it.
pub type FixedScanAlphaBeta<S> = FixedScanGh<S, 2>;
/// The α-β-γ filter as the track table runs it.
pub type FixedScanAlphaBetaGamma<S> = FixedScanGh<S, 3>;
/// The α-β-γ-η filter as the track table runs it.
pub type FixedScanAlphaBetaGammaEta<S> = FixedScanGh<S, 4>;

impl<S: Scalar, const N: usize> FixedScanGh<S, N> {
    /// A filter with constant gains `[g, h, k, l][..N]`, waiting for its first measurement.
    pub fn new(gains: [S::Gain; N]) -> Self {
        FixedScanGh {
            gains,
            q: [[S::ZERO; N]; 2],
            scan_s: S::ZERO,
            prediction: [S::ZERO; 2],
        }
    }

    /// The fixed-scan form of a general filter's design: `None` when its gains follow a
    /// schedule (they change every scan; the general filter runs those).
    pub fn from_filter(filter: &GhFilter<S, N>) -> Option<Self> {
        filter.constant_gains().map(Self::new)
    }

    /// The gains.
    pub fn gains(&self) -> [S::Gain; N] {
        self.gains
    }

    /// The interval the derivatives are scaled to, s; after `update` or `coast`, the one
    /// [`FixedScanGh::prediction`] is made for. Zero before the first prediction.
    pub fn interval(&self) -> S {
        self.scan_s
    }

    /// (Re)starts on a first measurement: position `z`, every derivative zero. Keeps the
    /// interval (the derivatives it scales are zero).
    pub fn start(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        self.q = [[S::ZERO; N]; 2];
        for (q, zi) in self.q.iter_mut().zip(z) {
            q[0] = zi;
        }
        self.prediction = z;
    }

    /// Predicts the position `dt` past the state, rescaling the derivatives first when `dt`
    /// is not [`FixedScanGh::interval`]; returns it. Right after `update` or `coast` with
    /// `dt == interval()` it recomputes the prediction already held, which is why callers
    /// may skip it then.
    #[inline]
    pub fn predict(&mut self, dt: Interval<S>) -> Vec2<S> {
        let dt = dt.seconds();
        if dt != self.scan_s {
            rescale_derivatives(&mut self.q, self.scan_s, dt);
            self.scan_s = dt;
        }
        for (p, q) in self.prediction.iter_mut().zip(&self.q) {
            *p = shifted(q)[0];
        }
        self.prediction
    }

    /// Closes a scan with a measured position: the update from the prediction, then the
    /// next scan's prediction at [`FixedScanGh::interval`].
    #[inline]
    pub fn update(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        let gains = self.gains;
        for ((q, p), zi) in self.q.iter_mut().zip(&mut self.prediction).zip(z) {
            // The prior: the held position, the derivatives shifted now (the position row
            // of the shift is dead code, dropped by the optimiser).
            let mut prior = shifted(q);
            prior[0] = *p;
            let e = zi.minus(*p);
            for ((qi, prior_i), &g) in q.iter_mut().zip(prior).zip(&gains) {
                *qi = prior_i.add_scaled(e, g);
            }
            *p = shifted(q)[0];
        }
    }

    /// Updates the state itself with a measured position, no prediction between, then
    /// predicts the next scan: [`GhFilter`]'s `update` without its `predict` (for a scan its
    /// caller could not predict the filter for).
    pub fn update_in_place(&mut self, z: Measurement<S>) {
        let z = z.position_m();
        let gains = self.gains;
        for ((q, p), zi) in self.q.iter_mut().zip(&mut self.prediction).zip(z) {
            let e = zi.minus(q[0]);
            for (qi, &g) in q.iter_mut().zip(&gains) {
                *qi = qi.add_scaled(e, g);
            }
            *p = shifted(q)[0];
        }
    }

    /// Closes a scan without a plot: the prediction becomes the state (as [`GhFilter`]'s
    /// state after its predict), then the next scan's prediction.
    #[inline]
    pub fn coast(&mut self) {
        for (q, p) in self.q.iter_mut().zip(&mut self.prediction) {
            let mut prior = shifted(q);
            prior[0] = *p;
            *q = prior;
            *p = shifted(q)[0];
        }
    }

    /// Position and velocity at the last scan closed.
    pub fn estimate(&self) -> Estimate<S> {
        super::gh::estimate_of(&self.q, self.scan_s)
    }

    /// The position the next update or coast takes as its prior.
    pub fn prediction(&self) -> Vec2<S> {
        self.prediction
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::alpha_beta::AlphaBetaGains;
    use crate::filter::alpha_beta_gamma::AbgGains;
    use crate::filter::alpha_beta_gamma_eta::AbgeGains;
    use crate::filter::testing::Noise;
    use crate::filter::Filter;
    use crate::scalar::Fix;

    /// What happens to a track in one scan.
    #[derive(Clone, Copy, Debug)]
    enum Step {
        /// A scan `dt` after the last, with a plot at `z` or none.
        Scan { dt: f64, z: Option<[f64; 2]> },
        /// A scan predicted and never closed (its assignments never came).
        Abandoned { dt: f64 },
        /// The track restarted on a plot.
        Restart([f64; 2]),
    }

    /// A target at 12 km moving at 7 m/s and turning, seen with 20 m noise; scans mostly
    /// 2.5 s apart, sometimes 2.4 or 3.1 s, one in six without a plot, one in fifty
    /// abandoned, one restart.
    fn steps(seed: u64, n: usize) -> std::vec::Vec<Step> {
        let mut noise = Noise::new(seed);
        let mut t = 0.0;
        (0..n)
            .map(|k| {
                let dt = match k % 23 {
                    7 => 2.4,
                    15 => 3.1,
                    _ => 2.5,
                };
                t += dt;
                let truth = [12_000.0 + 7.0 * t, -3_000.0 + 0.002 * t * t];
                let z = [truth[0] + noise.gauss(20.0), truth[1] + noise.gauss(20.0)];
                match k {
                    k if k == n / 2 => Step::Restart(z),
                    k if k % 50 == 49 => Step::Abandoned { dt },
                    k if k % 6 == 5 => Step::Scan { dt, z: None },
                    _ => Step::Scan { dt, z: Some(z) },
                }
            })
            .collect()
    }

    /// Runs the general filter and the fixed-scan form through `steps`, the fixed-scan one
    /// the way the track table drives it: `predict` skipped while the interval repeats and
    /// the prediction held is one made for it (after a close, or a start followed by
    /// `predict` at the last interval, as the table does for a new track). Asserts every
    /// prediction and estimate is the same bit for bit; returns how many predicts ran.
    fn same_bits<S: Scalar, const N: usize>(general: GhFilter<S, N>, steps: &[Step]) -> usize {
        let bits = |v: S| v.to_f64().to_bits();
        let same = |a: Vec2<S>, b: Vec2<S>| a.map(bits) == b.map(bits);
        let m = |z: [f64; 2]| Measurement::new(z.map(S::of)).unwrap();
        let mut g = general;
        let mut f = FixedScanGh::from_filter(&g).unwrap();
        let first = m([12_000.0, -3_000.0]);
        g.start(first);
        f.start(first);
        // Whether `f.prediction()` is the one for `f.interval()` past its state.
        let mut held = false;
        let mut predicted = 0;
        for (k, step) in steps.iter().enumerate() {
            let (dt, z, abandoned) = match *step {
                Step::Restart(z) => {
                    g.start(m(z));
                    f.start(m(z));
                    // The table predicts a new track at the last interval straight away.
                    held = f.interval() > S::ZERO;
                    if held {
                        f.predict(Interval::new(f.interval()).unwrap());
                    }
                    continue;
                }
                Step::Scan { dt, z } => (dt, z, false),
                Step::Abandoned { dt } => (dt, None, true),
            };
            let dt = Interval::new(S::of(dt)).unwrap();
            let pg = g.predict(dt);
            let pf = if held && dt.seconds() == f.interval() {
                f.prediction()
            } else {
                predicted += 1;
                f.predict(dt)
            };
            assert!(same(pg, pf), "step {k}: prediction {pg:?} vs {pf:?}");
            match z {
                Some(z) if !abandoned => {
                    g.update(m(z));
                    f.update(m(z));
                }
                // Without a plot, or never closed: the general filter's next predict goes
                // on from this one; the fixed-scan form coasts to get there.
                _ => f.coast(),
            }
            held = true;
            let (eg, ef) = (g.estimate(), f.estimate());
            assert!(
                same(eg.position_m, ef.position_m) && same(eg.velocity_mps, ef.velocity_mps),
                "step {k}: {eg:?} vs {ef:?}"
            );
        }
        predicted
    }

    #[test]
    fn the_fixed_scan_form_is_the_general_filter_bit_for_bit() {
        let s = steps(11, 600);
        let ab = AlphaBetaGains::BenedictBordner { alpha: 0.5 };
        let abg = AbgGains::FadingMemory { xi: 0.6 };
        let abge = AbgeGains::FadingMemory { xi: 0.7 };
        let mut predicted = 0;
        predicted += same_bits(ab.build::<f32>().unwrap(), &s);
        predicted += same_bits(ab.build::<f64>().unwrap(), &s);
        predicted += same_bits(ab.build::<Fix>().unwrap(), &s);
        predicted += same_bits(abg.build::<f32>().unwrap(), &s);
        predicted += same_bits(abg.build::<f64>().unwrap(), &s);
        predicted += same_bits(abg.build::<Fix>().unwrap(), &s);
        predicted += same_bits(abge.build::<f32>().unwrap(), &s);
        predicted += same_bits(abge.build::<Fix>().unwrap(), &s);
        // The skip was taken on most scans and the re-prediction on the rest: both paths ran.
        assert!(predicted > 8 * 40 && predicted < 8 * 300, "{predicted}");
    }

    #[test]
    fn schedules_stay_with_the_general_filter() {
        let ls = AlphaBetaGains::LeastSquares.build::<f32>().unwrap();
        assert!(FixedScanGh::from_filter(&ls).is_none());
        let fixed = AlphaBetaGains::FadingMemory { xi: 0.8 }
            .build::<f32>()
            .unwrap();
        let f = FixedScanGh::from_filter(&fixed).unwrap();
        assert_eq!(f.gains(), fixed.gains());
        assert_eq!(f.interval(), 0.0);
    }
}
