//! Whether a target stands still (moored, at anchor, a buoy): a target found so is shown
//! with no motion, its course and speed over ground 0, its CPA that of own ship passing a
//! fixed point.
//!
//! **Why.** A constant-velocity filter's velocity on a target that does not move is the
//! noise of its plots: on the Solent's moored boats (plots of 20–40 m) it showed a median
//! 0.5–1.2 kn in swinging directions, and about ten of them raised CPA alarms in a harbour;
//! on real radar captures stationary echoes' tracks showed up to 1.9 kn (issue #17,
//! docs/radar.md). A navigator reads a vector on a moored boat as a boat under way. The
//! device's filter is left alone (its velocity gates the next plots); only what is shown
//! changes.
//!
//! **The test** is Hotelling's T² on the velocity of a straight line in time fitted by least
//! squares to the plots a track took over its last [`WINDOW_S`] (at most [`MAX_PLOTS`]):
//! the test that the slope vector of a two-variate linear regression is zero (Johnson &
//! Wichern, *Applied Multivariate Statistical Analysis*, 6th ed., Pearson 2007, §7.8). With
//! n plots at times tᵢ, the fitted velocity v̂ and the residuals' 2 × 2 covariance Σ̂ (ν = n − 2
//! degrees of freedom), T² = Sₜₜ·v̂ᵀΣ̂⁻¹v̂ with Sₜₜ = Σ(tᵢ − t̄)², and for a target that stands
//! still F = (ν − 1)/(2ν)·T² is F(2, n − 3)-distributed *whatever the plots' accuracy and
//! its shape*: a radar's plot is an ellipse, its error across the beam (range × bearing
//! error) often many times its error along it, and the covariance is estimated, not assumed
//! round (pooling the axes, as a first version did, overstated the evidence across the beam).
//! F(2, m) has a closed form: P(F > x) = (1 + 2x/m)^(−m/2), so its p-quantile is
//! (m/2)·((1 − p)^(−2/m) − 1) (Abramowitz & Stegun 26.6.4 with ν₁ = 2).
//!
//! A target is found standing still when the fitted speed plus twice its standard error
//! along the worse axis is at most [`ENTER_BOUND_MPS`] (with 95–97 % confidence it is
//! slower, by Student's t with n − 2 degrees of freedom from 8 plots to 24: plots too noisy
//! to bound the speed say nothing) and either F is at most its [`ENTER_LEVEL`] quantile (the
//! velocity explains no more than chance would) or that bound is under [`DRIFT_MPS`] (a
//! motion too slow to matter, however significant), over at least [`MIN_PLOTS`] plots
//! spanning [`MIN_SPAN_S`]. It is found moving again when the fitted speed exceeds
//! [`LEAVE_SPEED_MPS`], or F its [`LEAVE_LEVEL`] quantile with the fitted speed less twice
//! its standard error over [`DRIFT_MPS`] (surely more than a drift: entering by a bound
//! under it and leaving by a fitted speed just over it made a vector come and go), or when
//! its window no longer holds enough plots (a coasting track: plots older than the window
//! are dropped every scan). The window slides one plot a scan; the two levels are its
//! hysteresis, so one plot's noise does not make a vector come and go. What it costs: a
//! target the plots cannot tell from still over a minute is shown still, up to about 3 kn
//! once found still (the leaving speed), and a ship getting under way shows its motion some
//! scans late (11–18 scans after casting off at 0.1 m/s² through 20 m plots, in the tests
//! below; on the Solent, docs/ais.md). A target shown still keeps its range from own ship
//! moored, and then raises no CPA/TCPA alarm ([`super::target::NO_RELATIVE_MOTION_MPS`]):
//! one closing on own ship at about a knot can be among them (measured, docs/ais.md).
//!
//! **Where it stands.** A target found still is also *associated* at where it stands
//! ([`StationaryTest::standing_m`], [`super::associate`]): a plot within the refined gate
//! about the mean of the window's plots is tested, and its pair cost taken, from that mean
//! instead of the device's prediction. The prediction carries the constant-velocity
//! filter's noisy velocity forward: in a moored cluster a still track drifted a few tens of
//! metres onto a neighbour's echo and took it, and the neighbour's track coasted off
//! (issues #16 and #17). The mean of n plots is known to σ/√n while the target stands
//! still. A plot outside that gate is tested from the prediction, at a higher cost, for a
//! ship casting off: it moves off the mean before the test finds it moving (11–18 scans in
//! the tests below), and a gate on the mean alone lost it (test `casting_off.rs`,
//! docs/ais.md).

use std::collections::{BTreeMap, VecDeque};

use tracker_core::geo::EastNorth;
use tracker_core::icd::{Assignment, TrackState, HIDDEN_PLOT};

/// The plots a track took over this long are tested, s.
pub const WINDOW_S: f64 = 60.0;
/// … at most this many (the newest).
pub const MAX_PLOTS: usize = 32;
/// The test says nothing with fewer plots than this …
pub const MIN_PLOTS: usize = 8;
/// … or spanning less than this, s.
pub const MIN_SPAN_S: f64 = 15.0;
/// A moving target is found still when F is at most this quantile of F(2, n − 3).
pub const ENTER_LEVEL: f64 = 0.95;
/// … and its fitted speed plus twice that speed's standard error (along the worse axis) is
/// at most this, m/s (2.9 kn): with 95–97 % confidence the target is slower.
pub const ENTER_BOUND_MPS: f64 = 1.5;
/// A motion this slow or slower is a drift, not a passage, m/s (0.5 kn): a moored boat
/// swinging, an echo's centroid wandering over its returns, a ship's own yaw left in the
/// picture. Sharp plots show it significant (on the 4G harbour capture's 2 m plots, 0.1–0.2
/// m/s with standard errors of 0.02–0.06 m/s), and a navigator reads it as standing
/// still: a target bounded under it is found still whatever F says, and one found still
/// is not found moving for a significant motion under it.
pub const DRIFT_MPS: f64 = 0.257;
/// A still target is found moving when F exceeds this quantile and its fitted speed less
/// twice its standard error exceeds [`DRIFT_MPS`] …
pub const LEAVE_LEVEL: f64 = 0.999;
/// … or its fitted speed exceeds this, m/s (2.9 kn).
pub const LEAVE_SPEED_MPS: f64 = 1.5;

/// The plots' positions are on a grid of this, m (tenths of a metre on the wire): their
/// rounding's variance, added to the residuals', keeps the test defined when every plot
/// lies on one line.
const GRID_M: f64 = 0.1;

/// The p-quantile of the F distribution with 2 and `m` degrees of freedom (see [the
/// module](self)) for `m` > 0 and 0 < `p` < 1; not a number or infinite outside them.
pub fn f2_quantile(p: f64, m: f64) -> f64 {
    (m / 2.0) * ((1.0 - p).powf(-2.0 / m) - 1.0)
}

/// A straight line in time fitted to a track's plots, and the test of its velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Plots fitted.
    pub plots: usize,
    /// Time from the first to the last, s.
    pub span_s: f64,
    /// The fitted velocity, m/s (east, north).
    pub velocity_mps: [f64; 2],
    /// The fitted velocity's standard error along the axis it is worst known on, m/s (from
    /// the residuals' covariance).
    pub velocity_sigma_mps: f64,
    /// The F statistic of Hotelling's T² for a velocity of zero (`f64::INFINITY` when the
    /// line fits exactly and the velocity is not zero).
    pub f: f64,
}

impl Fit {
    /// The line through `plots` (time s, position m); `None` with fewer than 4 plots, no
    /// spread in time, or a value not a number.
    pub fn of(plots: impl Iterator<Item = (f64, [f64; 2])> + Clone) -> Option<Fit> {
        let n = plots.clone().count();
        if n < 4 {
            return None;
        }
        let nf = n as f64;
        let (st, sx, sy) = plots.clone().fold((0.0, 0.0, 0.0), |(a, b, c), (t, p)| {
            (a + t, b + p[0], c + p[1])
        });
        let (tm, xm, ym) = (st / nf, sx / nf, sy / nf);
        let (mut stt, mut stx, mut sty) = (0.0, 0.0, 0.0);
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        let (mut t0, mut t1) = (f64::INFINITY, f64::NEG_INFINITY);
        for (t, p) in plots {
            let (dt, dx, dy) = (t - tm, p[0] - xm, p[1] - ym);
            stt += dt * dt;
            stx += dt * dx;
            sty += dt * dy;
            sxx += dx * dx;
            syy += dy * dy;
            sxy += dx * dy;
            t0 = t0.min(t);
            t1 = t1.max(t);
        }
        if !(stt > 0.0 && [stt, stx, sty, sxx, syy, sxy].iter().all(|v| v.is_finite())) {
            return None;
        }
        let v = [stx / stt, sty / stt];
        // The residuals' sums of squares and products about the line.
        let nu = nf - 2.0;
        let rounding = nu * GRID_M * GRID_M / 12.0;
        let (exx, eyy, exy) = (
            (sxx - stx * v[0]).max(0.0) + rounding,
            (syy - sty * v[1]).max(0.0) + rounding,
            sxy - stx * v[1],
        );
        let det = exx * eyy - exy * exy;
        // T² = Sₜₜ·vᵀ(E/ν)⁻¹v, E⁻¹ = [[eyy, −exy], [−exy, exx]]/det.
        let q = v[0] * v[0] * eyy - 2.0 * v[0] * v[1] * exy + v[1] * v[1] * exx;
        let f = if det > 0.0 {
            (nu - 1.0) / (2.0 * nu) * stt * nu * q / det
        } else if v != [0.0, 0.0] {
            f64::INFINITY
        } else {
            0.0
        };
        let worst = 0.5 * (exx + eyy) + (0.25 * (exx - eyy).powi(2) + exy * exy).sqrt();
        Some(Fit {
            plots: n,
            span_s: t1 - t0,
            velocity_mps: v,
            velocity_sigma_mps: (worst / nu / stt).sqrt(),
            f,
        })
    }

    /// The fitted speed, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.velocity_mps[0].hypot(self.velocity_mps[1])
    }

    /// Enough plots over enough time for the test to say anything.
    pub fn telling(&self) -> bool {
        self.plots >= MIN_PLOTS && self.span_s >= MIN_SPAN_S
    }

    /// The fitted speed plus twice its standard error, m/s: what the target is slower than
    /// with 95–97 % confidence.
    pub fn speed_bound_mps(&self) -> f64 {
        self.speed_mps() + 2.0 * self.velocity_sigma_mps
    }

    /// Found still, for a target not found still before.
    pub fn enters(&self) -> bool {
        self.telling()
            && self.speed_bound_mps() <= ENTER_BOUND_MPS
            && (self.f <= f2_quantile(ENTER_LEVEL, self.plots as f64 - 3.0)
                || self.speed_bound_mps() <= DRIFT_MPS)
    }

    /// Found moving, for a target found still before.
    pub fn leaves(&self) -> bool {
        !self.telling()
            || self.speed_mps() > LEAVE_SPEED_MPS
            || (self.f > f2_quantile(LEAVE_LEVEL, self.plots as f64 - 3.0)
                && self.speed_mps() - 2.0 * self.velocity_sigma_mps > DRIFT_MPS)
    }
}

#[derive(Clone, Debug, Default)]
struct Window {
    /// The plots the track took: time, s, and position in the local frame, m.
    plots: VecDeque<(f64, [f64; 2])>,
    /// The track's age when last reported, scans: a track of the same number reported
    /// younger is another (the device was reset and numbers its tracks again).
    age_scans: u16,
    still: bool,
}

/// Every track's plots and whether its target stands still. Memory: at most
/// [`MAX_PLOTS`] plots for each track the device holds (a track's window goes with it).
#[derive(Clone, Debug, Default)]
pub struct StationaryTest {
    windows: BTreeMap<u16, Window>,
}

impl StationaryTest {
    /// Takes a scan: the tracks the device reported, the plots each took (`assignments`,
    /// indices into `plots_m`, the scan's plots in the local frame, m) at `time_s`, s. A plot
    /// or a time that is not a number is not taken.
    pub fn observe(
        &mut self,
        time_s: f64,
        tracks: &[TrackState],
        assignments: &[Assignment],
        plots_m: &[EastNorth],
    ) {
        // A track reported lost keeps its window this scan (its last report is shown with
        // the motion it was shown with); gone from the report, it is forgotten.
        self.windows.retain(|id, w| {
            tracks
                .iter()
                .any(|t| t.track == *id && t.age_scans >= w.age_scans)
        });
        for t in tracks {
            if let Some(w) = self.windows.get_mut(&t.track) {
                w.age_scans = t.age_scans;
            }
        }
        if !time_s.is_finite() {
            return;
        }
        for a in assignments {
            let Some(p) = a
                .plot
                .filter(|p| *p != HIDDEN_PLOT)
                .and_then(|p| plots_m.get(usize::from(p)))
                .filter(|p| p.iter().all(|v| v.is_finite()))
            else {
                continue;
            };
            let Some(t) = tracks.iter().find(|t| t.track == a.track) else {
                continue;
            };
            let w = self.windows.entry(a.track).or_default();
            w.age_scans = t.age_scans;
            w.plots
                .push_back((time_s, [f64::from(p[0]), f64::from(p[1])]));
            while w.plots.len() > MAX_PLOTS {
                w.plots.pop_front();
            }
        }
        for w in self.windows.values_mut() {
            // Every window, not only those given a plot: a coasting track's plots age out.
            while w.plots.front().is_some_and(|(t, _)| time_s - t > WINDOW_S) {
                w.plots.pop_front();
            }
            // Relative to the newest plot: metres, not the frame's tens of kilometres.
            let Some(&(tn, pn)) = w.plots.back() else {
                w.still = false;
                continue;
            };
            let fit = Fit::of(
                w.plots
                    .iter()
                    .map(|(t, p)| (t - tn, [p[0] - pn[0], p[1] - pn[1]])),
            );
            w.still = match fit {
                None => false,
                Some(f) if w.still => !f.leaves(),
                Some(f) => f.enters(),
            };
        }
    }

    /// True when `track`'s target is found standing still.
    pub fn still(&self, track: u16) -> bool {
        self.windows.get(&track).is_some_and(|w| w.still)
    }

    /// Where `track`'s target stands when it is found standing still: the mean of the
    /// plots in its window, m (east, north, local frame); `None` for a target not found
    /// still.
    pub fn standing_at_m(&self, track: u16) -> Option<[f64; 2]> {
        let w = self.windows.get(&track).filter(|w| w.still)?;
        // Found still only on MIN_PLOTS or more, so never a division by zero.
        let n = w.plots.len() as f64;
        let sum = w
            .plots
            .iter()
            .fold([0.0, 0.0], |a, (_, p)| [a[0] + p[0], a[1] + p[1]]);
        Some([sum[0] / n, sum[1] / n])
    }

    /// Where every target found standing still stands ([`Self::standing_at_m`]), by track
    /// number, m (east, north, local frame; f32 as the wire's positions), as the
    /// association takes it.
    pub fn standing_m(&self) -> super::associate::StandingAt {
        self.windows
            .keys()
            .filter_map(|&t| Some((t, self.standing_at_m(t)?.map(|v| v as f32))))
            .collect()
    }

    /// `tracks` as shown: those found still with no velocity.
    pub fn shown(&self, tracks: &[TrackState]) -> Vec<TrackState> {
        tracks
            .iter()
            .map(|t| TrackState {
                velocity_mps: if self.still(t.track) {
                    [0.0; 2]
                } else {
                    t.velocity_mps
                },
                ..*t
            })
            .collect()
    }

    /// Forgets every track (the device's were cancelled).
    pub fn clear(&mut self) {
        self.windows.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracker_core::icd::TrackStatus;

    /// Gaussian noise from a seeded generator (Box–Muller).
    struct Noise(fastrand::Rng);

    impl Noise {
        fn gauss(&mut self, sigma: f64) -> f64 {
            let u = self.0.f64().max(1e-12);
            let v = self.0.f64();
            sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    fn state(track: u16) -> TrackState {
        TrackState {
            track,
            status: TrackStatus::Confirmed,
            position_m: [0.0; 2],
            velocity_mps: [3.0, 4.0],
            age_scans: 10,
            hit_history: 0x3ff,
        }
    }

    /// Scans every 2.5 s of one track whose plot at scan `k` is `at(k)` plus noise of
    /// `sigma_m` a axis; returns, per scan, whether it was found still.
    fn run(scans: u32, sigma_m: f64, seed: u64, at: impl Fn(f64) -> [f64; 2]) -> Vec<bool> {
        let mut noise = Noise(fastrand::Rng::with_seed(seed));
        let mut test = StationaryTest::default();
        let tracks = [state(5)];
        (0..scans)
            .map(|k| {
                let t = 2.5 * f64::from(k);
                let p = at(t);
                let z = [
                    (p[0] + noise.gauss(sigma_m)) as f32,
                    (p[1] + noise.gauss(sigma_m)) as f32,
                ];
                let took = [Assignment {
                    track: 5,
                    plot: Some(0),
                }];
                test.observe(1.0e9 + t, &tracks, &took, &[z]);
                test.still(5)
            })
            .collect()
    }

    #[test]
    fn the_f_quantiles_are_the_tables() {
        // F(2, m) 95 % and 99.9 % points from the tables (e.g. NIST/SEMATECH e-Handbook
        // §1.3.6.7.3): 4.103 and 14.905 at m = 10, 3.316 and 8.773 at m = 30; χ²₂/2 as m
        // grows (2.996 and 6.908).
        for (p, m, x) in [
            (0.95, 10.0, 4.103),
            (0.999, 10.0, 14.905),
            (0.95, 30.0, 3.316),
            (0.999, 30.0, 8.773),
            (0.95, 1e7, 2.996),
            (0.999, 1e7, 6.908),
        ] {
            assert!((f2_quantile(p, m) - x).abs() < 2e-3, "{p} {m}");
        }
    }

    #[test]
    fn a_moored_boat_is_found_still_and_stays_so() {
        // 30 m plots (the IMO model's at a few NM) for ten minutes, ten seeds: found still
        // once a window of plots bounds its speed (a minute or so), and held.
        for seed in 0..10 {
            let still = run(240, 30.0, seed, |_| [1500.0, -800.0]);
            let first = still.iter().position(|s| *s).expect("found still");
            assert!(first <= 30, "seed {seed}: first at scan {first}");
            let held = still[first..].iter().filter(|s| **s).count();
            assert!(
                held * 100 >= (still.len() - first) * 98,
                "seed {seed}: held {held} of {}",
                still.len() - first
            );
        }
    }

    #[test]
    fn a_ship_under_way_is_seldom_found_still() {
        // Through 30 m plots, ten minutes, ten seeds: at 3 kn (at the bound the speed is
        // tested against) on under 2.5 % of the scans; at 4.5 kn and 6 kn never.
        let still_scans = |speed: f64| -> usize {
            (0..10)
                .map(|seed| {
                    let still = run(240, 30.0, seed, |t| [speed * t, 0.5 * speed * t]);
                    still.iter().filter(|s| **s).count()
                })
                .sum()
        };
        let at_3_kn = still_scans(1.543);
        assert!(
            at_3_kn * 40 <= 2400,
            "3 kn: still on {at_3_kn} of 2400 scans"
        );
        assert_eq!(still_scans(2.315), 0);
        assert_eq!(still_scans(3.086), 0);
    }

    #[test]
    fn a_ship_getting_under_way_shows_its_motion_within_a_minute() {
        // Moored for five minutes, then 0.1 m/s² to 4 m/s (7.8 kn): found moving again
        // within 20 scans of casting off (11–18 measured), on every seed.
        for seed in 0..10 {
            let off = 300.0;
            let still = run(240, 20.0, seed, |t| {
                let s = (t - off).max(0.0);
                let d = if s < 40.0 {
                    0.05 * s * s
                } else {
                    80.0 + 4.0 * (s - 40.0)
                };
                [d, 0.0]
            });
            let cast_off = (off / 2.5) as usize;
            assert!(still[cast_off - 1], "seed {seed}: not still when moored");
            let moving = still[cast_off..].iter().position(|s| !*s).expect("moving");
            assert!(moving <= 20, "seed {seed}: still {moving} scans under way");
            assert!(
                still[cast_off + moving..].iter().all(|s| !*s),
                "seed {seed}: found still again under way"
            );
        }
    }

    /// Feeds track 1 a plot at (1500, −800) m ± 10 m every 2.5 s for `scans` scans from
    /// `t0_s`, as `state`; returns the last time.
    fn moored(test: &mut StationaryTest, state: TrackState, t0_s: f64, scans: u16) -> f64 {
        let mut noise = Noise(fastrand::Rng::with_seed(7));
        let mut t = t0_s;
        for k in 0..scans {
            t = t0_s + 2.5 * f64::from(k);
            let z = [
                (1500.0 + noise.gauss(10.0)) as f32,
                (-800.0 + noise.gauss(10.0)) as f32,
            ];
            let took = [Assignment {
                track: state.track,
                plot: Some(0),
            }];
            let s = TrackState {
                age_scans: state.age_scans + k,
                ..state
            };
            test.observe(t, &[s], &took, &[z]);
        }
        t
    }

    #[test]
    fn memory_is_bounded_and_bad_plots_are_not_taken() {
        let mut test = StationaryTest::default();
        let tracks = [state(1), state(2)];
        for k in 0..1000 {
            let took = [
                Assignment {
                    track: 1,
                    plot: Some(0),
                },
                // A plot index past the scan's plots, and the hidden-plot marker: ignored.
                Assignment {
                    track: 2,
                    plot: Some(7),
                },
                Assignment {
                    track: 2,
                    plot: Some(HIDDEN_PLOT),
                },
                // A track the device did not report: not taken.
                Assignment {
                    track: 9,
                    plot: Some(0),
                },
            ];
            test.observe(f64::from(k) * 0.1, &tracks, &took, &[[1.0, 2.0]]);
        }
        assert_eq!(test.windows.len(), 1);
        assert!(test.windows.values().all(|w| w.plots.len() <= MAX_PLOTS));
        // A moored boat found still; then a plot of no number and a time of none: not
        // taken, no panic, and the boat is still found still.
        let mut test = StationaryTest::default();
        let t = moored(&mut test, state(1), 0.0, 40);
        assert!(test.still(1));
        let nan = [Assignment {
            track: 1,
            plot: Some(0),
        }];
        let older = TrackState {
            age_scans: 60,
            ..state(1)
        };
        test.observe(t + 2.5, &[older], &nan, &[[f32::NAN, 0.0]]);
        test.observe(f64::NAN, &[older], &nan, &[[1500.0, -800.0]]);
        assert!(test.windows[&1]
            .plots
            .iter()
            .all(|(t, p)| t.is_finite() && p.iter().all(|v| v.is_finite())));
        assert!(test.still(1));
    }

    #[test]
    fn a_windows_life_is_its_tracks() {
        // Found still, then reported lost: still shown so on that report, forgotten after.
        let mut test = StationaryTest::default();
        let t = moored(&mut test, state(1), 0.0, 40);
        assert!(test.still(1));
        let lost = TrackState {
            status: TrackStatus::Lost,
            age_scans: 50,
            ..state(1)
        };
        test.observe(t + 2.5, &[lost], &[], &[]);
        assert!(test.still(1));
        test.observe(t + 5.0, &[], &[], &[]);
        assert!(!test.still(1) && test.windows.is_empty());
        // A device reset numbers its tracks again: a younger track of the same number is
        // another, and starts with no plots.
        let mut test = StationaryTest::default();
        let t = moored(&mut test, state(1), 0.0, 40);
        let young = TrackState {
            age_scans: 2,
            ..state(1)
        };
        test.observe(t + 2.5, &[young], &[], &[]);
        assert!(!test.still(1) && test.windows.is_empty());
        // Coasting: no plot for more than the window less the span the test needs, and
        // the plots left cannot tell: its motion is the filter's again.
        let mut test = StationaryTest::default();
        let t = moored(&mut test, state(1), 0.0, 40);
        let coasting = TrackState {
            status: TrackStatus::Coasting,
            age_scans: 60,
            ..state(1)
        };
        test.observe(t + 30.0, &[coasting], &[], &[]);
        assert!(test.still(1));
        test.observe(t + WINDOW_S - 10.0, &[coasting], &[], &[]);
        assert!(!test.still(1));
    }

    /// The F of `Fit::of` over `windows` windows of 24 plots every 2.5 s of a target still,
    /// its plots of σ `across_m` east and `along_m` north: how many exceed the 95 % point.
    fn f_over_95(windows: u64, across_m: f64, along_m: f64) -> u64 {
        let mut noise = Noise(fastrand::Rng::with_seed(11));
        let q = f2_quantile(0.95, 21.0);
        (0..windows)
            .filter(|_| {
                let plots: Vec<(f64, [f64; 2])> = (0..24)
                    .map(|k| {
                        let t = 2.5 * f64::from(k);
                        (t, [noise.gauss(across_m), noise.gauss(along_m)])
                    })
                    .collect();
                Fit::of(plots.iter().copied()).is_some_and(|f| f.f > q)
            })
            .count() as u64
    }

    #[test]
    fn the_test_holds_its_level_whatever_the_plots_shape() {
        // 4,000 windows of a still target: F passes its 95 % point on 4–6 % of them with
        // round plots and with plots ten times wider across the beam than along it
        // (pooling the axes passed it on about 7 % of the latter).
        for (across, along) in [(20.0, 20.0), (30.0, 3.0), (3.0, 30.0)] {
            let n = f_over_95(4000, across, along);
            assert!((160..=240).contains(&n), "{across}/{along} m: {n} of 4000");
        }
    }

    #[test]
    fn sharp_plots_tell_a_slow_passage_from_a_drift() {
        // 3 m plots at 0.8 m/s (1.6 kn): the speed is bounded under 1.5 m/s, so only F
        // tells it moving, on all but a few of the first windows (8–10 plots). 2 m plots at
        // 0.15 m/s: significant, but a drift, found still. At 0.35 m/s: a first window may
        // take it for still, but a minute's plots tell it moving, and it stays so.
        let found = |speed: f64, sigma: f64| -> usize {
            (0..10)
                .map(|seed| {
                    run(240, sigma, seed, |t| [speed * t, 0.0])
                        .iter()
                        .filter(|s| **s)
                        .count()
                })
                .sum()
        };
        let slow = found(0.8, 3.0);
        assert!(slow * 100 <= 2400, "0.8 m/s still on {slow} of 2400 scans");
        assert!(found(0.15, 2.0) >= 10 * 200, "{}", found(0.15, 2.0));
        for seed in 0..10 {
            let still = run(240, 2.0, seed, |t| [0.35 * t, 0.0]);
            assert!(still[24..].iter().all(|s| !*s), "0.35 m/s seed {seed}");
        }
        // Near the drift (0.20–0.30 m/s on 2 m plots) a target's state changes seldom: a
        // band of four standard errors lies between entering (the bound under the drift)
        // and leaving (the fitted speed less two standard errors over it). 10–23 changes
        // over ten 10-minute runs at each speed, the first found still among them (leaving
        // on the fitted speed alone changed state about 8 times a run).
        for speed in [0.2, 0.22, 0.24, 0.26, 0.28, 0.3] {
            let changes: usize = (0..10)
                .map(|seed| {
                    let still = run(240, 2.0, seed, |t| [speed * t, 0.0]);
                    still.windows(2).filter(|w| w[0] != w[1]).count()
                })
                .sum();
            assert!(changes <= 30, "{speed} m/s: {changes} changes in ten runs");
        }
    }

    #[test]
    fn plots_spread_across_the_beam_are_not_taken_for_motion() {
        // Plots of σ 30 m across the beam (east) and 3 m along it (north), the target still:
        // the test's F has the same distribution whatever the error's shape, so the boat is
        // found still about as often as with round plots.
        let mut found = 0;
        for seed in 0..20 {
            let mut noise = Noise(fastrand::Rng::with_seed(seed));
            let mut test = StationaryTest::default();
            for k in 0..120u16 {
                let z = [
                    (900.0 + noise.gauss(30.0)) as f32,
                    (300.0 + noise.gauss(3.0)) as f32,
                ];
                let s = TrackState {
                    age_scans: k + 1,
                    ..state(1)
                };
                let took = [Assignment {
                    track: 1,
                    plot: Some(0),
                }];
                test.observe(2.5 * f64::from(k), &[s], &took, &[z]);
                if k >= 40 && test.still(1) {
                    found += 1;
                }
            }
        }
        // 20 runs × 80 scans.
        assert!(
            found * 100 >= 1600 * 90,
            "found still on {found} of 1600 scans"
        );
    }

    #[test]
    fn a_still_target_stands_at_the_mean_of_its_plots() {
        let mut test = StationaryTest::default();
        let track = TrackState {
            age_scans: 1,
            ..state(1)
        };
        // Not yet found still after 3 scans: nowhere.
        let t = moored(&mut test, track, 0.0, 3);
        assert_eq!(test.standing_at_m(1), None);
        assert!(test.standing_m().is_empty());
        // The same track 57 scans on.
        let resumed = TrackState {
            age_scans: track.age_scans + 3,
            ..track
        };
        moored(&mut test, resumed, t + 2.5, 57);
        assert!(test.still(1));
        // The mean of the window's 25 plots of ±10 m: within 3·10/√25 = 6 m of the mooring.
        let at = test.standing_at_m(1).expect("found still");
        assert!((at[0] - 1500.0).hypot(at[1] + 800.0) < 6.0, "{at:?}");
        let w = &test.windows[&1];
        let n = w.plots.len() as f64;
        let mean_east = w.plots.iter().map(|(_, p)| p[0]).sum::<f64>() / n;
        assert!((at[0] - mean_east).abs() < 1e-9);
        assert_eq!(
            test.standing_m().into_iter().collect::<Vec<_>>(),
            [(1, at.map(|v| v as f32))]
        );
        assert_eq!(test.standing_at_m(2), None);
    }

    #[test]
    fn only_a_still_targets_motion_is_taken_away() {
        let mut test = StationaryTest::default();
        test.windows.insert(
            1,
            Window {
                plots: VecDeque::new(),
                age_scans: 10,
                still: true,
            },
        );
        let shown = test.shown(&[state(1), state(2)]);
        assert_eq!(shown[0].velocity_mps, [0.0; 2]);
        assert_eq!(shown[1].velocity_mps, [3.0, 4.0]);
        assert_eq!(shown[0].position_m, state(1).position_m);
    }
}
