//! # tracker-core
//!
//! The `no_std` heart of an ARPA-style marine radar tracker (automatic radar plotting aid).
//! It runs unchanged on a Cortex-M4F (the firmware, in `f32`) and on the host (in `f64`,
//! or in `f32` to reproduce the MCU bit for bit through the `inproc` link).
//!
//! ## Design
//!
//! The split follows the source thesis, which ran its tracker on a TMS320C6711 DSP board
//! beside a PC: the device predicts every track and does the cheap *rough* validation
//! gating; the host does the *refined* gating, data association and display. What crosses
//! between them is defined once, here:
//!
//! - [`icd`]: the wire types (the interface control document), versioned;
//! - [`frame`]: COBS + CRC-32 framing around postcard, with a resynchronising decoder;
//! - [`device`]: the device's request dispatcher, shared by the firmware and the host's
//!   in-process link, so both run the same code.
//!
//! Everything is fixed-capacity (`heapless`), allocation-free and `#![forbid(unsafe_code)]`.
//! Nothing reachable from link input panics: malformed bytes become counted errors.
//!
//! ## Features
//!
//! All opt-in. `std` adds `std::error::Error` impls for the host; `defmt` derives
//! `defmt::Format` for the firmware's logs. Code the MCU never runs is gated: `sim` (the
//! scenario simulator and its random numbers), `metrics` (the papers' accuracy measures),
//! `reference` (the dense EKF algebra and the coupled filter, kept to check and measure the
//! product's).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
#![warn(clippy::missing_errors_doc)]

mod bounded;
pub mod device;
pub mod filter;
mod float;
pub mod frame;
pub mod geo;
pub mod icd;
#[cfg(feature = "metrics")]
pub mod metrics;
pub mod nav;
pub mod radar;
pub mod scalar;
#[cfg(feature = "sim")]
pub mod sim;
pub mod spatial;
pub mod track;
pub mod tracker;
