//! UTC as the operator reads it, for the display, the plain table and the event log.

/// `hh:mm:ssZ` of a time in s since 1970-01-01 00:00 UTC.
pub fn utc_label(time_s: f64) -> String {
    let t = time_s.rem_euclid(86_400.0) as u64;
    format!("{:02}:{:02}:{:02}Z", t / 3600, t / 60 % 60, t % 60)
}
