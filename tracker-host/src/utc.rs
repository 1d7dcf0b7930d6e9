//! UTC as the operator reads it, and time differences, for the display, the plain table and the
//! event log.

/// Now by this host's clock, s since 1970-01-01 00:00 UTC (0 for a clock set before 1970).
pub fn now_s() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// UTC as this host's clock read it when the clock was started, running on from there on
/// the monotonic clock: times for live data that a step of the host's clock (NTP, or a
/// time source arriving on a PC that had none) neither jumps nor reverses. A step forward
/// read as time passing would look like a radar silent for that long, and lose every
/// target ([`crate::session::Session::scan`]).
#[derive(Clone, Copy, Debug)]
pub struct SteadyUtc {
    utc0_s: f64,
    t0: std::time::Instant,
}

impl SteadyUtc {
    /// Starts at this host's clock's now.
    pub fn start() -> Self {
        SteadyUtc {
            utc0_s: now_s(),
            t0: std::time::Instant::now(),
        }
    }

    /// Now, s since 1970-01-01 00:00 UTC: the start's time and the time since.
    pub fn now_s(&self) -> f64 {
        self.utc0_s + self.t0.elapsed().as_secs_f64()
    }
}

/// `hh:mm:ss` of a time in s, the time of day it falls on.
fn time_of_day(time_s: f64) -> String {
    let t = time_s.rem_euclid(86_400.0) as u64;
    format!("{:02}:{:02}:{:02}", t / 3600, t / 60 % 60, t % 60)
}

/// `hh:mm:ssZ` of a time in s since 1970-01-01 00:00 UTC.
pub fn utc_label(time_s: f64) -> String {
    format!("{}Z", time_of_day(time_s))
}

/// `yyyy-mm-dd hh:mm:ssZ` of a time in s since 1970-01-01 00:00 UTC (`?` beyond chrono's
/// years).
pub fn date_time_label(time_s: f64) -> String {
    chrono::DateTime::from_timestamp(time_s.floor() as i64, 0).map_or_else(
        || "?".to_string(),
        |d| d.format("%Y-%m-%d %H:%M:%SZ").to_string(),
    )
}

/// The scan time as the header shows it: [`utc_label`] when the clock is UTC, else the
/// source's own time of day without the `Z` (`t 00:01:05`).
pub fn scan_time_label(time_s: f64, is_utc: bool) -> String {
    if is_utc {
        utc_label(time_s)
    } else {
        format!("t {}", time_of_day(time_s))
    }
}

/// A time difference as a person reads it, before what it is measured from:
/// `4 h 38 min ahead of`, `12 s behind`.
pub fn offset_label(offset_s: f64) -> String {
    let way = if offset_s >= 0.0 {
        "ahead of"
    } else {
        "behind"
    };
    let a = offset_s.abs();
    let size = if a < 120.0 {
        format!("{a:.0} s")
    } else if a < 7200.0 {
        format!("{:.0} min", a / 60.0)
    } else if a < 3.0 * 86_400.0 {
        format!(
            "{} h {:.0} min",
            (a / 3600.0).floor(),
            (a % 3600.0 / 60.0).floor()
        )
    } else {
        format!("{:.0} days", a / 86_400.0)
    };
    format!("{size} {way}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_clock_starts_at_the_hosts_and_never_goes_back() {
        let clock = SteadyUtc::start();
        let first = clock.now_s();
        assert!((first - now_s()).abs() < 1.0, "{first}");
        let mut last = first;
        for _ in 0..1000 {
            let t = clock.now_s();
            assert!(t >= last, "{t} after {last}");
            last = t;
        }
    }

    #[test]
    fn a_clock_that_is_not_utc_is_not_labelled_utc() {
        assert_eq!(scan_time_label(3_661.0, true), "01:01:01Z");
        assert_eq!(scan_time_label(3_661.0, false), "t 01:01:01");
    }

    #[test]
    fn offsets_read_as_a_person_says_them() {
        assert_eq!(offset_label(12.4), "12 s ahead of");
        assert_eq!(offset_label(-600.0), "10 min behind");
        assert_eq!(
            offset_label(-(4.0 * 3600.0 + 38.0 * 60.0 + 5.0)),
            "4 h 38 min behind"
        );
        assert_eq!(offset_label(400.0 * 86_400.0), "400 days ahead of");
    }
}
