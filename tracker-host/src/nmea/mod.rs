//! NMEA 0183 with the bridge: what the tracker tells a chart plotter about its targets
//! ([`targets`]: `TTM` tracked target, `TLL` target latitude/longitude), the sentences a
//! simulated bridge sends ([`bridge`]), and the sockets, ports and files they travel through
//! ([`input`], [`out`]). What own ship makes of incoming sentences is in [`crate::own_ship`].
//!
//! Units on the wire are NMEA's: nautical miles, knots, degrees true, minutes, latitude and
//! longitude in degrees and minutes, UTC.

pub mod bridge;
pub mod input;
pub mod out;
pub mod sentence;
pub mod targets;

pub use input::{InSpec, NmeaIn};
pub use out::{NmeaOut, OutSpec};
pub use sentence::{checksum, sentence};
pub use targets::{targets_sentences, tll, ttm};

/// UTC `hhmmss.ss` of a time in s since 1970-01-01 00:00 UTC.
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

/// UTC date `ddmmyy` of a time in s since 1970-01-01 00:00 UTC.
pub(crate) fn date(time_s: f64) -> String {
    let day = (time_s / 86_400.0).floor() as i64;
    chrono::DateTime::from_timestamp(day * 86_400, 0)
        .map_or_else(|| "010170".to_string(), |d| d.format("%d%m%y").to_string())
}

/// An angle in degrees as `decimals` decimals in 0 ≤ a < 360: rounded first, then wrapped,
/// so 359.96 is `0.0`, never `360.0`.
pub(crate) fn angle_360(deg: f64, decimals: usize) -> String {
    let scale = 10f64.powi(decimals as i32);
    let mut a = (deg.rem_euclid(360.0) * scale).round() / scale;
    if a >= 360.0 {
        a -= 360.0;
    }
    format!("{a:.decimals$}")
}

/// Degrees of an angle in radians.
pub(crate) fn degrees(rad: f32) -> f64 {
    f64::from(rad).to_degrees()
}
