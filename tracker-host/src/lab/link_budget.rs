//! The link budget: bytes on the wire for one scan of a given picture, and the largest
//! picture a serial line carries in a scan with half the line left free.
//!
//! The bytes are counted by encoding the very messages a scan exchanges (the ICD's types,
//! the record writers of `tracker_core::icd::records`, postcard, CRC, COBS, delimiters),
//! with values at the expensive end of the real ones, so the count is what a busy scan
//! costs, not a best case:
//!
//! - plots 10–100 km from the origin (three bytes a coordinate); plot indices past the
//!   one-byte varints once there are more than 128 plots;
//! - every track's rough gate holding two plots and every track updated; as many plots
//!   starting tracks as the table has room for;
//! - coded against the base (the steady state: the host holds the last report) with
//!   changes at the busy end: predictions 3 m off the base moved on, new positions 40 m off
//!   it, velocities changed by 0.8 m/s, gate factors by 5 m (each two bytes but the
//!   prediction's); or, [`Coding::Whole`], every record whole (the scan after a lost
//!   report), targets up to 60 m/s and ages past 128 scans;
//! - the scan's frames as the session sends them: the plots in parts (each answered, the
//!   last by the gates in parts), the assignments in parts (the last answered by the
//!   track states in parts), parts filled as the device fills them.
//!
//! A UART frame of 8N1 is ten bits a byte.

use std::ops::Range;

use tracker_core::frame;
use tracker_core::icd::records::{self, GateOnGrid, GateReference, StateOnGrid};
use tracker_core::icd::varint::Writer;
use tracker_core::icd::{
    AssignmentBatch, Bytes, DeviceToHost, GatedBatch, Header, HostToDevice, PlotBatch, TrackBatch,
    TrackStatus, MAX_ASSIGNMENT_BYTES, MAX_ENCODED_FRAME_BYTES, MAX_PLOTS_PER_MESSAGE,
    MAX_PLOT_BYTES, MAX_RECORD_BYTES, PROTOCOL_VERSION,
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

/// How the scan's gates and states are coded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coding {
    /// Against the base: the host holds the last report (every scan but one after a loss).
    Base,
    /// Whole records: the scan after a report the host did not get, or its first.
    Whole,
}

/// Bytes of one frame carrying `body` (header, CRC, COBS and the delimiter included).
fn frame_bytes<T: serde::Serialize>(body: &T) -> usize {
    let header = Header {
        protocol: PROTOCOL_VERSION,
        // Past the two-byte varints, as after an hour of scans.
        request_id: 20_000,
    };
    let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
    frame::encode(&header, body, &mut out).expect("a part fits a frame")
}

/// Position `i` of a picture: 10–100 km from the origin, both coordinates three bytes.
fn position_m(i: usize) -> [f32; 2] {
    let x = 10_000.0 + 1_409.0 * (i % 64) as f32;
    [x, -x - 3.0]
}

/// `items` split at `per` a part, as the session splits a scan's plots: (part, parts, the
/// part's items); at least one part, an empty one for no items.
fn in_parts(items: usize, per: usize) -> impl Iterator<Item = (u8, u8, Range<usize>)> {
    let parts = items.div_ceil(per).max(1);
    (0..parts).map(move |p| (p as u8, parts as u8, p * per..items.min((p + 1) * per)))
}

/// Bytes of a report whose records `write` writes (record `i` after record `i - 1`'s
/// track), in parts filled as the device fills them: a record goes into the part while
/// `room` bytes are left.
fn report_bytes(
    records: usize,
    room: usize,
    write: impl Fn(&mut Writer<'_>, usize),
    message: impl Fn(u8, bool, &[u8]) -> usize,
) -> usize {
    let mut bytes = 0;
    let (mut i, mut part) = (0, 0u8);
    loop {
        let mut buf = [0u8; MAX_RECORD_BYTES];
        let mut w = Writer::new(&mut buf);
        while i < records && w.room() >= room {
            write(&mut w, i);
            i += 1;
        }
        let last = i >= records;
        bytes += message(part, last, w.written());
        if last {
            return bytes;
        }
        part += 1;
    }
}

/// Bytes on the wire, both ways, for one busy scan of `tracks` tracks and `plots` plots,
/// its records coded as `coding`.
pub fn scan_bytes_coded(tracks: usize, plots: usize, coding: Coding) -> usize {
    let scan = 5_000u32;
    let time_ms = 12_500_000u64;
    let base_scan = (coding == Coding::Base).then_some(scan - 1);
    let mut bytes = 0;
    // Plots out, in parts; each part but the last answered by an acknowledgement.
    let all_plots: Vec<[f32; 2]> = (0..plots).map(position_m).collect();
    for (part, parts, range) in in_parts(plots, MAX_PLOTS_PER_MESSAGE) {
        let mut buf = [0u8; MAX_PLOT_BYTES];
        let head = PlotBatch {
            scan,
            time_ms,
            part,
            parts,
            base_scan,
            plots: Bytes(&[]),
        };
        let batch = PlotBatch::pack(head, &all_plots[range], &mut buf);
        bytes += frame_bytes(&HostToDevice::Plots(batch));
        if part + 1 < parts {
            bytes += frame_bytes(&DeviceToHost::Ack);
        }
    }
    // The rough gates back, every track with two plots (none without plots).
    let track_number = |i: usize| 200 + i as u16;
    let plot_index = |i: usize| (i % plots.max(1)) as u16;
    let gated = if plots == 0 { 0 } else { tracks };
    let at = |i: usize| records::tenths(position_m(i));
    bytes += report_bytes(
        gated,
        records::MAX_GATE_RECORD_BYTES,
        |w, i| {
            let p = at(i);
            let gate = GateOnGrid {
                track: track_number(i),
                plots: [plot_index(2 * i), plot_index(2 * i + 1)]
                    .into_iter()
                    .take(plots.min(2))
                    .collect(),
                predicted_tenths: [p[0] + 30, p[1] - 30],
                cholesky_cm: [6000, 1500, 7070],
            };
            let reference = match coding {
                Coding::Base => GateReference {
                    moved_on: Some(p),
                    cholesky_cm: Some([6500, 1500, 6570]),
                },
                Coding::Whole => GateReference::default(),
            };
            let prev = if i == 0 { 0 } else { track_number(i - 1) };
            records::write_gate(w, prev, &gate, reference, at(2 * i % plots.max(1)));
        },
        |part, last, gates| {
            frame_bytes(&DeviceToHost::Gated(GatedBatch {
                scan,
                part,
                last,
                base_scan,
                live_tracks: tracks as u16,
                gates: Bytes(gates),
            }))
        },
    );
    // Assignments out: every track updated, free slots filled from the other plots.
    let updates: Vec<(u16, u16)> = (0..tracks.min(plots))
        .map(|i| (track_number(i), plot_index(i)))
        .collect();
    let initiate: Vec<u16> = (tracks..plots)
        .take(MAX_TRACKS - tracks.min(MAX_TRACKS))
        .map(|i| i as u16)
        .collect();
    let parts = AssignmentBatch::parts(updates.len(), initiate.len());
    for part in 0..parts {
        let mut buf = [0u8; MAX_ASSIGNMENT_BYTES];
        let batch = AssignmentBatch::pack(scan, (part, parts), &updates, &initiate, &mut buf);
        bytes += frame_bytes(&HostToDevice::Assign(batch));
        if part + 1 < parts {
            bytes += frame_bytes(&DeviceToHost::Ack);
        }
    }
    // The track states back (the tracks started this scan have one hit: not reported).
    let dt_s = records::interval_s(time_ms - 2_500, time_ms);
    bytes += report_bytes(
        tracks,
        records::MAX_STATE_RECORD_BYTES,
        |w, i| {
            let p = at(i);
            let base = StateOnGrid {
                track: track_number(i),
                status: TrackStatus::Confirmed,
                position_tenths: p,
                velocity_hundredths: [-6_000, 4_500],
                age_scans: 1_000,
                hit_history: 0x3ff,
            };
            let moved = base.moved_on(dt_s);
            let now = StateOnGrid {
                position_tenths: [moved[0] + 400, moved[1] - 400],
                velocity_hundredths: [-6_080, 4_580],
                age_scans: 1_001,
                ..base
            };
            let prev = if i == 0 { 0 } else { track_number(i - 1) };
            let with = (coding == Coding::Base).then_some(&base);
            records::write_state(w, prev, &now, true, with, dt_s);
        },
        |part, last, states| {
            frame_bytes(&DeviceToHost::Tracks(TrackBatch {
                scan,
                part,
                last,
                base_scan,
                states: Bytes(states),
            }))
        },
    );
    bytes
}

/// Bytes on the wire, both ways, for one busy scan of `tracks` tracks and `plots` plots in
/// the steady state ([`Coding::Base`]).
pub fn scan_bytes(tracks: usize, plots: usize) -> usize {
    scan_bytes_coded(tracks, plots, Coding::Base)
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
    let _ = writeln!(
        s,
        "the same with every record whole (the scan after a lost report):"
    );
    for t in [0usize, 16, 40, MAX_TRACKS] {
        let _ = write!(s, "{t:>7}");
        for p in plot_counts {
            let _ = write!(s, " {:>10}", scan_bytes_coded(t, p, Coding::Whole));
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
        assert!(scan_bytes_coded(40, 100, Coding::Whole) > scan_bytes(40, 100));
        // Deterministic counts of this protocol version; a change to the wire shows here.
        assert_eq!(scan_bytes(40, 200), 2_311);
        assert_eq!(scan_bytes(MAX_TRACKS, MAX_PLOTS_PER_SCAN), 3_399);
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
