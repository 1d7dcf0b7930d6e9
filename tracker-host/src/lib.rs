//! # tracker-host
//!
//! The PC side of the tracker: the link to the firmware (on QEMU, a board, or in-process),
//! and the commands a navigator, an integrator and a firmware engineer use. The binary is a
//! thin shell over [`cli::run`], so tests drive exactly what users run.
#![warn(missing_docs)]

pub mod arpa;
pub mod associate;
pub mod bench_mcu;
pub mod cli;
pub mod compare;
pub mod demo;
pub mod display;
pub mod evaluate;
pub mod faults;
pub mod link;
pub mod link_check;
pub mod nmea;
pub mod precision;
pub mod qemu;
pub mod replay;
pub mod replay_nav;
pub mod reproduce;
pub mod target;
