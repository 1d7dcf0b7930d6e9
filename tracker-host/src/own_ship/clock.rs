//! The bridge's clock: UTC from the sentences' time fields, with the date from RMC and ZDA.
//!
//! Times are seconds since 1970-01-01 00:00 UTC. A time of day without a date takes the
//! date in force; midnight is recognised when the time of day falls by more than half a day
//! (23:59:57.5 then 00:00:00.0 is 2.5 s later, the next day). Before any date is known a
//! provisional day is used (the recording's first date when it has one, today's for a live
//! source, else day 0): only differences between times matter then. A time earlier than
//! the newest one used is a step backwards: refused (the caller counts it and skips the
//! sentence), the clock unchanged. A time more than [`MAX_JUMP_S`] ahead is taken only when
//! the next timed sentence confirms it (lands within [`MAX_JUMP_S`] after it): one sentence
//! stamped an hour ahead (a corrupt time with a valid checksum) would otherwise make every
//! later one a step back; a real gap (a receiver off for hours) costs one sentence.

use super::sentences::{Day, Stamp};

/// Seconds in a day.
pub const DAY_S: f64 = 86_400.0;

/// The day `t_s` (s since 1970) falls on, days since 1970.
pub fn day_of_s(t_s: f64) -> Day {
    (t_s / DAY_S).floor() as Day
}

/// How far back a time may be before it is a step backwards, s (sentences of one epoch
/// share a time; receivers round it).
const SAME_TIME_S: f64 = 1e-3;

/// A jump forward longer than this needs a second sentence to confirm it, s.
pub const MAX_JUMP_S: f64 = 60.0;

/// The clock.
#[derive(Clone, Debug, PartialEq)]
pub struct UtcClock {
    day: Option<Day>,
    provisional_day: Day,
    newest_s: Option<f64>,
    /// A jump ahead seen once (its time), waiting for a second sentence to confirm it.
    jump_to: Option<f64>,
}

/// Why the clock refuses a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refused {
    /// Earlier than the newest time used.
    Backwards {
        /// The refused time, s.
        time_s: f64,
        /// The newest time used, s.
        newest_s: f64,
    },
    /// Far ahead of the newest time, not (yet) confirmed.
    Jump {
        /// The refused time, s.
        time_s: f64,
        /// The newest time used, s.
        newest_s: f64,
    },
}

impl UtcClock {
    /// A clock that takes `provisional_day` until a sentence gives the date.
    pub fn new(provisional_day: Day) -> Self {
        UtcClock {
            day: None,
            provisional_day,
            newest_s: None,
            jump_to: None,
        }
    }

    /// The newest time used, s.
    pub fn newest_s(&self) -> Option<f64> {
        self.newest_s
    }

    /// Whether a sentence has given the date (else times count from the provisional day).
    pub fn date_known(&self) -> bool {
        self.day.is_some()
    }

    /// Takes a dated `stamp` the clock refused while its date was provisional: the
    /// provisional day was a guess (a live source's is this computer's date, wrong when its
    /// clock is hours out across midnight, or years), the sentence's date is not. The clock
    /// starts again at its time, which it returns; `None` (nothing changes) for a stamp
    /// without a date or a time, or once the date is known.
    pub fn rebase(&mut self, stamp: &Stamp) -> Option<f64> {
        let (tod, day) = (stamp.time_of_day_s?, stamp.day?);
        if self.day.is_some() {
            return None;
        }
        let t = day as f64 * DAY_S + tod;
        self.day = Some(day);
        self.newest_s = Some(t);
        self.jump_to = None;
        Some(t)
    }

    /// The time `stamp` stands for, without taking it (`None` for a stamp without a time).
    pub fn peek(&self, stamp: &Stamp) -> Option<f64> {
        self.resolve(stamp).map(|(t, _)| t)
    }

    fn resolve(&self, stamp: &Stamp) -> Option<(f64, Day)> {
        let tod = stamp.time_of_day_s?;
        if let Some(day) = stamp.day {
            return Some((day as f64 * DAY_S + tod, day));
        }
        let day = self.day.unwrap_or(self.provisional_day);
        let at = |d: Day| d as f64 * DAY_S + tod;
        let Some(newest) = self.newest_s else {
            return Some((at(day), day));
        };
        // The day that puts the time nearest the newest: across midnight forwards (the time
        // of day fell) or backwards (a step back over midnight).
        [day, day + 1, day - 1]
            .into_iter()
            .map(|d| (at(d), d))
            .min_by(|a, b| (a.0 - newest).abs().total_cmp(&(b.0 - newest).abs()))
    }

    /// Takes `stamp`'s time: returns it (`Ok(None)` for a stamp without a time).
    ///
    /// # Errors
    /// [`Refused::Backwards`] when the time is earlier than the newest one used;
    /// [`Refused::Jump`] when it is more than [`MAX_JUMP_S`] ahead and no sentence confirmed
    /// the jump yet (nothing changes but the note of the jump).
    pub fn take(&mut self, stamp: &Stamp) -> Result<Option<f64>, Refused> {
        let Some((t, day)) = self.resolve(stamp) else {
            return Ok(None);
        };
        if let Some(newest) = self.newest_s {
            if t > newest + MAX_JUMP_S {
                // Confirmed when a jump seen before lands within MAX_JUMP_S before this one.
                let confirmed = self
                    .jump_to
                    .is_some_and(|j| (j..=j + MAX_JUMP_S).contains(&t));
                if !confirmed {
                    self.jump_to = Some(t);
                    return Err(Refused::Jump {
                        time_s: t,
                        newest_s: newest,
                    });
                }
                self.jump_to = None;
            } else if t < newest - SAME_TIME_S {
                return Err(Refused::Backwards {
                    time_s: t,
                    newest_s: newest,
                });
            }
        }
        self.newest_s = Some(self.newest_s.map_or(t, |n| n.max(t)));
        if stamp.day.is_some() || self.day.is_some() {
            self.day = Some(day);
        } else {
            self.provisional_day = day;
        }
        Ok(Some(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(tod: f64, day: Option<Day>) -> Stamp {
        Stamp {
            time_of_day_s: Some(tod),
            day,
        }
    }

    #[test]
    fn midnight_rolls_over_and_steps_back_are_refused() {
        let mut c = UtcClock::new(0);
        let d = 17_763; // 2018-08-20
        assert_eq!(
            c.take(&at(86_397.5, Some(d))),
            Ok(Some(d as f64 * DAY_S + 86_397.5))
        );
        // A time-only sentence just after midnight: 2.5 s later, the next day.
        let t = c.take(&at(0.0, None)).unwrap().unwrap();
        assert_eq!(t, (d + 1) as f64 * DAY_S);
        // A dated sentence agrees.
        assert_eq!(c.take(&at(1.0, Some(d + 1))), Ok(Some(t + 1.0)));
        // 23:59:50 without a date, after 00:00:01: a step back over midnight, refused.
        let back = c.take(&at(DAY_S - 10.0, None)).unwrap_err();
        assert_eq!(
            back,
            Refused::Backwards {
                time_s: (d + 1) as f64 * DAY_S - 10.0,
                newest_s: (d + 1) as f64 * DAY_S + 1.0
            }
        );
        // A step back of 13 s (Humminbird's log) is refused; the clock stays.
        let mut c = UtcClock::new(5);
        c.take(&at(70_000.0, None)).unwrap();
        assert!(c.take(&at(69_987.0, None)).is_err());
        assert_eq!(c.newest_s(), Some(5.0 * DAY_S + 70_000.0));
        // Sentences of one epoch share a time.
        assert!(c.take(&at(70_000.0, None)).is_ok());
        assert_eq!(c.take(&Stamp::default()), Ok(None));
    }

    #[test]
    fn the_first_date_replaces_a_wrong_provisional_day() {
        // This computer's date is a day ahead of the bridge's (its clock 12 h fast across
        // midnight): a time-only sentence is taken on it, and the first RMC's date is a day
        // back, refused as a step back; rebased on it, the clock goes on from there.
        let d = 20_000;
        let mut c = UtcClock::new(d + 1);
        c.take(&at(82_800.0, None)).unwrap();
        let rmc = at(82_801.0, Some(d));
        assert!(matches!(c.take(&rmc), Err(Refused::Backwards { .. })));
        assert!(!c.date_known());
        assert_eq!(c.rebase(&rmc), Some(d as f64 * DAY_S + 82_801.0));
        assert!(c.date_known());
        assert_eq!(
            c.take(&at(82_802.0, None)),
            Ok(Some(d as f64 * DAY_S + 82_802.0))
        );
        // Once the date is known, nothing is rebased.
        assert_eq!(c.rebase(&at(10.0, Some(d - 400))), None);
    }

    #[test]
    fn a_jump_ahead_needs_a_second_sentence() {
        let mut c = UtcClock::new(100);
        let t0 = 100.0 * DAY_S + 36_000.0;
        assert!(c.take(&at(36_000.0, None)).is_ok());
        // One sentence an hour ahead (a corrupt time): refused; the next ones are fine.
        assert!(matches!(
            c.take(&at(39_600.0, None)),
            Err(Refused::Jump { .. })
        ));
        assert_eq!(c.take(&at(36_001.0, None)), Ok(Some(t0 + 1.0)));
        assert_eq!(c.take(&at(36_002.0, None)), Ok(Some(t0 + 2.0)));
        // A receiver back after 2.5 hours: the first sentence is refused, the second confirms.
        let later = 36_002.0 + 9_000.0;
        assert!(c.take(&at(later, None)).is_err());
        assert_eq!(c.take(&at(later + 1.0, None)), Ok(Some(t0 + 9_003.0)));
        assert_eq!(c.newest_s(), Some(t0 + 9_003.0));
    }
}
