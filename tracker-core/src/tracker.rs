//! The device's scan cycle (thesis §2.4): plots in, rough gates out; assignments in, track
//! states out.
//!
//! A scan arrives as [`PlotBatch`] parts, in order. When the last part is in, every track
//! is predicted to the scan time and rough-gated, and the gates go back to the host in
//! [`GatedBatch`] parts. The host answers with [`AssignmentBatch`] parts; when the last is
//! in, the table is updated and the track states go back in [`TrackBatch`] parts. Anything
//! out of order is refused with [`ErrorCode::OutOfSequence`] and changes nothing.

use heapless::Vec;

use crate::bounded::take_up_to;
use crate::filter::Measurement;
use crate::geo::EastNorth;
use crate::icd::{
    Assignment, AssignmentBatch, ErrorCode, GatedBatch, PlotBatch, TrackBatch, TrackCommand,
    TrackerConfig, MAX_GATES_PER_MESSAGE, MAX_TRACKS_PER_MESSAGE,
};
use crate::track::{ApplyReport, TrackTable, MAX_TRACKS};

/// Plots one scan may hold.
pub const MAX_PLOTS_PER_SCAN: usize = 256;

/// Where a scan is in its cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Phase {
    /// Waiting for the first plot part of a scan.
    Idle,
    /// Receiving plot parts; the next expected part.
    Plots { scan: u32, next: u8, parts: u8 },
    /// Gates sent; receiving assignment parts.
    Assign { scan: u32, next: u8, parts: u8 },
}

/// The device-side tracker.
#[derive(Clone, Debug)]
pub struct Tracker {
    table: TrackTable,
    phase: Phase,
    scan_time_ms: u64,
    last_scan_time_ms: Option<u64>,
    plots: Vec<EastNorth, MAX_PLOTS_PER_SCAN>,
    assignments: Vec<Assignment, MAX_TRACKS>,
    initiate: Vec<u16, MAX_PLOTS_PER_SCAN>,
    last_report: ApplyReport,
    report_scan: u32,
}

impl Default for Tracker {
    fn default() -> Self {
        Self::new()
    }
}

impl Tracker {
    /// An empty tracker with the default configuration.
    pub const fn new() -> Self {
        Tracker {
            table: TrackTable::new(),
            phase: Phase::Idle,
            scan_time_ms: 0,
            last_scan_time_ms: None,
            plots: Vec::new(),
            assignments: Vec::new(),
            initiate: Vec::new(),
            last_report: ApplyReport {
                updated: 0,
                coasted: 0,
                initiated: 0,
                refused_full: 0,
                dropped: 0,
            },
            report_scan: 0,
        }
    }

    /// The track table.
    pub fn table(&self) -> &TrackTable {
        &self.table
    }

    /// What the last scan's update did.
    pub fn last_report(&self) -> ApplyReport {
        self.last_report
    }

    /// Sets the configuration for new tracks.
    ///
    /// # Errors
    /// [`ErrorCode::InvalidValue`] as [`TrackTable::configure`].
    pub fn configure(&mut self, config: TrackerConfig) -> Result<(), ErrorCode> {
        self.table.configure(config)
    }

    /// Takes one part of a scan's plots. Returns the number of gate parts to send when the
    /// scan is complete, `None` while more parts are due.
    ///
    /// # Errors
    /// [`ErrorCode::OutOfSequence`] for a part out of order or a scan not later than the last; [`ErrorCode::CapacityExceeded`] past [`MAX_PLOTS_PER_SCAN`]; [`ErrorCode::InvalidValue`] for a plot no filter would take (beyond [`crate::filter::MAX_POSITION_M`]; the scan is dropped).
    pub fn plots(&mut self, batch: &PlotBatch) -> Result<Option<u8>, ErrorCode> {
        let expected = match self.phase {
            Phase::Plots { scan, next, parts } if scan == batch.scan && parts == batch.parts => {
                next
            }
            _ => 0,
        };
        if batch.part != expected || batch.parts == 0 || batch.part >= batch.parts {
            return Err(ErrorCode::OutOfSequence);
        }
        if batch.part == 0 {
            if self.last_scan_time_ms.is_some_and(|t| batch.time_ms <= t) {
                return Err(ErrorCode::OutOfSequence);
            }
            self.plots.clear();
        }
        if self.plots.len() + batch.plots_m.len() > MAX_PLOTS_PER_SCAN {
            self.phase = Phase::Idle;
            return Err(ErrorCode::CapacityExceeded);
        }
        if batch
            .plots_m
            .iter()
            .any(|&p| Measurement::<f32>::new(p).is_err())
        {
            self.phase = Phase::Idle;
            return Err(ErrorCode::InvalidValue);
        }
        // Capacity was checked above.
        let _ = self.plots.extend_from_slice(&batch.plots_m);
        if batch.part + 1 < batch.parts {
            self.phase = Phase::Plots {
                scan: batch.scan,
                next: batch.part + 1,
                parts: batch.parts,
            };
            return Ok(None);
        }
        // The scan is complete: predict and gate.
        let scan_s = self
            .last_scan_time_ms
            .map_or(0.0, |t| batch.time_ms.saturating_sub(t) as f32 / 1000.0);
        self.scan_time_ms = batch.time_ms;
        self.table.predict(batch.time_ms);
        self.table.gate(&self.plots, scan_s);
        self.phase = Phase::Assign {
            scan: batch.scan,
            next: 0,
            parts: 0,
        };
        self.report_scan = batch.scan;
        self.assignments.clear();
        self.initiate.clear();
        Ok(Some(parts_for(self.table.len(), MAX_GATES_PER_MESSAGE)))
    }

    /// Gate part `part` of the current scan.
    pub fn gated_part(&self, part: u8, parts: u8) -> GatedBatch {
        let start = usize::from(part) * MAX_GATES_PER_MESSAGE;
        let end = (start + MAX_GATES_PER_MESSAGE).min(self.table.len());
        GatedBatch {
            scan: self.report_scan,
            part,
            parts,
            gates: take_up_to((start..end).filter_map(|i| self.table.gated(i))),
        }
    }

    /// Takes one part of the host's assignments. Returns the number of track parts to send
    /// when the scan is closed, `None` while more parts are due.
    ///
    /// # Errors
    /// [`ErrorCode::OutOfSequence`] for no open scan or a part out of order; [`ErrorCode::CapacityExceeded`] for more assignments than tracks; the table's own refusals ([`TrackTable::apply`]).
    pub fn assign(&mut self, batch: &AssignmentBatch) -> Result<Option<u8>, ErrorCode> {
        let Phase::Assign { scan, next, parts } = self.phase else {
            return Err(ErrorCode::OutOfSequence);
        };
        let parts_ok = parts == 0 || parts == batch.parts;
        if batch.scan != scan || batch.part != next || !parts_ok || batch.part >= batch.parts {
            return Err(ErrorCode::OutOfSequence);
        }
        if self
            .assignments
            .extend_from_slice(&batch.assignments)
            .is_err()
            || self.initiate.extend_from_slice(&batch.initiate).is_err()
        {
            self.phase = Phase::Idle;
            return Err(ErrorCode::CapacityExceeded);
        }
        if batch.part + 1 < batch.parts {
            self.phase = Phase::Assign {
                scan,
                next: batch.part + 1,
                parts: batch.parts,
            };
            return Ok(None);
        }
        self.phase = Phase::Idle;
        let report = self.table.apply(
            self.scan_time_ms,
            &self.plots,
            &self.assignments,
            &self.initiate,
        )?;
        self.last_report = report;
        self.last_scan_time_ms = Some(self.scan_time_ms);
        Ok(Some(self.track_parts()))
    }

    /// Parts needed to report every track.
    pub fn track_parts(&self) -> u8 {
        parts_for(self.table.len(), MAX_TRACKS_PER_MESSAGE)
    }

    /// Track report part `part`.
    pub fn tracks_part(&self, part: u8, parts: u8) -> TrackBatch {
        let start = usize::from(part) * MAX_TRACKS_PER_MESSAGE;
        TrackBatch {
            scan: self.report_scan,
            part,
            parts,
            tracks: take_up_to(
                self.table
                    .tracks()
                    .skip(start)
                    .take(MAX_TRACKS_PER_MESSAGE)
                    .map(|t| t.state()),
            ),
        }
    }

    /// Carries out an operator command.
    ///
    /// # Errors
    /// [`ErrorCode::InvalidValue`] for a plot or track that does not exist; [`ErrorCode::CapacityExceeded`] for an acquisition into a full table.
    pub fn command(&mut self, command: TrackCommand) -> Result<(), ErrorCode> {
        match command {
            TrackCommand::Acquire { plot } => {
                let z = self
                    .plots
                    .get(usize::from(plot))
                    .and_then(|z| Measurement::new(*z).ok())
                    .ok_or(ErrorCode::InvalidValue)?;
                self.table.start_track(self.scan_time_ms, z).map(|_| ())
            }
            TrackCommand::Cancel { track } => self.table.cancel(track),
            TrackCommand::CancelAll => {
                self.table.cancel_all();
                Ok(())
            }
        }
    }
}

/// Parts needed to carry `items` at `per_part` a message: at least one, at most 255.
/// Plain arithmetic (no `div_ceil`/`clamp`, whose checks would leave a panic path).
fn parts_for(items: usize, per_part: usize) -> u8 {
    let per_part = per_part.max(1);
    let parts = items / per_part + usize::from(!items.is_multiple_of(per_part));
    parts.max(1).min(usize::from(u8::MAX)) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plots(scan: u32, time_ms: u64, part: u8, parts: u8, ps: &[EastNorth]) -> PlotBatch {
        PlotBatch {
            scan,
            time_ms,
            part,
            parts,
            plots_m: ps.iter().copied().collect(),
        }
    }

    #[test]
    fn a_scan_in_two_parts_then_assignments() {
        let mut t = Tracker::new();
        let p = [0.0, 1000.0];
        assert_eq!(t.plots(&plots(0, 0, 0, 2, &[p])), Ok(None));
        assert_eq!(t.plots(&plots(0, 0, 1, 2, &[p])), Ok(Some(1)));
        let a = AssignmentBatch {
            scan: 0,
            part: 0,
            parts: 1,
            assignments: Vec::new(),
            initiate: Vec::from_slice(&[0]).unwrap(),
        };
        assert_eq!(t.assign(&a), Ok(Some(1)));
        assert_eq!(t.table().len(), 1);
        let r = t.tracks_part(0, 1);
        assert_eq!(r.tracks.len(), 1);
        assert!((r.tracks[0].position_m[1] - 1000.0).abs() < 0.05);
    }

    #[test]
    fn out_of_order_parts_are_refused() {
        let mut t = Tracker::new();
        let p = [0.0, 1000.0];
        assert_eq!(
            t.plots(&plots(0, 0, 1, 2, &[p])),
            Err(ErrorCode::OutOfSequence)
        );
        let a = AssignmentBatch {
            scan: 0,
            part: 0,
            parts: 1,
            assignments: Vec::new(),
            initiate: Vec::new(),
        };
        assert_eq!(t.assign(&a), Err(ErrorCode::OutOfSequence), "no scan open");
        assert_eq!(t.plots(&plots(0, 5000, 0, 1, &[p])), Ok(Some(1)));
        assert_eq!(
            t.assign(&AssignmentBatch {
                scan: 1,
                ..a.clone()
            }),
            Err(ErrorCode::OutOfSequence)
        );
        assert_eq!(t.assign(&a), Ok(Some(1)));
        // Time must move on between scans.
        assert_eq!(
            t.plots(&plots(1, 5000, 0, 1, &[p])),
            Err(ErrorCode::OutOfSequence)
        );
        let far = [0.0, 2.0e7];
        assert_eq!(
            t.plots(&plots(1, 7500, 0, 1, &[far])),
            Err(ErrorCode::InvalidValue)
        );
    }
}
