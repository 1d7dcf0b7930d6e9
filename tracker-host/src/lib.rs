//! # tracker-host
//!
//! The PC side of the tracker. The product, by concern:
//!
//! | module | what |
//! |---|---|
//! | [`link`] | the link to the device: transports (in-process, TCP, serial, QEMU), the request client, `link-check` |
//! | [`source`] | where plots come from: the simulator, a recorded plots file (and its truth file) |
//! | [`own_ship`] | where own ship comes from: the plot source, NMEA through the dead-reckoning filter |
//! | [`radar`] | radar spokes from a network capture or live multicast (Navico, Garmin), for plot extraction |
//! | [`session`] | the host half of a scan: the device over the link, refined gate, association, target data, alarms |
//! | [`sink`], [`record`], [`score`] | where scan reports go: recordings, the scorer |
//! | [`nmea`], [`origin`] | NMEA 0183 in and out, the local frame on the globe |
//! | [`udp`] | UDP datagrams with the kernel's count of those it dropped |
//! | [`display`] | the radar display (terminal) and the plain table |
//! | [`app`] | the commands `demo` and `track` as wirings of the above |
//! | [`cli`] | the command line, a thin dispatcher |
//!
//! and apart from it, [`lab`]: the research tools (`replay`, `compare`, `precision`,
//! `arpa`, `reproduce`, `bench-mcu`). The binary is a thin shell over [`cli::run`], so
//! tests drive exactly what users run.
#![warn(missing_docs)]
#![warn(clippy::missing_errors_doc)]

pub mod ais;
pub mod app;
pub mod cli;
pub mod csv_input;
pub mod display;
pub mod event_log;
pub mod font;
pub mod lab;
pub mod link;
pub mod nmea;
pub mod origin;
pub mod own_ship;
pub mod radar;
pub mod record;
pub mod score;
pub mod session;
pub mod sink;
pub mod source;
pub mod udp;
pub mod utc;
