//! AIS in: `!AIVDM`/`!AIVDO` sentences from the same sources as own ship's NMEA (a
//! recording, UDP, TCP, serial, a radar capture), decoded into a table of AIS targets.
//!
//! | module | what |
//! |---|---|
//! | [`fragment`] | one sentence as a fragment: fields checked (GoFree's extra field accepted) |
//! | [`assemble`] | multi-fragment messages joined, bounded |
//! | [`report`] | a decoded message (by the `aivdm` crate) read into what the table keeps |
//! | [`decoder`] | [`AisDecoder`]: lines in, reports out, everything counted |
//! | [`duplicates`] | [`AisDuplicates`]: a message heard from two sources taken once |
//! | [`targets`] | [`AisTargets`]: the table, extrapolation, IEC 62388 lost times, CPA/TCPA |
//!
//! Message types used: 1–3 (class A position), 5 (class A static and voyage), 18 and 19
//! (class B position), 24 (class B static), 27 (long range); every other type decodes and
//! is counted as not used. Payload decoding is the `aivdm` crate's (no_std, ITU-R
//! M.1371-5, all 27 types): chosen over `nmea-parser`, which would also replace our GNSS
//! parsing but pulls in `alloc`-heavy dependencies and decodes fewer fields we need, and
//! over `ais`, which has no class B static data; fragment reassembly is ours because
//! `aivdm`'s refuses GoFree's extra field and keys fragments without the channel.

pub mod assemble;
pub mod decoder;
pub mod duplicates;
pub mod fragment;
pub mod report;
pub mod targets;

pub use decoder::{AisCounts, AisDecoder};
pub use duplicates::AisDuplicates;
pub use report::{AisReport, StationClass};
pub use targets::{AisTarget, AisTargetData, AisTargets};

/// An MMSI as it is written (ITU-R M.585): nine digits, its leading zeros kept, which say
/// what it is (`00…` a coast station, `0…` a group of ships); `2447004` would be read as
/// another number (a new user's trial).
pub fn mmsi_text(mmsi: u32) -> String {
    format!("{mmsi:09}")
}
