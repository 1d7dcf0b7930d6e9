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

use heapless::String;

use crate::frame::{self, FrameDecoder, FrameError};
use crate::icd::{
    DeviceInfo, DeviceToHost, ErrorCode, Header, HostToDevice, LinkStats, HOST_TO_DEVICE_VARIANTS,
    MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, PROTOCOL_VERSION, UNPAIRED_REQUEST_ID,
};
use crate::tracker::Tracker;

/// What a request is answered with: one frame, or a report in parts (each its own frame,
/// all carrying the request's id).
// No heap to box into; a reply lives only until it is encoded.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Reply {
    /// One message.
    One(DeviceToHost),
    /// The scan's rough gates, in this many parts.
    Gated {
        /// Number of parts.
        parts: u8,
    },
    /// The track table, in this many parts.
    Tracks {
        /// Number of parts.
        parts: u8,
    },
}

/// How a state-changing request was answered, in a few bytes: every such answer is an
/// acknowledgement, an error, or a report regenerated from the (unchanged) state.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Answered {
    Ack,
    Error(ErrorCode),
    Gated { parts: u8 },
    Tracks { parts: u8 },
}

impl Answered {
    fn of(reply: &Reply) -> Answered {
        match reply {
            Reply::One(DeviceToHost::Error(e)) => Answered::Error(*e),
            Reply::One(_) => Answered::Ack,
            Reply::Gated { parts } => Answered::Gated { parts: *parts },
            Reply::Tracks { parts } => Answered::Tracks { parts: *parts },
        }
    }

    fn reply(self) -> Reply {
        match self {
            Answered::Ack => Reply::One(DeviceToHost::Ack),
            Answered::Error(e) => Reply::One(DeviceToHost::Error(e)),
            Answered::Gated { parts } => Reply::Gated { parts },
            Answered::Tracks { parts } => Reply::Tracks { parts },
        }
    }
}

/// Static facts about the device, reported in the handshake.
#[derive(Clone, Copy, Debug)]
pub struct DeviceConfig {
    /// Firmware identification, e.g. `tracker-firmware 0.1.0 (mps2-an386)`.
    pub firmware: &'static str,
    /// Differs from boot to boot.
    pub boot_id: u32,
    /// Track table size.
    pub max_tracks: u16,
    /// Plots accepted per scan.
    pub max_plots_per_scan: u16,
}

/// The link endpoint and request dispatcher of the tracker device.
#[derive(Clone, Debug)]
pub struct Device {
    config: DeviceConfig,
    tracker: Tracker,
    /// The last state-changing request's id and how it was answered: a retry (the host
    /// resends with the same id when the reply was lost) is answered again, not redone.
    last_change: Option<(u32, Answered)>,
    decoder: FrameDecoder,
    stats: LinkStats,
    scratch: [u8; MAX_FRAME_BYTES],
    tx: [u8; MAX_ENCODED_FRAME_BYTES],
}

impl Device {
    /// A device waiting for its first frame.
    pub const fn new(config: DeviceConfig) -> Self {
        Device {
            config,
            tracker: Tracker::new(),
            decoder: FrameDecoder::new(),
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
            scratch: [0; MAX_FRAME_BYTES],
            tx: [0; MAX_ENCODED_FRAME_BYTES],
        }
    }

    /// Sets the boot id reported in the handshake (known only at run time on a board).
    pub fn set_boot_id(&mut self, boot_id: u32) {
        self.config.boot_id = boot_id;
    }

    /// The link counters.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Takes one byte from the link; when it completes a frame, handles it and hands the
    /// encoded reply to `send`.
    pub fn receive(&mut self, byte: u8, send: &mut impl FnMut(&[u8])) {
        self.stats.bytes_in = self.stats.bytes_in.wrapping_add(1);
        let Some(result) = self.decoder.push(byte) else {
            return;
        };
        let decoded = result
            .map_err(|e| (None, e))
            .and_then(|p| frame::decode_payload::<HostToDevice>(p, HOST_TO_DEVICE_VARIANTS));
        // Replies are sent from where they are made and passed on by reference: a reply can
        // hold a kilobyte, and each move of it is a kilobyte copied (about 3,500
        // instructions on the M4F).
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
                    self.send_reply(id, &answered.reply(), send);
                } else {
                    let reply = self.handle(&request);
                    if changes {
                        self.last_change = Some((id, Answered::of(&reply)));
                    }
                    self.send_reply(id, &reply, send);
                }
            }
            Err((header, error)) => {
                self.count(error);
                let id = header.map_or(UNPAIRED_REQUEST_ID, |h| h.request_id);
                self.send_reply(id, &Reply::One(DeviceToHost::Error(error.code())), send);
            }
        }
    }

    /// Encodes and sends `reply`, in as many frames as it has parts.
    fn send_reply(&mut self, request_id: u32, reply: &Reply, send: &mut impl FnMut(&[u8])) {
        match reply {
            Reply::One(body) => {
                if matches!(body, DeviceToHost::Error(_)) && request_id != UNPAIRED_REQUEST_ID {
                    self.stats.request_errors = self.stats.request_errors.wrapping_add(1);
                }
                self.reply(request_id, body, send);
            }
            &Reply::Gated { parts } => {
                for part in 0..parts {
                    let body = DeviceToHost::Gated(self.tracker.gated_part(part, parts));
                    self.reply(request_id, &body, send);
                }
            }
            &Reply::Tracks { parts } => {
                for part in 0..parts {
                    let body = DeviceToHost::Tracks(self.tracker.tracks_part(part, parts));
                    self.reply(request_id, &body, send);
                }
            }
        }
    }

    /// Carries out one decoded request.
    pub fn handle(&mut self, request: &HostToDevice) -> Reply {
        let ack = |r: Result<(), ErrorCode>| {
            Reply::One(match r {
                Ok(()) => DeviceToHost::Ack,
                Err(e) => DeviceToHost::Error(e),
            })
        };
        match request {
            HostToDevice::Hello => {
                // A handshake opens a new session (perhaps a restarted host, whose request ids
                // start again): forget the last request, so no new one passes for a retry.
                self.last_change = None;
                Reply::One(DeviceToHost::HelloAck(self.info()))
            }
            HostToDevice::Echo(bytes) => Reply::One(DeviceToHost::Echo(bytes.clone())),
            HostToDevice::GetStats => Reply::One(DeviceToHost::Stats(self.stats)),
            HostToDevice::Configure(config) => ack(self.tracker.configure(*config)),
            HostToDevice::Command(command) => ack(self.tracker.command(*command)),
            HostToDevice::Plots(batch) => match self.tracker.plots(batch) {
                Ok(Some(parts)) => Reply::Gated { parts },
                Ok(None) => Reply::One(DeviceToHost::Ack),
                Err(e) => Reply::One(DeviceToHost::Error(e)),
            },
            HostToDevice::Assign(batch) => match self.tracker.assign(batch) {
                Ok(Some(parts)) => Reply::Tracks { parts },
                Ok(None) => Reply::One(DeviceToHost::Ack),
                Err(e) => Reply::One(DeviceToHost::Error(e)),
            },
            HostToDevice::GetTracks => Reply::Tracks {
                parts: self.tracker.track_parts(),
            },
        }
    }

    /// The tracker.
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    fn info(&self) -> DeviceInfo {
        let mut firmware = String::new();
        // Truncate rather than fail: the name is informational.
        for c in self.config.firmware.chars() {
            if firmware.push(c).is_err() {
                break;
            }
        }
        DeviceInfo {
            protocol: PROTOCOL_VERSION,
            firmware,
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

    fn reply(&mut self, request_id: u32, body: &DeviceToHost, send: &mut impl FnMut(&[u8])) {
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id,
        };
        let encoded = match frame::encode(&header, body, &mut self.scratch, &mut self.tx) {
            Ok(n) => n,
            // Cannot happen for ICD messages (a test proves the largest fit); answer with
            // the smallest message rather than stay silent.
            Err(_) => {
                let err = DeviceToHost::Error(ErrorCode::Malformed);
                match frame::encode(&header, &err, &mut self.scratch, &mut self.tx) {
                    Ok(n) => n,
                    Err(_) => return,
                }
            }
        };
        self.stats.frames_out = self.stats.frames_out.wrapping_add(1);
        if let Some(bytes) = self.tx.get(..encoded) {
            send(bytes);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::decode_payload;
    use std::vec::Vec;

    const CONFIG: DeviceConfig = DeviceConfig {
        firmware: "test",
        boot_id: 42,
        max_tracks: 64,
        max_plots_per_scan: 256,
    };

    /// Runs bytes through a device and decodes every reply.
    fn exchange(dev: &mut Device, bytes: &[u8]) -> Vec<(Header, DeviceToHost)> {
        let mut wire = Vec::new();
        for &b in bytes {
            dev.receive(b, &mut |out| wire.extend_from_slice(out));
        }
        let mut dec = FrameDecoder::new();
        let mut replies = Vec::new();
        for b in wire {
            if let Some(r) = dec.push(b) {
                replies.push(decode_payload(r.unwrap(), u32::MAX).unwrap());
            }
        }
        replies
    }

    fn request(id: u32, body: &HostToDevice) -> Vec<u8> {
        let mut scratch = [0u8; MAX_FRAME_BYTES];
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let h = Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        };
        let n = frame::encode(&h, body, &mut scratch, &mut out).unwrap();
        out[..n].to_vec()
    }

    #[test]
    fn handshake_reports_the_device() {
        let mut dev = Device::new(CONFIG);
        let r = exchange(&mut dev, &request(1, &HostToDevice::Hello));
        let [(h, DeviceToHost::HelloAck(info))] = &r[..] else {
            panic!("{r:?}")
        };
        assert_eq!(h.request_id, 1);
        assert_eq!(info.protocol, PROTOCOL_VERSION);
        assert_eq!(info.boot_id, 42);
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
        assert!(matches!(r[1].1, DeviceToHost::Error(_)));
        assert_eq!(r[1].0.request_id, UNPAIRED_REQUEST_ID);
        assert!(matches!(r[2].1, DeviceToHost::Error(ErrorCode::BadCrc)));
        let DeviceToHost::Stats(s) = r[3].1 else {
            panic!()
        };
        assert_eq!(
            s.frames_ok, 2,
            "stats are read while handling the 3rd good frame"
        );
        assert_eq!(s.rejected(), 2);
        assert_eq!(r[3].0.request_id, 3);
    }

    #[test]
    fn a_retried_request_is_answered_again_not_redone() {
        use crate::icd::{AssignmentBatch, PlotBatch};
        let mut dev = Device::new(CONFIG);
        let scan = HostToDevice::Plots(PlotBatch {
            scan: 0,
            time_ms: 0,
            part: 0,
            parts: 1,
            plots_m: heapless::Vec::from_slice(&[[0.0, 1000.0]]).unwrap(),
        });
        let first = exchange(&mut dev, &request(5, &scan));
        let assign = HostToDevice::Assign(AssignmentBatch {
            scan: 0,
            part: 0,
            parts: 1,
            assignments: heapless::Vec::new(),
            initiate: heapless::Vec::from_slice(&[0]).unwrap(),
        });
        let a = exchange(&mut dev, &request(6, &assign));
        // The reply was lost; the host resends request 6: same answer, one track, not two.
        let again = exchange(&mut dev, &request(6, &assign));
        assert_eq!(a, again);
        assert_eq!(dev.tracker().table().len(), 1);
        assert_eq!(dev.stats().duplicate_requests, 1);
        assert!(matches!(first[0].1, DeviceToHost::Gated(_)));
        // A new id is a new request (here out of sequence: no scan open).
        let r = exchange(&mut dev, &request(7, &assign));
        assert_eq!(r[0].1, DeviceToHost::Error(ErrorCode::OutOfSequence));
    }

    #[test]
    fn a_scan_through_the_link_answers_in_parts() {
        use crate::icd::{AssignmentBatch, PlotBatch, MAX_TRACKS_PER_MESSAGE};
        let mut dev = Device::new(CONFIG);
        let n = MAX_TRACKS_PER_MESSAGE as u16 + 6;
        let batch = PlotBatch {
            scan: 0,
            time_ms: 0,
            part: 0,
            parts: 1,
            plots_m: (0..n).map(|i| [500.0 * f32::from(i), 1000.0]).collect(),
        };
        let r = exchange(&mut dev, &request(5, &HostToDevice::Plots(batch)));
        assert!(matches!(r[..], [(_, DeviceToHost::Gated(_))]), "{r:?}");
        let assign = AssignmentBatch {
            scan: 0,
            part: 0,
            parts: 1,
            assignments: heapless::Vec::new(),
            initiate: (0..n).collect(),
        };
        let r = exchange(&mut dev, &request(6, &HostToDevice::Assign(assign)));
        // More tracks than a message holds: two parts, both answering request 6.
        assert_eq!(r.len(), 2, "{r:?}");
        for (i, (h, body)) in r.iter().enumerate() {
            assert_eq!(h.request_id, 6);
            let DeviceToHost::Tracks(t) = body else {
                panic!("{body:?}")
            };
            assert_eq!((t.part, t.parts), (i as u8, 2));
        }
        let r = exchange(&mut dev, &request(7, &HostToDevice::GetTracks));
        assert_eq!(r.len(), 2);
        let r = exchange(
            &mut dev,
            &request(
                8,
                &HostToDevice::Command(crate::icd::TrackCommand::CancelAll),
            ),
        );
        assert_eq!(r[0].1, DeviceToHost::Ack);
        assert_eq!(dev.tracker().table().len(), 0);
    }
}
