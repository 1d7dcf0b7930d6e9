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

/// Hundredths of a second in a day.
const CENTIS_A_DAY: i64 = 8_640_000;

/// A time in s since 1970 in whole hundredths, rounded once, so that [`utc`] and [`date`]
/// agree: 23:59:59.996 is 00:00:00.00 of the next day, not of the day ending.
fn centis(time_s: f64) -> i64 {
    (time_s * 100.0).round() as i64
}

/// UTC `hhmmss.ss` of a time in s since 1970-01-01 00:00 UTC.
pub(crate) fn utc(time_s: f64) -> String {
    let c = centis(time_s).rem_euclid(CENTIS_A_DAY);
    let (h, m) = (c / 360_000, c / 6_000 % 60);
    format!("{h:02}{m:02}{:02}.{:02}", c / 100 % 60, c % 100)
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
    let day = centis(time_s).div_euclid(CENTIS_A_DAY);
    chrono::DateTime::from_timestamp(day * 86_400, 0)
        .map_or_else(|| "010170".to_string(), |d| d.format("%d%m%y").to_string())
}

/// An angle in degrees as `decimals` decimals in 0 ≤ a < 360: rounded first, then wrapped,
/// so 359.96 is `0.0`, never `360.0`.
pub(crate) fn angle_360(deg: f64, decimals: usize) -> String {
    format!("{:.decimals$}", shown_angle_deg(deg, decimals))
}

/// An angle as it is shown with `decimals` places, degrees: rounded first, then wrapped
/// into 0–360 (359.96° shows as 0.0, never as 360.0).
pub(crate) fn shown_angle_deg(deg: f64, decimals: usize) -> f64 {
    let scale = 10f64.powi(decimals as i32);
    let a = (deg.rem_euclid(360.0) * scale).round() / scale;
    if a >= 360.0 {
        a - 360.0
    } else {
        a
    }
}

/// A signed value as it is shown with `decimals` places: rounded first, and one that rounds
/// to zero is 0, never −0 (a TCPA just past its CPA).
pub(crate) fn shown_signed(v: f64, decimals: usize) -> f64 {
    let scale = 10f64.powi(decimals as i32);
    (v * scale).round() / scale + 0.0
}

/// Degrees of an angle in radians.
pub(crate) fn degrees(rad: f32) -> f64 {
    f64::from(rad).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_and_date_are_rounded_together() {
        // 2026-12-03 00:00 UTC.
        let day = 1_796_256_000.0;
        assert_eq!(
            (utc(day + 45_296.5), date(day + 45_296.5)),
            ("123456.50".into(), "031226".into())
        );
        // The last few milliseconds of a day are the next one's first hundredth, date too.
        let late = day - 0.004;
        assert_eq!(
            (utc(late), date(late)),
            ("000000.00".into(), "031226".into())
        );
        assert_eq!(
            (utc(day - 0.006), date(day - 0.006)),
            ("235959.99".into(), "021226".into())
        );
    }
}
