//! The device side of the link: bytes in, frames decoded, requests dispatched, replies out.
//!
//! This is the firmware's whole main-loop logic, kept in the core so the host's `inproc`
//! link runs exactly the code the MCU runs. The firmware only moves bytes between its UART
//! and [`Device::receive`].
//!
//! Every frame gets exactly one reply: the answer to the request, or an
//! [`DeviceToHost::Error`] naming what was wrong with it (with [`UNPAIRED_REQUEST_ID`] when
//! the frame was too damaged to carry a readable request id). Nothing a peer sends can
//! panic the device or leave it in a state other than "waiting for the next frame".

use crate::frame::{self, FrameDecoder, FrameError};
use crate::icd::varint::Writer;
use crate::icd::{
    Bytes, DeviceInfo, DeviceToHost, ErrorCode, GatedBatch, Header, HostToDevice, LinkStats,
    TrackBatch, HOST_TO_DEVICE_VARIANTS, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES,
    MAX_RECORD_BYTES, PROTOCOL_VERSION, UNPAIRED_REQUEST_ID,
};
use crate::tracker::Tracker;

/// What a request is answered with: one message, or a report in parts (each its own frame,
/// all carrying the request's id), made from the table as it is sent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reply<'a> {
    /// One message (an echo borrows the request's bytes).
    One(DeviceToHost<'a>),
    /// The scan's rough gates.
    Gated,
    /// The track states.
    Tracks,
}

/// How a state-changing request was answered, in a few bytes: every such answer is an
/// acknowledgement, an error, or a report made again from the (unchanged) state.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Answered {
    Ack,
    Error(ErrorCode),
    Gated,
    Tracks,
}

impl Answered {
    fn of(reply: &Reply<'_>) -> Answered {
        match reply {
            Reply::One(DeviceToHost::Error(e)) => Answered::Error(*e),
            Reply::One(_) => Answered::Ack,
            Reply::Gated => Answered::Gated,
            Reply::Tracks => Answered::Tracks,
        }
    }

    fn reply(self) -> Reply<'static> {
        match self {
            Answered::Ack => Reply::One(DeviceToHost::Ack),
            Answered::Error(e) => Reply::One(DeviceToHost::Error(e)),
            Answered::Gated => Reply::Gated,
            Answered::Tracks => Reply::Tracks,
        }
    }
}

/// Static facts about the device, reported in the handshake.
#[derive(Clone, Copy, Debug)]
pub struct DeviceConfig {
    /// Firmware identification, e.g. `tracker-firmware 0.1.0 (mps2-an386)` (at most 48
    /// bytes are sent).
    pub firmware: &'static str,
    /// Differs from boot to boot.
    pub boot_id: u32,
    /// Track table size.
    pub max_tracks: u16,
    /// Plots accepted per scan.
    pub max_plots_per_scan: u16,
}

/// The dispatcher: requests carried out, replies chosen, counters kept.
#[derive(Clone, Debug)]
struct Dispatch {
    config: DeviceConfig,
    tracker: Tracker,
    /// The last state-changing request's id and how it was answered: a retry (the host
    /// resends with the same id when the reply was lost) is answered again, not redone.
    last_change: Option<(u32, Answered)>,
    stats: LinkStats,
}

/// The link endpoint and request dispatcher of the tracker device.
///
/// A request is read where it lies in the frame buffer, and its reply is written straight
/// into the frame it goes out in: nothing on the link path moves a message by value.
#[derive(Clone, Debug)]
pub struct Device {
    dispatch: Dispatch,
    decoder: FrameDecoder,
    /// A report part's records, before they go into their frame.
    records: [u8; MAX_RECORD_BYTES],
    tx: [u8; MAX_ENCODED_FRAME_BYTES],
}

impl Device {
    /// A device waiting for its first frame.
    pub const fn new(config: DeviceConfig) -> Self {
        Device {
            dispatch: Dispatch {
                config,
                tracker: Tracker::new(),
                stats: LinkStats {
                    bytes_in: 0,
                    frames_ok: 0,
                    bad_cobs: 0,
                    bad_crc: 0,
                    oversize: 0,
                    malformed: 0,
                    unknown_message: 0,
                    version_mismatch: 0,
                    request_errors: 0,
                    frames_out: 0,
                    duplicate_requests: 0,
                },
                last_change: None,
            },
            decoder: FrameDecoder::new(),
            records: [0; MAX_RECORD_BYTES],
            tx: [0; MAX_ENCODED_FRAME_BYTES],
        }
    }

    /// Sets the boot id reported in the handshake (known only at run time on a board).
    pub fn set_boot_id(&mut self, boot_id: u32) {
        self.dispatch.config.boot_id = boot_id;
    }

    /// The link counters.
    pub fn stats(&self) -> LinkStats {
        self.dispatch.stats
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        &self.dispatch.tracker
    }

    /// The tracker, to drive its scan cycle without the link (the benches measure the
    /// tracking work apart from reading the frames).
    pub fn tracker_mut(&mut self) -> &mut Tracker {
        &mut self.dispatch.tracker
    }

    /// Takes bytes from the link (as many as the UART has: one, or a DMA buffer's worth);
    /// each frame they complete is handled and its encoded reply handed to `send`.
    #[inline]
    pub fn receive(&mut self, bytes: &[u8], send: &mut impl FnMut(&[u8])) {
        // A byte inside a frame, as a UART hands them over: kept, nothing more. Small
        // enough to be inlined into the UART loop.
        if let [byte] = *bytes {
            if byte != 0 {
                self.dispatch.stats.bytes_in = self.dispatch.stats.bytes_in.wrapping_add(1);
                self.decoder.keep(byte);
                return;
            }
        }
        self.receive_frames(bytes, send);
    }

    /// [`Device::receive`] for bytes that may end a frame.
    #[inline(never)]
    fn receive_frames(&mut self, mut bytes: &[u8], send: &mut impl FnMut(&[u8])) {
        let n = u32::try_from(bytes.len()).unwrap_or(u32::MAX);
        self.dispatch.stats.bytes_in = self.dispatch.stats.bytes_in.wrapping_add(n);
        while !bytes.is_empty() {
            let (used, frame) = self.decoder.push_slice(bytes);
            bytes = bytes.get(used..).unwrap_or(&[]);
            let Some(result) = frame else {
                continue;
            };
            let out = Out {
                records: &mut self.records,
                tx: &mut self.tx,
            };
            self.dispatch.frame(result, out, send);
        }
    }

    /// Carries out one decoded request.
    pub fn handle<'r>(&mut self, request: &HostToDevice<'r>) -> Reply<'r> {
        self.dispatch.handle(request)
    }
}

/// The buffers a reply is encoded through.
struct Out<'a> {
    records: &'a mut [u8; MAX_RECORD_BYTES],
    tx: &'a mut [u8; MAX_ENCODED_FRAME_BYTES],
}

impl Dispatch {
    /// One delimited frame: decoded, dispatched, answered.
    fn frame(
        &mut self,
        result: Result<&[u8], FrameError>,
        out: Out<'_>,
        send: &mut impl FnMut(&[u8]),
    ) {
        let decoded = result
            .map_err(|e| (None, e))
            .and_then(|p| frame::decode_payload::<HostToDevice>(p, HOST_TO_DEVICE_VARIANTS));
        match decoded {
            Ok((header, request)) => {
                self.stats.frames_ok = self.stats.frames_ok.wrapping_add(1);
                let id = header.request_id;
                let changes = request.changes_state();
                let repeated = match self.last_change {
                    Some((last, answered)) if changes && last == id => Some(answered),
                    _ => None,
                };
                if let Some(answered) = repeated {
                    self.stats.duplicate_requests = self.stats.duplicate_requests.wrapping_add(1);
                    self.send_reply(id, answered.reply(), out, send);
                } else {
                    let reply = self.handle(&request);
                    if changes {
                        self.last_change = Some((id, Answered::of(&reply)));
                    }
                    // Content that decoded as a message but not as its lists is a
                    // malformed frame too.
                    if reply == Reply::One(DeviceToHost::Error(ErrorCode::Malformed)) {
                        self.stats.malformed = self.stats.malformed.wrapping_add(1);
                    }
                    self.send_reply(id, reply, out, send);
                }
            }
            Err((header, error)) => {
                self.count(error);
                let id = header.map_or(UNPAIRED_REQUEST_ID, |h| h.request_id);
                let reply = Reply::One(DeviceToHost::Error(error.code()));
                self.send_reply(id, reply, out, send);
            }
        }
    }

    /// Encodes and sends `reply`, a report in as many frames as its records need.
    fn send_reply(
        &mut self,
        request_id: u32,
        reply: Reply<'_>,
        out: Out<'_>,
        send: &mut impl FnMut(&[u8]),
    ) {
        let Out { records, tx } = out;
        let mut emit = |body: &DeviceToHost<'_>, stats: &mut LinkStats| {
            let header = Header {
                protocol: PROTOCOL_VERSION,
                request_id,
            };
            let encoded = match frame::encode(&header, body, tx) {
                Ok(n) => n,
                // Cannot happen for ICD messages (a test proves the largest fit); answer
                // with the smallest message rather than stay silent.
                Err(_) => {
                    let err = DeviceToHost::Error(ErrorCode::Malformed);
                    match frame::encode(&header, &err, tx) {
                        Ok(n) => n,
                        Err(_) => return,
                    }
                }
            };
            stats.frames_out = stats.frames_out.wrapping_add(1);
            if let Some(bytes) = tx.get(..encoded) {
                send(bytes);
            }
        };
        match reply {
            Reply::One(body) => {
                if matches!(body, DeviceToHost::Error(_)) && request_id != UNPAIRED_REQUEST_ID {
                    self.stats.request_errors = self.stats.request_errors.wrapping_add(1);
                }
                emit(&body, &mut self.stats);
            }
            Reply::Gated | Reply::Tracks => {
                let tracker = &self.tracker;
                let tracks = tracker.table().len();
                let (mut from, mut part) = (0, 0u8);
                loop {
                    let mut w = Writer::new(&mut records[..]);
                    let next = match reply {
                        Reply::Gated => tracker.write_gates(from, &mut w),
                        _ => tracker.write_states(from, &mut w),
                    };
                    // A part that took no track (cannot be: a record always fits an
                    // empty part) ends the report rather than loop.
                    let last = next >= tracks || next <= from;
                    let n = w.len();
                    let bytes = Bytes(records.get(..n).unwrap_or(&[]));
                    let body = match reply {
                        Reply::Gated => {
                            let (scan, base_scan, live_tracks) = tracker.gate_report();
                            DeviceToHost::Gated(GatedBatch {
                                scan,
                                part,
                                last,
                                base_scan,
                                live_tracks,
                                gates: bytes,
                            })
                        }
                        _ => {
                            let (scan, base_scan) = tracker.state_report();
                            DeviceToHost::Tracks(TrackBatch {
                                scan,
                                part,
                                last,
                                base_scan,
                                states: bytes,
                            })
                        }
                    };
                    emit(&body, &mut self.stats);
                    if last {
                        break;
                    }
                    from = next;
                    part = part.wrapping_add(1);
                }
            }
        }
    }

    /// Carries out one decoded request.
    fn handle<'r>(&mut self, request: &HostToDevice<'r>) -> Reply<'r> {
        let ack = |r: Result<(), ErrorCode>| {
            Reply::One(match r {
                Ok(()) => DeviceToHost::Ack,
                Err(e) => DeviceToHost::Error(e),
            })
        };
        match *request {
            HostToDevice::Hello => {
                // A handshake opens a new session (perhaps a restarted host, whose request ids
                // start again): forget the last request, so no new one passes for a retry.
                self.last_change = None;
                Reply::One(DeviceToHost::HelloAck(self.info()))
            }
            HostToDevice::Echo(bytes) => Reply::One(DeviceToHost::Echo(bytes)),
            HostToDevice::GetStats => Reply::One(DeviceToHost::Stats(self.stats)),
            HostToDevice::Configure(config) => ack(self.tracker.configure(config)),
            HostToDevice::Command(command) => ack(self.tracker.command(command)),
            HostToDevice::Plots(ref batch) => match self.tracker.take_plots(batch) {
                Ok(true) => Reply::Gated,
                Ok(false) => Reply::One(DeviceToHost::Ack),
                Err(e) => Reply::One(DeviceToHost::Error(e)),
            },
            HostToDevice::Assign(ref batch) => match self.tracker.assign(batch) {
                Ok(true) => Reply::Tracks,
                Ok(false) => Reply::One(DeviceToHost::Ack),
                Err(e) => Reply::One(DeviceToHost::Error(e)),
            },
            HostToDevice::GetTracks => {
                self.tracker.whole_report();
                Reply::Tracks
            }
        }
    }

    fn info(&self) -> DeviceInfo<'static> {
        let name = self.config.firmware;
        // At most 48 bytes, cut at a character boundary: the name is informational.
        let mut end = name.len().min(48);
        while !name.is_char_boundary(end) {
            end = end.saturating_sub(1);
        }
        DeviceInfo {
            protocol: PROTOCOL_VERSION,
            firmware: name.get(..end).unwrap_or(""),
            max_frame_bytes: MAX_FRAME_BYTES as u16,
            max_tracks: self.config.max_tracks,
            max_plots_per_scan: self.config.max_plots_per_scan,
            boot_id: self.config.boot_id,
        }
    }

    fn count(&mut self, error: FrameError) {
        let s = &mut self.stats;
        let counter = match error {
            FrameError::Cobs => &mut s.bad_cobs,
            FrameError::Crc => &mut s.bad_crc,
            FrameError::Oversize => &mut s.oversize,
            FrameError::Malformed | FrameError::BufferTooSmall => &mut s.malformed,
            FrameError::UnknownMessage => &mut s.unknown_message,
            FrameError::VersionMismatch { .. } => &mut s.version_mismatch,
        };
        *counter = counter.wrapping_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::decode_payload;
    use crate::icd::records::{self, GateReference, StateOnGrid};
    use crate::icd::varint::Reader;
    use crate::icd::{
        AssignmentBatch, PlotBatch, TrackCommand, MAX_ASSIGNMENT_BYTES, MAX_PLOT_BYTES,
    };
    use crate::track::MAX_TRACKS;
    use std::vec::Vec;

    const CONFIG: DeviceConfig = DeviceConfig {
        firmware: "test",
        boot_id: 42,
        max_tracks: MAX_TRACKS as u16,
        max_plots_per_scan: 256,
    };

    /// Runs bytes through a device (one slice, and again a byte at a time on a clone: the
    /// same replies) and returns each reply frame's checked payload.
    fn exchange(dev: &mut Device, bytes: &[u8]) -> Vec<Vec<u8>> {
        let mut bytewise = dev.clone();
        let (mut wire, mut wire_bytewise) = (Vec::new(), Vec::new());
        dev.receive(bytes, &mut |out| wire.extend_from_slice(out));
        for b in bytes {
            bytewise.receive(core::slice::from_ref(b), &mut |out| {
                wire_bytewise.extend_from_slice(out)
            });
        }
        assert_eq!(wire, wire_bytewise, "one slice and a byte at a time");
        let mut dec = FrameDecoder::new();
        let mut payloads = Vec::new();
        for b in wire {
            if let Some(r) = dec.push(b) {
                payloads.push(r.unwrap().to_vec());
            }
        }
        payloads
    }

    fn reply(payload: &[u8]) -> (Header, DeviceToHost<'_>) {
        decode_payload(payload, u32::MAX).unwrap()
    }

    fn request(id: u32, body: &HostToDevice) -> Vec<u8> {
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let h = Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        };
        let n = frame::encode(&h, body, &mut out).unwrap();
        out[..n].to_vec()
    }

    fn plots_request(id: u32, scan: u32, base: Option<u32>, plots: &[[f32; 2]]) -> Vec<u8> {
        let mut buf = [0u8; MAX_PLOT_BYTES];
        let head = PlotBatch {
            scan,
            time_ms: u64::from(scan) * 2500,
            part: 0,
            parts: 1,
            base_scan: base,
            plots: Bytes(&[]),
        };
        request(
            id,
            &HostToDevice::Plots(PlotBatch::pack(head, plots, &mut buf)),
        )
    }

    /// Every part of a scan's assignments, the parts numbered `id`, `id + 1000`, ….
    fn assign_request(id: u32, scan: u32, updates: &[(u16, u16)], initiate: &[u16]) -> Vec<u8> {
        let parts = AssignmentBatch::parts(updates.len(), initiate.len());
        let mut bytes = Vec::new();
        for part in 0..parts {
            let mut buf = [0u8; MAX_ASSIGNMENT_BYTES];
            let b = AssignmentBatch::pack(scan, (part, parts), updates, initiate, &mut buf);
            bytes.extend(request(
                id + 1000 * u32::from(part),
                &HostToDevice::Assign(b),
            ));
        }
        bytes
    }

    #[test]
    fn handshake_reports_the_device() {
        let mut dev = Device::new(CONFIG);
        let r = exchange(&mut dev, &request(1, &HostToDevice::Hello));
        let (h, DeviceToHost::HelloAck(info)) = reply(&r[0]) else {
            panic!("{r:?}")
        };
        assert_eq!(h.request_id, 1);
        assert_eq!(info.protocol, PROTOCOL_VERSION);
        assert_eq!(info.boot_id, 42);
        assert_eq!(info.firmware, "test");
    }

    #[test]
    fn every_frame_gets_one_reply_and_errors_are_counted() {
        let mut dev = Device::new(CONFIG);
        let mut stream = request(1, &HostToDevice::Hello);
        stream.extend_from_slice(&[1, 2, 3, 0]); // garbage
        let mut bad = request(2, &HostToDevice::GetStats);
        bad[1] ^= 0x10;
        stream.extend_from_slice(&bad);
        stream.extend_from_slice(&request(3, &HostToDevice::GetStats));
        let r = exchange(&mut dev, &stream);
        assert_eq!(r.len(), 4);
        assert!(matches!(reply(&r[1]).1, DeviceToHost::Error(_)));
        assert_eq!(reply(&r[1]).0.request_id, UNPAIRED_REQUEST_ID);
        assert!(matches!(
            reply(&r[2]).1,
            DeviceToHost::Error(ErrorCode::BadCrc)
        ));
        let (h, DeviceToHost::Stats(s)) = reply(&r[3]) else {
            panic!()
        };
        assert_eq!(
            s.frames_ok, 2,
            "stats are read while handling the 3rd good frame"
        );
        assert_eq!(s.rejected(), 2);
        assert_eq!(h.request_id, 3);
    }

    #[test]
    fn an_echo_comes_back_as_it_went() {
        let mut dev = Device::new(CONFIG);
        let bytes: Vec<u8> = (0..1000).map(|i| (i % 251) as u8).collect();
        let r = exchange(&mut dev, &request(9, &HostToDevice::Echo(Bytes(&bytes))));
        assert_eq!(reply(&r[0]).1, DeviceToHost::Echo(Bytes(&bytes)));
    }

    #[test]
    fn lists_that_do_not_decode_are_malformed_and_counted() {
        let mut dev = Device::new(CONFIG);
        let head = PlotBatch {
            scan: 0,
            time_ms: 0,
            part: 0,
            parts: 1,
            base_scan: None,
            plots: Bytes(&[2, 4, 6]), // one and a half plots
        };
        let r = exchange(&mut dev, &request(5, &HostToDevice::Plots(head)));
        assert_eq!(reply(&r[0]).1, DeviceToHost::Error(ErrorCode::Malformed));
        assert_eq!(dev.stats().malformed, 1);
        // The device goes on: a good scan is taken.
        let r = exchange(&mut dev, &plots_request(6, 0, None, &[[0.0, 1000.0]]));
        assert!(matches!(reply(&r[0]).1, DeviceToHost::Gated(_)));
    }

    #[test]
    fn a_retried_request_is_answered_again_not_redone() {
        let mut dev = Device::new(CONFIG);
        let first = exchange(&mut dev, &plots_request(5, 0, None, &[[0.0, 1000.0]]));
        let assign = assign_request(6, 0, &[], &[0]);
        let a = exchange(&mut dev, &assign);
        // The reply was lost; the host resends request 6: same answer, one track, not two.
        let again = exchange(&mut dev, &assign);
        assert_eq!(a, again);
        assert_eq!(dev.tracker().table().len(), 1);
        assert_eq!(dev.stats().duplicate_requests, 1);
        assert!(matches!(reply(&first[0]).1, DeviceToHost::Gated(_)));
        // A new id is a new request (here out of sequence: no scan open).
        let r = exchange(&mut dev, &assign_request(7, 0, &[], &[0]));
        assert_eq!(
            reply(&r[0]).1,
            DeviceToHost::Error(ErrorCode::OutOfSequence)
        );
    }

    /// The host's side of the records, as plainly as it can be said: the last report's
    /// states and the factors of the gates sent at its scan.
    #[derive(Default)]
    struct Host {
        base: Option<(u32, u64)>,
        states: Vec<StateOnGrid>,
        factors: Vec<(u16, [i32; 3])>,
        plots: Vec<[i32; 2]>,
    }

    impl Host {
        fn gates(&mut self, payloads: &[Vec<u8>], time_ms: u64) -> Vec<records::GateOnGrid> {
            let mut out = Vec::new();
            let mut factors = Vec::new();
            for (i, p) in payloads.iter().enumerate() {
                let DeviceToHost::Gated(g) = reply(p).1 else {
                    panic!("{:?}", reply(p).1)
                };
                assert_eq!((g.part as usize, g.last), (i, i + 1 == payloads.len()));
                let with_base = g.base_scan.is_some();
                if with_base {
                    assert_eq!(g.base_scan, self.base.map(|b| b.0));
                }
                let dt = self.base.map_or(0.0, |b| records::interval_s(b.1, time_ms));
                let mut r = Reader::new(g.gates.0);
                let mut prev = 0;
                while !r.is_empty() {
                    let gate = records::read_gate(
                        &mut r,
                        prev,
                        |t| GateReference {
                            moved_on: self
                                .states
                                .iter()
                                .find(|s| with_base && s.track == t)
                                .map(|s| s.moved_on(dt)),
                            cholesky_cm: self
                                .factors
                                .iter()
                                .find(|f| with_base && f.0 == t)
                                .map(|f| f.1),
                        },
                        |i| self.plots.get(usize::from(i)).copied(),
                    )
                    .unwrap();
                    prev = gate.track;
                    factors.push((gate.track, gate.cholesky_cm));
                    out.push(gate);
                }
            }
            self.factors = factors;
            out
        }

        fn states(&mut self, payloads: &[Vec<u8>], time_ms: u64) {
            let mut states = Vec::new();
            let mut scan = 0;
            for p in payloads {
                let DeviceToHost::Tracks(t) = reply(p).1 else {
                    panic!()
                };
                scan = t.scan;
                let with_base = t.base_scan.is_some();
                let dt = self.base.map_or(0.0, |b| records::interval_s(b.1, time_ms));
                let mut r = Reader::new(t.states.0);
                let mut prev = 0;
                while !r.is_empty() {
                    let s = records::read_state(
                        &mut r,
                        prev,
                        |k| {
                            self.states
                                .iter()
                                .find(|s| with_base && s.track == k)
                                .copied()
                        },
                        dt,
                    )
                    .unwrap();
                    prev = s.track;
                    states.push(s);
                }
            }
            states.retain(|s| s.status != crate::icd::TrackStatus::Lost);
            self.states = states;
            self.base = Some((scan, time_ms));
        }
    }

    #[test]
    fn gates_and_states_decode_to_the_tables_values_against_each_base() {
        // Ten targets over thirty scans; the host holds every report, except that it
        // misses one (and names an older base: the device then sends whole records).
        let mut dev = Device::new(CONFIG);
        let mut host = Host::default();
        let mut id = 1;
        let mut whole_after_miss = 0;
        for scan in 0..30u32 {
            let t = f32::from(scan as u16) * 2.5;
            let plots: Vec<[f32; 2]> = (0..10)
                .map(|i| {
                    let i = i as f32;
                    [
                        1000.0 * i + 4.0 * t + (t * 1.7 + i).sin() * 30.0,
                        -500.0 * i + 2.0 * t,
                    ]
                })
                .map(crate::icd::fixed::position_on_grid)
                .collect();
            host.plots = plots.iter().map(|&p| records::tenths(p)).collect();
            let time_ms = u64::from(scan) * 2500;
            let named = if scan == 17 {
                Some(3)
            } else {
                host.base.map(|b| b.0)
            };
            let r = exchange(&mut dev, &plots_request(id, scan, named, &plots));
            id += 1;
            if scan == 17 {
                let DeviceToHost::Gated(g) = reply(&r[0]).1 else {
                    panic!()
                };
                assert_eq!(g.base_scan, None, "the base the host named is not the last");
                host.base = None;
                host.states.clear();
                whole_after_miss += 1;
            }
            let gates = host.gates(&r, time_ms);
            // The gates are the table's, on the grid.
            let table: Vec<_> = dev
                .tracker()
                .table()
                .tracks()
                .filter(|t| !t.gated_plots().is_empty())
                .map(|t| {
                    records::GateOnGrid::of(
                        t.id,
                        heapless::Vec::from_slice(t.gated_plots()).unwrap(),
                        t.filter().prediction(),
                        t.innovation_cov_m2(),
                    )
                })
                .collect();
            assert_eq!(gates, table, "scan {scan}");
            // Each gate's nearest plot, else a new track.
            let mut updates = Vec::new();
            let mut used = Vec::new();
            for g in &gates {
                if let Some(&p) = g.plots.iter().find(|p| !used.contains(*p)) {
                    used.push(p);
                    updates.push((g.track, p));
                }
            }
            let initiate: Vec<u16> = (0..plots.len() as u16)
                .filter(|p| !gates.iter().any(|g| g.plots.contains(p)))
                .collect();
            let r = exchange(&mut dev, &assign_request(id, scan, &updates, &initiate));
            id += 1;
            host.states(&r, time_ms);
            let table: Vec<StateOnGrid> = dev
                .tracker()
                .table()
                .tracks()
                .map(|t| t.state())
                .filter(|s| records::reported(s.status, s.hit_history))
                .map(|s| StateOnGrid::of(&s))
                .collect();
            assert_eq!(host.states, table, "scan {scan}");
        }
        assert_eq!(whole_after_miss, 1);
        assert!(host.states.len() >= 10, "{}", host.states.len());
    }

    #[test]
    fn a_report_of_many_tracks_comes_in_parts() {
        let mut dev = Device::new(CONFIG);
        // A full table, far out (four-byte coordinates) and old (two-byte age and hits): its
        // whole records fill more than a part.
        let n = MAX_TRACKS as u16;
        let plots: Vec<[f32; 2]> = (0..n).map(|i| [-100_000.0 * f32::from(i), 5.0e6]).collect();
        let ids: Vec<u16> = (0..n).collect();
        let updates: Vec<(u16, u16)> = (1..=n).zip(0..n).collect();
        for scan in 0..130u32 {
            exchange(&mut dev, &plots_request(10, scan, None, &plots));
            let (u, start): (&[(u16, u16)], &[u16]) = if scan == 0 {
                (&[], &ids)
            } else {
                (&updates, &[])
            };
            let mut r = exchange(&mut dev, &assign_request(20 + scan, scan, u, start));
            assert_eq!(reply(&r[0]).1, DeviceToHost::Ack, "the first of two parts");
            r.remove(0);
            if scan == 129 {
                assert!(r.len() >= 2, "{} parts", r.len());
                for (i, p) in r.iter().enumerate() {
                    let (h, DeviceToHost::Tracks(t)) = reply(p) else {
                        panic!()
                    };
                    assert_eq!(h.request_id, 20 + scan + 1000, "the last part's request");
                    assert_eq!((usize::from(t.part), t.last), (i, i + 1 == r.len()));
                }
            }
        }
        assert_eq!(dev.tracker().table().len(), MAX_TRACKS);
        let r = exchange(&mut dev, &request(40, &HostToDevice::GetTracks));
        assert!(r.len() >= 2);
        let r = exchange(
            &mut dev,
            &request(41, &HostToDevice::Command(TrackCommand::CancelAll)),
        );
        assert_eq!(reply(&r[0]).1, DeviceToHost::Ack);
        assert_eq!(dev.tracker().table().len(), 0);
    }
}
