//! Interface control document: the wire types shared by the firmware and the host.
//!
//! One module, both sides (the postcard-rpc ICD pattern). A frame on the link is
//!
//! ```text
//! COBS( postcard(Header) ‖ postcard(body) ‖ CRC-32/ISO-HDLC little-endian ) ‖ 0x00
//! ```
//!
//! where the body is a [`HostToDevice`] from the host or a [`DeviceToHost`] from the device.
//! Framing lives in [`crate::frame`]. Every frame carries the [`PROTOCOL_VERSION`] so a
//! mismatched peer is told so instead of being misread, and a request id that the device
//! echoes in its reply so the host can pair responses and retry lost requests.
//!
//! Compatibility rule: variants and fields are only ever appended; any change that alters
//! the encoding of an existing variant bumps [`PROTOCOL_VERSION`].

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::filter::kalman::{KalmanConfig, QModel};
use crate::filter::FilterConfig;

pub mod fixed;
pub mod records;
pub mod varint;

/// Bumped on every incompatible change to the types of this module.
///
/// 3: the filter configuration is the core's [`FilterConfig`] (every filter, its full
/// design); a track's `innovation_cov_m2` is named for what it holds.
///
/// 4: lengths and speeds in fixed point ([`fixed`]); plots go to the device as positions
/// in the local frame (the host converts them, as it must for its own refined gate, so the
/// device needs neither own ship nor trigonometry); track states no longer repeat the
/// innovation covariance their gate carried; fewer, fuller parts.
///
/// 5: messages are read where they lie in the frame (byte strings borrowed, lists packed
/// into byte strings of [`records`]); gates only for tracks with plots in them, and gates
/// and states coded against the scan's plots and the host's last report (the base); a
/// report in parts says which part is the last; track states from a track's second hit.
///
/// 6: a gate's Cholesky factor in whole centimetres (was tenths of a metre), so that the
/// link's rounding no longer decides a plot on the refined gate's edge ([`fixed`]).
///
/// 7: an update may name [`HIDDEN_PLOT`]: the track coasts, its target hidden in a plot
/// another track took, and the miss does not count towards its loss.
pub const PROTOCOL_VERSION: u16 = 7;

/// The plot index an update names for a firm track whose target is *hidden*: no plot of
/// its own, but a plot inside its refined gate went to another firm track (two targets in
/// one resolution cell give one plot). The track coasts; the miss counts towards its loss
/// only after [`crate::track::HIDDEN_LOST_AFTER_COASTS`] scans in a row without a plot
/// ([`crate::track`]'s life cycle). No scan has this many plots.
pub const HIDDEN_PLOT: u16 = u16::MAX;

/// Largest decoded frame: header + body + CRC, before COBS.
pub const MAX_FRAME_BYTES: usize = 1024;

/// Largest frame on the wire: COBS adds one byte per 254 and the 0x00 delimiter.
pub const MAX_ENCODED_FRAME_BYTES: usize = cobs::max_encoding_length(MAX_FRAME_BYTES) + 1;

/// Payload capacity of [`HostToDevice::Echo`]; sized so the largest echo fills a frame.
pub const MAX_ECHO_BYTES: usize = 1000;

/// Radar plots carried by one [`HostToDevice::Plots`] message (a scan may take several).
/// At most ten bytes each (two five-byte varints), so a full message fits a frame.
pub const MAX_PLOTS_PER_MESSAGE: usize = 96;

/// Plot indices one track's rough gate can return.
pub const MAX_PLOTS_PER_GATE: usize = 8;

/// Assignments (and plots to start tracks from) per [`HostToDevice::Assign`] message.
pub const MAX_ASSIGNMENTS_PER_MESSAGE: usize = 48;

/// Bytes of records one gate or track report part carries at most: the rest of a frame
/// after the CRC and the largest header and message head.
pub const MAX_RECORD_BYTES: usize = MAX_FRAME_BYTES - 64;

/// Request id the device uses when it cannot tell which request a reply belongs to
/// (the frame was too damaged to read its header). Hosts never send it.
pub const UNPAIRED_REQUEST_ID: u32 = 0;

/// A byte string: a varint length, then the bytes, read where it lies in the frame.
///
/// Postcard writes a byte string as it writes a sequence of `u8`, so an echo's wire is the
/// same as before protocol 5; here it is read and written as one slice instead of one
/// serde call a byte.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Bytes<'a>(pub &'a [u8]);

impl Serialize for Bytes<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(self.0)
    }
}

impl<'de: 'a, 'a> Deserialize<'de> for Bytes<'a> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        <&'a [u8]>::deserialize(d).map(Bytes)
    }
}

/// Opens every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// The sender's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Chosen by the host, echoed by the device; never [`UNPAIRED_REQUEST_ID`] from a host.
    pub request_id: u32,
}

/// Messages from the host to the device, read where they lie in the frame.
///
/// Variant order is part of the wire format: append only.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum HostToDevice<'a> {
    /// Handshake: the device answers [`DeviceToHost::HelloAck`] when the versions agree.
    Hello,
    /// Link test: the device returns the bytes unchanged in [`DeviceToHost::Echo`] (at most
    /// [`MAX_ECHO_BYTES`]).
    #[serde(borrow)]
    Echo(Bytes<'a>),
    /// Read the link and dispatch counters ([`DeviceToHost::Stats`]).
    GetStats,
    /// Choose the filter and its parameters for every track from now on.
    Configure(TrackerConfig),
    /// Radar plots of one scan (possibly one part of several).
    #[serde(borrow)]
    Plots(PlotBatch<'a>),
    /// The host's choice of plot for each gated track, closing a scan.
    #[serde(borrow)]
    Assign(AssignmentBatch<'a>),
    /// Operator commands: acquire or cancel targets.
    Command(TrackCommand),
    /// Ask for every live track ([`DeviceToHost::Tracks`], whole records, possibly in
    /// several parts).
    GetTracks,
}

impl HostToDevice<'_> {
    /// True for requests that change the device's state (the ones a retry must not carry
    /// out twice).
    pub fn changes_state(&self) -> bool {
        matches!(
            self,
            HostToDevice::Configure(_)
                | HostToDevice::Plots(_)
                | HostToDevice::Assign(_)
                | HostToDevice::Command(_)
        )
    }
}

/// Number of [`HostToDevice`] variants this version knows. A frame naming a higher
/// variant index is an unknown message (a newer host), not a damaged one.
pub const HOST_TO_DEVICE_VARIANTS: u32 = 8;

/// Messages from the device to the host, read where they lie in the frame.
///
/// Variant order is part of the wire format: append only.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum DeviceToHost<'a> {
    /// Handshake reply.
    #[serde(borrow)]
    HelloAck(DeviceInfo<'a>),
    /// The bytes of a [`HostToDevice::Echo`], unchanged.
    #[serde(borrow)]
    Echo(Bytes<'a>),
    /// Link and dispatch counters.
    Stats(LinkStats),
    /// A request was understood and carried out; nothing else to report.
    Ack,
    /// Rough gates (answers [`HostToDevice::Plots`]).
    #[serde(borrow)]
    Gated(GatedBatch<'a>),
    /// Track states (answers [`HostToDevice::Assign`] and [`HostToDevice::GetTracks`]).
    #[serde(borrow)]
    Tracks(TrackBatch<'a>),
    /// The request failed; the device state is unchanged by it.
    Error(ErrorCode),
}

/// What a device reports in its handshake.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeviceInfo<'a> {
    /// The device's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Firmware name and version, e.g. `tracker-firmware 0.1.0 (mps2-an386)`.
    pub firmware: &'a str,
    /// Frames are at most this long (decoded bytes).
    pub max_frame_bytes: u16,
    /// Size of the track table.
    pub max_tracks: u16,
    /// Plots the device accepts per scan.
    pub max_plots_per_scan: u16,
    /// Changes on every boot, so a host can tell a reset device from the one it knew.
    pub boot_id: u32,
}

/// Why a request failed, or why a frame was rejected.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorCode {
    /// The COBS encoding was invalid (a damaged or truncated frame).
    BadCobs,
    /// The CRC did not match (a damaged frame).
    BadCrc,
    /// The frame exceeded [`MAX_ENCODED_FRAME_BYTES`] before its delimiter.
    Oversize,
    /// CRC correct but the content did not decode (a peer bug, not line noise).
    Malformed,
    /// A message this version does not know (the peer is newer).
    UnknownMessage,
    /// The peer speaks another protocol version; `device` is ours.
    VersionMismatch {
        /// The device's protocol version.
        device: u16,
    },
    /// Known message, but this firmware does not implement it (yet).
    Unsupported,
    /// A configured limit was exceeded (plots per scan, tracks per table).
    CapacityExceeded,
    /// A value was out of range or not finite.
    InvalidValue,
    /// The request does not fit the device's state (e.g. assignments for no open scan).
    OutOfSequence,
}

impl core::fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ErrorCode::BadCobs => f.write_str("a damaged frame (bad COBS)"),
            ErrorCode::BadCrc => f.write_str("a damaged frame (bad CRC)"),
            ErrorCode::Oversize => f.write_str("a frame over the largest size"),
            ErrorCode::Malformed => f.write_str("a frame whose content does not decode"),
            ErrorCode::UnknownMessage => f.write_str("a message it does not know"),
            ErrorCode::VersionMismatch { device } => {
                write!(f, "another protocol version (the device speaks {device})")
            }
            ErrorCode::Unsupported => f.write_str("a message this firmware does not implement"),
            ErrorCode::CapacityExceeded => {
                f.write_str("over its capacity (plots a scan or tracks in its table)")
            }
            ErrorCode::InvalidValue => f.write_str("a value out of range or not finite"),
            ErrorCode::OutOfSequence => f.write_str("a request out of sequence"),
        }
    }
}

/// Counters the device keeps about its link; all wrap at `u32::MAX`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkStats {
    /// Bytes received.
    pub bytes_in: u32,
    /// Frames that decoded and were dispatched.
    pub frames_ok: u32,
    /// Frames rejected for bad COBS.
    pub bad_cobs: u32,
    /// Frames rejected for a CRC mismatch (including frames too short to hold one).
    pub bad_crc: u32,
    /// Frames longer than the maximum.
    pub oversize: u32,
    /// Frames whose content did not decode.
    pub malformed: u32,
    /// Frames naming an unknown message.
    pub unknown_message: u32,
    /// Frames from another protocol version.
    pub version_mismatch: u32,
    /// Requests answered with an [`ErrorCode`] other than the framing ones above.
    pub request_errors: u32,
    /// Frames sent.
    pub frames_out: u32,
    /// Retries of a state-changing request answered again without carrying it out twice.
    pub duplicate_requests: u32,
}

impl LinkStats {
    /// Frames rejected for any reason.
    pub fn rejected(&self) -> u32 {
        self.bad_cobs
            .wrapping_add(self.bad_crc)
            .wrapping_add(self.oversize)
            .wrapping_add(self.malformed)
            .wrapping_add(self.unknown_message)
            .wrapping_add(self.version_mismatch)
    }
}

/// Tracker configuration sent with [`HostToDevice::Configure`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackerConfig {
    /// The filter every new track runs, with its parameters (designed once, on the device,
    /// when the configuration arrives).
    pub filter: FilterConfig,
    /// Rough gate half-width in standard deviations of the predicted position.
    pub gate_sigmas: f32,
    /// Smallest rough gate radius, metres.
    pub min_gate_m: f32,
    /// Largest rough gate radius, metres.
    pub max_gate_m: f32,
    /// Standard deviation of a plot's position, m: the g-h filters' gates are sized from
    /// it (the Kalman filters use their own covariance).
    pub plot_sigma_m: f32,
    /// Fastest target expected, m/s: sizes the gate of a track with one plot, whose
    /// velocity is still unknown.
    pub max_speed_mps: f32,
}

impl TrackerConfig {
    /// CV Kalman (CWNA, q = 0.05 m²/s³, r = (50 m)², initial velocity variance (20 m/s)²),
    /// 4σ gates of 100 m to 2 km, 50 m plots, targets up to 20 m/s (39 kn).
    pub const DEFAULT: TrackerConfig = TrackerConfig {
        filter: FilterConfig::KalmanCv(KalmanConfig {
            q: 0.05,
            q_model: QModel::Continuous,
            r: 2500.0,
            p0_derivative: 400.0,
        }),
        gate_sigmas: 4.0,
        min_gate_m: 100.0,
        max_gate_m: 2000.0,
        plot_sigma_m: 50.0,
        max_speed_mps: 20.0,
    };
}

/// One radar plot: a detection in polar coordinates relative to own ship, as a radar or
/// the simulator gives it. Not itself on the wire: the host sends plots as local
/// positions ([`PlotBatch`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Plot {
    /// Range, metres.
    pub range_m: f32,
    /// Bearing, radians clockwise from true north.
    pub bearing_rad: f32,
}

/// Plots of one scan, or one part of them, as positions in the local frame.
///
/// The host converts each plot from range and bearing (it needs the position for its own
/// refined gate), rounds it to [`fixed::LENGTH_RESOLUTION_M`] and uses the rounded
/// position itself ([`fixed::position_on_grid`]), so both sides hold the same plots.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlotBatch<'a> {
    /// Scan number, increasing by one per antenna revolution.
    pub scan: u32,
    /// Scan time, milliseconds since the tracker started.
    pub time_ms: u64,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts this scan is sent in.
    pub parts: u8,
    /// The scan of the last track report the host holds whole ([`TrackBatch::scan`]): the
    /// base this scan's gates and states may be coded against; `None` for none.
    pub base_scan: Option<u32>,
    /// The plots of this part: east, north, metres in the local frame, as
    /// [`records::write_plots`] packs them (at most [`MAX_PLOTS_PER_MESSAGE`]).
    #[serde(borrow)]
    pub plots: Bytes<'a>,
}

/// The plots inside one track's rough gate, as the host uses them (decoded from a gate
/// record, [`records::GateOnGrid::gated`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GatedPlots {
    /// Track number.
    pub track: u16,
    /// Predicted position east, north, metres in the local frame.
    pub predicted_m: [f32; 2],
    /// Innovation covariance [s_xx, s_xy, s_yy], m², for the host's refined gate.
    pub innovation_cov_m2: [f32; 3],
    /// Indices into the scan's plots, in the order they were sent.
    pub plots: Vec<u16, MAX_PLOTS_PER_GATE>,
}

/// Rough gates of one scan, or one part of them: one record a track with plots in its
/// gate, in table order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GatedBatch<'a> {
    /// The scan these gates belong to.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// This is the report's last part.
    pub last: bool,
    /// The base the records are coded against ([`PlotBatch::base_scan`] when the device
    /// could use it, else `None`).
    pub base_scan: Option<u32>,
    /// Tracks in the device's table (a gate is sent only for those with plots in it): a
    /// host that knew tracks and hears of none knows the device lost them.
    pub live_tracks: u16,
    /// Gate records ([`records::write_gate`]), at most [`MAX_RECORD_BYTES`].
    #[serde(borrow)]
    pub gates: Bytes<'a>,
}

/// The plot the host chose for one track; `plot: None` coasts the track.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Assignment {
    /// Track number.
    pub track: u16,
    /// Index of the plot in the scan, or `None` to coast ([`HIDDEN_PLOT`]: to coast, the
    /// target hidden in another track's plot).
    pub plot: Option<u16>,
}

/// Assignments for one scan, or one part of them. A track not named coasts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AssignmentBatch<'a> {
    /// The scan the assignments close.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
    /// (track, plot) updates in table order ([`records::write_updates`], at most
    /// [`MAX_ASSIGNMENTS_PER_MESSAGE`]).
    #[serde(borrow)]
    pub updates: Bytes<'a>,
    /// Indices of plots that should start tentative tracks, the host's choice
    /// ([`records::write_indices`], at most [`MAX_ASSIGNMENTS_PER_MESSAGE`]).
    #[serde(borrow)]
    pub initiate: Bytes<'a>,
}

/// Bytes a full [`PlotBatch`]'s plots take at most: two five-byte varints a plot.
pub const MAX_PLOT_BYTES: usize = MAX_PLOTS_PER_MESSAGE * 10;

impl<'a> PlotBatch<'a> {
    /// Part `part` of `parts` of a scan's plots, `plots` (at most [`MAX_PLOTS_PER_MESSAGE`];
    /// more are left out) packed into `buf`.
    pub fn pack(
        head: PlotBatch<'static>,
        plots: &[crate::geo::EastNorth],
        buf: &'a mut [u8; MAX_PLOT_BYTES],
    ) -> PlotBatch<'a> {
        let plots = plots.get(..MAX_PLOTS_PER_MESSAGE).unwrap_or(plots);
        let mut w = varint::Writer::new(buf);
        records::write_plots(&mut w, plots);
        let n = w.len();
        PlotBatch {
            plots: Bytes(buf.get(..n).unwrap_or(&[])),
            ..head
        }
    }
}

/// Bytes one [`AssignmentBatch`]'s two lists take at most.
pub const MAX_ASSIGNMENT_BYTES: usize = MAX_ASSIGNMENTS_PER_MESSAGE * (5 + 3 + 3);

impl<'a> AssignmentBatch<'a> {
    /// The number of parts one scan's `updates` (track, plot) and `initiate` lists take at
    /// [`MAX_ASSIGNMENTS_PER_MESSAGE`] each a part, at least one (an empty part still closes
    /// the scan). More than 255 parts cannot be numbered: the count saturates and the
    /// device refuses the scan as out of sequence.
    pub fn parts(updates: usize, initiate: usize) -> u8 {
        let per = MAX_ASSIGNMENTS_PER_MESSAGE;
        let parts = updates.div_ceil(per).max(initiate.div_ceil(per)).max(1);
        u8::try_from(parts).unwrap_or(u8::MAX)
    }

    /// Part `part` of `parts` of a scan's `updates` and `initiate` lists, packed into `buf`.
    pub fn pack(
        scan: u32,
        (part, parts): (u8, u8),
        updates: &[(u16, u16)],
        initiate: &[u16],
        buf: &'a mut [u8; MAX_ASSIGNMENT_BYTES],
    ) -> AssignmentBatch<'a> {
        let per = MAX_ASSIGNMENTS_PER_MESSAGE;
        let from = usize::from(part) * per;
        let window = |n: usize| from.min(n)..(from + per).min(n);
        let updates = updates.get(window(updates.len())).unwrap_or(&[]);
        let initiate = initiate.get(window(initiate.len())).unwrap_or(&[]);
        let mut w = varint::Writer::new(buf);
        records::write_updates(&mut w, updates);
        let split = w.len();
        records::write_indices(&mut w, initiate);
        let end = w.len();
        let (first, second) = buf.split_at(split);
        AssignmentBatch {
            scan,
            part,
            parts,
            updates: Bytes(first),
            initiate: Bytes(second.get(..end - split).unwrap_or(&[])),
        }
    }
}

/// Operator commands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrackCommand {
    /// Start a track on a plot of the last scan.
    Acquire {
        /// Index of the plot in the last scan.
        plot: u16,
    },
    /// Drop one track.
    Cancel {
        /// Track number.
        track: u16,
    },
    /// Drop every track.
    CancelAll,
}

/// Life-cycle state of a track.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrackStatus {
    /// Started, not yet confirmed (M of N).
    Tentative,
    /// Confirmed and updated this scan.
    Confirmed,
    /// Confirmed but not seen this scan; running on prediction.
    Coasting,
    /// Dropped after too many misses; reported once.
    Lost,
}

impl TrackStatus {
    /// Confirmed or coasting: a track the operator is shown, scored against the truth, and
    /// given its plots before tentative ones.
    pub const fn is_firm(self) -> bool {
        matches!(self, TrackStatus::Confirmed | TrackStatus::Coasting)
    }
}

/// A track's filtered state in the local frame (east/north metres from the origin the
/// own-ship positions are given in), as the host uses it (decoded from a state record,
/// [`records::StateOnGrid::state`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackState {
    /// Track number.
    pub track: u16,
    /// Life-cycle state.
    pub status: TrackStatus,
    /// Position east, north, metres.
    pub position_m: [f32; 2],
    /// Velocity east, north, m/s.
    pub velocity_mps: [f32; 2],
    /// Scans since the track started.
    pub age_scans: u16,
    /// Hits in the last 10 scans, one bit a scan, newest lowest.
    pub hit_history: u16,
}

/// Track states, or one part of them: one record a reported track
/// ([`records::reported`]), in table order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackBatch<'a> {
    /// The scan the states belong to (the last the device closed).
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// This is the report's last part.
    pub last: bool,
    /// The base the records are coded against, or `None` (whole records).
    pub base_scan: Option<u32>,
    /// State records ([`records::write_state`]), at most [`MAX_RECORD_BYTES`].
    #[serde(borrow)]
    pub states: Bytes<'a>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<'a, T: Serialize + Deserialize<'a> + PartialEq + core::fmt::Debug>(
        v: &T,
        buf: &'a mut [u8; MAX_FRAME_BYTES],
    ) {
        let bytes: &'a [u8] = postcard::to_slice(v, buf).expect("fits in a frame");
        let back: T = postcard::from_bytes(bytes).expect("decodes");
        assert_eq!(&back, v);
    }

    fn largest_echo() -> std::vec::Vec<u8> {
        (0..MAX_ECHO_BYTES).map(|i| i as u8).collect()
    }

    #[test]
    fn echo_bytes_keep_the_wire_of_a_u8_sequence() {
        let (mut a, mut b) = ([0u8; MAX_FRAME_BYTES], [0u8; MAX_FRAME_BYTES]);
        let all = largest_echo();
        for n in [0, 1, 127, 128, MAX_ECHO_BYTES] {
            let v = &all[..n];
            // Variant 1 in both enums, then the bytes as a plain sequence of u8.
            let seq: Vec<u8, MAX_ECHO_BYTES> = Vec::from_slice(v).unwrap();
            let plain = postcard::to_slice(&(1u32, seq), &mut b).unwrap().to_vec();
            let h = postcard::to_slice(&HostToDevice::Echo(Bytes(v)), &mut a).unwrap();
            assert_eq!(h, plain.as_slice(), "{n}");
            let d = postcard::to_slice(&DeviceToHost::Echo(Bytes(v)), &mut a).unwrap();
            assert_eq!(d, plain.as_slice(), "{n}");
            let back: HostToDevice = postcard::from_bytes(&plain).unwrap();
            assert_eq!(back, HostToDevice::Echo(Bytes(v)));
        }
    }

    #[test]
    fn every_host_message_round_trips() {
        let mut plot_buf = [0u8; MAX_PLOT_BYTES];
        let plots = PlotBatch::pack(
            PlotBatch {
                scan: 7,
                time_ms: 21_000,
                part: 0,
                parts: 1,
                base_scan: Some(6),
                plots: Bytes(&[]),
            },
            &[[1852.0, -0.5], [-123_456.7, 9.9]],
            &mut plot_buf,
        );
        let mut assign_buf = [0u8; MAX_ASSIGNMENT_BYTES];
        let assign = AssignmentBatch::pack(7, (0, 1), &[(3, 0), (9, 1)], &[4], &mut assign_buf);
        let echo = largest_echo();
        let msgs = [
            HostToDevice::Hello,
            HostToDevice::Echo(Bytes(&echo)),
            HostToDevice::GetStats,
            HostToDevice::Configure(TrackerConfig::DEFAULT),
            HostToDevice::Plots(plots),
            HostToDevice::Assign(assign),
            HostToDevice::Command(TrackCommand::CancelAll),
            HostToDevice::GetTracks,
        ];
        for m in &msgs {
            round_trip(m, &mut [0u8; MAX_FRAME_BYTES]);
        }
        let mut back = std::vec::Vec::new();
        records::read_plots(plots.plots.0, |p| back.push(p)).unwrap();
        assert_eq!(back, [[1852.0, -0.5], [-123_456.7, 9.9]]);
        let mut back = std::vec::Vec::new();
        records::read_updates(assign.updates.0, |t, p| back.push((t, p))).unwrap();
        assert_eq!(back, [(3, 0), (9, 1)]);
    }

    #[test]
    fn every_device_message_round_trips() {
        let echo = largest_echo();
        let msgs = [
            DeviceToHost::HelloAck(DeviceInfo {
                protocol: PROTOCOL_VERSION,
                firmware: "tracker-firmware 0.1.0",
                max_frame_bytes: MAX_FRAME_BYTES as u16,
                max_tracks: 64,
                max_plots_per_scan: 256,
                boot_id: 0xdead_beef,
            }),
            DeviceToHost::Echo(Bytes(&echo)),
            DeviceToHost::Stats(LinkStats {
                frames_ok: 3,
                ..LinkStats::default()
            }),
            DeviceToHost::Ack,
            DeviceToHost::Gated(GatedBatch {
                scan: 9,
                part: 0,
                last: true,
                base_scan: Some(8),
                live_tracks: 12,
                gates: Bytes(&[1, 2, 3]),
            }),
            DeviceToHost::Tracks(TrackBatch {
                scan: 9,
                part: 1,
                last: false,
                base_scan: None,
                states: Bytes(&[4, 5]),
            }),
            DeviceToHost::Error(ErrorCode::VersionMismatch { device: 1 }),
        ];
        for m in &msgs {
            round_trip(m, &mut [0u8; MAX_FRAME_BYTES]);
        }
    }

    #[test]
    fn assignments_split_into_parts_in_order() {
        let updates: std::vec::Vec<(u16, u16)> = (0..50).map(|i| (i, i)).collect();
        let initiate: std::vec::Vec<u16> = (0..100).collect();
        let parts = AssignmentBatch::parts(updates.len(), initiate.len());
        assert_eq!(parts, 3);
        let (mut all_updates, mut all_initiate) = (std::vec::Vec::new(), std::vec::Vec::new());
        for part in 0..parts {
            let mut buf = [0u8; MAX_ASSIGNMENT_BYTES];
            let b = AssignmentBatch::pack(4, (part, parts), &updates, &initiate, &mut buf);
            assert_eq!((b.scan, b.part, b.parts), (4, part, 3));
            records::read_updates(b.updates.0, |t, p| all_updates.push((t, p))).unwrap();
            records::read_indices(b.initiate.0, |i| all_initiate.push(i)).unwrap();
        }
        assert_eq!((all_updates, all_initiate), (updates, initiate));
        // Nothing to say still closes the scan.
        assert_eq!(AssignmentBatch::parts(0, 0), 1);
    }

    #[test]
    fn variant_count_matches_the_enum() {
        // The last variant's index is the count minus one: keeps HOST_TO_DEVICE_VARIANTS
        // honest when a variant is appended.
        let mut buf = [0u8; 8];
        let bytes = postcard::to_slice(&HostToDevice::GetTracks, &mut buf).unwrap();
        assert_eq!(u32::from(bytes[0]) + 1, HOST_TO_DEVICE_VARIANTS);
    }

    #[test]
    fn largest_messages_fit_a_frame() {
        let mut buf = [0u8; MAX_FRAME_BYTES];
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: u32::MAX,
        };
        let crc = 4;
        let echo = largest_echo();
        let records = [0xFFu8; MAX_RECORD_BYTES];
        let worst_plots = [0xFFu8; MAX_PLOT_BYTES];
        let worst_lists = [0xFFu8; MAX_ASSIGNMENT_BYTES];
        let (updates, initiate) = worst_lists.split_at(MAX_ASSIGNMENTS_PER_MESSAGE * 8);
        for body in [
            DeviceToHost::Echo(Bytes(&echo)),
            DeviceToHost::Tracks(TrackBatch {
                scan: u32::MAX,
                part: u8::MAX,
                last: false,
                base_scan: Some(u32::MAX),
                states: Bytes(&records),
            }),
            DeviceToHost::Gated(GatedBatch {
                scan: u32::MAX,
                part: u8::MAX,
                last: false,
                base_scan: Some(u32::MAX),
                live_tracks: u16::MAX,
                gates: Bytes(&records),
            }),
        ] {
            let n = postcard::to_slice(&(header, body), &mut buf).unwrap().len();
            assert!(n + crc <= MAX_FRAME_BYTES, "{n}");
        }
        for body in [
            HostToDevice::Plots(PlotBatch {
                scan: u32::MAX,
                time_ms: u64::MAX,
                part: u8::MAX,
                parts: u8::MAX,
                base_scan: Some(u32::MAX),
                plots: Bytes(&worst_plots),
            }),
            HostToDevice::Assign(AssignmentBatch {
                scan: u32::MAX,
                part: u8::MAX,
                parts: u8::MAX,
                updates: Bytes(updates),
                initiate: Bytes(initiate),
            }),
            HostToDevice::Configure(TrackerConfig::DEFAULT),
        ] {
            let n = postcard::to_slice(&(header, body), &mut buf).unwrap().len();
            assert!(n + crc <= MAX_FRAME_BYTES, "{n}");
        }
    }
}
