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

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

use crate::bounded::take_up_to;

use crate::filter::kalman::{KalmanConfig, QModel};
use crate::filter::FilterConfig;

pub mod fixed;

/// Bumped on every incompatible change to the types of this module.
///
/// 3: the filter configuration is the core's [`FilterConfig`] (every filter, its full
/// design); a track's `innovation_cov_m2` is named for what it holds.
///
/// 4: lengths and speeds in fixed point ([`fixed`]); plots go to the device as positions
/// in the local frame (the host converts them, as it must for its own refined gate, so the
/// device needs neither own ship nor trigonometry); track states no longer repeat the
/// innovation covariance their gate carried; fewer, fuller parts.
pub const PROTOCOL_VERSION: u16 = 4;

/// Largest decoded frame: header + body + CRC, before COBS.
pub const MAX_FRAME_BYTES: usize = 1024;

/// Largest frame on the wire: COBS adds one byte per 254 and the 0x00 delimiter.
pub const MAX_ENCODED_FRAME_BYTES: usize = cobs::max_encoding_length(MAX_FRAME_BYTES) + 1;

/// Payload capacity of [`HostToDevice::Echo`]; sized so the largest echo fills a frame.
pub const MAX_ECHO_BYTES: usize = 1000;

/// Radar plots carried by one [`HostToDevice::Plots`] message (a scan may take several).
/// At most ten bytes each (two five-byte varints), so a full message fits a frame.
pub const MAX_PLOTS_PER_MESSAGE: usize = 96;

/// Track states carried by one [`DeviceToHost::Tracks`] message (at most 30 bytes each).
pub const MAX_TRACKS_PER_MESSAGE: usize = 32;

/// Plot indices one track's rough gate can return in a [`GatedPlots`] entry.
pub const MAX_PLOTS_PER_GATE: usize = 8;

/// Gate results per [`DeviceToHost::Gated`] message.
pub const MAX_GATES_PER_MESSAGE: usize = 16;

/// Assignments per [`HostToDevice::Assign`] message.
pub const MAX_ASSIGNMENTS_PER_MESSAGE: usize = 48;

/// Request id the device uses when it cannot tell which request a reply belongs to
/// (the frame was too damaged to read its header). Hosts never send it.
pub const UNPAIRED_REQUEST_ID: u32 = 0;

/// Opens every frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// The sender's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Chosen by the host, echoed by the device; never [`UNPAIRED_REQUEST_ID`] from a host.
    pub request_id: u32,
}

/// A byte vector as one byte string. In postcard that is the same bytes as a sequence of
/// `u8` (a varint length, then the bytes), so the wire is unchanged; but the bytes move as one
/// slice instead of one serde call each (a 1,000-byte echo cost about 40 instructions a byte
/// each way).
mod byte_string {
    use core::fmt;

    use heapless::Vec;
    use serde::de::{self, SeqAccess, Visitor};
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer, const N: usize>(
        bytes: &Vec<u8, N>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        serializer.serialize_bytes(bytes)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(
        deserializer: D,
    ) -> Result<Vec<u8, N>, D::Error> {
        deserializer.deserialize_bytes(Bytes::<N>)
    }

    struct Bytes<const N: usize>;

    impl<'de, const N: usize> Visitor<'de> for Bytes<N> {
        type Value = Vec<u8, N>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "at most {N} bytes")
        }

        fn visit_bytes<E: de::Error>(self, v: &[u8]) -> Result<Self::Value, E> {
            Vec::from_slice(v).map_err(|_| E::invalid_length(v.len(), &self))
        }

        // Self-describing formats (JSON) may hand the bytes over as a sequence.
        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut out = Vec::new();
            while let Some(b) = seq.next_element()? {
                out.push(b)
                    .map_err(|_| de::Error::invalid_length(N + 1, &self))?;
            }
            Ok(out)
        }
    }
}

/// Messages from the host to the device.
///
/// Variant order is part of the wire format: append only.
// No heap to box into: one message is decoded at a time, so its size is what it is.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum HostToDevice {
    /// Handshake: the device answers [`DeviceToHost::HelloAck`] when the versions agree.
    Hello,
    /// Link test: the device returns the bytes unchanged in [`DeviceToHost::Echo`].
    Echo(#[serde(with = "byte_string")] Vec<u8, MAX_ECHO_BYTES>),
    /// Read the link and dispatch counters ([`DeviceToHost::Stats`]).
    GetStats,
    /// Choose the filter and its parameters for every track from now on.
    Configure(TrackerConfig),
    /// Radar plots of one scan (possibly one part of several).
    Plots(PlotBatch),
    /// The host's choice of plot for each gated track, closing a scan.
    Assign(AssignmentBatch),
    /// Operator commands: acquire or cancel targets.
    Command(TrackCommand),
    /// Ask for every live track ([`DeviceToHost::Tracks`], possibly in several parts).
    GetTracks,
}

impl HostToDevice {
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

/// Messages from the device to the host.
///
/// Variant order is part of the wire format: append only.
// No heap to box into: one message is decoded at a time, so its size is what it is.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum DeviceToHost {
    /// Handshake reply.
    HelloAck(DeviceInfo),
    /// The bytes of a [`HostToDevice::Echo`], unchanged.
    Echo(#[serde(with = "byte_string")] Vec<u8, MAX_ECHO_BYTES>),
    /// Link and dispatch counters.
    Stats(LinkStats),
    /// A request was understood and carried out; nothing else to report.
    Ack,
    /// Per-track plots inside the rough gates (answers [`HostToDevice::Plots`]).
    Gated(GatedBatch),
    /// Track states (answers [`HostToDevice::Assign`] and [`HostToDevice::GetTracks`]).
    Tracks(TrackBatch),
    /// The request failed; the device state is unchanged by it.
    Error(ErrorCode),
}

/// What a device reports in its handshake.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct DeviceInfo {
    /// The device's [`PROTOCOL_VERSION`].
    pub protocol: u16,
    /// Firmware name and version, e.g. `tracker-firmware 0.1.0 (mps2-an386)`.
    pub firmware: String<48>,
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlotBatch {
    /// Scan number, increasing by one per antenna revolution.
    pub scan: u32,
    /// Scan time, milliseconds since the tracker started.
    pub time_ms: u64,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts this scan is sent in.
    pub parts: u8,
    /// The plots of this part: east, north, metres in the local frame (tenths of a metre
    /// on the wire).
    #[serde(with = "fixed::positions_m")]
    pub plots_m: Vec<[f32; 2], MAX_PLOTS_PER_MESSAGE>,
}

/// The plots inside one track's rough gate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GatedPlots {
    /// Track number.
    pub track: u16,
    /// Predicted position east, north, metres in the local frame (tenths on the wire).
    #[serde(with = "fixed::position_m")]
    pub predicted_m: [f32; 2],
    /// Innovation covariance [s_xx, s_xy, s_yy], m², for the host's refined gate (its
    /// Cholesky factor in tenths of a metre on the wire).
    #[serde(with = "fixed::covariance_m2")]
    pub innovation_cov_m2: [f32; 3],
    /// Indices into the scan's plots, in the order they were sent.
    pub plots: Vec<u16, MAX_PLOTS_PER_GATE>,
}

/// Rough-gate results of one scan, or one part of them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GatedBatch {
    /// The scan these gates belong to.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
    /// Per-track gates.
    pub gates: Vec<GatedPlots, MAX_GATES_PER_MESSAGE>,
}

/// The plot the host chose for one track; `plot: None` coasts the track.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Assignment {
    /// Track number.
    pub track: u16,
    /// Index of the plot in the scan, or `None` to coast.
    pub plot: Option<u16>,
}

/// Assignments for one scan, or one part of them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AssignmentBatch {
    /// The scan the assignments close.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
    /// The assignments of this part.
    pub assignments: Vec<Assignment, MAX_ASSIGNMENTS_PER_MESSAGE>,
    /// Indices of plots that should start tentative tracks (the host's choice).
    pub initiate: Vec<u16, MAX_ASSIGNMENTS_PER_MESSAGE>,
}

impl AssignmentBatch {
    /// The parts carrying one scan's `updates` and `initiate` list, in order: as many as
    /// the longer of the two needs at [`MAX_ASSIGNMENTS_PER_MESSAGE`] a part, and at least
    /// one (an empty part still closes the scan). More than 255 parts cannot be numbered;
    /// the count saturates and the device refuses the scan as out of sequence.
    pub fn parts<'a>(
        scan: u32,
        updates: &'a [Assignment],
        initiate: &'a [u16],
    ) -> impl Iterator<Item = AssignmentBatch> + 'a {
        let per = MAX_ASSIGNMENTS_PER_MESSAGE;
        let parts = updates
            .len()
            .div_ceil(per)
            .max(initiate.len().div_ceil(per))
            .max(1);
        let numbered = u8::try_from(parts).unwrap_or(u8::MAX);
        (0..numbered).map(move |part| {
            let from = usize::from(part) * per;
            AssignmentBatch {
                scan,
                part,
                parts: numbered,
                assignments: take_up_to(updates.iter().skip(from).copied()),
                initiate: take_up_to(initiate.iter().skip(from).copied()),
            }
        })
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
/// own-ship positions are given in).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackState {
    /// Track number.
    pub track: u16,
    /// Life-cycle state.
    pub status: TrackStatus,
    /// Position east, north, metres (tenths on the wire).
    #[serde(with = "fixed::position_m")]
    pub position_m: [f32; 2],
    /// Velocity east, north, m/s (hundredths on the wire).
    #[serde(with = "fixed::velocity_mps")]
    pub velocity_mps: [f32; 2],
    /// Scans since the track started.
    pub age_scans: u16,
    /// Hits in the last 10 scans, one bit a scan, newest lowest.
    pub hit_history: u16,
}

/// Track states, or one part of them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackBatch {
    /// The scan the states belong to.
    pub scan: u32,
    /// Index of this part, from 0.
    pub part: u8,
    /// Number of parts.
    pub parts: u8,
    /// The states of this part.
    pub tracks: Vec<TrackState, MAX_TRACKS_PER_MESSAGE>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<T: Serialize + serde::de::DeserializeOwned + PartialEq + core::fmt::Debug>(
        v: &T,
    ) {
        let mut buf = [0u8; MAX_FRAME_BYTES];
        let bytes = postcard::to_slice(v, &mut buf).expect("fits in a frame");
        let back: T = postcard::from_bytes(bytes).expect("decodes");
        assert_eq!(&back, v);
    }

    fn largest_echo() -> Vec<u8, MAX_ECHO_BYTES> {
        let mut v = Vec::new();
        for i in 0..MAX_ECHO_BYTES {
            v.push(i as u8).unwrap();
        }
        v
    }

    #[test]
    fn echo_bytes_keep_the_wire_of_a_u8_sequence() {
        let (mut a, mut b) = ([0u8; MAX_FRAME_BYTES], [0u8; MAX_FRAME_BYTES]);
        for n in [0, 1, 127, 128, MAX_ECHO_BYTES] {
            let v: Vec<u8, MAX_ECHO_BYTES> = largest_echo().iter().copied().take(n).collect();
            // Variant 1 in both enums, then the bytes as a plain sequence of u8.
            let plain = postcard::to_slice(&(1u32, &v), &mut b).unwrap().to_vec();
            let h = postcard::to_slice(&HostToDevice::Echo(v.clone()), &mut a).unwrap();
            assert_eq!(h, plain.as_slice(), "{n}");
            let d = postcard::to_slice(&DeviceToHost::Echo(v.clone()), &mut a).unwrap();
            assert_eq!(d, plain.as_slice(), "{n}");
            let back: HostToDevice = postcard::from_bytes(&plain).unwrap();
            assert_eq!(back, HostToDevice::Echo(v));
        }
        // One byte more than the capacity is refused, not truncated.
        let mut long = [0u8; MAX_ECHO_BYTES + 4];
        long[0] = 1;
        long[1..3].copy_from_slice(&[0xe9, 0x07]); // varint 1001
        assert!(postcard::from_bytes::<HostToDevice>(&long).is_err());
    }

    #[test]
    fn every_host_message_round_trips() {
        // Values on the wire's grid come back exactly.
        let plots_m = Vec::from_slice(&[[1852.0, -0.5], [-123_456.7, 9.9]]).unwrap();
        let msgs = [
            HostToDevice::Hello,
            HostToDevice::Echo(largest_echo()),
            HostToDevice::GetStats,
            HostToDevice::Configure(TrackerConfig::DEFAULT),
            HostToDevice::Plots(PlotBatch {
                scan: 7,
                time_ms: 21_000,
                part: 0,
                parts: 1,
                plots_m,
            }),
            HostToDevice::Assign(AssignmentBatch {
                scan: 7,
                part: 0,
                parts: 1,
                assignments: Vec::from_slice(&[Assignment {
                    track: 3,
                    plot: Some(0),
                }])
                .unwrap(),
                initiate: Vec::new(),
            }),
            HostToDevice::Command(TrackCommand::CancelAll),
            HostToDevice::GetTracks,
        ];
        for m in &msgs {
            round_trip(m);
        }
    }

    #[test]
    fn every_device_message_round_trips() {
        let msgs = [
            DeviceToHost::HelloAck(DeviceInfo {
                protocol: PROTOCOL_VERSION,
                firmware: String::try_from("tracker-firmware 0.1.0").unwrap(),
                max_frame_bytes: MAX_FRAME_BYTES as u16,
                max_tracks: 64,
                max_plots_per_scan: 256,
                boot_id: 0xdead_beef,
            }),
            DeviceToHost::Echo(largest_echo()),
            DeviceToHost::Stats(LinkStats {
                frames_ok: 3,
                ..LinkStats::default()
            }),
            DeviceToHost::Ack,
            DeviceToHost::Gated(GatedBatch {
                scan: 9,
                part: 0,
                parts: 1,
                gates: Vec::from_slice(&[GatedPlots {
                    track: 300,
                    predicted_m: [-2000.5, 15_000.0],
                    // Cholesky factor [50, 2, 40] m: exact on the grid.
                    innovation_cov_m2: [2500.0, 100.0, 1604.0],
                    plots: Vec::from_slice(&[0, 200]).unwrap(),
                }])
                .unwrap(),
            }),
            DeviceToHost::Tracks(TrackBatch {
                scan: 9,
                part: 0,
                parts: 1,
                tracks: Vec::from_slice(&[TrackState {
                    track: 300,
                    status: TrackStatus::Confirmed,
                    position_m: [-2000.5, 15_000.0],
                    velocity_mps: [5.25, -0.5],
                    age_scans: 40,
                    hit_history: 0x3ff,
                }])
                .unwrap(),
            }),
            DeviceToHost::Error(ErrorCode::VersionMismatch { device: 1 }),
        ];
        for m in &msgs {
            round_trip(m);
        }
    }

    #[test]
    fn assignments_split_into_parts_in_order() {
        let updates: std::vec::Vec<Assignment> = (0..50)
            .map(|i| Assignment {
                track: i,
                plot: Some(i),
            })
            .collect();
        let initiate: std::vec::Vec<u16> = (0..100).collect();
        let parts: std::vec::Vec<AssignmentBatch> =
            AssignmentBatch::parts(4, &updates, &initiate).collect();
        assert_eq!(parts.len(), 3);
        let all_updates: std::vec::Vec<Assignment> =
            parts.iter().flat_map(|p| p.assignments.clone()).collect();
        let all_initiate: std::vec::Vec<u16> =
            parts.iter().flat_map(|p| p.initiate.clone()).collect();
        assert_eq!((all_updates, all_initiate), (updates, initiate));
        for (i, p) in parts.iter().enumerate() {
            assert_eq!((p.scan, p.part, p.parts), (4, i as u8, 3));
        }
        // Nothing to say still closes the scan.
        let empty: std::vec::Vec<AssignmentBatch> = AssignmentBatch::parts(4, &[], &[]).collect();
        assert_eq!(empty.len(), 1);
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
        let full_tracks = TrackBatch {
            scan: u32::MAX,
            part: 0,
            parts: 1,
            tracks: core::iter::repeat_n(
                TrackState {
                    track: u16::MAX,
                    status: TrackStatus::Coasting,
                    position_m: [f32::MAX; 2],
                    velocity_mps: [f32::MIN; 2],
                    age_scans: u16::MAX,
                    hit_history: u16::MAX,
                },
                MAX_TRACKS_PER_MESSAGE,
            )
            .collect(),
        };
        let full_plots = PlotBatch {
            scan: u32::MAX,
            time_ms: u64::MAX,
            part: 0,
            parts: 1,
            plots_m: core::iter::repeat_n([f32::MIN, f32::MAX], MAX_PLOTS_PER_MESSAGE).collect(),
        };
        let full_gates = GatedBatch {
            scan: u32::MAX,
            part: 0,
            parts: 1,
            gates: core::iter::repeat_n(
                GatedPlots {
                    track: u16::MAX,
                    predicted_m: [f32::MIN; 2],
                    // Every Cholesky entry past i32's range: the longest encoding.
                    innovation_cov_m2: [1e20, 1e20, 2e20],
                    plots: core::iter::repeat_n(u16::MAX, MAX_PLOTS_PER_GATE).collect(),
                },
                MAX_GATES_PER_MESSAGE,
            )
            .collect(),
        };
        let crc = 4;
        for body in [
            DeviceToHost::Echo(largest_echo()),
            DeviceToHost::Tracks(full_tracks),
            DeviceToHost::Gated(full_gates),
        ] {
            let n = postcard::to_slice(&(header, body), &mut buf).unwrap().len();
            assert!(n + crc <= MAX_FRAME_BYTES, "{n}");
        }
        let n = postcard::to_slice(&(header, HostToDevice::Plots(full_plots)), &mut buf)
            .unwrap()
            .len();
        assert!(n + crc <= MAX_FRAME_BYTES, "{n}");
    }
}
