//! Scoring a run against the simulation's truth: confirmation delay, false tracks, track
//! swaps, position and velocity errors, CPA and TCPA errors.
//!
//! Each scan, every confirmed or coasting track is matched to a true target within
//! [`MATCH_RADIUS_M`]: the one it followed before while that one is still within reach,
//! else the nearest. A track whose match changes from one target to another (because the
//! one it followed went out of reach) has *swapped*; a confirmed track unmatched on most of
//! its scans is *false*.

use std::collections::{BTreeMap, BTreeSet};

use tracker_core::geo;
use tracker_core::icd::{TrackState, TrackStatus};
use tracker_core::sim::ScanOutput;

use crate::target::OwnShip;

/// A track within this distance of a target is following it, m.
pub const MATCH_RADIUS_M: f32 = 300.0;

/// Track age after which CPA/TCPA accuracy is scored: 3 minutes, as the IMO tables.
pub const SETTLED_S: f32 = 180.0;

#[derive(Clone, Debug, Default)]
struct TrackRecord {
    matched_scans: u32,
    unmatched_scans: u32,
    last_truth: Option<u16>,
    swaps: u32,
}

/// Running scores.
#[derive(Clone, Debug, Default)]
pub struct Evaluator {
    tracks: BTreeMap<u16, TrackRecord>,
    first_detected: BTreeMap<u16, u32>,
    first_confirmed: BTreeMap<u16, u32>,
    sum_sq_pos: f64,
    sum_sq_vel: f64,
    matched: u64,
    cpa_errors_m: Vec<f32>,
    tcpa_errors_s: Vec<f32>,
    scans: u32,
}

/// The scores of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Scans run.
    pub scans: u32,
    /// Targets in the scenario.
    pub targets: usize,
    /// Targets ever detected.
    pub targets_detected: usize,
    /// Targets followed by a confirmed track at some point.
    pub targets_confirmed: usize,
    /// Longest delay from a target's first detection to its confirmed track, scans.
    pub max_confirm_delay_scans: u32,
    /// Targets confirmed within 5 scans of their first detection.
    pub confirmed_within_5: usize,
    /// Targets detected on 5+ scans but never confirmed.
    pub never_confirmed: usize,
    /// Confirmed tracks that followed no target on most of their scans.
    pub false_tracks: usize,
    /// Confirmed tracks in all.
    pub confirmed_tracks: usize,
    /// Times a track jumped from one target to another.
    pub swaps: u32,
    /// RMS position error of matched tracks, m.
    pub rms_position_m: f64,
    /// RMS velocity error of matched tracks, m/s.
    pub rms_velocity_mps: f64,
    /// 95th percentile of |CPA error| for settled tracks on approaching targets, m.
    pub cpa_error_p95_m: f32,
    /// 95th percentile of |TCPA error|, s.
    pub tcpa_error_p95_s: f32,
}

fn p95(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f32 * 0.95).round() as usize]
}

impl Evaluator {
    /// Scores one scan: the simulation's output and the tracks the tracker reported for it.
    pub fn scan(&mut self, truth: &ScanOutput, tracks: &[TrackState], scan_s: f32) {
        self.scans += 1;
        for (src, _) in truth.plot_source.iter().zip(&truth.plots) {
            if let Some(id) = src {
                self.first_detected.entry(*id).or_insert(truth.scan);
            }
        }
        let own = OwnShip {
            position_m: truth.own_position_m,
            velocity_mps: truth.own_velocity_mps,
        };
        for t in tracks {
            if !matches!(t.status, TrackStatus::Confirmed | TrackStatus::Coasting) {
                continue;
            }
            let distance = |x: &tracker_core::sim::Truth| {
                libm::hypotf(
                    x.position_m[0] - t.position_m[0],
                    x.position_m[1] - t.position_m[1],
                )
            };
            let rec_last = self.tracks.get(&t.track).and_then(|r| r.last_truth);
            // Stay with the target the track followed while it is still within reach (two
            // crossing targets are both near the track for a while); otherwise the nearest.
            let kept = rec_last
                .and_then(|id| truth.truth.iter().find(|x| x.id == id))
                .map(|x| (distance(x), x))
                .filter(|(d, _)| *d <= MATCH_RADIUS_M);
            let nearest = kept.or_else(|| {
                truth
                    .truth
                    .iter()
                    .map(|x| (distance(x), x))
                    .filter(|(d, _)| *d <= MATCH_RADIUS_M)
                    .min_by(|a, b| a.0.total_cmp(&b.0))
            });
            let rec = self.tracks.entry(t.track).or_default();
            let Some((d, x)) = nearest else {
                rec.unmatched_scans += 1;
                continue;
            };
            rec.matched_scans += 1;
            if rec.last_truth.is_some_and(|prev| prev != x.id) {
                rec.swaps += 1;
            }
            rec.last_truth = Some(x.id);
            self.first_confirmed.entry(x.id).or_insert(truth.scan);
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
    }

    /// The scores so far.
    pub fn summary(&self, targets: usize) -> Summary {
        let detected: BTreeSet<u16> = self.first_detected.keys().copied().collect();
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
        Summary {
            scans: self.scans,
            targets,
            targets_detected: detected.len(),
            targets_confirmed: self.first_confirmed.len(),
            max_confirm_delay_scans: max_delay,
            confirmed_within_5: delays.iter().filter(|&&d| d <= 5).count(),
            never_confirmed: never,
            false_tracks: self
                .tracks
                .values()
                .filter(|r| r.unmatched_scans > r.matched_scans)
                .count(),
            confirmed_tracks: self.tracks.len(),
            swaps: self.tracks.values().map(|r| r.swaps).sum(),
            rms_position_m: (self.sum_sq_pos / n).sqrt(),
            rms_velocity_mps: (self.sum_sq_vel / n).sqrt(),
            cpa_error_p95_m: p95(&mut cpa),
            tcpa_error_p95_s: p95(&mut tcpa),
        }
    }
}

impl Summary {
    /// The summary as text.
    pub fn report(&self) -> String {
        format!(
            "scans: {}\n\
             targets: {} ({} detected, {} followed by a confirmed track, {} detected on 5+ scans never confirmed)\n\
             confirmation: {} targets within 5 scans of first detection, the slowest after {} scans\n\
             confirmed tracks: {} ({} false)\n\
             track swaps: {}\n\
             RMS error: position {:.1} m, velocity {:.2} m/s\n\
             CPA/TCPA error after 3 min (95th percentile, approaching targets): {:.0} m, {:.0} s",
            self.scans,
            self.targets,
            self.targets_detected,
            self.targets_confirmed,
            self.never_confirmed,
            self.confirmed_within_5,
            self.max_confirm_delay_scans,
            self.confirmed_tracks,
            self.false_tracks,
            self.swaps,
            self.rms_position_m,
            self.rms_velocity_mps,
            self.cpa_error_p95_m,
            self.tcpa_error_p95_s,
        )
    }
}
