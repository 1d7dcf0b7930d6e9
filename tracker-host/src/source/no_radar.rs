//! No radar: scans without plots, for `track --nmea-in SOURCE` alone, an AIS target table
//! and its CPA/TCPA alarm with no radar to track (a yacht whose radar is off, or that has
//! none).
//!
//! The session still runs a scan every [`PERIOD_S`]: own ship and the AIS targets are
//! brought to the scan's time, their CPA and TCPA computed, and the picture drawn and sent,
//! as with a radar. Over a recording the scans follow its own time, from its first fix to
//! its last; over a live source, this computer's clock, until the run is stopped.

use std::time::{Duration, Instant};

use super::{PlotSource, RadarScan, SourceScan};

/// How often the picture is brought up to date without a radar, s: a radar's antenna
/// period (AIS class A reports come every 2–10 s under way, class B every 30 s).
pub const PERIOD_S: f64 = 2.5;

/// How often a wait for the next live scan looks for Ctrl-C.
const INTERRUPT_POLL: Duration = Duration::from_millis(250);

/// Where the scans' times come from.
#[derive(Clone, Copy, Debug)]
enum Clock {
    /// A recording's time, s since 1970: the next scan's and the last fix's.
    Recording { next_s: f64, end_s: f64 },
    /// This computer's clock, read once and run on the monotonic clock (a step of the
    /// host's clock, NTP setting a Raspberry Pi's, neither stalls nor reverses the scans):
    /// the next scan is due at this instant.
    Live {
        due: Instant,
        clock: crate::utc::SteadyUtc,
    },
}

/// Scans without plots, every [`PERIOD_S`]. See the module documentation.
#[derive(Debug)]
pub struct NoRadarSource {
    clock: Clock,
    scan: u32,
    live_deadline: Option<Instant>,
    utc: bool,
}

impl NoRadarSource {
    /// Over a recording whose fixes run from `start_s` to `end_s` (s since 1970): scans
    /// from `start_s`, the last at or past `end_s`.
    pub fn over_recording(start_s: f64, end_s: f64) -> Self {
        Self::on(Clock::Recording {
            next_s: start_s,
            end_s,
        })
    }

    /// With `utc` false, the recording's times are made up (it has no time of its own, so
    /// its fixes are put at the start of a day) and are not shown or sent as UTC.
    pub fn with_utc(mut self, utc: bool) -> Self {
        self.utc = utc;
        self
    }

    /// Live: the first scan now, then every [`PERIOD_S`] on this computer's clock.
    pub fn live() -> Self {
        Self::on(Clock::Live {
            due: Instant::now(),
            clock: crate::utc::SteadyUtc::start(),
        })
    }

    fn on(clock: Clock) -> Self {
        NoRadarSource {
            clock,
            scan: 0,
            live_deadline: None,
            utc: true,
        }
    }

    fn scan_at(&mut self, time_s: f64) -> SourceScan {
        self.scan += 1;
        SourceScan {
            radar: RadarScan {
                scan: self.scan,
                time_s,
                plots: Vec::new(),
            },
            ..SourceScan::default()
        }
    }
}

impl PlotSource for NoRadarSource {
    fn has_radar(&self) -> bool {
        false
    }

    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        match self.clock {
            Clock::Recording { next_s, end_s } => {
                // The last scan is the first at or past the last fix: what the recording
                // holds up to its last fix is read.
                if next_s - PERIOD_S >= end_s {
                    return Ok(None);
                }
                self.clock = Clock::Recording {
                    next_s: next_s + PERIOD_S,
                    end_s,
                };
                Ok(Some(self.scan_at(next_s)))
            }
            Clock::Live { due, clock } => {
                // Waits until the scan is due, but not past the caller's deadline (the
                // display answers keys meanwhile) nor past Ctrl-C.
                loop {
                    let now = Instant::now();
                    if now >= due {
                        break;
                    }
                    if crate::app::interrupt::interrupted()
                        || self.live_deadline.is_some_and(|d| now >= d)
                    {
                        return Ok(None);
                    }
                    let until = self.live_deadline.map_or(due, |d| d.min(due));
                    std::thread::sleep(until.saturating_duration_since(now).min(INTERRUPT_POLL));
                }
                // The next one a period on, or a period from now after a long pause (a
                // suspended laptop does not make up the scans it slept through).
                let period = Duration::from_secs_f64(PERIOD_S);
                let now = Instant::now();
                let next = if due + period < now {
                    now + period
                } else {
                    due + period
                };
                self.clock = Clock::Live { due: next, clock };
                Ok(Some(self.scan_at(clock.now_s())))
            }
        }
    }

    fn time_is_utc(&self) -> bool {
        self.utc
    }

    fn is_live(&self) -> bool {
        matches!(self.clock, Clock::Live { .. })
    }

    fn set_live_wait(&mut self, wait: Option<Duration>) {
        self.live_deadline = wait.map(|w| Instant::now() + w);
    }

    fn scan_period_s(&self) -> Option<f64> {
        Some(PERIOD_S)
    }

    fn scans_left(&self) -> Option<u64> {
        match self.clock {
            Clock::Recording { next_s, end_s } if next_s - PERIOD_S < end_s => {
                Some(((end_s - next_s) / PERIOD_S).ceil().max(0.0) as u64 + 1)
            }
            Clock::Recording { .. } => Some(0),
            Clock::Live { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_recording_is_scanned_from_its_first_fix_to_its_last() {
        let mut s = NoRadarSource::over_recording(1000.0, 1006.0);
        assert_eq!(s.scans_left(), Some(4));
        let mut times = Vec::new();
        while let Some(scan) = s.next_scan().unwrap() {
            assert!(scan.radar.plots.is_empty() && scan.own_ship.is_none());
            times.push((scan.radar.scan, scan.radar.time_s));
        }
        // The last at or past the last fix.
        assert_eq!(times, [(1, 1000.0), (2, 1002.5), (3, 1005.0), (4, 1007.5)]);
        assert_eq!(s.scans_left(), Some(0));
        assert!(!s.is_live());
    }

    #[test]
    fn live_scans_come_on_the_clock_and_a_wait_ends_without_one() {
        let mut s = NoRadarSource::live();
        assert!(s.is_live());
        let first = s.next_scan().unwrap().expect("the first scan at once");
        assert!((first.radar.time_s - crate::utc::now_s()).abs() < 1.0);
        // The next is 2.5 s away: a wait of 50 ms gives none, and the source goes on.
        s.set_live_wait(Some(Duration::from_millis(50)));
        assert!(s.next_scan().unwrap().is_none());
        s.set_live_wait(None);
        let t = Instant::now();
        let second = s.next_scan().unwrap().expect("the second on the clock");
        assert_eq!(second.radar.scan, 2);
        let waited = t.elapsed().as_secs_f64();
        assert!(waited > 2.0, "{waited}");
    }
}
