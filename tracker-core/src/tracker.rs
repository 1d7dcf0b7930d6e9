//! The device's scan cycle (thesis §2.4): plots in, rough gates out; assignments in, track
//! states out.
//!
//! A scan arrives as [`PlotBatch`] parts, in order. When the last part is in, every track
//! is predicted to the scan time and rough-gated, and the gates go back to the host as
//! [`GatedBatch`](crate::icd::GatedBatch) parts. The host answers with [`AssignmentBatch`] parts; when the last is
//! in, the table is updated and the track states go back as [`TrackBatch`](crate::icd::TrackBatch) parts. Anything
//! out of order is refused with [`ErrorCode::OutOfSequence`] and changes nothing.
//!
//! The gates and states are coded against the report the host holds (the base,
//! [`crate::icd::records`]): when the last plot part names the scan of the device's last
//! report, and nothing has moved in the table since, each track that report carried is
//! the base of its records; otherwise every record is whole.

use heapless::Vec;

use crate::filter::Measurement;
use crate::geo::EastNorth;
use crate::icd::fixed::cholesky_cm;
use crate::icd::records::{self, GateOnGrid, GateReference, StateOnGrid};
use crate::icd::varint::Writer;
use crate::icd::{
    Assignment, AssignmentBatch, ErrorCode, PlotBatch, TrackCommand, TrackStatus, TrackerConfig,
};
use crate::track::{ApplyReport, TrackTable, MAX_TRACKS};

/// Plots one scan may hold.
pub const MAX_PLOTS_PER_SCAN: usize = 256;

// The handshake reports it in a u16.
const _: () = assert!(MAX_PLOTS_PER_SCAN <= u16::MAX as usize);

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

/// What the host holds of one slot's track, as far as coding against it needs: the
/// position and velocity its last report carried, and the Cholesky factor of the gate sent
/// for it at that scan. Kept small (24 bytes a slot): a velocity past ±327.67 m/s (16 bits of
/// hundredths) leaves the track without a base, and its records are sent whole; a factor
/// entry past ±327.67 m (16 bits of centimetres) leaves the base without its factor, and the
/// next gate's factor alone is sent whole (the host holds every factor it was sent, so it
/// reads either).
#[derive(Clone, Copy, Debug, PartialEq)]
struct SlotBase {
    /// The track the base is of (0: none).
    track: u16,
    has_factor: bool,
    velocity_hundredths: [i16; 2],
    cholesky_cm: [i16; 3],
    position_tenths: [i32; 2],
}

impl SlotBase {
    /// The base of track `t` as its report gave it, with the factor of its last gate.
    fn of(state: &StateOnGrid, factor: Option<[i32; 3]>) -> Self {
        let v = state.velocity_hundredths.map(i16::try_from);
        let (Ok(ve), Ok(vn)) = (v[0], v[1]) else {
            return NO_BASE;
        };
        let l = factor.map(|f| f.map(i16::try_from));
        let (has_factor, cholesky_cm) = match l {
            Some([Ok(a), Ok(b), Ok(c)]) => (true, [a, b, c]),
            _ => (false, [0; 3]),
        };
        SlotBase {
            track: state.track,
            has_factor,
            velocity_hundredths: [ve, vn],
            cholesky_cm,
            position_tenths: state.position_tenths,
        }
    }

    /// The state the writers code against (only position and velocity are read).
    fn state(&self) -> StateOnGrid {
        StateOnGrid {
            track: self.track,
            status: TrackStatus::Confirmed,
            position_tenths: self.position_tenths,
            velocity_hundredths: self.velocity_hundredths.map(i32::from),
            age_scans: 0,
            hit_history: 0,
        }
    }

    /// The factor of the gate sent at the base scan, if one was.
    fn cholesky_cm(&self) -> Option<[i32; 3]> {
        self.has_factor.then_some(self.cholesky_cm.map(i32::from))
    }
}

const NO_BASE: SlotBase = SlotBase {
    track: 0,
    has_factor: false,
    velocity_hundredths: [0; 2],
    cholesky_cm: [0; 3],
    position_tenths: [0; 2],
};

/// A plots part's head: everything of a [`PlotBatch`] but its plots.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlotsHead {
    /// Scan number.
    pub scan: u32,
    /// Scan time, ms.
    pub time_ms: u64,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
    /// The report the host holds ([`PlotBatch::base_scan`]).
    pub base_scan: Option<u32>,
}

impl PlotsHead {
    /// The head of `batch`.
    pub fn of(batch: &PlotBatch) -> Self {
        PlotsHead {
            scan: batch.scan,
            time_ms: batch.time_ms,
            part: batch.part,
            parts: batch.parts,
            base_scan: batch.base_scan,
        }
    }
}

/// An assignments part's head: everything of an [`AssignmentBatch`] but its lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AssignHead {
    /// The scan the assignments close.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
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
    /// The plots to start tracks from: no more than a table can take; the rest are
    /// refused as the table is full ([`ApplyReport::refused_full`]).
    initiate: Vec<u16, MAX_TRACKS>,
    /// Initiations past [`Tracker::initiate`]'s room.
    initiate_over: u16,
    last_report: ApplyReport,
    report_scan: u32,
    /// Per slot, the base of the open scan's records.
    bases: [SlotBase; MAX_TRACKS],
    /// The base the open scan's records are coded against: its scan and time.
    base: Option<(u32, u64)>,
    /// Per slot, the track the last report carried (0: none).
    reported: [u16; MAX_TRACKS],
    /// The last report's scan and time, while the table has not moved since.
    report_holds: Option<(u32, u64)>,
    /// The next state report is whole (a [`Tracker::whole_report`] asked for it).
    whole: bool,
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
            initiate_over: 0,
            last_report: ApplyReport {
                updated: 0,
                coasted: 0,
                initiated: 0,
                refused_full: 0,
                dropped: 0,
            },
            report_scan: 0,
            bases: [NO_BASE; MAX_TRACKS],
            base: None,
            reported: [0; MAX_TRACKS],
            report_holds: None,
            whole: false,
        }
    }

    /// The track table.
    pub fn table(&self) -> &TrackTable {
        &self.table
    }

    /// The plots of the open (or last) scan, in the order the host sent them.
    pub fn plots(&self) -> &[EastNorth] {
        &self.plots
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

    /// Takes one part of a scan's plots. Returns `true` when the scan is complete (its gates
    /// are then to be sent), `false` while more parts are due.
    ///
    /// # Errors
    /// [`ErrorCode::OutOfSequence`] for a part out of order or a scan not later than the last; [`ErrorCode::CapacityExceeded`] past [`MAX_PLOTS_PER_SCAN`]; [`ErrorCode::InvalidValue`] for a plot no filter would take (beyond [`crate::filter::MAX_POSITION_M`]); [`ErrorCode::Malformed`] for plots that do not decode (the scan is dropped in these three cases).
    pub fn take_plots(&mut self, batch: &PlotBatch) -> Result<bool, ErrorCode> {
        let head = PlotsHead::of(batch);
        self.take_positions(head, records::plots(batch.plots.0))
    }

    /// [`Tracker::take_plots`] for plots already read: `plots` yields each position, or
    /// [`varint::Malformed`](crate::icd::varint::Malformed) where the list does not decode.
    ///
    /// # Errors
    /// As [`Tracker::take_plots`].
    pub fn take_positions(
        &mut self,
        batch: PlotsHead,
        plots: impl Iterator<Item = Result<EastNorth, crate::icd::varint::Malformed>>,
    ) -> Result<bool, ErrorCode> {
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
        // Taken straight into the scan's plots; a bad part takes the scan with it.
        let before = self.plots.len();
        let mut error = None;
        for p in plots {
            let e = match p {
                Err(_) => ErrorCode::Malformed,
                Ok(p) if Measurement::<f32>::new(p).is_err() => ErrorCode::InvalidValue,
                Ok(p) => match self.plots.push(p) {
                    Ok(()) => continue,
                    Err(_) => ErrorCode::CapacityExceeded,
                },
            };
            error = Some(e);
            break;
        }
        if let Some(e) = error {
            self.plots.truncate(before);
            self.phase = Phase::Idle;
            return Err(e);
        }
        if batch.part + 1 < batch.parts {
            self.phase = Phase::Plots {
                scan: batch.scan,
                next: batch.part + 1,
                parts: batch.parts,
            };
            return Ok(false);
        }
        // The scan is complete: the base, then predict and gate.
        self.take_base(batch.base_scan);
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
        self.initiate_over = 0;
        Ok(true)
    }

    /// The base of this scan's records: the last report's tracks, if the host names that
    /// report and the table has not moved since.
    fn take_base(&mut self, host_holds: Option<u32>) {
        let holds = match (self.report_holds, host_holds) {
            (Some((scan, time_ms)), Some(named)) if scan == named => Some((scan, time_ms)),
            _ => None,
        };
        // Every live slot's entry is written (the others are never read), so nothing of an
        // earlier base survives.
        for (slot, t) in self.table.placed() {
            let (Some(base), Some(&reported)) = (self.bases.get_mut(slot), self.reported.get(slot))
            else {
                continue;
            };
            // A lost track was reported once; the host holds it no longer.
            *base = if holds.is_some() && reported == t.id && t.status != TrackStatus::Lost {
                // Before this scan's gating, a track still holds the last scan's gate: sent
                // if it had plots in it.
                let sent = !t.gated_plots().is_empty();
                let factor = sent.then(|| cholesky_cm(t.innovation_cov_m2()));
                SlotBase::of(&StateOnGrid::of(&t.state()), factor)
            } else {
                NO_BASE
            };
        }
        self.base = holds;
        // From here the table moves: the report no longer describes it.
        self.report_holds = None;
        self.whole = false;
    }

    fn slot_base(&self, slot: usize, track: u16) -> Option<&SlotBase> {
        self.base?;
        self.bases
            .get(slot)
            .filter(|b| b.track == track && b.track != 0)
    }

    /// The open scan's gate report: its scan, the base its records are coded against, and
    /// the tracks in the table.
    pub fn gate_report(&self) -> (u32, Option<u32>, u16) {
        (
            self.report_scan,
            self.base.map(|(scan, _)| scan),
            self.table.len() as u16,
        )
    }

    /// Writes the gate records of the tracks from place `from` in the table on, as many as
    /// fit `w`; returns the place after the last written (the table's length when all are).
    pub fn write_gates(&self, from: usize, w: &mut Writer<'_>) -> usize {
        let dt_s = self
            .base
            .map_or(0.0, |(_, t)| records::interval_s(t, self.scan_time_ms));
        let mut prev = 0;
        for (place, (slot, t)) in self.table.placed().enumerate().skip(from) {
            let plots = t.gated_plots();
            let Some(&first) = plots.first() else {
                continue;
            };
            if w.room() < records::MAX_GATE_RECORD_BYTES {
                return place;
            }
            let gate = GateOnGrid::of(
                t.id,
                Vec::from_slice(plots).unwrap_or_default(),
                t.filter().prediction(),
                t.innovation_cov_m2(),
            );
            let reference = self
                .slot_base(slot, t.id)
                .map_or(GateReference::default(), |b| GateReference {
                    moved_on: Some(b.state().moved_on(dt_s)),
                    cholesky_cm: b.cholesky_cm(),
                });
            let first_plot = self
                .plots
                .get(usize::from(first))
                .map_or([0; 2], |&p| records::tenths(p));
            records::write_gate(w, prev, &gate, reference, first_plot);
            prev = t.id;
        }
        self.table.len()
    }

    /// Takes one part of the host's assignments. Returns `true` when the scan is closed (its
    /// states are then to be sent), `false` while more parts are due.
    ///
    /// # Errors
    /// [`ErrorCode::OutOfSequence`] for no open scan or a part out of order; [`ErrorCode::CapacityExceeded`] for more assignments than tracks; [`ErrorCode::Malformed`] for lists that do not decode; the table's own refusals ([`TrackTable::apply`]).
    pub fn assign(&mut self, batch: &AssignmentBatch) -> Result<bool, ErrorCode> {
        let head = AssignHead {
            scan: batch.scan,
            part: batch.part,
            parts: batch.parts,
        };
        self.take_assignments(
            head,
            records::updates(batch.updates.0),
            records::indices(batch.initiate.0),
        )
    }

    /// [`Tracker::assign`] for lists already read: `updates` yields (track, plot) pairs,
    /// `initiate` plot indices, or [`varint::Malformed`](crate::icd::varint::Malformed) where
    /// a list does not decode.
    ///
    /// # Errors
    /// As [`Tracker::assign`].
    pub fn take_assignments(
        &mut self,
        batch: AssignHead,
        updates: impl Iterator<Item = Result<(u16, u16), crate::icd::varint::Malformed>>,
        initiate: impl Iterator<Item = Result<u16, crate::icd::varint::Malformed>>,
    ) -> Result<bool, ErrorCode> {
        let Phase::Assign { scan, next, parts } = self.phase else {
            return Err(ErrorCode::OutOfSequence);
        };
        let parts_ok = parts == 0 || parts == batch.parts;
        if batch.scan != scan || batch.part != next || !parts_ok || batch.part >= batch.parts {
            return Err(ErrorCode::OutOfSequence);
        }
        let (mut full, mut malformed) = (false, false);
        for u in updates {
            match u {
                Ok((track, plot)) => {
                    let a = Assignment {
                        track,
                        plot: Some(plot),
                    };
                    full |= self.assignments.push(a).is_err();
                }
                Err(_) => malformed = true,
            }
        }
        for p in initiate {
            match p {
                // More than a table can start: refused when the scan closes, as a full
                // table refuses them.
                Ok(p) => {
                    if self.initiate.push(p).is_err() {
                        self.initiate_over = self.initiate_over.saturating_add(1);
                    }
                }
                Err(_) => malformed = true,
            }
        }
        if full || malformed {
            self.phase = Phase::Idle;
            return Err(if full {
                ErrorCode::CapacityExceeded
            } else {
                ErrorCode::Malformed
            });
        }
        if batch.part + 1 < batch.parts {
            self.phase = Phase::Assign {
                scan,
                next: batch.part + 1,
                parts: batch.parts,
            };
            return Ok(false);
        }
        self.phase = Phase::Idle;
        let report = self.table.apply(
            self.scan_time_ms,
            &self.plots,
            &self.assignments,
            &self.initiate,
        )?;
        self.last_report = ApplyReport {
            refused_full: report.refused_full.saturating_add(self.initiate_over),
            ..report
        };
        self.last_scan_time_ms = Some(self.scan_time_ms);
        self.note_report();
        Ok(true)
    }

    /// The tracks the coming report carries, and that it describes the table from now on.
    fn note_report(&mut self) {
        self.reported = [0; MAX_TRACKS];
        for (slot, t) in self.table.placed() {
            if let Some(r) = self.reported.get_mut(slot) {
                if records::reported(t.status, t.hit_history()) {
                    *r = t.id;
                }
            }
        }
        self.report_holds = self
            .last_scan_time_ms
            .map(|time_ms| (self.report_scan, time_ms));
    }

    /// Makes the next state report whole (every record without a base): the host asked
    /// for the full table ([`crate::icd::HostToDevice::GetTracks`]). While no scan is open
    /// it is also what the host holds from then on.
    pub fn whole_report(&mut self) {
        self.whole = true;
        if self.phase == Phase::Idle {
            self.note_report();
        } else {
            self.report_holds = None;
        }
    }

    /// The state report: its scan and the base its records are coded against.
    pub fn state_report(&self) -> (u32, Option<u32>) {
        let base = if self.whole { None } else { self.base };
        (self.report_scan, base.map(|(scan, _)| scan))
    }

    /// Writes the state records of the reported tracks from place `from` in the table on,
    /// as many as fit `w`; returns the place after the last written (the table's length
    /// when all are).
    pub fn write_states(&self, from: usize, w: &mut Writer<'_>) -> usize {
        let base = if self.whole { None } else { self.base };
        let dt_s = base.map_or(0.0, |(_, t)| records::interval_s(t, self.scan_time_ms));
        let mut prev = 0;
        for (place, (slot, t)) in self.table.placed().enumerate().skip(from) {
            let state = t.state();
            if !records::reported(state.status, state.hit_history) {
                continue;
            }
            if w.room() < records::MAX_STATE_RECORD_BYTES {
                return place;
            }
            let b = base.and(self.slot_base(slot, t.id)).map(SlotBase::state);
            records::write_state(
                w,
                prev,
                &StateOnGrid::of(&state),
                t.hit_last_scan(),
                b.as_ref(),
                dt_s,
            );
            prev = t.id;
        }
        self.table.len()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icd::varint::Reader;
    use crate::icd::{Bytes, MAX_ASSIGNMENT_BYTES, MAX_PLOT_BYTES};

    #[test]
    fn a_base_past_sixteen_bits_is_dropped_not_wrapped() {
        let state = |v| StateOnGrid {
            track: 7,
            status: TrackStatus::Confirmed,
            position_tenths: [1_000_000, -2_000_000],
            velocity_hundredths: v,
            age_scans: 3,
            hit_history: 0b111,
        };
        // A wide gate (a 400 m factor): the base keeps the state, not the factor.
        let b = SlotBase::of(&state([1_200, -300]), Some([40_000, -120, 3_500]));
        assert_eq!(b.track, 7);
        assert_eq!(b.cholesky_cm(), None);
        assert_eq!(b.state().position_tenths, [1_000_000, -2_000_000]);
        assert_eq!(b.state().velocity_hundredths, [1_200, -300]);
        // At the edge of 16 bits the factor is kept, and read back as it was.
        let b = SlotBase::of(&state([1_200, -300]), Some([32_767, -32_768, 1]));
        assert_eq!(b.cholesky_cm(), Some([32_767, -32_768, 1]));
        // A velocity past 16 bits: no base at all.
        let b = SlotBase::of(&state([40_000, 0]), Some([4_000, 0, 4_000]));
        assert_eq!(b, NO_BASE);
    }

    /// Takes a plots part (the test's buffers stay on the stack).
    fn plots(
        t: &mut Tracker,
        scan: u32,
        time_ms: u64,
        part: (u8, u8),
        ps: &[EastNorth],
    ) -> Result<bool, ErrorCode> {
        let mut buf = [0u8; MAX_PLOT_BYTES];
        let head = PlotBatch {
            scan,
            time_ms,
            part: part.0,
            parts: part.1,
            base_scan: None,
            plots: Bytes(&[]),
        };
        t.take_plots(&PlotBatch::pack(head, ps, &mut buf))
    }

    fn assign(
        t: &mut Tracker,
        scan: u32,
        updates: &[(u16, u16)],
        initiate: &[u16],
    ) -> Result<bool, ErrorCode> {
        let mut buf = [0u8; MAX_ASSIGNMENT_BYTES];
        t.assign(&AssignmentBatch::pack(
            scan,
            (0, 1),
            updates,
            initiate,
            &mut buf,
        ))
    }

    #[test]
    fn a_scan_in_two_parts_then_assignments() {
        let mut t = Tracker::new();
        let p = [0.0, 1000.0];
        assert_eq!(plots(&mut t, 0, 0, (0, 2), &[p]), Ok(false));
        assert_eq!(plots(&mut t, 0, 0, (1, 2), &[p]), Ok(true));
        assert_eq!(t.plots().len(), 2);
        assert_eq!(assign(&mut t, 0, &[], &[0]), Ok(true));
        assert_eq!(t.table().len(), 1);
        // A one-hit tentative track is gated but not reported.
        let mut buf = [0u8; 64];
        let mut w = Writer::new(&mut buf);
        assert_eq!(t.write_states(0, &mut w), 1);
        assert!(w.is_empty());
        assert_eq!(plots(&mut t, 1, 2500, (0, 1), &[[0.0, 1010.0]]), Ok(true));
        let mut w = Writer::new(&mut buf);
        t.write_gates(0, &mut w);
        let mut r = Reader::new(w.written());
        let tenths = |i: u16| t.plots().get(usize::from(i)).map(|&p| records::tenths(p));
        let g = records::read_gate(&mut r, 0, |_| GateReference::default(), tenths).unwrap();
        assert_eq!(g.plots.as_slice(), &[0]);
        assert_eq!(assign(&mut t, 1, &[(g.track, 0)], &[]), Ok(true));
        let mut w = Writer::new(&mut buf);
        t.write_states(0, &mut w);
        let mut r = Reader::new(w.written());
        let s = records::read_state(&mut r, 0, |_| None, 0.0)
            .unwrap()
            .state();
        assert!((s.position_m[1] - 1010.0).abs() < 10.0, "{s:?}");
        assert_eq!(s.hit_history, 0b11);
    }

    #[test]
    fn out_of_order_parts_are_refused() {
        let mut t = Tracker::new();
        let p = [0.0, 1000.0];
        assert_eq!(
            plots(&mut t, 0, 0, (1, 2), &[p]),
            Err(ErrorCode::OutOfSequence)
        );
        assert_eq!(
            assign(&mut t, 0, &[], &[]),
            Err(ErrorCode::OutOfSequence),
            "no scan open"
        );
        assert_eq!(plots(&mut t, 0, 5000, (0, 1), &[p]), Ok(true));
        assert_eq!(assign(&mut t, 1, &[], &[]), Err(ErrorCode::OutOfSequence));
        assert_eq!(assign(&mut t, 0, &[], &[]), Ok(true));
        // Time must move on between scans.
        assert_eq!(
            plots(&mut t, 1, 5000, (0, 1), &[p]),
            Err(ErrorCode::OutOfSequence)
        );
        let far = [0.0, 2.0e7];
        assert_eq!(
            plots(&mut t, 1, 7500, (0, 1), &[far]),
            Err(ErrorCode::InvalidValue)
        );
        // More plots than a scan holds.
        let many = [p; crate::icd::MAX_PLOTS_PER_MESSAGE];
        assert_eq!(plots(&mut t, 1, 7500, (0, 3), &many), Ok(false));
        assert_eq!(plots(&mut t, 1, 7500, (1, 3), &many), Ok(false));
        assert_eq!(
            plots(&mut t, 1, 7500, (2, 3), &many),
            Err(ErrorCode::CapacityExceeded)
        );
    }
}
