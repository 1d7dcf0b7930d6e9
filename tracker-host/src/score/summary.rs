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
    /// Track-scans matched to a target, which the RMS errors are over (none: the RMS errors
    /// are 0 and the text says none was scored).
    pub matched_track_scans: u64,
    /// RMS position error of matched tracks, m.
    pub rms_position_m: f64,
    /// RMS velocity error of matched tracks, m/s.
    pub rms_velocity_mps: f64,
    /// 95th percentile of |CPA error| for settled tracks (3 minutes old) on approaching
    /// targets, m; `None` (JSON `null`) when no such track was scored, as in a run shorter
    /// than 3 minutes.
    pub cpa_error_p95_m: Option<f32>,
    /// 95th percentile of |TCPA error| likewise, s.
    pub tcpa_error_p95_s: Option<f32>,
    /// The cut-off of OSPA and GOSPA, m.
    pub ospa_c_m: f64,
    /// The order of OSPA and GOSPA.
    pub ospa_p: f64,
    /// OSPA between the targets in radar range and the confirmed and coasting tracks, mean
    /// over the scans, m.
    pub ospa_mean_m: f64,
    /// GOSPA (α = 2) likewise, m.
    pub gospa_mean_m: f64,
    /// OSPA per scored scan, m (JSON only).
    pub ospa_per_scan_m: Vec<f64>,
    /// GOSPA per scored scan, m (JSON only).
    pub gospa_per_scan_m: Vec<f64>,
    /// Target-scans in radar range with no track, of targets some track had followed
    /// before.
    pub untracked_target_scans: u64,
    /// Times a target in radar range lost its last track.
    pub track_breaks: u32,
    /// Breaks that ended with a track following the target again.
    pub breaks_reacquired: usize,
    /// Mean time from a break to the target's next track, scans.
    pub reacquire_mean_scans: f64,
    /// Longest such time, scans.
    pub reacquire_max_scans: u32,
    /// The motion shown against the truth ([`super::motion`]).
    #[serde(flatten)]
    pub motion: super::motion::MotionScores,
    /// Radar/AIS pairing against the truth, when the truth's ids are MMSIs and AIS was
    /// heard.
    #[serde(skip_serializing_if = "Option::is_none", flatten)]
    pub pairing: Option<super::pairing::PairingScores>,
}

impl Summary {
    /// The summary as text.
    pub fn report(&self) -> String {
        let mut s = format!(
            "scans: {}\n\
             targets: {} ({} detected, {} followed by a confirmed track, {} detected on 5+ scans never confirmed)\n\
             confirmation: {} targets within 5 scans of first detection, the slowest after {} scans\n\
             confirmed tracks: {} ({} false)\n\
             track swaps: {}\n\
             RMS error: {}\n\
             CPA/TCPA error after 3 min (95th percentile, approaching targets): {}\n\
             OSPA (c = {:.0} m, p = {}): mean {:.1} m; GOSPA (α = 2): mean {:.1} m\n\
             continuity: {} untracked target-scans, {} track breaks ({} re-acquired, mean {:.1} scans, longest {})",
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
            if self.matched_track_scans == 0 {
                "none scored (no track followed a target)".to_string()
            } else {
                format!(
                    "position {:.1} m, velocity {:.2} m/s",
                    self.rms_position_m, self.rms_velocity_mps
                )
            },
            match (self.cpa_error_p95_m, self.tcpa_error_p95_s) {
                (Some(cpa), Some(tcpa)) => format!("{cpa:.0} m, {tcpa:.0} s"),
                _ => "none scored (no track of an approaching target 3 min old)".to_string(),
            },
            self.ospa_c_m,
            self.ospa_p,
            self.ospa_mean_m,
            self.gospa_mean_m,
            self.untracked_target_scans,
            self.track_breaks,
            self.breaks_reacquired,
            self.reacquire_mean_scans,
            self.reacquire_max_scans,
        );
        s += &format!("\nmotion shown: {}", self.motion.line());
        if let Some(p) = &self.pairing {
            s += &format!(
                "\nradar/AIS pairs: {} pair-scans right, {} wrong, {} on tracks of no ship; {} of {} ships with a track and AIS paired ({} within {} scans), time to pair mean {:.1} s, 95 % {}, max {:.1} s; radar targets shown as AIS targets while pairing: {} scans right, {} wrong ({} ship-scans hidden), {} on tracks of no ship; {} ships associated (paired or shown as their AIS target), mean {:.1} s, 95 % {}; ships shown twice: {} ship-scans ({} after {} scans); ships without AIS shown only as the echo they share: {} ship-scans",
                p.pairs_correct,
                p.pairs_wrong,
                p.pairs_unverified,
                p.ships_paired,
                p.ships_with_track_and_ais,
                p.ships_paired_in_time,
                super::pairing::PAIRING_ALLOWANCE_SCANS,
                p.time_to_pair_mean_s,
                p.time_to_pair_p95_s
                    .map_or("not reached".to_string(), |t| format!("within {t:.1} s")),
                p.time_to_pair_max_s,
                p.merged_correct,
                p.merged_wrong,
                p.ships_hidden,
                p.merged_unverified,
                p.ships_associated,
                p.time_to_associate_mean_s,
                p.time_to_associate_p95_s
                    .map_or("not reached".to_string(), |t| format!("within {t:.1} s")),
                p.ships_unpaired,
                p.ships_unpaired_late,
                super::pairing::PAIRING_ALLOWANCE_SCANS,
                p.ships_in_echo_only,
            );
        }
        s
    }
}
