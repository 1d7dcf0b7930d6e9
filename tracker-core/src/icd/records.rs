//! The packed record lists inside the scan's messages, and what each record is coded
//! against.
//!
//! Every number here is an integer on the wire's grid ([`super::fixed`]: tenths of a metre,
//! a gate's Cholesky factor in centimetres, hundredths of a metre a second), and the two
//! sides compute every reference from the same integers with the same `f32` operations, so
//! a value decoded on the host is the value the device coded, bit for bit, on any link.
//!
//! What a record is coded against (all of it known to both sides when it is read):
//!
//! - **the scan's plots**, which the host sent: a gate's predicted position is sent as its
//!   offset from the first plot in the gate (tens of metres: two bytes a coordinate, not
//!   three), unless the track is in the base;
//! - **the base**: the track states of the report before, which the host holds and names in
//!   its next [`super::PlotBatch`] (`base_scan`). A track in the base is sent as what
//!   changed: its predicted and new positions as offsets from the base position moved on
//!   at the base velocity (zero for a coasting track), its velocity as the change from the
//!   base's, its gate's Cholesky factor as the change from the one sent at the base scan;
//!   its age and hit history follow from the base's and one bit. The device uses the base
//!   only when it knows the host holds it (the scan named is its last report, and nothing
//!   moved since), and says which base it used in every reply, so a host that missed a
//!   report is sent whole records instead, never misread ones.
//!
//! Record layouts (varints as [`super::varint`]):
//!
//! ```text
//! gate:  head u8 = plots (1–8) | 0x10 prediction from the base | 0x20 factor from the base
//!        track − previous record's track (i32; the first from 0)
//!        plot indices (u32 each)
//!        predicted east, north − reference (i32, tenths)
//!        Cholesky l11, l21, l22 (− the base's) (i32, centimetres)
//! state: head u8 = status (0–3) | 0x04 hit on this scan | 0x08 whole
//!        track − previous record's track (i32)
//!        whole:   east, north (i32, tenths); v_east, v_north (i32, hundredths);
//!                 age (u32), hit history (u32)
//!        changed: east, north − the base moved on (i32, tenths);
//!                 v_east, v_north − the base's (i32, hundredths)
//! ```

use heapless::Vec;

use super::fixed::{
    cholesky_cm, covariance_from_cholesky, length_from_tenths, length_to_tenths,
    speed_from_hundredths, speed_to_hundredths,
};
use super::varint::{Malformed, Reader, Writer};
use super::{GatedPlots, TrackState, TrackStatus, MAX_PLOTS_PER_GATE};
use crate::geo::EastNorth;

/// Bits of hit history a state carries ([`TrackState::hit_history`]).
pub const HIT_HISTORY_BITS: u32 = 10;

const HIT_HISTORY_MASK: u16 = (1 << HIT_HISTORY_BITS) - 1;

/// The largest gate record: head, a five-byte track step, eight three-byte plot indices,
/// five five-byte numbers.
pub const MAX_GATE_RECORD_BYTES: usize = 1 + 5 + MAX_PLOTS_PER_GATE * 3 + 5 * 5;

/// The largest state record: head, a five-byte track step, four five-byte numbers, two
/// three-byte ones.
pub const MAX_STATE_RECORD_BYTES: usize = 1 + 5 + 4 * 5 + 2 * 3;

const GATE_PLOTS: u8 = 0x0F;
const GATE_PREDICTION_FROM_BASE: u8 = 0x10;
const GATE_FACTOR_FROM_BASE: u8 = 0x20;
const STATE_STATUS: u8 = 0x03;
const STATE_HIT: u8 = 0x04;
const STATE_WHOLE: u8 = 0x08;

/// Seconds from `from_ms` to `to_ms`, as both sides compute it for the base's motion.
pub fn interval_s(from_ms: u64, to_ms: u64) -> f32 {
    to_ms.saturating_sub(from_ms) as f32 / 1000.0
}

/// A position east, north (m) in tenths.
pub fn tenths(p: EastNorth) -> [i32; 2] {
    p.map(length_to_tenths)
}

/// A track's state on the wire's grid: what the host holds and the next report is coded
/// against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateOnGrid {
    /// Track number.
    pub track: u16,
    /// Life-cycle state.
    pub status: TrackStatus,
    /// Position east, north, tenths of a metre.
    pub position_tenths: [i32; 2],
    /// Velocity east, north, hundredths of a metre a second.
    pub velocity_hundredths: [i32; 2],
    /// Scans since the track started.
    pub age_scans: u16,
    /// Hits in the last [`HIT_HISTORY_BITS`] scans, newest lowest.
    pub hit_history: u16,
}

impl StateOnGrid {
    /// `state` rounded to the grid.
    pub fn of(state: &TrackState) -> Self {
        StateOnGrid {
            track: state.track,
            status: state.status,
            position_tenths: tenths(state.position_m),
            velocity_hundredths: state.velocity_mps.map(speed_to_hundredths),
            age_scans: state.age_scans,
            hit_history: state.hit_history & HIT_HISTORY_MASK,
        }
    }

    /// The state in metres and metres a second.
    pub fn state(&self) -> TrackState {
        TrackState {
            track: self.track,
            status: self.status,
            position_m: self.position_tenths.map(length_from_tenths),
            velocity_mps: self.velocity_hundredths.map(speed_from_hundredths),
            age_scans: self.age_scans,
            hit_history: self.hit_history,
        }
    }

    /// The base position moved on `dt_s` at the base velocity, in tenths: the reference of a
    /// track's predicted and new positions.
    pub fn moved_on(&self, dt_s: f32) -> [i32; 2] {
        let p = self.position_tenths.map(length_from_tenths);
        let v = self.velocity_hundredths.map(speed_from_hundredths);
        [
            length_to_tenths(p[0] + v[0] * dt_s),
            length_to_tenths(p[1] + v[1] * dt_s),
        ]
    }
}

/// A report is shown to the operator from a track's second hit: a tentative track with one
/// hit (most of them clutter that goes on the next scan) is gated but not reported.
pub fn reported(status: TrackStatus, hit_history: u16) -> bool {
    status != TrackStatus::Tentative || (hit_history & HIT_HISTORY_MASK).count_ones() >= 2
}

fn status_code(s: TrackStatus) -> u8 {
    match s {
        TrackStatus::Tentative => 0,
        TrackStatus::Confirmed => 1,
        TrackStatus::Coasting => 2,
        TrackStatus::Lost => 3,
    }
}

fn status_of(code: u8) -> TrackStatus {
    match code & STATE_STATUS {
        0 => TrackStatus::Tentative,
        1 => TrackStatus::Confirmed,
        2 => TrackStatus::Coasting,
        _ => TrackStatus::Lost,
    }
}

fn step(from: u16, to: u16) -> i32 {
    i32::from(to) - i32::from(from)
}

fn stepped(from: u16, by: i32) -> Result<u16, Malformed> {
    let to = i32::from(from).checked_add(by).ok_or(Malformed)?;
    u16::try_from(to).map_err(|_| Malformed)
}

fn sub2(a: [i32; 2], b: [i32; 2]) -> [i32; 2] {
    [a[0].wrapping_sub(b[0]), a[1].wrapping_sub(b[1])]
}

fn add2(a: [i32; 2], b: [i32; 2]) -> [i32; 2] {
    [a[0].wrapping_add(b[0]), a[1].wrapping_add(b[1])]
}

/// Plots as (east, north) tenth-metre pairs.
pub fn write_plots(w: &mut Writer<'_>, plots: &[EastNorth]) {
    for p in plots {
        let [e, n] = tenths(*p);
        w.i32(e);
        w.i32(n);
    }
}

/// The plots [`write_plots`] wrote, in metres, one by one; a pair that does not decode
/// yields [`Malformed`] and ends the list.
pub fn plots(bytes: &[u8]) -> impl Iterator<Item = Result<EastNorth, Malformed>> + '_ {
    let mut r = Reader::new(bytes);
    let mut failed = false;
    core::iter::from_fn(move || {
        if failed || r.is_empty() {
            return None;
        }
        let pair = r.i32().and_then(|e| Ok([e, r.i32()?]));
        failed = pair.is_err();
        Some(pair.map(|p| p.map(length_from_tenths)))
    })
}

/// Reads the plots [`write_plots`] wrote, in metres, handing each to `each`; stops at the
/// first that does not decode.
///
/// # Errors
/// [`Malformed`] when the bytes are not whole pairs.
pub fn read_plots(bytes: &[u8], mut each: impl FnMut(EastNorth)) -> Result<(), Malformed> {
    for p in plots(bytes) {
        each(p?);
    }
    Ok(())
}

/// Plot indices (the plots that start tracks).
pub fn write_indices(w: &mut Writer<'_>, indices: &[u16]) {
    for &i in indices {
        w.u32(u32::from(i));
    }
}

/// The indices [`write_indices`] wrote, one by one; one past `u16::MAX` or cut short
/// yields [`Malformed`] and ends the list.
pub fn indices(bytes: &[u8]) -> impl Iterator<Item = Result<u16, Malformed>> + '_ {
    let mut r = Reader::new(bytes);
    let mut failed = false;
    core::iter::from_fn(move || {
        if failed || r.is_empty() {
            return None;
        }
        let i = r.u16();
        failed = i.is_err();
        Some(i)
    })
}

/// Reads the indices [`write_indices`] wrote.
///
/// # Errors
/// [`Malformed`] for a number past `u16::MAX` or cut short.
pub fn read_indices(bytes: &[u8], mut each: impl FnMut(u16)) -> Result<(), Malformed> {
    for i in indices(bytes) {
        each(i?);
    }
    Ok(())
}

/// Updates as (track − the previous update's track, plot) pairs: the host lists them in
/// table order, so the steps are small.
pub fn write_updates(w: &mut Writer<'_>, updates: &[(u16, u16)]) {
    let mut prev = 0;
    for &(track, plot) in updates {
        w.i32(step(prev, track));
        w.u32(u32::from(plot));
        prev = track;
    }
}

/// The (track, plot) pairs [`write_updates`] wrote, one by one; a pair out of range or
/// cut short yields [`Malformed`] and ends the list.
pub fn updates(bytes: &[u8]) -> impl Iterator<Item = Result<(u16, u16), Malformed>> + '_ {
    let mut r = Reader::new(bytes);
    let mut prev = 0;
    let mut failed = false;
    core::iter::from_fn(move || {
        if failed || r.is_empty() {
            return None;
        }
        let pair = r
            .i32()
            .and_then(|step| stepped(prev, step))
            .and_then(|track| Ok((track, r.u16()?)));
        match pair {
            Ok((track, _)) => prev = track,
            Err(_) => failed = true,
        }
        Some(pair)
    })
}

/// Reads the (track, plot) pairs [`write_updates`] wrote.
///
/// # Errors
/// [`Malformed`] for a track or plot out of range, or bytes cut short.
pub fn read_updates(bytes: &[u8], mut each: impl FnMut(u16, u16)) -> Result<(), Malformed> {
    for u in updates(bytes) {
        let (t, p) = u?;
        each(t, p);
    }
    Ok(())
}

/// A rough gate on the wire's grid.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GateOnGrid {
    /// Track number.
    pub track: u16,
    /// The plots inside it (at least one: gates without plots are not sent).
    pub plots: Vec<u16, MAX_PLOTS_PER_GATE>,
    /// Predicted position east, north, tenths of a metre.
    pub predicted_tenths: [i32; 2],
    /// The innovation covariance's Cholesky factor `[l11, l21, l22]`, whole centimetres.
    pub cholesky_cm: [i32; 3],
}

impl GateOnGrid {
    /// A gate from the device's values.
    pub fn of(
        track: u16,
        plots: Vec<u16, MAX_PLOTS_PER_GATE>,
        predicted_m: EastNorth,
        innovation_cov_m2: [f32; 3],
    ) -> Self {
        GateOnGrid {
            track,
            plots,
            predicted_tenths: tenths(predicted_m),
            cholesky_cm: cholesky_cm(innovation_cov_m2),
        }
    }

    /// The gate in metres: the host's refined gate works on this.
    pub fn gated(&self) -> GatedPlots {
        GatedPlots {
            track: self.track,
            predicted_m: self.predicted_tenths.map(length_from_tenths),
            innovation_cov_m2: covariance_from_cholesky(self.cholesky_cm),
            plots: self.plots.clone(),
        }
    }
}

/// What a gate record of one track is coded against.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GateReference {
    /// The track's base moved on to this scan ([`StateOnGrid::moved_on`]), when it is in
    /// the base.
    pub moved_on: Option<[i32; 2]>,
    /// The factor sent in the track's gate at the base scan, when one was.
    pub cholesky_cm: Option<[i32; 3]>,
}

/// Writes one gate record after the one of track `prev` (0 for the first of a message).
/// `first_plot_tenths` is the position of `gate.plots[0]`.
pub fn write_gate(
    w: &mut Writer<'_>,
    prev: u16,
    gate: &GateOnGrid,
    reference: GateReference,
    first_plot_tenths: [i32; 2],
) {
    let count = gate.plots.len() as u8 & GATE_PLOTS;
    let mut head = count;
    let from = match reference.moved_on {
        Some(m) => {
            head |= GATE_PREDICTION_FROM_BASE;
            m
        }
        None => first_plot_tenths,
    };
    let l_from = match reference.cholesky_cm {
        Some(l) => {
            head |= GATE_FACTOR_FROM_BASE;
            l
        }
        None => [0; 3],
    };
    w.byte(head);
    w.i32(step(prev, gate.track));
    for &p in &gate.plots {
        w.u32(u32::from(p));
    }
    for d in sub2(gate.predicted_tenths, from) {
        w.i32(d);
    }
    for (l, b) in gate.cholesky_cm.iter().zip(l_from) {
        w.i32(l.wrapping_sub(b));
    }
}

/// Reads one gate record after the one of track `prev`. `reference` gives what the host
/// holds for a track; `plot_tenths` a plot's position by index.
///
/// # Errors
/// [`Malformed`] for bytes cut short, no plots or more than a gate holds, a record coded
/// against a base the host does not hold, or a plot index past the scan's.
pub fn read_gate(
    r: &mut Reader<'_>,
    prev: u16,
    reference: impl Fn(u16) -> GateReference,
    plot_tenths: impl Fn(u16) -> Option<[i32; 2]>,
) -> Result<GateOnGrid, Malformed> {
    let head = r.byte()?;
    let count = usize::from(head & GATE_PLOTS);
    if count == 0 || count > MAX_PLOTS_PER_GATE || head & !0x3F != 0 {
        return Err(Malformed);
    }
    let track = stepped(prev, r.i32()?)?;
    let mut plots = Vec::new();
    for _ in 0..count {
        plots.push(r.u16()?).map_err(|_| Malformed)?;
    }
    let known = reference(track);
    let from = if head & GATE_PREDICTION_FROM_BASE != 0 {
        known.moved_on.ok_or(Malformed)?
    } else {
        plot_tenths(*plots.first().ok_or(Malformed)?).ok_or(Malformed)?
    };
    let l_from = if head & GATE_FACTOR_FROM_BASE != 0 {
        known.cholesky_cm.ok_or(Malformed)?
    } else {
        [0; 3]
    };
    let predicted_tenths = add2([r.i32()?, r.i32()?], from);
    let mut cholesky_cm = [0; 3];
    for (l, b) in cholesky_cm.iter_mut().zip(l_from) {
        *l = r.i32()?.wrapping_add(b);
    }
    Ok(GateOnGrid {
        track,
        plots,
        predicted_tenths,
        cholesky_cm,
    })
}

/// Writes one state record after the one of track `prev`: whole without a base, else what
/// changed since it, the base moved on `dt_s`. `hit` says the track took a plot this scan.
pub fn write_state(
    w: &mut Writer<'_>,
    prev: u16,
    state: &StateOnGrid,
    hit: bool,
    base: Option<&StateOnGrid>,
    dt_s: f32,
) {
    let mut head = status_code(state.status);
    if hit {
        head |= STATE_HIT;
    }
    match base {
        Some(b) => {
            w.byte(head);
            w.i32(step(prev, state.track));
            for d in sub2(state.position_tenths, b.moved_on(dt_s)) {
                w.i32(d);
            }
            for d in sub2(state.velocity_hundredths, b.velocity_hundredths) {
                w.i32(d);
            }
        }
        None => {
            w.byte(head | STATE_WHOLE);
            w.i32(step(prev, state.track));
            for x in state
                .position_tenths
                .iter()
                .chain(&state.velocity_hundredths)
            {
                w.i32(*x);
            }
            w.u32(u32::from(state.age_scans));
            w.u32(u32::from(state.hit_history));
        }
    }
}

/// Reads one state record after the one of track `prev`; `base` gives the state the host
/// holds for a track, moved on `dt_s`.
///
/// # Errors
/// [`Malformed`] for bytes cut short, a number out of range, or a record coded against a
/// base the host does not hold.
pub fn read_state(
    r: &mut Reader<'_>,
    prev: u16,
    base: impl Fn(u16) -> Option<StateOnGrid>,
    dt_s: f32,
) -> Result<StateOnGrid, Malformed> {
    let head = r.byte()?;
    if head & !0x0F != 0 {
        return Err(Malformed);
    }
    let status = status_of(head);
    let hit = u16::from(head & STATE_HIT != 0);
    let track = stepped(prev, r.i32()?)?;
    if head & STATE_WHOLE != 0 {
        let position_tenths = [r.i32()?, r.i32()?];
        let velocity_hundredths = [r.i32()?, r.i32()?];
        return Ok(StateOnGrid {
            track,
            status,
            position_tenths,
            velocity_hundredths,
            age_scans: r.u16()?,
            hit_history: r.u16()? & HIT_HISTORY_MASK,
        });
    }
    let b = base(track).ok_or(Malformed)?;
    let position_tenths = add2([r.i32()?, r.i32()?], b.moved_on(dt_s));
    let velocity_hundredths = add2([r.i32()?, r.i32()?], b.velocity_hundredths);
    Ok(StateOnGrid {
        track,
        status,
        position_tenths,
        velocity_hundredths,
        age_scans: b.age_scans.saturating_add(1),
        hit_history: ((b.hit_history << 1) | hit) & HIT_HISTORY_MASK,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(track: u16, e: f32, vn: f32, age: u16, hits: u16) -> StateOnGrid {
        StateOnGrid::of(&TrackState {
            track,
            status: TrackStatus::Confirmed,
            position_m: [e, -e / 2.0],
            velocity_mps: [3.0, vn],
            age_scans: age,
            hit_history: hits,
        })
    }

    #[test]
    fn plots_updates_and_indices_round_trip() {
        let mut buf = [0u8; 256];
        let plots = [[0.0, 0.0], [-12_345.6, 22_000.1], [0.1, -0.1]];
        let mut w = Writer::new(&mut buf);
        write_plots(&mut w, &plots);
        let mut back = std::vec::Vec::new();
        read_plots(w.written(), |p| back.push(p)).unwrap();
        assert_eq!(back, plots);
        let updates = [(3, 0), (7, 12), (7, 300), (2, 1), (u16::MAX, 255)];
        let mut w = Writer::new(&mut buf);
        write_updates(&mut w, &updates);
        let mut back = std::vec::Vec::new();
        read_updates(w.written(), |t, p| back.push((t, p))).unwrap();
        assert_eq!(back, updates);
        let mut w = Writer::new(&mut buf);
        write_indices(&mut w, &[0, 127, 128, 255]);
        assert_eq!(w.len(), 6);
        let mut back = std::vec::Vec::new();
        read_indices(w.written(), |i| back.push(i)).unwrap();
        assert_eq!(back, [0, 127, 128, 255]);
        assert_eq!(
            read_plots(&[2, 4, 6], |_| {}),
            Err(Malformed),
            "half a pair"
        );
    }

    #[test]
    fn gates_round_trip_against_each_reference() {
        let mut buf = [0u8; 128];
        let plots = [[118_000, -40_017], [118_310, -40_500]];
        let gate = GateOnGrid {
            track: 300,
            plots: Vec::from_slice(&[1, 0]).unwrap(),
            predicted_tenths: [118_250, -40_400],
            cholesky_cm: [552, -13, 540],
        };
        let base = GateReference {
            moved_on: Some([118_251, -40_398]),
            cholesky_cm: Some([550, -13, 541]),
        };
        for (sent, held) in [
            (GateReference::default(), GateReference::default()),
            (base, base),
            (
                GateReference {
                    cholesky_cm: None,
                    ..base
                },
                base,
            ),
        ] {
            let mut w = Writer::new(&mut buf);
            write_gate(&mut w, 290, &gate, sent, plots[1]);
            let mut r = Reader::new(w.written());
            let back = read_gate(
                &mut r,
                290,
                |_| held,
                |i| plots.get(usize::from(i)).copied(),
            );
            assert_eq!(back, Ok(gate.clone()), "{sent:?}");
            assert!(r.is_empty());
        }
        // Against a base: 1 head + 1 step + 2 plots + 2 + 3 small numbers.
        let mut w = Writer::new(&mut buf);
        write_gate(&mut w, 290, &gate, base, plots[1]);
        assert_eq!(w.len(), 9);
        // Coded against a base the reader does not hold: refused, not misread.
        let mut r = Reader::new(w.written());
        let none = |_| GateReference::default();
        let plot = |i: u16| plots.get(usize::from(i)).copied();
        assert_eq!(read_gate(&mut r, 290, none, plot), Err(Malformed));
    }

    #[test]
    fn states_round_trip_whole_and_changed() {
        let mut buf = [0u8; 64];
        let base = state(41, 10_000.0, -4.0, 30, 0b11_1111_1111);
        let dt_s = interval_s(100_000, 102_500);
        let mut now = state(41, 10_007.3, -4.1, 31, 0b11_1111_1110);
        now.status = TrackStatus::Coasting;
        for (with, hit) in [(None, false), (Some(&base), false)] {
            let mut w = Writer::new(&mut buf);
            write_state(&mut w, 40, &now, hit, with, dt_s);
            let mut r = Reader::new(w.written());
            assert_eq!(read_state(&mut r, 40, |_| Some(base), dt_s), Ok(now));
            assert!(r.is_empty());
        }
        // Changed: a few bytes (head, step, four small numbers).
        let mut w = Writer::new(&mut buf);
        write_state(&mut w, 40, &now, false, Some(&base), dt_s);
        assert!(w.len() <= 8, "{}", w.len());
        let mut r = Reader::new(w.written());
        assert_eq!(read_state(&mut r, 40, |_| None, dt_s), Err(Malformed));
    }

    #[test]
    fn a_one_hit_tentative_track_is_not_reported() {
        assert!(!reported(TrackStatus::Tentative, 0b1));
        assert!(reported(TrackStatus::Tentative, 0b101));
        assert!(reported(TrackStatus::Coasting, 0));
    }
}
