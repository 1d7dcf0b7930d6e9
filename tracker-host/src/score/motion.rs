//! The motion the navigator is shown, against the truth: targets that stand still shown
//! moving, targets under way shown still, and CPA/TCPA alarms the truth does not bear out.
//!
//! Each scan, every target drawn with its motion known ([`TargetData::trend_known`]) whose
//! track the scorer matched to a true target is counted by the true target's speed: *still*
//! under [`STILL_MPS`], *moving* at [`MOVING_MPS`] or more. A still target shown at 1 kn or
//! more is shown moving; a moving one shown under half a knot is shown still. An alarm
//! (the target drawn dangerous with the run's limits, [`TargetData::dangerous`]) is *false*
//! when the true target's CPA and TCPA from own ship's true state are clear of the limits
//! widened as a raised alarm's are ([`ALARM_CLEAR_FACTOR`], [`ALARM_PASSED_S`]): an alarm
//! held a little past the limits is not counted false.

use std::collections::BTreeMap;

use serde::Serialize;
use tracker_core::geo;

use super::ScanTruth;
use crate::session::target::{AlarmLimits, TargetData, ALARM_CLEAR_FACTOR, ALARM_PASSED_S};

/// A true target slower than this stands still, m/s (0.5 kn; moored boats' AIS reports in
/// the Solent give 0.0–0.1 kn).
pub const STILL_MPS: f32 = 0.257;
/// A true target this fast or faster is under way, m/s (3 kn).
pub const MOVING_MPS: f32 = 1.543;
/// Shown moving: 1 kn or more, m/s.
pub const SHOWN_MOVING_MPS: f32 = 0.514;
/// Shown still: under half a knot, m/s.
pub const SHOWN_STILL_MPS: f32 = 0.257;

/// What the motion shown came to.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct MotionScores {
    /// Target-scans of true targets standing still, drawn with their motion known.
    pub still_target_scans: u64,
    /// … of those shown at 1 kn or more.
    pub still_shown_moving: u64,
    /// Target-scans of true targets under way (3 kn or more), drawn with their motion known.
    pub moving_target_scans: u64,
    /// … of those shown under half a knot.
    pub moving_shown_still: u64,
    /// Target-scans drawn with the CPA/TCPA alarm on a matched track.
    pub alarm_target_scans: u64,
    /// … of those whose true target is clear of the limits.
    pub alarms_false: u64,
    /// … of those on a true target standing still.
    pub alarms_false_still: u64,
    /// Target-scans of true targets followed by a track drawn with its motion known and
    /// well within the limits (CPA and TCPA under the limits narrowed by
    /// [`ALARM_CLEAR_FACTOR`], TCPA from 0, approaching): an alarm is due. Counted once a
    /// target, however many tracks follow it.
    pub alarms_due: u64,
    /// … of those with the alarm raised on none of their tracks.
    pub alarms_missed: u64,
}

impl MotionScores {
    /// The figures as one line of text.
    pub fn line(&self) -> String {
        format!(
            "standing still shown at 1 kn or more {} of {} target-scans, under way (3 kn or more) shown under 0.5 kn {} of {}; CPA/TCPA alarms {} target-scans, {} not borne out by the truth ({} on targets standing still), {} of {} due by the truth missed",
            self.still_shown_moving,
            self.still_target_scans,
            self.moving_shown_still,
            self.moving_target_scans,
            self.alarm_target_scans,
            self.alarms_false,
            self.alarms_false_still,
            self.alarms_missed,
            self.alarms_due,
        )
    }
}

/// The tally, scan by scan ([`MotionScorer::scan`]).
#[derive(Clone, Debug, Default)]
pub struct MotionScorer {
    scores: MotionScores,
}

impl MotionScorer {
    /// One scan: `matched` maps tracks to true targets' ids, `targets` are those drawn,
    /// `limits` the CPA/TCPA alarm limits they were drawn with.
    pub fn scan(
        &mut self,
        truth: &ScanTruth,
        matched: &BTreeMap<u16, u32>,
        targets: &[TargetData],
        limits: &AlarmLimits,
    ) {
        // True targets with an alarm due: raised on any of their tracks?
        let mut due: BTreeMap<u32, bool> = BTreeMap::new();
        for d in targets.iter().filter(|d| d.trend_known) {
            let Some(x) = matched
                .get(&d.track)
                .and_then(|id| truth.targets.iter().find(|x| x.id == *id))
            else {
                continue;
            };
            let speed = x.velocity_mps[0].hypot(x.velocity_mps[1]);
            let still = speed < STILL_MPS;
            if still {
                self.scores.still_target_scans += 1;
                if d.speed_mps >= SHOWN_MOVING_MPS {
                    self.scores.still_shown_moving += 1;
                }
            } else if speed >= MOVING_MPS {
                self.scores.moving_target_scans += 1;
                if d.speed_mps < SHOWN_STILL_MPS {
                    self.scores.moving_shown_still += 1;
                }
            }
            let c = geo::cpa(
                truth.own.position_m,
                truth.own.velocity_mps,
                x.position_m,
                x.velocity_mps,
            );
            let rel = geo::relative_velocity(truth.own.velocity_mps, x.velocity_mps);
            let within = |factor: f32, passed_s: f32| {
                limits.within(c, rel[0].hypot(rel[1]), factor, passed_s)
            };
            let dangerous = d.dangerous(limits);
            if dangerous {
                self.scores.alarm_target_scans += 1;
                if !within(ALARM_CLEAR_FACTOR, ALARM_PASSED_S) {
                    self.scores.alarms_false += 1;
                    if still {
                        self.scores.alarms_false_still += 1;
                    }
                }
            }
            // Due well inside the limits (a shown CPA a little over the limit for a true one a
            // little under is no miss), once for a target however many tracks follow it.
            if within(1.0 / ALARM_CLEAR_FACTOR, 0.0) {
                *due.entry(x.id).or_insert(false) |= dangerous;
            }
        }
        self.scores.alarms_due += due.len() as u64;
        self.scores.alarms_missed += due.values().filter(|raised| !**raised).count() as u64;
    }

    /// The scores so far.
    pub fn scores(&self) -> MotionScores {
        self.scores.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::own_ship::OwnShip;
    use crate::score::TargetTruth;
    use tracker_core::icd::{TrackState, TrackStatus};

    fn truth(velocity_mps: [f32; 2], east_m: f32) -> ScanTruth {
        ScanTruth {
            targets: vec![TargetTruth {
                id: 7,
                position_m: [east_m, 0.0],
                velocity_mps,
                detected: true,
                in_range: true,
            }],
            ..ScanTruth::default()
        }
    }

    fn shown(velocity_mps: [f32; 2], east_m: f32) -> TargetData {
        TargetData::new(
            &OwnShip::default(),
            &TrackState {
                track: 3,
                status: TrackStatus::Confirmed,
                position_m: [east_m, 0.0],
                velocity_mps,
                age_scans: 30,
                hit_history: 0x3ff,
            },
        )
    }

    #[test]
    fn still_and_moving_targets_are_counted_by_the_truths_speed() {
        let matched = BTreeMap::from([(3u16, 7u32)]);
        let limits = AlarmLimits::default();
        let mut s = MotionScorer::default();
        // A moored boat shown at 1.2 kn, then at 0; a ship at 10 kn shown at 0.2 kn, then
        // at 9 kn; a boat at 1 kn (neither) is not counted.
        for (true_v, shown_v) in [
            ([0.0; 2], [0.6, 0.0]),
            ([0.0; 2], [0.0; 2]),
            ([5.1, 0.0], [0.2, 0.0]),
            ([5.1, 0.0], [4.6, 0.0]),
            ([0.5, 0.0], [0.0; 2]),
        ] {
            s.scan(
                &truth(true_v, 5000.0),
                &matched,
                &[shown(shown_v, 5000.0)],
                &limits,
            );
        }
        // A track the scorer did not match is not counted.
        s.scan(
            &truth([0.0; 2], 5000.0),
            &BTreeMap::new(),
            &[shown([3.0, 0.0], 5000.0)],
            &limits,
        );
        let m = s.scores();
        assert_eq!((m.still_target_scans, m.still_shown_moving), (2, 1));
        assert_eq!((m.moving_target_scans, m.moving_shown_still), (2, 1));
        assert_eq!(m.alarm_target_scans, 0);
    }

    #[test]
    fn an_alarm_the_truth_does_not_bear_out_is_false() {
        let matched = BTreeMap::from([(3u16, 7u32)]);
        let limits = AlarmLimits::default();
        let mut s = MotionScorer::default();
        // Own ship stopped at the origin. A moored boat 1 km east shown heading west at
        // 2 m/s: CPA 0 in 500 s, an alarm; the truth (still) has no relative motion.
        s.scan(
            &truth([0.0; 2], 1000.0),
            &matched,
            &[shown([-2.0, 0.0], 1000.0)],
            &limits,
        );
        // A ship truly heading west at 2 m/s: the same alarm, borne out.
        s.scan(
            &truth([-2.0, 0.0], 1000.0),
            &matched,
            &[shown([-2.0, 0.0], 1000.0)],
            &limits,
        );
        // A boat truly closing at 1 kn shown still: an alarm due and missed.
        s.scan(
            &truth([-0.5, 0.0], 250.0),
            &matched,
            &[shown([0.0; 2], 250.0)],
            &limits,
        );
        // Two tracks on one ship due an alarm, one raising it: due once, not missed.
        let both = BTreeMap::from([(3u16, 7u32), (4u16, 7u32)]);
        let other = TargetData {
            track: 4,
            ..shown([0.0; 2], 1000.0)
        };
        s.scan(
            &truth([-2.0, 0.0], 1000.0),
            &both,
            &[shown([-2.0, 0.0], 1000.0), other],
            &limits,
        );
        let m = s.scores();
        assert_eq!(m.alarm_target_scans, 3);
        assert_eq!((m.alarms_false, m.alarms_false_still), (1, 1));
        assert_eq!((m.alarms_due, m.alarms_missed), (3, 1));
    }
}
