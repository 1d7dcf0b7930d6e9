//! Target numbers: the numbers the navigator and every plotter know targets by, the same on
//! the display, in the table and in `TTM`.
//!
//! They are not the device's track numbers (which run to 65,535 and restart with the
//! device): 01–99, unique among the targets shown, kept for a track's life, and a number
//! given back waits longest before it is given again, so a plotter that missed a target's
//! end does not join a new target to the old one's trail. Shown are the tracked targets
//! (confirmed and coasting) and, as acquiring, tentative tracks that have had a second plot
//! (a first plot alone is mostly clutter, and has no velocity yet). A number is given when a
//! target is tracked, not while it is acquiring: in a harbour most acquisitions fail, and
//! numbering them ran through all 99 numbers in a 51-s capture (290 targets sent to a
//! plotter, 236 never more than acquiring) and gave a number back 5 s after its end. With
//! more tracked targets than numbers the least important wait: dangerous first, then
//! nearest; those left without a number are counted.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use tracker_core::icd::{TrackState, TrackStatus};

use super::target::{AlarmLimits, TargetData};
use super::trend::TrendModel;
use crate::own_ship::OwnShip;

/// The highest target number (two digits; 00 is not used).
pub const MAX_TARGET_NUMBER: u8 = 99;

/// A tentative track is shown (acquiring) from this many plots on.
pub const ACQUIRING_FROM_HITS: u32 = 2;

/// A firm target whose motion's trend is not known yet has failed its acquisition, and is
/// not shown, after this many scans in a row without a plot: as long as a tentative track is
/// kept. Such a track's velocity comes from its first few plots (with 40 m plots every 2.5 s,
/// two plots give it σ 23 m/s a axis), so coasting it draws a symbol drifting away from its
/// echo at tens of knots; on real traffic most were second tracks beside a ship, shown
/// beside its AIS target. The device still holds the track: if it takes a plot again it is
/// shown again, as acquiring, under the number it had (plotters were told it ended, `L`,
/// when it failed; the number is held for it while the device holds the track).
pub const ACQUISITION_MISSES: u32 = 2;

/// The numbers and who holds them.
#[derive(Clone, Debug, PartialEq)]
pub struct TargetNumbers {
    free: VecDeque<u8>,
    of_track: BTreeMap<u16, u8>,
    last: BTreeMap<u16, TargetData>,
    /// Numbered tracks whose acquisition failed ([`ACQUISITION_MISSES`]), not shown, and
    /// told ended, while the device holds them.
    failed: BTreeSet<u16>,
    /// Targets that waited for a number (target-scans).
    pub waited: u64,
}

/// One scan's numbered targets.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Numbered {
    /// Confirmed and coasting tracks, nearest first.
    pub tracked: Vec<TargetData>,
    /// Tentative tracks with a second plot, nearest first, without numbers.
    pub acquiring: Vec<TargetData>,
    /// Numbered targets shown last scan and gone now (lost), as they were last seen: their
    /// numbers are free from the next scan.
    pub ended: Vec<TargetData>,
}

impl TargetNumbers {
    /// Numbers 1 to `highest` (at most [`MAX_TARGET_NUMBER`]).
    pub fn new(highest: u8) -> Self {
        TargetNumbers {
            free: (1..=highest.min(MAX_TARGET_NUMBER)).collect(),
            of_track: BTreeMap::new(),
            last: BTreeMap::new(),
            failed: BTreeSet::new(),
            waited: 0,
        }
    }

    /// The number `track` holds, if any.
    pub fn held(&self, track: u16) -> Option<u8> {
        self.of_track.get(&track).copied()
    }

    fn take(&mut self, track: u16) -> Option<u8> {
        if let Some(n) = self.of_track.get(&track) {
            return Some(*n);
        }
        let n = self.free.pop_front()?;
        self.of_track.insert(track, n);
        Some(n)
    }

    fn release(&mut self, track: u16) {
        if let Some(n) = self.of_track.remove(&track) {
            self.free.push_back(n);
        }
        self.last.remove(&track);
        self.failed.remove(&track);
    }

    /// Numbers the device's `tracks` seen from `own`; a confirmed or coasting target's
    /// motion is shown once `trend` knows it, and from then on ([`super::trend`]; without a
    /// model, every firm target's: an alarm is better given than withheld when it cannot be
    /// judged).
    pub fn scan(
        &mut self,
        own: &OwnShip,
        tracks: &[TrackState],
        limits: &AlarmLimits,
        trend: Option<&TrendModel>,
    ) -> Numbered {
        let shown = |t: &TrackState| match t.status {
            TrackStatus::Confirmed | TrackStatus::Coasting => true,
            TrackStatus::Tentative => (t.hit_history & 0x3ff).count_ones() >= ACQUIRING_FROM_HITS,
            TrackStatus::Lost => false,
        };
        let failed = |t: &TrackState, d: &TargetData| {
            t.status.is_firm()
                && !d.trend_known
                && t.hit_history & ((1 << ACQUISITION_MISSES) - 1) == 0
        };
        let mut live: Vec<TargetData> = tracks
            .iter()
            .filter(|t| shown(t))
            .map(|t| {
                let last = self.last.get(&t.track);
                let d = TargetData {
                    // Once known, kept for the track's life ([`super::trend`]).
                    trend_known: t.status.is_firm()
                        && (last.is_some_and(|d| d.trend_known)
                            || trend.is_none_or(|m| m.known(t))),
                    alarm_held: last.is_some_and(|d| d.dangerous(limits)),
                    ..TargetData::new(own, t)
                };
                (t, d)
            })
            .filter(|(t, d)| !failed(t, d))
            .map(|(_, d)| d)
            .collect();
        let mut out = Numbered::default();
        // Ends: their numbers go back after this scan's numbers are given, to the back of the
        // queue, so no number ends and starts in the same scan.
        let mut ending = Vec::new();
        let held: Vec<u16> = self.of_track.keys().copied().collect();
        for track in held {
            if live.iter().any(|t| t.track == track) {
                self.failed.remove(&track);
                continue;
            }
            // A firm track not shown has failed its acquisition: told once, its number held.
            let failed = tracks
                .iter()
                .any(|t| t.track == track && t.status.is_firm());
            if failed && !self.failed.insert(track) {
                continue;
            }
            if !failed && self.failed.contains(&track) {
                // Dropped by the device after its failed acquisition was told.
                ending.push(track);
                continue;
            }
            let data = tracks
                .iter()
                .find(|t| t.track == track)
                .map(|t| TargetData::new(own, t))
                .or_else(|| self.last.get(&track).copied());
            if let Some(mut d) = data {
                d.number = self.held(track);
                d.status = TrackStatus::Lost;
                // Its motion as it was shown: a failed acquisition's never was.
                d.trend_known = self.last.get(&track).is_some_and(|l| l.trend_known);
                out.ended.push(d);
            }
            if !failed {
                ending.push(track);
            }
        }
        // Most important first: dangerous, then nearest.
        live.sort_by(|a, b| {
            (!a.dangerous(limits))
                .cmp(&!b.dangerous(limits))
                .then(a.range_m.total_cmp(&b.range_m))
        });
        for mut t in live {
            if t.status == TrackStatus::Tentative {
                out.acquiring.push(t);
                continue;
            }
            t.number = self.take(t.track);
            if t.number.is_none() {
                self.waited += 1;
            }
            self.last.insert(t.track, t);
            out.tracked.push(t);
        }
        for track in ending {
            self.release(track);
        }
        // A tracked target that never had a number and is gone is forgotten too.
        let firm: Vec<u16> = out.tracked.iter().map(|t| t.track).collect();
        self.last
            .retain(|track, _| firm.contains(track) || self.of_track.contains_key(track));
        for list in [&mut out.tracked, &mut out.acquiring] {
            list.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracker_core::geo::METRES_PER_NM;

    fn track(id: u16, status: TrackStatus, hits: u16, north: f32) -> TrackState {
        TrackState {
            track: id,
            status,
            position_m: [0.0, north],
            velocity_mps: [0.0, 0.0],
            age_scans: 4,
            hit_history: hits,
        }
    }

    /// Own ship stopped at the origin, the default alarms, 40 m plots every 2.5 s.
    fn trend_setup() -> (OwnShip, AlarmLimits, TrendModel) {
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        (
            own,
            AlarmLimits::default(),
            TrendModel::new(40.0, 2.5, 20.0).unwrap(),
        )
    }

    /// A target whose CPA crosses the limit and back with its velocity's noise is one
    /// alarm, not one a crossing; it ends once the CPA is clear of the widened limit, and
    /// a minute after the target has passed.
    #[test]
    fn an_alarm_stays_on_through_a_cpa_that_jitters_about_its_limit() {
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let limits = AlarmLimits::default();
        let mut n = TargetNumbers::new(MAX_TARGET_NUMBER);
        // 5 km north, heading south at 5 m/s, passing `cpa_m` to the east of own ship.
        let heading_to_pass = |north: f32, cpa_m: f32| {
            let v = 5.0f32;
            let angle = (cpa_m / north).asin();
            TrackState {
                velocity_mps: [v * angle.sin(), -v * angle.cos()],
                age_scans: 40,
                ..track(10, TrackStatus::Confirmed, 0x3ff, north)
            }
        };
        let mut alarm = |north: f32, cpa_nm: f32| {
            let t = heading_to_pass(north, cpa_nm * METRES_PER_NM);
            let s = n.scan(&own, &[t], &limits, None);
            s.tracked[0].dangerous(&limits)
        };
        let mut raises = 0;
        let mut on = false;
        for (i, cpa_nm) in [0.95, 1.05, 0.97, 1.1, 0.99, 1.15, 0.9].iter().enumerate() {
            let now = alarm(3000.0 - 10.0 * i as f32, *cpa_nm);
            raises += u32::from(now && !on);
            on = now;
        }
        assert_eq!((raises, on), (1, true), "one alarm, still on");
        // Clear of 1.2 NM: off; back under the limit: a new alarm.
        assert!(!alarm(2900.0, 1.25));
        assert!(!alarm(2890.0, 1.1), "not held once off");
        assert!(alarm(2880.0, 0.9));
        // Passed: the TCPA a little negative holds it, a minute past ends it.
        let passing = |tcpa_s: f32| TrackState {
            position_m: [100.0, 5.0 * tcpa_s],
            velocity_mps: [0.0, -5.0],
            age_scans: 40,
            ..track(10, TrackStatus::Confirmed, 0x3ff, 0.0)
        };
        let mut at = |tcpa_s: f32| {
            let s = n.scan(&own, &[passing(tcpa_s)], &limits, None);
            s.tracked[0].dangerous(&limits)
        };
        assert!(at(-10.0));
        assert!(at(-50.0));
        assert!(!at(-70.0));
    }

    /// Confirmed track 10, 5 km north, `age` scans old with `hits`.
    fn at(age: u16, hits: u16) -> TrackState {
        TrackState {
            age_scans: age,
            ..track(10, TrackStatus::Confirmed, hits, 5000.0)
        }
    }

    #[test]
    fn a_targets_motion_once_shown_stays_shown() {
        let (own, limits, model) = trend_setup();
        let mut n = TargetNumbers::new(9);
        let s = n.scan(&own, &[at(13, 0x3ff)], &limits, Some(&model));
        assert!(!s.tracked[0].trend_known, "13 plots of 40 m: not yet");
        let s = n.scan(&own, &[at(14, 0x3ff)], &limits, Some(&model));
        assert!(s.tracked[0].trend_known, "the 14th");
        // A miss widens the covariance past the limit again; the motion stays shown.
        assert!(!model.known(&at(15, 0x3fe)));
        let s = n.scan(&own, &[at(15, 0x3fe)], &limits, Some(&model));
        assert!(s.tracked[0].trend_known);
        // A tentative track's motion is not shown.
        let young = TrackState {
            track: 11,
            ..track(11, TrackStatus::Tentative, 0b11, 6000.0)
        };
        let s = n.scan(&own, &[at(16, 0x3fd), young], &limits, Some(&model));
        assert!(!s.acquiring[0].trend_known);
        // Both end: the tracked one with its motion shown; the acquiring one, never
        // numbered, unseen by a plotter.
        let s = n.scan(&own, &[], &limits, Some(&model));
        assert_eq!(s.ended.len(), 1);
        assert!(s.ended[0].track == 10 && s.ended[0].trend_known);
    }

    #[test]
    fn an_acquisition_that_misses_twice_has_failed_until_its_next_plot() {
        let (own, limits, model) = trend_setup();
        let mut n = TargetNumbers::new(9);
        let s = n.scan(&own, &[at(4, 0b1111)], &limits, Some(&model));
        assert_eq!(s.tracked[0].number, Some(1));
        // One miss: still shown, as acquiring.
        let s = n.scan(&own, &[at(5, 0b11110)], &limits, Some(&model));
        assert_eq!((s.tracked.len(), s.tracked[0].trend_known), (1, false));
        // Two in a row: not shown; ended once (a plotter is told `L`) with no motion.
        let s = n.scan(&own, &[at(6, 0b111100)], &limits, Some(&model));
        assert!(s.tracked.is_empty() && s.acquiring.is_empty());
        assert_eq!((s.ended.len(), s.ended[0].number), (1, Some(1)));
        assert!(!s.ended[0].trend_known);
        let s = n.scan(&own, &[at(7, 0b1111000)], &limits, Some(&model));
        assert!(s.tracked.is_empty() && s.ended.is_empty());
        // A plot again: shown again, under its number.
        let s = n.scan(&own, &[at(8, 0b11110001)], &limits, Some(&model));
        assert_eq!((s.tracked.len(), s.tracked[0].number), (1, Some(1)));
        // Failed again, then dropped by the device: told once, its number given back.
        n.scan(&own, &[at(9, 0b11_1100_0010)], &limits, Some(&model));
        let s = n.scan(&own, &[at(10, 0b11_1000_0100)], &limits, Some(&model));
        assert_eq!(s.ended.len(), 1);
        let s = n.scan(&own, &[at(11, 0b11_0000_1000)], &limits, Some(&model));
        assert!(s.ended.is_empty());
        let s = n.scan(&own, &[], &limits, Some(&model));
        assert!(s.ended.is_empty() && n.of_track.is_empty() && n.failed.is_empty());
        // A target whose motion is known is never hidden for its misses.
        let mut n = TargetNumbers::new(9);
        n.scan(&own, &[at(14, 0x3ff)], &limits, Some(&model));
        let s = n.scan(&own, &[at(16, 0x3fc)], &limits, Some(&model));
        assert_eq!(s.tracked.len(), 1);
        // Without a trend model every firm target's motion counts as known: none hidden.
        let mut n = TargetNumbers::new(9);
        let s = n.scan(&own, &[at(6, 0b111100)], &limits, None);
        assert_eq!(s.tracked.len(), 1);
    }

    #[test]
    fn numbers_are_unique_kept_and_given_back_last() {
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let limits = AlarmLimits::default();
        let mut n = TargetNumbers::new(3);
        let a = track(10, TrackStatus::Confirmed, 0b111, 5000.0);
        let b = track(11, TrackStatus::Confirmed, 0b111, 6000.0);
        let clutter = track(12, TrackStatus::Tentative, 0b1, 7000.0);
        let s = n.scan(&own, &[a, b, clutter], &limits, None);
        assert_eq!(
            s.tracked.iter().map(|t| t.number).collect::<Vec<_>>(),
            [Some(1), Some(2)]
        );
        assert!(s.acquiring.is_empty(), "one plot is not shown");
        // Acquiring: shown, numbered only once tracked; a failed acquisition ends unseen by
        // a plotter (no number, no `L`).
        let acquiring = track(15, TrackStatus::Tentative, 0b11, 7500.0);
        let s = n.scan(&own, &[a, b, acquiring], &limits, None);
        assert_eq!(s.acquiring.len(), 1);
        assert_eq!(s.acquiring[0].number, None);
        let s = n.scan(&own, &[a, b], &limits, None);
        assert!(s.ended.is_empty());
        let c = track(13, TrackStatus::Confirmed, 0b11, 8000.0);
        let d = track(14, TrackStatus::Confirmed, 0b11, 9000.0);
        let s = n.scan(&own, &[a, b, c, d], &limits, None);
        let number =
            |s: &Numbered, id: u16| s.tracked.iter().find(|t| t.track == id).unwrap().number;
        assert_eq!(number(&s, 13), Some(3));
        assert_eq!(number(&s, 14), None, "every number in use");
        assert_eq!(n.waited, 1);
        // b ends: its number is sent with the end, and free only from the next scan.
        let s = n.scan(&own, &[a, c, d], &limits, None);
        assert_eq!(s.ended.len(), 1);
        assert_eq!((s.ended[0].track, s.ended[0].number), (11, Some(2)));
        assert_eq!(number(&s, 14), None);
        let s = n.scan(&own, &[a, c, d], &limits, None);
        assert_eq!(number(&s, 14), Some(2));
        assert_eq!(n.held(10), Some(1), "kept for the track's life");
        // Nothing is kept of tracks gone without a number.
        n.scan(&own, &[], &limits, None);
        assert!(n.last.is_empty() && n.of_track.is_empty());
    }
}
