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
//! ([`TrackState::hit_history`]). So the core's own CV Kalman filter in the product's
//! configuration ([`FilterConfig::tracking`]) is run here on the track's hits and misses;
//! for the other filters this is the accuracy a CV Kalman filter would have on the same
//! plots. Once known, a target's motion stays shown for the track's life (the session's
//! numbering holds it): a miss widens the covariance a little, and a vector and alarm that
//! came and went with every miss would be worse than one shown a scan early.

use tracker_core::filter::kalman::cv::KalmanCv;
use tracker_core::filter::{Filter, FilterConfig, FilterKind, Interval, Measurement};
use tracker_core::icd::TrackState;
use tracker_core::track::KEEP_N;

/// A velocity within this factor of its steady-state standard deviation counts as known.
pub const STEADY_FACTOR: f64 = 1.25;

/// The trend is shown this long after the track's first plot whatever its accuracy (IMO
/// MSC.192(79) 5.25.4.1), s.
pub const TREND_WITHIN_S: f64 = 60.0;

/// A track is held steadily with a plot on at least this many of its last
/// [`STEADY_OF`] scans (of all its scans, while younger).
pub const STEADY_HITS: u32 = 3;
/// See [`STEADY_HITS`].
pub const STEADY_OF: u16 = 5;

/// True when `track` had a plot on at least [`STEADY_HITS`] of its last [`STEADY_OF`]
/// scans. The velocity σ assumes every plot was the target's: a track that takes a plot
/// after coasting has a velocity from two positions far apart in time, which is as
/// accurate as the σ says only if that plot was its target's, and after several misses its
/// gate has grown over other echoes.
fn held_steadily(track: &TrackState) -> bool {
    let scans = track.age_scans.clamp(1, STEADY_OF);
    let mask = (1u16 << scans) - 1;
    (track.hit_history & mask).count_ones() >= STEADY_HITS.min(u32::from(scans))
}

/// Scans of the covariance recursion at most: by then every configuration the product
/// makes is in its steady state (40 m plots every 2.5 s: within 0.1 % after 40).
const MAX_SCANS: u32 = 200;

/// The velocity accuracy of the product's CV Kalman filter on a given picture: the plots'
/// accuracy, the scan interval, the filter's process noise and a new track's velocity
/// variance ([`FilterConfig::tracking`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrendModel {
    /// Plot accuracy, m (one axis).
    plot_sigma_m: f64,
    /// Scan interval.
    scan: Interval<f64>,
    /// The filter, as a track's starts.
    filter: KalmanCv<f64>,
    /// The steady-state velocity standard deviation, m/s (one axis).
    steady_sigma_mps: f64,
}

impl TrendModel {
    /// The model for plots of `plot_sigma_m` (m, one axis) every `scan_s` (s), targets up to
    /// `max_speed_mps` (m/s, a new track's velocity σ); `None` when any of them is not a
    /// positive number (or the interval is outside the filters' range).
    pub fn new(plot_sigma_m: f32, scan_s: f64, max_speed_mps: f32) -> Option<Self> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !(positive(plot_sigma_m) && positive(max_speed_mps)) {
            return None;
        }
        let FilterConfig::KalmanCv(k) =
            FilterConfig::tracking(FilterKind::KalmanCv, plot_sigma_m, max_speed_mps)
        else {
            return None;
        };
        let mut m = TrendModel {
            plot_sigma_m: f64::from(plot_sigma_m),
            scan: Interval::new(scan_s).ok()?,
            filter: k.build_cv::<f64>().ok()?,
            steady_sigma_mps: 0.0,
        };
        m.steady_sigma_mps = m.run(|_| true, MAX_SCANS);
        Some(m)
    }

    /// The scan interval the model is for, s.
    pub fn scan_s(&self) -> f64 {
        self.scan.seconds()
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
        // `scan` scans after the first: `back` = age − 1 − scan scans before the last.
        self.run(
            |scan| {
                let back = age - 1 - scan;
                back >= KEEP_N || (hit_history >> back) & 1 == 1
            },
            age,
        )
    }

    /// True when the motion of `track` is known well enough to show ([the module](self)):
    /// near its steady state, or a minute after its first plot.
    pub fn known(&self, track: &TrackState) -> bool {
        f64::from(track.age_scans.saturating_sub(1)) * self.scan_s() >= TREND_WITHIN_S
            || (held_steadily(track)
                && self.velocity_sigma_mps(track.hit_history, track.age_scans)
                    <= STEADY_FACTOR * self.steady_sigma_mps)
    }

    /// The velocity σ (m/s, one axis) after `scans` scans of the filter from a first plot,
    /// scan `k` (1 to `scans` − 1) with a plot when `hit(k)`. The covariance depends on the
    /// hits alone, so every plot is put at the origin.
    fn run(&self, hit: impl Fn(u32) -> bool, scans: u32) -> f64 {
        let mut f = self.filter;
        let origin = Measurement::new([0.0; 2]).ok();
        if let Some(z) = origin {
            f.start(z);
        }
        for k in 1..scans {
            f.predict(self.scan);
            if let (true, Some(z)) = (hit(k), origin) {
                f.update(z);
            }
        }
        f.covariance().vv.sqrt()
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
        // ten scans, a minute after its first plot (the 25th scan).
        let open = TrendModel::new(40.0, 2.5, 20.0).unwrap();
        let n = (3..30u16).find(|&n| open.known(&track(0x3ff, n))).unwrap();
        assert_eq!(n, 14);
        assert!(!open.known(&track(0, 24)));
        assert!(open.known(&track(0, 25)), "60 s at 2.5 s a scan");
    }

    #[test]
    fn a_plot_taken_after_coasting_does_not_make_the_motion_known() {
        // 10 m plots: three plots, five misses, a plot. The velocity's σ from two positions
        // 15 s apart is near the steady state, but the plot may be another echo's.
        let m = TrendModel::new(10.4, 2.5, 20.0).unwrap();
        let coasted = 0b1_1100_0001;
        assert!(
            m.velocity_sigma_mps(coasted, 9) <= STEADY_FACTOR * m.steady_sigma_mps(),
            "the σ alone would show it"
        );
        assert!(!m.known(&track(coasted, 9)));
        // Two more plots in a row: held steadily again, and known.
        assert!(m.known(&track(0b111_0000_0111, 11)));
        // Young tracks count their own scans: three of three.
        assert!(TrendModel::new(2.0, 2.5, 20.0)
            .unwrap()
            .known(&track(0b1111, 4)));
    }

    #[test]
    fn nonsense_makes_no_model() {
        assert!(TrendModel::new(f32::NAN, 2.5, 20.0).is_none());
        assert!(TrendModel::new(10.0, 0.0, 20.0).is_none());
        assert!(TrendModel::new(-1.0, 2.5, 20.0).is_none());
        assert!(TrendModel::new(10.0, 2.5, 0.0).is_none());
    }
}
