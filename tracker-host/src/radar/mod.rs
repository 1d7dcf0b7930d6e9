//! Radar input: spokes from a network capture or from the radar itself, for plot extraction.
//!
//! | module | what |
//! |---|---|
//! | [`source`] | [`SpokeSource`]: spokes with their time from a capture or live, counted |
//! | [`spec`] | [`RadarSpec`]: `pcap:PATH`, `navico[@IFACE_IP]`, `garmin[@IFACE_IP]` |
//! | [`capture`] | pcap/pcapng (plain or gzip) → UDP datagrams, IPv4 fragments reassembled |
//! | [`nmea_text`] | the NMEA 0183 lines inside a capture (UDP 10110, TCP 2000 and 2599) |
//! | [`live`] | the spoke multicast groups joined on an interface |
//! | [`decoder`] | [`SpokeDecoder`]: what the decoders below share |
//! | [`navico`] | Navico BR24/3G/4G/HALO frames of 32 spokes, 2,048 a rotation, 4-bit samples |
//! | [`garmin`] | Garmin xHD, one spoke a datagram, 1,440 a rotation, 8-bit samples |
//! | [`stats`] | a spoke stream followed: rotations, range changes, order |
//! | [`picture`] | a rotation's echoes on a coarse north-up grid, for the display and snapshots |
//! | [`fault`] | what a decoder refused, counted by kind |
//!
//! Every spoke is a [`tracker_core::radar::Spoke`] borrowing its decoder's sample buffer:
//! angle index from the bow, clockwise; range spanned by the samples in metres; heading
//! when the radar sends a true one. Decoders never panic on what they are given: every
//! unknown, truncated or inconsistent packet is counted by kind and skipped.
//!
//! Formats as measured on five real captures (`../shared/realdata/radar/`, tests in
//! `tests/radar_captures.rs`): Navico HALO (two), 4G and 3G, Garmin xHD.

pub mod capture;
pub mod decoder;
pub mod fault;
pub mod garmin;
pub mod live;
pub mod navico;
pub mod nmea_text;
pub mod picture;
pub mod source;
pub mod spec;
pub mod stats;

pub use capture::{CaptureOptions, CaptureReader, CaptureStats, Datagram};
pub use decoder::SpokeDecoder;
pub use fault::{Fault, FaultCounts};
pub use picture::EchoImage;
pub use source::{RadarStats, SpokeSource};
pub use spec::{RadarKind, RadarSpec};
pub use stats::{SpokeMeta, SpokeStats};
