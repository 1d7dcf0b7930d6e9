//! NMEA 0183 with the bridge: what the tracker tells a chart plotter about its targets
//! ([`targets`]: `TTM` tracked target, `TLL` target latitude/longitude), the sentences a
//! simulated bridge sends ([`bridge`]), and the sockets, ports and files they travel through
//! ([`io`]). What own ship makes of incoming sentences is in [`crate::own_ship`].
//!
//! Units on the wire are NMEA's: nautical miles, knots, degrees true, minutes, latitude and
//! longitude in degrees and minutes, UTC.

pub mod bridge;
pub mod io;
pub mod targets;

pub use io::{InSpec, NmeaIn, NmeaOut, OutSpec};
pub use targets::{targets_sentences, tll, ttm};

/// XOR of the bytes between `$` and `*`.
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |acc, b| acc ^ b)
}

/// `$body*HH` with its checksum and CR LF.
pub fn sentence(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body))
}

/// UTC `hhmmss.ss` of the scenario's time (which starts at midnight).
pub(crate) fn utc(time_s: f64) -> String {
    let t = time_s.rem_euclid(86_400.0);
    let centis = (t * 100.0).round() as u64 % 8_640_000;
    let (h, m) = (centis / 360_000, centis / 6_000 % 60);
    format!("{h:02}{m:02}{:02}.{:02}", centis / 100 % 60, centis % 100)
}

/// `ddmm.mmmmm,N` (or `dddmm.mmmmm,E` with `degree_digits` 3).
pub(crate) fn angle_field(v: f64, degree_digits: usize, pos: char, neg: char) -> String {
    let a = v.abs();
    let mut deg = a.trunc();
    let mut min = ((a - deg) * 60.0 * 100_000.0).round() / 100_000.0;
    if min >= 60.0 {
        deg += 1.0;
        min -= 60.0;
    }
    let hemisphere = if v < 0.0 { neg } else { pos };
    format!(
        "{:0w$}{:08.5},{hemisphere}",
        deg as u32,
        min,
        w = degree_digits
    )
}

pub(crate) fn degrees(rad: f32) -> f64 {
    f64::from(rad).to_degrees().rem_euclid(360.0)
}
