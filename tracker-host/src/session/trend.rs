//! When a target's motion is known well enough to show: its vector, course and speed, CPA
//! and TCPA, and the CPA/TCPA alarm.
//!
//! IMO MSC.192(79) 5.25.4.1: once a target is acquired, the system presents the *trend* of
//! its motion within one minute; 5.25.4.7: the tracking accuracy holds once the track is in
//! steady state, and "may be significantly reduced during or shortly after acquisition".
//! IEC 62388 draws a target still in acquisition without a vector. A track confirmed on its
//! third plot has a velocity from two intervals of plots: with the Garmin's 10 m plots its
//! σ is 2.9 m/s a axis (a speed error of up to 14 kn, 95 %), and on a short capture
//! most of the targets shown at tens of knots, with CPA alarms, were such tracks
//! (docs/radar.md). So the motion of a confirmed target is shown, and alarms, once its
//! velocity is known nearly as well as it will be: its standard deviation within
//! [`STEADY_FACTOR`] of the steady state for the plots' accuracy, or one minute after the
//! track started, whichever comes first.
//!
//! How well the velocity is known is worked out here, not read from the device: a CV Kalman
//! filter's covariance depends on the plots' accuracy, the scan interval and which scans had
//! a plot, not on the plots themselves, and the device reports each track's hits
//! ([`TrackState::hit_history`]). It is the covariance of the product's CV Kalman
//! configuration ([`FilterConfig::tracking`]): for the other filters, the accuracy a CV
//! Kalman filter would have on the same plots.

use tracker_core::filter::{FilterConfig, FilterKind};
use tracker_core::icd::TrackState;
use tracker_core::track::KEEP_N;

/// A velocity within this factor of its steady-state standard deviation counts as known.
pub const STEADY_FACTOR: f64 = 1.25;

/// The trend is shown this long after the track started whatever its accuracy (IMO
/// MSC.192(79) 5.25.4.1), s.
pub const TREND_WITHIN_S: f64 = 60.0;

/// Scans of the covariance recursion at most: by then every configuration the product
/// makes is in its steady state (40 m plots every 2.5 s: within 0.1 % after 40).
const MAX_SCANS: u32 = 200;

/// The velocity accuracy of a CV Kalman filter on a given picture: plots' accuracy, scan
/// interval, process noise and the velocity variance a track starts with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrendModel {
    /// Plot accuracy, m (one axis).
    plot_sigma_m: f64,
    /// Scan interval, s.
    scan_s: f64,
    /// Continuous white-noise acceleration spectral density, m²/s³.
    q: f64,
    /// A new track's velocity variance, m²/s² (one axis).
    p0_velocity: f64,
    /// The steady-state velocity standard deviation, m/s (one axis).
    steady_sigma_mps: f64,
}

/// One axis of a CV filter's covariance: `[p_xx, p_xv, p_vv]` (m², m²/s, m²/s²).
type Cov = [f64; 3];

impl TrendModel {
    /// The model for plots of `plot_sigma_m` (m, one axis) every `scan_s` (s), targets up to
    /// `max_speed_mps`, with the product's CV Kalman configuration for them; `None` when
    /// either is not a positive number.
    pub fn new(plot_sigma_m: f32, scan_s: f64, max_speed_mps: f32) -> Option<Self> {
        let FilterConfig::KalmanCv(k) =
            FilterConfig::tracking(FilterKind::KalmanCv, plot_sigma_m, max_speed_mps)
        else {
            return None;
        };
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(f64::from(plot_sigma_m)) && ok(scan_s) && ok(k.q) && ok(k.p0_derivative)) {
            return None;
        }
        let mut m = TrendModel {
            plot_sigma_m: f64::from(plot_sigma_m),
            scan_s,
            q: k.q,
            p0_velocity: k.p0_derivative,
            steady_sigma_mps: 0.0,
        };
        let mut p = m.start();
        for _ in 1..MAX_SCANS {
            p = m.update(m.predict(p));
        }
        m.steady_sigma_mps = p[2].sqrt();
        Some(m)
    }

    /// The scan interval the model is for, s.
    pub fn scan_s(&self) -> f64 {
        self.scan_s
    }

    /// The plot accuracy the model is for, m.
    pub fn plot_sigma_m(&self) -> f64 {
        self.plot_sigma_m
    }

    /// The velocity standard deviation in steady state, m/s (one axis).
    pub fn steady_sigma_mps(&self) -> f64 {
        self.steady_sigma_mps
    }

    /// The velocity standard deviation of a track `age_scans` old (the first scan counts)
    /// with `hit_history` (bit 0 the last scan, [`KEEP_N`] bits), m/s (one axis). Scans
    /// older than the history are taken as hits (the track was kept through them).
    pub fn velocity_sigma_mps(&self, hit_history: u16, age_scans: u16) -> f64 {
        let age = u32::from(age_scans.max(1)).min(MAX_SCANS);
        let mut p = self.start();
        for scan in 1..age {
            // `back` scans before the last: its hit bit, while the history holds it.
            let back = age - 1 - scan;
            let hit = back >= KEEP_N || (hit_history >> back) & 1 == 1;
            p = self.predict(p);
            if hit {
                p = self.update(p);
            }
        }
        p[2].sqrt()
    }

    /// True when the motion of `track` is known well enough to show ([the module](self)).
    pub fn known(&self, track: &TrackState) -> bool {
        f64::from(track.age_scans) * self.scan_s >= TREND_WITHIN_S
            || self.velocity_sigma_mps(track.hit_history, track.age_scans)
                <= STEADY_FACTOR * self.steady_sigma_mps
    }

    /// The covariance after a track's first plot.
    fn start(&self) -> Cov {
        [self.plot_sigma_m * self.plot_sigma_m, 0.0, self.p0_velocity]
    }

    /// One scan's prediction (constant velocity, continuous white-noise acceleration).
    fn predict(&self, [a, b, c]: Cov) -> Cov {
        let (t, q) = (self.scan_s, self.q);
        [
            a + 2.0 * t * b + t * t * c + q * t * t * t / 3.0,
            b + t * c + q * t * t / 2.0,
            c + q * t,
        ]
    }

    /// An update with a plot.
    fn update(&self, [a, b, c]: Cov) -> Cov {
        let s = a + self.plot_sigma_m * self.plot_sigma_m;
        let (ka, kb) = (a / s, b / s);
        [a - ka * a, b - ka * b, c - kb * b]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracker_core::icd::TrackStatus;

    fn track(hit_history: u16, age_scans: u16) -> TrackState {
        TrackState {
            track: 1,
            status: TrackStatus::Confirmed,
            position_m: [0.0; 2],
            velocity_mps: [0.0; 2],
            age_scans,
            hit_history,
        }
    }

    #[test]
    fn the_steady_state_is_the_kalman_filters() {
        // Worked by the recursion in the notes (docs/radar.md): 40 m plots every 2.5 s,
        // q 0.05, 1.062 m/s; 10.4 m, 0.740; 2 m, 0.462.
        for (sigma, steady) in [(40.0, 1.062), (10.4, 0.740), (2.0, 0.462)] {
            let m = TrendModel::new(sigma, 2.5, 20.0).unwrap();
            assert!(
                (m.steady_sigma_mps() - steady).abs() < 0.001,
                "{sigma}: {m:?}"
            );
        }
        // A new track's velocity is the start's; every hit brings it down.
        let m = TrendModel::new(10.4, 2.5, 20.0).unwrap();
        assert!((m.velocity_sigma_mps(1, 1) - 20.0).abs() < 1e-9);
        let sigmas: Vec<f64> = (2..12).map(|n| m.velocity_sigma_mps(0x3ff, n)).collect();
        assert!(sigmas.windows(2).all(|w| w[1] < w[0]), "{sigmas:?}");
    }

    #[test]
    fn the_motion_is_shown_near_the_steady_state_or_after_a_minute() {
        // 10.4 m plots: the velocity's σ is 2.92 m/s after 3 plots, 1.38 after 5, 0.94
        // after 7 (above 1.25 × 0.740 = 0.925), 0.85 after 8: shown from the 8th.
        let m = TrendModel::new(10.4, 2.5, 20.0).unwrap();
        let first = (3..30u16)
            .find(|&n| m.known(&track(0x3ff, n)))
            .expect("known in time");
        assert_eq!(first, 8);
        // A plot every other scan does not bring it sooner (fewer plots over the same time).
        let gappy = (3..30u16)
            .find(|&n| m.known(&track(0b01_0101_0101, n)))
            .unwrap();
        assert!(gappy >= first, "{gappy} against {first}");
        // Plots of 2 m settle sooner: from the 4th plot.
        let harbour = TrendModel::new(2.0, 2.5, 20.0).unwrap();
        assert_eq!(
            (3..30u16).find(|&n| harbour.known(&track(0x3ff, n))),
            Some(4)
        );
        // 40 m plots every 2.5 s: from the 14th plot (about 33 s); with no plot in its last
        // ten scans, at a minute.
        let open = TrendModel::new(40.0, 2.5, 20.0).unwrap();
        let n = (3..30u16).find(|&n| open.known(&track(0x3ff, n))).unwrap();
        assert_eq!(n, 14);
        assert!(!open.known(&track(0, 23)));
        assert!(open.known(&track(0, 24)), "60 s at 2.5 s a scan");
    }

    #[test]
    fn nonsense_makes_no_model() {
        assert!(TrendModel::new(f32::NAN, 2.5, 20.0).is_none());
        assert!(TrendModel::new(10.0, 0.0, 20.0).is_none());
        assert!(TrendModel::new(-1.0, 2.5, 20.0).is_none());
    }
}
