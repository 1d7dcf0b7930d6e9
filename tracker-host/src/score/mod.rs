//! Scoring a run against the truth (the simulator's, or a truth file's): confirmation
//! delay, false tracks, track swaps, position and velocity errors, CPA and TCPA errors.
//!
//! Each scan, every confirmed or coasting track is matched to a true target within
//! [`MATCH_RADIUS_M`]: the one it followed before while that one is still within reach and
//! no other is nearer by more than [`SWAP_MARGIN_M`], else the nearest. A track whose match changes from one target to another (because the
//! one it followed went out of reach) has *swapped*; a confirmed track unmatched on most of
//! its scans is *false*.
//!
//! Each scan also gives the field's set distances between the targets in radar range and
//! the confirmed and coasting tracks ([`ospa`]: OSPA and GOSPA, c = [`ospa::OSPA_C_M`],
//! p = [`ospa::OSPA_P`]), and continuity: a target in radar range that some track followed
//! before and none follows now is *untracked* that scan; the scan it loses its last track
//! starts a *track break*, which ends when a track follows it again (the time to
//! re-acquire).

pub mod motion;
pub mod ospa;
pub mod pairing;
mod summary;
mod truth;

use std::collections::{BTreeMap, BTreeSet};

use tracker_core::geo;
use tracker_core::icd::TrackState;

pub use summary::Summary;
pub use truth::{ScanTruth, TargetTruth};

/// A track within this distance of a target is following it, m.
pub const MATCH_RADIUS_M: f32 = 300.0;

/// A track stays with the target it followed unless another is nearer by more than this,
/// m: two crossing targets are both near a track for a while, and a track between them has
/// not swapped; one that sits on the other target has.
pub const SWAP_MARGIN_M: f32 = 100.0;

/// Track age after which CPA/TCPA accuracy is scored: 3 minutes, as the IMO tables.
pub const SETTLED_S: f32 = 180.0;

#[derive(Clone, Debug, Default)]
struct TrackRecord {
    matched_scans: u32,
    unmatched_scans: u32,
    last_truth: Option<u32>,
    /// The scan it was last matched at.
    last_matched_scan: Option<u32>,
    swaps: u32,
}

/// Running scores.
#[derive(Clone, Debug, Default)]
pub struct Scorer {
    tracks: BTreeMap<u16, TrackRecord>,
    first_detected: BTreeMap<u32, u32>,
    first_confirmed: BTreeMap<u32, u32>,
    targets: BTreeSet<u32>,
    sum_sq_pos: f64,
    sum_sq_vel: f64,
    matched: u64,
    cpa_errors_m: Vec<f32>,
    tcpa_errors_s: Vec<f32>,
    scans: u32,
    last_scan: Option<u32>,
    continuity: BTreeMap<u32, Continuity>,
    untracked_target_scans: u64,
    track_breaks: u32,
    reacquire_scans: Vec<u32>,
    ospa_m: Vec<f64>,
    gospa_m: Vec<f64>,
}

/// One target's continuity so far.
#[derive(Clone, Copy, Debug, Default)]
struct Continuity {
    /// Some track has followed it.
    followed: bool,
    /// The scan its last track was lost, while it has none.
    broken_since: Option<u32>,
}

/// The 95th percentile of `v`, `None` when it is empty.
fn p95(v: &mut [f32]) -> Option<f32> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(((v.len() - 1) as f32 * 0.95).round() as usize)
        .copied()
}

impl Scorer {
    /// Scores one scan: its number, the truth, and the tracks the tracker reported for it;
    /// `scan_s` is the antenna period (a track's age in scans times it is its age in s).
    pub fn scan(&mut self, scan: u32, truth: &ScanTruth, tracks: &[TrackState], scan_s: f32) {
        self.scans += 1;
        self.last_scan = Some(scan);
        for t in &truth.targets {
            self.targets.insert(t.id);
            if t.detected {
                self.first_detected.entry(t.id).or_insert(scan);
            }
        }
        let own = truth.own;
        let mut followed: BTreeSet<u32> = BTreeSet::new();
        for t in tracks {
            if !t.status.is_firm() {
                continue;
            }
            let distance = |x: &TargetTruth| {
                libm::hypotf(
                    x.position_m[0] - t.position_m[0],
                    x.position_m[1] - t.position_m[1],
                )
            };
            let rec_last = self.tracks.get(&t.track).and_then(|r| r.last_truth);
            // Stay with the target the track followed while it is still within reach (two
            // crossing targets are both near the track for a while); otherwise the nearest.
            let nearest_of_all = truth
                .targets
                .iter()
                .map(|x| (distance(x), x))
                .filter(|(d, _)| *d <= MATCH_RADIUS_M)
                .min_by(|a, b| a.0.total_cmp(&b.0));
            // ...but not once another target is clearly nearer: then it has swapped.
            let kept = rec_last
                .and_then(|id| truth.targets.iter().find(|x| x.id == id))
                .map(|x| (distance(x), x))
                .filter(|(d, _)| *d <= MATCH_RADIUS_M)
                .filter(|(d, _)| nearest_of_all.is_some_and(|(n, _)| *d <= n + SWAP_MARGIN_M));
            let nearest = kept.or(nearest_of_all);
            let rec = self.tracks.entry(t.track).or_default();
            let Some((d, x)) = nearest else {
                rec.unmatched_scans += 1;
                continue;
            };
            rec.matched_scans += 1;
            rec.last_matched_scan = Some(scan);
            if rec.last_truth.is_some_and(|prev| prev != x.id) {
                rec.swaps += 1;
            }
            rec.last_truth = Some(x.id);
            followed.insert(x.id);
            self.first_confirmed.entry(x.id).or_insert(scan);
            self.sum_sq_pos += f64::from(d * d);
            let dv = libm::hypotf(
                x.velocity_mps[0] - t.velocity_mps[0],
                x.velocity_mps[1] - t.velocity_mps[1],
            );
            self.sum_sq_vel += f64::from(dv * dv);
            self.matched += 1;
            if f32::from(t.age_scans) * scan_s >= SETTLED_S {
                let est = geo::cpa(
                    own.position_m,
                    own.velocity_mps,
                    t.position_m,
                    t.velocity_mps,
                );
                let tru = geo::cpa(
                    own.position_m,
                    own.velocity_mps,
                    x.position_m,
                    x.velocity_mps,
                );
                // Scored where TCPA means something: approaching, within 30 minutes.
                if tru.tcpa_s > 0.0 && tru.tcpa_s < 1800.0 {
                    self.cpa_errors_m.push((est.cpa_m - tru.cpa_m).abs());
                    self.tcpa_errors_s.push((est.tcpa_s - tru.tcpa_s).abs());
                }
            }
        }
        self.continuity_scan(scan, truth, &followed);
        self.set_distance_scan(truth, tracks);
    }

    fn continuity_scan(&mut self, scan: u32, truth: &ScanTruth, followed: &BTreeSet<u32>) {
        for x in truth.targets.iter().filter(|x| x.in_range) {
            let c = self.continuity.entry(x.id).or_default();
            if followed.contains(&x.id) {
                if let Some(since) = c.broken_since.take() {
                    self.reacquire_scans.push(scan.saturating_sub(since));
                }
                c.followed = true;
            } else if c.followed {
                self.untracked_target_scans += 1;
                if c.broken_since.is_none() {
                    c.broken_since = Some(scan);
                    self.track_breaks += 1;
                }
            }
        }
    }

    fn set_distance_scan(&mut self, truth: &ScanTruth, tracks: &[TrackState]) {
        let xs: Vec<[f64; 2]> = truth
            .targets
            .iter()
            .filter(|x| x.in_range)
            .map(|x| x.position_m.map(f64::from))
            .collect();
        let ys: Vec<[f64; 2]> = tracks
            .iter()
            .filter(|t| t.status.is_firm())
            .map(|t| t.position_m.map(f64::from))
            .collect();
        let d = ospa::set_distance(&xs, &ys, ospa::OSPA_C_M, ospa::OSPA_P);
        self.ospa_m.push(d.ospa_m);
        self.gospa_m.push(d.gospa_m);
    }

    /// Each confirmed or coasting track of the last scan scored and the target (truth id) it
    /// was matched to then.
    pub fn matched(&self, tracks: &[TrackState]) -> BTreeMap<u16, u32> {
        tracks
            .iter()
            .filter(|t| t.status.is_firm())
            .filter_map(|t| {
                let r = self.tracks.get(&t.track)?;
                // Matched this very scan, not some scan before it.
                (r.last_matched_scan.is_some() && r.last_matched_scan == self.last_scan)
                    .then_some(r.last_truth)
                    .flatten()
                    .map(|id| (t.track, id))
            })
            .collect()
    }

    /// The scores so far.
    pub fn summary(&self) -> Summary {
        let detected: BTreeSet<u32> = self.first_detected.keys().copied().collect();
        let delays: Vec<u32> = self
            .first_confirmed
            .iter()
            .filter_map(|(id, c)| self.first_detected.get(id).map(|d| c.saturating_sub(*d)))
            .collect();
        let max_delay = delays.iter().copied().max().unwrap_or(0);
        let never = detected
            .iter()
            .filter(|id| !self.first_confirmed.contains_key(id))
            .filter(|id| {
                self.first_detected
                    .get(id)
                    .is_some_and(|d| self.scans.saturating_sub(*d) >= 5)
            })
            .count();
        let n = self.matched.max(1) as f64;
        let mut cpa = self.cpa_errors_m.clone();
        let mut tcpa = self.tcpa_errors_s.clone();
        let mean = |v: &[f64]| v.iter().fold(0.0, |a, x| a + x) / v.len().max(1) as f64;
        let reacquired = self.reacquire_scans.len();
        Summary {
            motion: Default::default(),
            scans: self.scans,
            targets: self.targets.len(),
            targets_detected: detected.len(),
            targets_confirmed: self.first_confirmed.len(),
            max_confirm_delay_scans: max_delay,
            confirmed_within_5_scans: delays.iter().filter(|&&d| d <= 5).count(),
            never_confirmed: never,
            false_tracks: self
                .tracks
                .values()
                .filter(|r| r.unmatched_scans > r.matched_scans)
                .count(),
            confirmed_tracks: self.tracks.len(),
            track_swaps: self.tracks.values().map(|r| r.swaps).sum(),
            matched_track_scans: self.matched,
            rms_position_m: (self.sum_sq_pos / n).sqrt(),
            rms_velocity_mps: (self.sum_sq_vel / n).sqrt(),
            cpa_error_p95_m: p95(&mut cpa),
            tcpa_error_p95_s: p95(&mut tcpa),
            ospa_c_m: ospa::OSPA_C_M,
            ospa_p: ospa::OSPA_P,
            ospa_mean_m: mean(&self.ospa_m),
            gospa_mean_m: mean(&self.gospa_m),
            ospa_per_scan_m: self.ospa_m.clone(),
            gospa_per_scan_m: self.gospa_m.clone(),
            untracked_target_scans: self.untracked_target_scans,
            track_breaks: self.track_breaks,
            breaks_reacquired: reacquired,
            reacquire_mean_scans: self
                .reacquire_scans
                .iter()
                .fold(0.0, |a, &s| a + f64::from(s))
                / reacquired.max(1) as f64,
            reacquire_max_scans: self.reacquire_scans.iter().copied().max().unwrap_or(0),
            pairing: None,
        }
    }
}

/// For each matched track, the truth target nearest it.
fn nearest_truth(
    truth: &ScanTruth,
    tracks: &[TrackState],
    matched: &BTreeMap<u16, u32>,
) -> BTreeMap<u16, u32> {
    tracks
        .iter()
        .filter(|t| matched.contains_key(&t.track))
        .filter_map(|t| {
            let d = |x: &TargetTruth| {
                libm::hypotf(
                    x.position_m[0] - t.position_m[0],
                    x.position_m[1] - t.position_m[1],
                )
            };
            let x = truth.targets.iter().min_by(|a, b| d(a).total_cmp(&d(b)))?;
            Some((t.track, x.id))
        })
        .collect()
}

/// The scorer as a sink: scores every scan whose source carries truth.
#[derive(Clone, Debug, Default)]
pub struct ScoreSink {
    scorer: Scorer,
    scan_s: f32,
    scored: bool,
    pairing: pairing::PairingScorer,
    motion: motion::MotionScorer,
    /// The run's CPA/TCPA alarm limits (the motion scorer counts false alarms).
    limits: crate::session::target::AlarmLimits,
    /// Pairing is scored once the truth's ids are MMSIs (real traffic) and AIS is heard.
    pairing_scored: bool,
}

impl ScoreSink {
    /// Scores with `scan_s`, the antenna period (a track's age in scans times it is its age).
    pub fn new(scan_s: f32) -> Self {
        ScoreSink {
            scan_s,
            ..ScoreSink::default()
        }
    }

    /// … counting the alarms raised with `limits` against the truth.
    pub fn with_alarms(mut self, limits: crate::session::target::AlarmLimits) -> Self {
        self.limits = limits;
        self
    }

    /// The scores so far; `None` when no scan carried truth.
    pub fn summary(&self) -> Option<Summary> {
        self.scored.then(|| {
            let mut s = self.scorer.summary();
            s.motion = self.motion.scores();
            s.pairing = self
                .pairing_scored
                .then(|| self.pairing.scores(f64::from(self.scan_s)));
            s
        })
    }
}

impl crate::sink::ScanSink for ScoreSink {
    fn scan(
        &mut self,
        scan: &crate::source::SourceScan,
        report: &crate::session::ScanReport,
    ) -> anyhow::Result<()> {
        if let Some(truth) = &scan.truth {
            self.scorer
                .scan(report.scan, truth, &report.tracks, self.scan_s);
            self.scored = true;
            let matched = self.scorer.matched(&report.tracks);
            self.motion
                .scan(truth, &matched, &report.targets, &self.limits);
            if truth.ids_are_mmsi && !report.ais.is_empty() {
                let pairs: Vec<(u16, u32)> =
                    report.paired.iter().map(|p| (p.track, p.mmsi)).collect();
                let ais: Vec<u32> = report.ais.iter().map(|a| a.mmsi).collect();
                let nearest = nearest_truth(truth, &report.tracks, &matched);
                let merged: Vec<(u16, u32)> =
                    report.merged.iter().map(|c| (c.track, c.mmsi)).collect();
                let drawn: Vec<u16> = report.targets.iter().map(|t| t.track).collect();
                let in_echo: Vec<u16> = report.in_echo.iter().map(|t| t.track).collect();
                let picture = pairing::Picture {
                    pairs: &pairs,
                    merged: &merged,
                    ais: &ais,
                    drawn: &drawn,
                    in_echo: &in_echo,
                };
                self.pairing.scan(report.scan, &matched, &nearest, &picture);
                self.pairing_scored = true;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracker_core::icd::TrackStatus;

    fn target(id: u32, east_m: f32, in_range: bool) -> TargetTruth {
        TargetTruth {
            id,
            position_m: [east_m, 0.0],
            velocity_mps: [0.0, 0.0],
            detected: true,
            in_range,
        }
    }

    fn track(id: u16, east_m: f32) -> TrackState {
        TrackState {
            track: id,
            status: TrackStatus::Confirmed,
            position_m: [east_m, 0.0],
            velocity_mps: [0.0, 0.0],
            age_scans: 10,
            hit_history: 0x3ff,
        }
    }

    fn truth(targets: &[TargetTruth]) -> ScanTruth {
        ScanTruth {
            targets: targets.to_vec(),
            ..ScanTruth::default()
        }
    }

    #[test]
    fn a_run_with_no_track_on_a_target_scores_no_rms_error() {
        let mut s = Scorer::default();
        s.scan(0, &truth(&[target(1, 0.0, true)]), &[], 2.5);
        let m = s.summary();
        assert_eq!(m.matched_track_scans, 0);
        assert!(
            m.report().contains("RMS error: none scored"),
            "{}",
            m.report()
        );
        s.scan(1, &truth(&[target(1, 0.0, true)]), &[track(1, 3.0)], 2.5);
        let m = s.summary();
        assert_eq!(m.matched_track_scans, 1);
        assert!(
            m.report().contains("RMS error: position 3.0 m"),
            "{}",
            m.report()
        );
    }

    #[test]
    fn a_break_counts_its_untracked_scans_and_its_time_to_reacquire() {
        let mut s = Scorer::default();
        // Target 1 tracked on scans 0–2, no track on 3 and 4, a new track from 5. Target 2
        // is never tracked (not counted: no track ever followed it); target 3 is tracked,
        // then leaves radar range with its track gone (not counted).
        for scan in 0..7 {
            let tracks = match scan {
                0..=2 => vec![track(1, 0.0), track(3, 5000.0)],
                3 | 4 => vec![],
                _ => vec![track(7, 10.0)],
            };
            let t = truth(&[
                target(1, 0.0, true),
                target(2, 2000.0, true),
                target(3, 5000.0, scan <= 2),
            ]);
            s.scan(scan, &t, &tracks, 2.5);
        }
        let m = s.summary();
        assert_eq!(m.untracked_target_scans, 2);
        assert_eq!(m.track_breaks, 1);
        assert_eq!(m.breaks_reacquired, 1);
        assert_eq!(m.reacquire_mean_scans, 2.0);
        assert_eq!(m.reacquire_max_scans, 2);
        // OSPA per scan: scans 0–2: targets 1, 2, 3 against tracks at 0 and 5000: one
        // missed (c): √(500²/3); scans 3–4: two targets in range, no track: c; 5–6: the
        // track 10 m off target 1, target 2 missed: √((10² + 500²)/2).
        let want = [
            (250_000.0_f64 / 3.0).sqrt(),
            500.0,
            (250_100.0_f64 / 2.0).sqrt(),
        ];
        let got = &m.ospa_per_scan_m;
        assert_eq!(got.len(), 7);
        for (i, g) in got.iter().enumerate() {
            let w = want[match i {
                0..=2 => 0,
                3 | 4 => 1,
                _ => 2,
            }];
            assert!((g - w).abs() < 1e-3, "scan {i}: {g} against {w}");
        }
    }

    #[test]
    fn a_track_that_sits_on_another_target_has_swapped() {
        let mut s = Scorer::default();
        // Targets 130 m apart; the track follows target 1, drifts to the middle (still
        // target 1's), then sits on target 2: one swap.
        for (scan, east) in [(0, 0.0), (1, 60.0), (2, 125.0)] {
            let t = truth(&[target(1, 0.0, true), target(2, 130.0, true)]);
            s.scan(scan, &t, &[track(4, east)], 2.5);
        }
        assert_eq!(s.summary().track_swaps, 1);
    }
}
