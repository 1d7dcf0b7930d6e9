//! The link budget: bytes on the wire for one scan of a given picture, and the largest
//! picture a serial line carries in a scan with half the line left free.
//!
//! The bytes are counted by encoding the very messages a scan exchanges (the ICD's types,
//! postcard, CRC, COBS, delimiters), filled with values at the expensive end of the real
//! ones, so the count is what a busy scan costs, not a best case:
//!
//! - plots and tracks 10–100 km from the origin (three bytes a coordinate), targets up to
//!   60 m/s (two bytes a speed component), gates of 6.5 m to 1.6 km (two bytes a Cholesky
//!   entry);
//! - track numbers and request ids past the one-byte varints; every track's rough gate
//!   holding two plots and every track updated; as many plots starting tracks as the
//!   table has room for;
//! - the scan's frames as the session sends them: the plots in parts (each answered, the
//!   last by the gates in parts), the assignments in parts (the last answered by the
//!   track states in parts).
//!
//! A UART frame of 8N1 is ten bits a byte.

use std::ops::Range;

use tracker_core::frame;
use tracker_core::icd::{
    Assignment, AssignmentBatch, DeviceToHost, GatedBatch, GatedPlots, Header, HostToDevice,
    PlotBatch, TrackBatch, TrackState, TrackStatus, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES,
    MAX_GATES_PER_MESSAGE, MAX_PLOTS_PER_MESSAGE, MAX_TRACKS_PER_MESSAGE, PROTOCOL_VERSION,
};
use tracker_core::track::MAX_TRACKS;
use tracker_core::tracker::MAX_PLOTS_PER_SCAN;

/// Bits on the line per byte: start, eight data bits, stop (8N1).
pub const UART_BITS_PER_BYTE: u32 = 10;

/// The scan period the budget is drawn for, s (a 24 rpm antenna).
pub const SCAN_PERIOD_S: f64 = 2.5;

/// Share of the line the tracker may use; the rest stays free for retries and other
/// traffic.
pub const LINE_SHARE: f64 = 0.5;

/// Bytes of one frame carrying `body` (header, CRC, COBS and the delimiter included).
fn frame_bytes<T: serde::Serialize>(body: &T) -> usize {
    let header = Header {
        protocol: PROTOCOL_VERSION,
        // Past the two-byte varints, as after an hour of scans.
        request_id: 20_000,
    };
    let mut scratch = [0u8; MAX_FRAME_BYTES];
    let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
    frame::encode(&header, body, &mut scratch, &mut out).expect("a part fits a frame")
}

/// Position `i` of a picture: 10–100 km from the origin, both coordinates three bytes.
fn position_m(i: usize) -> [f32; 2] {
    let x = 10_000.0 + 1_409.0 * (i % 64) as f32;
    [x, -x - 3.0]
}

/// `items` split at `per` a part, as the session splits a scan's messages: (part, parts,
/// the part's items); at least one part, an empty one for no items.
fn in_parts(items: usize, per: usize) -> impl Iterator<Item = (u8, u8, Range<usize>)> {
    let parts = items.div_ceil(per).max(1);
    (0..parts).map(move |p| (p as u8, parts as u8, p * per..items.min((p + 1) * per)))
}

/// Bytes on the wire, both ways, for one scan of `tracks` tracks and `plots` plots.
pub fn scan_bytes(tracks: usize, plots: usize) -> usize {
    let scan = 5_000u32;
    let time_ms = 12_500_000u64;
    let mut bytes = 0;
    // Plots out, in parts; each part but the last answered by an acknowledgement.
    for (part, parts, range) in in_parts(plots, MAX_PLOTS_PER_MESSAGE) {
        bytes += frame_bytes(&HostToDevice::Plots(PlotBatch {
            scan,
            time_ms,
            part,
            parts,
            plots_m: range.map(position_m).collect(),
        }));
        if part + 1 < parts {
            bytes += frame_bytes(&DeviceToHost::Ack);
        }
    }
    // The rough gates back.
    let track_number = |i: usize| 200 + i as u16;
    let plot_index = |i: usize| (i % plots.max(1)) as u16;
    for (part, parts, range) in in_parts(tracks, MAX_GATES_PER_MESSAGE) {
        let gates = range
            .map(|i| GatedPlots {
                track: track_number(i),
                predicted_m: position_m(i),
                innovation_cov_m2: [3600.0, 900.0, 5000.0],
                plots: [plot_index(2 * i), plot_index(2 * i + 1)]
                    .into_iter()
                    .take(plots.min(2))
                    .collect(),
            })
            .collect();
        bytes += frame_bytes(&DeviceToHost::Gated(GatedBatch {
            scan,
            part,
            parts,
            gates,
        }));
    }
    // Assignments out: every track updated, free slots filled from the other plots.
    let updates: Vec<Assignment> = (0..tracks.min(plots))
        .map(|i| Assignment {
            track: track_number(i),
            plot: Some(plot_index(i)),
        })
        .collect();
    let initiate: Vec<u16> = (tracks..plots)
        .take(MAX_TRACKS - tracks.min(MAX_TRACKS))
        .map(|i| i as u16)
        .collect();
    let assign: Vec<AssignmentBatch> = AssignmentBatch::parts(scan, &updates, &initiate).collect();
    for (part, batch) in assign.iter().enumerate() {
        bytes += frame_bytes(&HostToDevice::Assign(batch.clone()));
        if part + 1 < assign.len() {
            bytes += frame_bytes(&DeviceToHost::Ack);
        }
    }
    // The track states back, the new tracks among them.
    let reported = (tracks + initiate.len()).min(MAX_TRACKS);
    for (part, parts, range) in in_parts(reported, MAX_TRACKS_PER_MESSAGE) {
        let states = range
            .map(|i| TrackState {
                track: track_number(i),
                status: TrackStatus::Confirmed,
                position_m: position_m(i),
                velocity_mps: [-60.0, 45.0],
                age_scans: 1_000,
                hit_history: 0x3ff,
            })
            .collect();
        bytes += frame_bytes(&DeviceToHost::Tracks(TrackBatch {
            scan,
            part,
            parts,
            tracks: states,
        }));
    }
    bytes
}

/// Bytes a scan may take on a UART at `baud` with [`LINE_SHARE`] of the line.
pub fn bytes_per_scan_allowed(baud: u32) -> usize {
    (f64::from(baud) / f64::from(UART_BITS_PER_BYTE) * SCAN_PERIOD_S * LINE_SHARE) as usize
}

/// For each track count up to the device's table, the most plots a scan (up to the
/// device's limit) that fit `allowed` bytes: `(tracks, plots)` pairs, `None` where not
/// even an empty scan fits.
pub fn largest_pictures(allowed: usize) -> Vec<(usize, Option<usize>)> {
    (0..=MAX_TRACKS)
        .step_by(8)
        .map(|t| {
            let fits = (0..=MAX_PLOTS_PER_SCAN)
                .rev()
                .find(|&p| scan_bytes(t, p) <= allowed);
            (t, fits)
        })
        .collect()
}

/// The report `tracker-host link-budget` prints.
pub fn report(bauds: &[u32]) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "bytes on the link per scan, both ways (frames, CRC and COBS included; busy values, see docs)"
    );
    let plot_counts = [0usize, 50, 100, 200, MAX_PLOTS_PER_SCAN];
    let _ = write!(s, "{:>7}", "tracks");
    for p in plot_counts {
        let _ = write!(s, " {:>10}", format!("{p} plots"));
    }
    s.push('\n');
    for t in [0usize, 16, 40, MAX_TRACKS] {
        let _ = write!(s, "{t:>7}");
        for p in plot_counts {
            let _ = write!(s, " {:>10}", scan_bytes(t, p));
        }
        s.push('\n');
    }
    for &baud in bauds {
        let allowed = bytes_per_scan_allowed(baud);
        let _ = writeln!(
            s,
            "\n{baud} baud (8N1), {SCAN_PERIOD_S} s scans, {:.0} % of the line: {allowed} B a scan",
            LINE_SHARE * 100.0
        );
        let all = scan_bytes(MAX_TRACKS, MAX_PLOTS_PER_SCAN);
        if all <= allowed {
            let _ = writeln!(
                s,
                "  every picture the device holds fits: {MAX_TRACKS} tracks with {MAX_PLOTS_PER_SCAN} plots take {all} B"
            );
            continue;
        }
        for (t, p) in largest_pictures(allowed) {
            match p {
                Some(p) => {
                    let _ = writeln!(s, "  {t:>2} tracks: up to {p} plots a scan");
                }
                None => {
                    let _ = writeln!(s, "  {t:>2} tracks: does not fit");
                }
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_grow_with_tracks_and_plots() {
        assert!(scan_bytes(0, 0) > 0);
        assert!(scan_bytes(40, 100) > scan_bytes(40, 50));
        assert!(scan_bytes(40, 100) > scan_bytes(16, 100));
        // Deterministic counts of this protocol version; a change to the wire shows here.
        assert_eq!(scan_bytes(40, 200), 3_341);
        assert_eq!(scan_bytes(MAX_TRACKS, MAX_PLOTS_PER_SCAN), 4_204);
    }

    #[test]
    fn the_allowance_is_half_the_line() {
        // 115,200 baud at 10 bits a byte is 11,520 B/s: 28,800 B in 2.5 s, half of it.
        assert_eq!(bytes_per_scan_allowed(115_200), 14_400);
        assert_eq!(bytes_per_scan_allowed(38_400), 4_800);
    }

    #[test]
    fn a_slow_line_limits_the_picture() {
        let allowed = bytes_per_scan_allowed(9_600);
        for (t, p) in largest_pictures(allowed) {
            if let Some(p) = p {
                assert!(scan_bytes(t, p) <= allowed);
                if p < MAX_PLOTS_PER_SCAN {
                    assert!(scan_bytes(t, p + 1) > allowed);
                }
            }
        }
    }
}
