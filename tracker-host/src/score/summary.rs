//! A scored run's summary: as text for the operator, and as JSON fields (stable snake_case
//! keys, units in the names) in `--summary-json`.

use serde::Serialize;

/// The scores of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Scans scored.
    #[serde(rename = "scored_scans")]
    pub scans: u32,
    /// Targets in the truth.
    pub targets: usize,
    /// Targets ever detected.
    pub targets_detected: usize,
    /// Targets followed by a confirmed track at some point.
    pub targets_confirmed: usize,
    /// Longest delay from a target's first detection to its confirmed track, scans.
    pub max_confirm_delay_scans: u32,
    /// Targets confirmed within 5 scans of their first detection.
    pub confirmed_within_5_scans: usize,
    /// Targets detected on 5+ scans but never confirmed.
    pub never_confirmed: usize,
    /// Confirmed tracks that followed no target on most of their scans.
    pub false_tracks: usize,
    /// Confirmed tracks in all.
    pub confirmed_tracks: usize,
    /// Times a track jumped from one target to another.
    pub track_swaps: u32,
    /// RMS position error of matched tracks, m.
    pub rms_position_m: f64,
    /// RMS velocity error of matched tracks, m/s.
    pub rms_velocity_mps: f64,
    /// 95th percentile of |CPA error| for settled tracks on approaching targets, m.
    pub cpa_error_p95_m: f32,
    /// 95th percentile of |TCPA error|, s.
    pub tcpa_error_p95_s: f32,
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
            self.confirmed_within_5_scans,
            self.max_confirm_delay_scans,
            self.confirmed_tracks,
            self.false_tracks,
            self.track_swaps,
            self.rms_position_m,
            self.rms_velocity_mps,
            self.cpa_error_p95_m,
            self.tcpa_error_p95_s,
        )
    }
}
