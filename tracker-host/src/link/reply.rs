//! The device's replies as the host keeps them: [`tracker_core::icd::DeviceToHost`] is read
//! where it lies in the frame buffer, which the next frame overwrites; these own their bytes.

use tracker_core::icd::{DeviceToHost, ErrorCode, LinkStats};

/// What a device reports in its handshake ([`tracker_core::icd::DeviceInfo`], owned).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceInfo {
    /// The device's protocol version.
    pub protocol: u16,
    /// Firmware name and version.
    pub firmware: String,
    /// Frames are at most this long (decoded bytes).
    pub max_frame_bytes: u16,
    /// Size of the track table.
    pub max_tracks: u16,
    /// Plots the device accepts per scan.
    pub max_plots_per_scan: u16,
    /// Changes on every boot.
    pub boot_id: u32,
}

/// One part of a report ([`tracker_core::icd::GatedBatch`] or
/// [`tracker_core::icd::TrackBatch`]), owned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReportPart {
    /// The scan the report belongs to.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// This is the report's last part.
    pub last: bool,
    /// The base its records are coded against.
    pub base_scan: Option<u32>,
    /// Tracks in the device's table (gate reports only; 0 in state reports).
    pub live_tracks: u16,
    /// The packed records ([`tracker_core::icd::records`]).
    pub records: Vec<u8>,
}

/// A reply from the device.
#[derive(Clone, Debug, PartialEq)]
pub enum Reply {
    /// Handshake reply.
    HelloAck(DeviceInfo),
    /// An echo's bytes.
    Echo(Vec<u8>),
    /// Link and dispatch counters.
    Stats(LinkStats),
    /// Understood and carried out.
    Ack,
    /// A part of the scan's rough gates.
    Gated(ReportPart),
    /// A part of the track states.
    Tracks(ReportPart),
    /// The request failed; the device's state is unchanged by it.
    Error(ErrorCode),
}

impl Reply {
    /// The part number and whether it is the last, for the reports; `(0, true)` otherwise.
    pub fn part(&self) -> (u8, bool) {
        match self {
            Reply::Gated(p) | Reply::Tracks(p) => (p.part, p.last),
            _ => (0, true),
        }
    }
}

/// What the reply is, in words, for an error that names an answer the request did not
/// expect (a peer's bug, not the operator's): its kind and part, not its bytes.
impl std::fmt::Display for Reply {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Reply::HelloAck(_) => f.write_str("a handshake reply"),
            Reply::Echo(bytes) => write!(f, "an echo of {} B", bytes.len()),
            Reply::Stats(_) => f.write_str("the link's counters"),
            Reply::Ack => f.write_str("an acknowledgement"),
            Reply::Gated(p) => write!(f, "part {} of scan {}'s rough gates", p.part, p.scan),
            Reply::Tracks(p) => write!(f, "part {} of scan {}'s track report", p.part, p.scan),
            Reply::Error(code) => write!(f, "a refusal ({code})"),
        }
    }
}

impl From<DeviceToHost<'_>> for Reply {
    fn from(m: DeviceToHost<'_>) -> Self {
        match m {
            DeviceToHost::HelloAck(i) => Reply::HelloAck(DeviceInfo {
                protocol: i.protocol,
                firmware: i.firmware.to_string(),
                max_frame_bytes: i.max_frame_bytes,
                max_tracks: i.max_tracks,
                max_plots_per_scan: i.max_plots_per_scan,
                boot_id: i.boot_id,
            }),
            DeviceToHost::Echo(b) => Reply::Echo(b.0.to_vec()),
            DeviceToHost::Stats(s) => Reply::Stats(s),
            DeviceToHost::Ack => Reply::Ack,
            DeviceToHost::Gated(g) => Reply::Gated(ReportPart {
                scan: g.scan,
                part: g.part,
                last: g.last,
                base_scan: g.base_scan,
                live_tracks: g.live_tracks,
                records: g.gates.0.to_vec(),
            }),
            DeviceToHost::Tracks(t) => Reply::Tracks(ReportPart {
                scan: t.scan,
                part: t.part,
                last: t.last,
                base_scan: t.base_scan,
                live_tracks: 0,
                records: t.states.0.to_vec(),
            }),
            DeviceToHost::Error(e) => Reply::Error(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reply_is_told_in_words_not_bytes() {
        let part = ReportPart {
            scan: 7,
            part: 2,
            last: false,
            base_scan: None,
            live_tracks: 3,
            records: vec![0; 900],
        };
        assert_eq!(
            Reply::Tracks(part.clone()).to_string(),
            "part 2 of scan 7's track report"
        );
        assert_eq!(
            Reply::Gated(part).to_string(),
            "part 2 of scan 7's rough gates"
        );
        assert_eq!(Reply::Echo(vec![1; 16]).to_string(), "an echo of 16 B");
        assert_eq!(
            Reply::Error(ErrorCode::CapacityExceeded).to_string(),
            format!("a refusal ({})", ErrorCode::CapacityExceeded)
        );
    }
}
