//! Scoring a run against the truth (the simulator's, or a truth file's): confirmation
//! delay, false tracks, track swaps, position and velocity errors, CPA and TCPA errors.
//!
//! Each scan, every confirmed or coasting track is matched to a true target within
//! [`MATCH_RADIUS_M`]: the one it followed before while that one is still within reach,
//! else the nearest. A track whose match changes from one target to another (because the
//! one it followed went out of reach) has *swapped*; a confirmed track unmatched on most of
//! its scans is *false*.

pub mod pairing;
mod summary;
mod truth;

use std::collections::{BTreeMap, BTreeSet};

use tracker_core::geo;
use tracker_core::icd::{TrackState, TrackStatus};

pub use summary::Summary;
pub use truth::{ScanTruth, TargetTruth};

/// A track within this distance of a target is following it, m.
pub const MATCH_RADIUS_M: f32 = 300.0;

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
}

fn p95(v: &mut [f32]) -> f32 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    v[((v.len() - 1) as f32 * 0.95).round() as usize]
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
        for t in tracks {
            if !matches!(t.status, TrackStatus::Confirmed | TrackStatus::Coasting) {
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
            let kept = rec_last
                .and_then(|id| truth.targets.iter().find(|x| x.id == id))
                .map(|x| (distance(x), x))
                .filter(|(d, _)| *d <= MATCH_RADIUS_M);
            let nearest = kept.or_else(|| {
                truth
                    .targets
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
            rec.last_matched_scan = Some(scan);
            if rec.last_truth.is_some_and(|prev| prev != x.id) {
                rec.swaps += 1;
            }
            rec.last_truth = Some(x.id);
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
    }

    /// Each confirmed or coasting track of the last scan scored and the target (truth id) it
    /// was matched to then.
    pub fn matched(&self, tracks: &[TrackState]) -> BTreeMap<u16, u32> {
        tracks
            .iter()
            .filter(|t| matches!(t.status, TrackStatus::Confirmed | TrackStatus::Coasting))
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
        Summary {
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
            rms_position_m: (self.sum_sq_pos / n).sqrt(),
            rms_velocity_mps: (self.sum_sq_vel / n).sqrt(),
            cpa_error_p95_m: p95(&mut cpa),
            tcpa_error_p95_s: p95(&mut tcpa),
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

    /// The scores so far; `None` when no scan carried truth.
    pub fn summary(&self) -> Option<Summary> {
        self.scored.then(|| {
            let mut s = self.scorer.summary();
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
            if truth.ids_are_mmsi && !report.ais.is_empty() {
                let pairs: Vec<(u16, u32)> =
                    report.paired.iter().map(|p| (p.track, p.mmsi)).collect();
                let ais: Vec<u32> = report.ais.iter().map(|a| a.mmsi).collect();
                let matched = self.scorer.matched(&report.tracks);
                let nearest = nearest_truth(truth, &report.tracks, &matched);
                self.pairing
                    .scan(report.scan, &matched, &nearest, &pairs, &ais);
                self.pairing_scored = true;
            }
        }
        Ok(())
    }
}
