//! Own ship from NMEA: every line classified, the chosen talkers' readings timed by the
//! bridge's clock and fed to paper 004's dead-reckoning filter (DRKF): GNSS position and
//! velocity over ground, the heading (true, or magnetic made true with the variation), the
//! log's speed through the water. Counted per kind and reason ([`NavCounts`]).
//!
//! Speed through the water (`VHW`, `VBW` water) enters as the DRKF's log row through the
//! water (eq. 7d: the filter estimates the current between it and the GNSS velocity); speed
//! over ground along the keel (`VBW` ground) enters, with the heading, as a velocity over
//! ground.
//!
//! A magnetic heading (`HDG`, `HDM`) is made true with the variation: the sentence's own
//! (`HDG`), else the GNSS receiver's (`RMC`), else the operator's (`--magnetic-variation`);
//! with none of them it is not used (counted `no_variation`).
//!
//! Sensor failures: a position older than [`POSITION_LOST_S`] is dead reckoning (an alarm
//! with its age); after [`MAX_DEAD_RECKONING_S`] of that, or a gap of that long between
//! fixes, own ship's motion is no longer known (targets' true motion is not given) and the
//! filter restarts at the next fix. A heading that stops for [`HEADING_LOST_S`] is an alarm.

use std::collections::BTreeMap;

use tracker_core::nav::drkf::{ix, Drkf, DrkfConfig, GyroMode, NavFix, SpeedlogMode};
use tracker_core::nav::GaussMarkov;

use super::clock::{self, UtcClock};
use super::select::Selector;
use super::sentences::{decode, Decoded, Reading, Rejection};
use super::{OwnShip, OwnShipQuality};
use crate::nmea::sentence::{self, Line, LineError};
use crate::origin::Origin;

/// A position older than this is dead reckoning, s.
pub const POSITION_LOST_S: f64 = 10.0;

/// Dead reckoning longer than this leaves own ship's motion unknown; a gap between fixes
/// this long restarts the filter, s.
pub const MAX_DEAD_RECKONING_S: f64 = 300.0;

/// A sentence without a position this long after the last fix no longer moves the filter:
/// the fixes have stopped (a bridge GNSS sends one a second), s.
pub const FIX_GAP_S: f64 = 2.0;

/// A heading silent this long (after one was received) is an alarm, s.
pub const HEADING_LOST_S: f64 = 10.0;

/// A reading timed this far after the time own ship is asked for is not of that time: it
/// gives own ship nothing (no heading, no position), s. A recording of another voyage,
/// played with a capture a year before it, had its untimed headings held for the whole
/// capture, their age negative, and turned a head-up radar's picture by them.
pub const AHEAD_OF_TIME_S: f64 = 10.0;

/// Own ship's motion over ground is known once the filter's velocity standard deviation
/// per axis has come down to this, m/s (about 2 kn; 0.3 m/s on a steady GNSS feed): a
/// filter started on a position alone holds a velocity of zero with a σ of 3 m/s, which
/// is no knowledge of the motion (the true vectors and a plotter's `RMC` must not take it
/// as own ship stopped). Once known, dead reckoning keeps it for
/// [`MAX_DEAD_RECKONING_S`].
pub const MOTION_KNOWN_SIGMA_MPS: f64 = 1.0;

/// A position fix further than this from the dead-reckoned position, plus three standard
/// deviations of it and [`MAX_UNMODELLED_SPEED_MPS`] for every second since the last fix, is
/// implausible, m.
pub const PLAUSIBLE_M: f64 = 200.0;

/// How fast own ship may have gone where the filter did not see it, m/s (about 30 kn).
pub const MAX_UNMODELLED_SPEED_MPS: f64 = 15.0;

/// Implausible fixes, consistent with each other, that are believed: own ship really is
/// there (a receiver restarting far away, a wrong first fix); the filter starts again.
pub const CONSISTENT_FIXES_TO_JUMP: usize = 5;

/// An implausible fix is an alarm for this long, s.
pub const IMPLAUSIBLE_ALARM_S: f64 = 30.0;

/// What became of the lines.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct NavCounts {
    /// Lines read (annotations and blank lines included).
    pub lines: u64,
    /// A recording's lines after the run's last scan (or after the operator quit): not
    /// read into own ship, counted at the end so that every line is accounted for.
    pub after_last_scan: u64,
    /// Sentences used (at least one reading applied).
    pub used: u64,
    /// Well-formed sentences own ship does not use (satellites, depth, wind, AIS,
    /// proprietary), and those of a talker not chosen for its quantity.
    pub ignored: u64,
    /// Of the ignored: sentences of a talker not chosen for their quantity.
    pub other_source: u64,
    /// A recording's annotations (`#` comments, JSON reports): not sentences.
    pub annotations: u64,
    /// Rejected: the checksum does not match.
    pub bad_checksum: u64,
    /// Rejected: not framed as a sentence, or fields that do not parse.
    pub malformed: u64,
    /// Rejected: data flagged invalid or empty (RMC `V`, GGA quality 0, empty HDT).
    pub void: u64,
    /// Rejected: a time earlier than the newest one used.
    pub stale: u64,
    /// Rejected: a time far ahead of the newest, not (yet) confirmed by the next sentence.
    pub time_jump: u64,
    /// Rejected: a position fix too far from where own ship can be (a receiver gone wrong).
    pub implausible: u64,
    /// Rejected: a value out of range.
    pub out_of_range: u64,
    /// Rejected: a heading that should be true is magnetic (`HDT,…,M`).
    pub not_true: u64,
    /// Rejected: a magnetic heading with no variation known.
    pub no_variation: u64,
    /// Ignored sentences by type (`GSV`, `VDM`, `P` for proprietary, …).
    pub ignored_by_type: BTreeMap<String, u64>,
    /// Own ship's AIS transponder's reports (`AIVDO`) taken as a sensor (counted here, not
    /// in the sentence counts above: the AIS decoder counts their sentences).
    pub ais_own: u64,
    /// … of which one reading or more was used.
    pub ais_own_used: u64,
}

impl NavCounts {
    /// Sentences rejected, for any reason.
    pub fn rejected(&self) -> u64 {
        self.bad_checksum
            + self.malformed
            + self.void
            + self.stale
            + self.time_jump
            + self.implausible
            + self.out_of_range
            + self.not_true
            + self.no_variation
    }

    /// Blank lines: what is neither a sentence nor an annotation.
    pub fn blank(&self) -> u64 {
        self.lines - self.used - self.ignored - self.annotations - self.rejected()
    }

    fn reject(&mut self, r: Rejection) {
        match r {
            Rejection::Malformed => self.malformed += 1,
            Rejection::Void => self.void += 1,
            Rejection::NotTrue => self.not_true += 1,
            Rejection::OutOfRange => self.out_of_range += 1,
        }
    }

    /// The kinds ignored most, with their counts, for the summary (`GSV 426, MWV 282, XDR
    /// 141, DBT 120, 5 more kinds; `): the whole list is the JSON's
    /// [`NavCounts::ignored_by_type`].
    /// A new user's trial read "2590 ignored" and could not tell which without the JSON.
    fn most_ignored(&self) -> String {
        const SHOWN: usize = 4;
        let mut kinds: Vec<(&String, &u64)> = self.ignored_by_type.iter().collect();
        kinds.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let mut out: Vec<String> = kinds
            .iter()
            .take(SHOWN)
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        if kinds.len() > SHOWN {
            out.push(format!("{} more kinds", kinds.len() - SHOWN));
        }
        if out.is_empty() {
            String::new()
        } else {
            format!("{}; ", out.join(", "))
        }
    }

    fn ignore(&mut self, kind: &str) {
        self.ignored += 1;
        *self.ignored_by_type.entry(kind.to_string()).or_default() += 1;
    }
}

impl std::fmt::Display for NavCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} lines: {} used, {} ignored ({}{} of another talker), {} rejected (bad checksum {}, malformed {}, void {}, stale {}, time jump {}, implausible {}, out of range {}, not true {}, no variation {}), {} annotations",
            self.lines,
            self.used,
            self.ignored,
            self.most_ignored(),
            self.other_source,
            self.rejected(),
            self.bad_checksum,
            self.malformed,
            self.void,
            self.stale,
            self.time_jump,
            self.implausible,
            self.out_of_range,
            self.not_true,
            self.no_variation,
            self.annotations
        )?;
        if self.after_last_scan > 0 {
            let at_least = if self.after_last_scan >= super::MAX_UNREAD_COUNTED {
                "at least "
            } else {
                ""
            };
            write!(
                f,
                "; {at_least}{} after the last scan, not read",
                self.after_last_scan
            )?;
        }
        Ok(())
    }
}

/// The DRKF's sensor model for bridge NMEA: GNSS 5 m and 0.1 m/s, heading 0.5° (of the
/// hull's velocity through the water: a heading is not a course over ground), log 0.1 m/s
/// through the water, a ship's accelerations.
fn drkf_config() -> DrkfConfig {
    let mut c = DrkfConfig::table_1(1).unwrap_or_else(|| unreachable!("test 1 exists"));
    // The current (with the wind's leeway: whatever makes the course over ground differ
    // from the heading and the speed over ground from the log's) about 2 kn, holding for a
    // minute: with the paper's Table I current (0.55 m/s, 6 s) the set decayed between two
    // fixes and the course shown swung 2–5° towards a heading 20–90° off it.
    c.current = GaussMarkov::with_variance(1.0, 1.0 / 60.0);
    c.acceleration = GaussMarkov::with_variance(0.05 * 0.05, 0.1);
    c.gps_position_var = 25.0;
    c.gps_velocity_var = 0.01;
    c.gyro_var = 0.5f64.to_radians().powi(2);
    c.speedlog_var = 0.01;
    c.speedlog_mode = SpeedlogMode::ThroughWater;
    c.gyro_mode = GyroMode::HeadingThroughWater;
    c
}

/// Whether the filter knows own ship's velocity over ground ([`MOTION_KNOWN_SIGMA_MPS`]).
fn velocity_known(d: &Drkf<f64>) -> bool {
    let c = d.own_ship_covariance();
    let mean_variance = 0.5 * (c[(2, 2)] + c[(3, 3)]);
    mean_variance <= MOTION_KNOWN_SIGMA_MPS * MOTION_KNOWN_SIGMA_MPS
}

/// How late a live line's arrival time may be, s: a live source's lines are read together
/// once a scan and taken as heard then, up to a scan after they came. Before the first
/// timed sentence, readings heard without a position (a heading) are restarted on the
/// bridge's time only when it is behind their arrival by more than this (a PC clock not
/// set); by less it is the reading's delay, not the clock's error.
pub const HEARD_LATE_S: f64 = 10.0;

/// Own ship from NMEA.
pub struct OwnShipNav {
    origin: Origin,
    clock: UtcClock,
    selector: Selector,
    drkf: Option<Drkf<f64>>,
    /// Time of the filter's state, s.
    time_s: f64,
    /// A recording's line with no time, before any timed one, is taken at this time at
    /// the earliest (s): the start of the provisional day (today's, unless the recording
    /// has a date), so a recording with no time in any sentence is today's, not 1970's.
    untimed_from_s: f64,
    /// The filter has known own ship's velocity since it started ([`MOTION_KNOWN_SIGMA_MPS`]).
    motion_measured: bool,
    /// The arrival time (s) of the last reading taken at its arrival
    /// ([`OwnShipNav::feed_heard`]) before any timed sentence: the arrival clock may not be
    /// the bridge's.
    heard_before_clock_s: Option<f64>,
    /// The lines "heard" are a recording's, their times given by the replay (its first time
    /// looked for ahead, or the scan's), not a live arrival's: told so on a restart.
    replayed: bool,
    /// Velocity over ground from before the first position.
    velocity: Option<[f64; 2]>,
    variation_deg: Option<f64>,
    operator_variation_deg: Option<f64>,
    last_position_s: Option<f64>,
    last_heading_s: Option<f64>,
    heading_deg: Option<f64>,
    counts: NavCounts,
    events: crate::event_log::EventLog,
    /// Implausible fixes in a row (time, local position), to believe a real jump.
    implausible: Vec<(f64, [f64; 2])>,
    last_implausible_s: Option<f64>,
    /// The position fixes used (time, latitude, longitude), when asked to keep them.
    fixes: Option<Vec<(f64, f64, f64)>>,
    /// A recording's track's first and last fix, s since 1970 ([`OwnShipNav::within`]).
    window_s: Option<(f64, f64)>,
}

impl OwnShipNav {
    /// No fix yet. Times before the first dated sentence count from `provisional_day` (days
    /// since 1970); `variation_deg` is the operator's magnetic variation (east positive).
    pub fn new(origin: Origin, provisional_day: i64, variation_deg: Option<f64>) -> Self {
        OwnShipNav::with_selector(origin, provisional_day, variation_deg, Selector::default())
    }

    /// As [`OwnShipNav::new`], choosing talkers with `selector`.
    pub fn with_selector(
        origin: Origin,
        provisional_day: i64,
        variation_deg: Option<f64>,
        selector: Selector,
    ) -> Self {
        OwnShipNav {
            origin,
            clock: UtcClock::new(provisional_day),
            selector,
            drkf: None,
            time_s: 0.0,
            untimed_from_s: provisional_day as f64 * clock::DAY_S,
            motion_measured: false,
            heard_before_clock_s: None,
            replayed: false,
            velocity: None,
            variation_deg: None,
            operator_variation_deg: variation_deg,
            last_position_s: None,
            last_heading_s: None,
            heading_deg: None,
            counts: NavCounts::default(),
            events: crate::event_log::EventLog::default(),
            implausible: Vec::new(),
            last_implausible_s: None,
            fixes: None,
            window_s: None,
        }
    }

    /// Refuses, as a time jump, a dated sentence more than
    /// [`super::recording::MAX_FIX_GAP_S`] outside `window_s` (a recording's track's first
    /// and last fix, s since 1970); `None` refuses none.
    pub fn within(mut self, window_s: Option<(f64, f64)>) -> Self {
        self.window_s = window_s;
        self
    }

    /// Lines fed with a time of their own ([`OwnShipNav::feed_heard`]) are a recording's,
    /// timed by its replay: a restart on its first time is told in those words.
    pub fn replayed(mut self, replayed: bool) -> Self {
        self.replayed = replayed;
        self
    }

    /// Keeps every position fix used, for [`OwnShipNav::fixes`].
    pub fn keep_fixes(mut self) -> Self {
        self.fixes = Some(Vec::new());
        self
    }

    /// The position fixes used so far: (time s since 1970, latitude, longitude), when kept.
    pub fn fixes(&self) -> &[(f64, f64, f64)] {
        self.fixes.as_deref().unwrap_or(&[])
    }

    /// Counts a line refused for a time out of sequence (found by a reader's look-ahead:
    /// one sentence stamped far from its neighbours).
    pub fn refuse_out_of_sequence(&mut self) {
        self.counts.lines += 1;
        self.counts.stale += 1;
    }

    /// The counts so far.
    pub fn counts(&self) -> &NavCounts {
        &self.counts
    }

    /// Changes of source, disagreements between sources, filter restarts, oldest first.
    pub fn events(&self) -> Vec<String> {
        let mut e = self.selector.events();
        e.extend(self.events.lines("own-ship filter"));
        e
    }

    /// Counts `n` lines of a recording left after the run's last scan.
    pub fn note_unread(&mut self, n: u64) {
        self.counts.after_last_scan += n;
    }

    /// Whether a sentence has given the date (before it, times count from the provisional
    /// day: a live source's is this computer's date).
    pub fn date_known(&self) -> bool {
        self.clock.date_known()
    }

    /// The newest sentence time used, s since 1970.
    pub fn newest_s(&self) -> Option<f64> {
        self.clock.newest_s()
    }

    /// The time `line` carries on this clock, if it is a timed sentence that would be used
    /// (for replaying a recording in step: a line is due once its time has come).
    pub fn time_of(&self, line: &str) -> Option<f64> {
        let Ok(Line::Sentence(s)) = sentence::parse(line) else {
            return None;
        };
        match decode(&s, line) {
            Decoded::Readings(stamp, _) | Decoded::Time(stamp) => self.clock.peek(&stamp),
            _ => None,
        }
    }

    /// [`OwnShipNav::time_of`], but `None` for a dated sentence far outside the recording's
    /// track ([`OwnShipNav::within`]), which the filter refuses: not the recording's time.
    pub fn time_in_window_of(&self, line: &str) -> Option<f64> {
        let t = self.time_of(line)?;
        let gap = super::recording::MAX_FIX_GAP_S;
        let dated = || {
            matches!(sentence::parse(line), Ok(Line::Sentence(s))
                if matches!(decode(&s, line),
                    Decoded::Readings(stamp, _) | Decoded::Time(stamp) if stamp.day.is_some()))
        };
        match self.window_s {
            Some((first, last)) if (t < first - gap || t > last + gap) && dated() => None,
            _ => Some(t),
        }
    }

    /// Takes one line. A sentence without a time (`GLL` or `VTG` from some receivers, `HDT`)
    /// is taken at the newest time used: a recording's lines come in the order they were
    /// sent.
    pub fn feed(&mut self, line: &str) {
        self.feed_line(line, None);
    }

    /// Takes one line heard at `heard_s` (s since 1970, on this clock: the caller adds the
    /// offset between the bridge's UTC and its own time when it knows one). A sentence
    /// without a time is taken at `heard_s` or the newest time used, whichever is later:
    /// with no timed sentence at all (a capture of `GLL` without times), own ship's fixes
    /// are as fresh as their arrival, not as old as the epoch.
    pub fn feed_heard(&mut self, line: &str, heard_s: f64) {
        self.feed_line(line, Some(heard_s));
    }

    fn feed_line(&mut self, line: &str, heard_s: Option<f64>) {
        self.counts.lines += 1;
        let s = match sentence::parse(line) {
            Ok(Line::Sentence(s)) => s,
            Ok(Line::Annotation) => {
                self.counts.annotations += 1;
                return;
            }
            Ok(Line::Blank) => return,
            Err(LineError::BadChecksum) => {
                self.counts.bad_checksum += 1;
                return;
            }
            Err(LineError::Malformed(_)) => {
                self.counts.malformed += 1;
                return;
            }
        };
        let (stamp, readings) = match decode(&s, line) {
            Decoded::Readings(stamp, readings) => (stamp, readings),
            Decoded::Time(stamp) => (stamp, Vec::new()),
            Decoded::Ignored => {
                let kind = if s.proprietary { "P" } else { s.kind };
                self.counts.ignore(kind);
                return;
            }
            Decoded::Rejected(r) => {
                self.counts.reject(r);
                return;
            }
        };
        // A dated sentence far outside the recording's track: another date, not this voyage.
        if let (Some((first, last)), Some(_)) = (self.window_s, stamp.day) {
            let gap = super::recording::MAX_FIX_GAP_S;
            if self
                .clock
                .peek(&stamp)
                .is_some_and(|t| t < first - gap || t > last + gap)
            {
                self.counts.time_jump += 1;
                return;
            }
        }
        let first_time = self.clock.newest_s().is_none();
        let now = match self.clock.take(&stamp) {
            Ok(Some(t)) => {
                // Readings heard before the first timed sentence were taken at their
                // arrival; a bridge clock behind that (a PC clock not set) would leave the
                // filter ahead of every later reading, one far ahead would fly it on: start
                // it again on the bridge's time, forgetting the arrival clock's times.
                // (Against the arrival time of those readings, not the filter's: a heading
                // before any position starts no filter and leaves its time unset.)
                // A filter started on arrival times is restarted on any offset beyond a
                // second (its fixes would be mistimed); headings alone only beyond a scan's
                // lateness ([`HEARD_LATE_S`]).
                let ahead_s = self.heard_before_clock_s.map_or(0.0, |h| t - h);
                let behind_s = if self.drkf.is_some() {
                    1.0
                } else {
                    HEARD_LATE_S
                };
                if first_time
                    && self.heard_before_clock_s.is_some()
                    && !(-behind_s..=clock::MAX_JUMP_S).contains(&ahead_s)
                {
                    let offset = crate::utc::offset_label(ahead_s);
                    let why = if self.replayed {
                        format!("the recording's first time is {offset} the time its untimed sentences before it were taken at (its first time looked for ahead, or the scan's)")
                    } else {
                        format!("the bridge's UTC is {offset} the time the sentences before it were heard")
                    };
                    self.events
                        .push(format!("own-ship filter restarted: {why}"));
                    self.restart_at(t);
                }
                t
            }
            Ok(None) => match heard_s {
                Some(heard) => {
                    let at = self.heard_time(heard);
                    if self.clock.newest_s().is_none() {
                        self.heard_before_clock_s = Some(at);
                    }
                    at
                }
                None => self
                    .clock
                    .newest_s()
                    .unwrap_or(self.time_s.max(self.untimed_from_s)),
            },
            Err(
                clock::Refused::Backwards { newest_s, .. } | clock::Refused::Jump { newest_s, .. },
            ) if !self.clock.date_known() && stamp.day.is_some() => {
                // The first date: the times before it were on a provisional day (a live
                // source's is this computer's date), and this sentence's date is the
                // bridge's. Start again on it.
                let Some(t) = self.clock.rebase(&stamp) else {
                    return;
                };
                self.events.push(format!(
                    "own-ship filter restarted: the first date heard puts the bridge's UTC {} the provisional date's (this computer's date) taken before it",
                    crate::utc::offset_label(t - newest_s)
                ));
                self.restart_at(t);
                t
            }
            Err(clock::Refused::Backwards { .. }) => {
                self.counts.stale += 1;
                return;
            }
            Err(clock::Refused::Jump { .. }) => {
                self.counts.time_jump += 1;
                return;
            }
        };
        if readings.is_empty() {
            // A time-only sentence (ZDA): it set the clock.
            self.counts.used += 1;
            return;
        }
        self.apply_readings(s.talker, &readings, now);
    }

    /// Takes own ship's AIS transponder's report (`AIVDO`: its GNSS position, SOG, COG and
    /// heading) as one more own-ship sensor, talker `AI`, at `heard_s` (s since 1970, the
    /// time the line was read: AIS carries no date or hour), or the clock's newest time if
    /// that is later. The talker choice applies: `AI` gives way to another talker that
    /// delivers, dated with it ([`super::select`]), and stands in for what it stops giving.
    pub fn feed_ais_own(&mut self, r: &crate::ais::AisReport, heard_s: f64) {
        if !r.own_ship {
            return;
        }
        let mut readings = Vec::new();
        if let Some((lat_deg, lon_deg)) = r.position_deg {
            readings.push(Reading::Position { lat_deg, lon_deg });
        }
        if let Some(sog) = r.sog_kn {
            readings.push(Reading::GroundVelocity {
                sog_mps: sog * 1852.0 / 3600.0,
                cog_deg: r.cog_deg.filter(|_| sog > 0.0),
            });
        }
        if let Some(h) = r.heading_deg {
            readings.push(Reading::HeadingTrue(f64::from(h)));
        }
        if readings.is_empty() {
            return;
        }
        // Timed by when it was heard: with GNSS silent the clock stands still, and readings
        // stamped with its time would be flown on from there as if old. (A recording's
        // replay gives the newest timed sentence's time: the lines after its GNSS stops are
        // read at one scan anyway.)
        let now = self.heard_time(heard_s);
        if self.clock.newest_s().is_none() {
            // Taken at its arrival before any timed sentence, as an untimed line heard.
            self.heard_before_clock_s = Some(now);
        }
        // The sentence counts are the lines'; an AIS report is not a line of this reader.
        let before = self.counts.clone();
        self.apply_readings(super::select::AIS_TALKER, &readings, now);
        let used = self.counts.used > before.used;
        self.counts = before;
        self.counts.ais_own += 1;
        self.counts.ais_own_used += u64::from(used);
    }

    /// The time of a reading without a time of its own, heard at `heard_s`: never before
    /// the newest time used, nor before the filter's.
    fn heard_time(&self, heard_s: f64) -> f64 {
        self.clock
            .newest_s()
            .map_or(heard_s, |n| n.max(heard_s))
            .max(self.time_s)
    }

    fn apply_readings(&mut self, talker: &str, readings: &[Reading], now: f64) {
        let mut fix = NavFix::default();
        let (mut chosen, mut other) = (0, 0);
        for r in readings {
            let r = match *r {
                Reading::Variation(v) => {
                    self.variation_deg = Some(v);
                    continue;
                }
                // A magnetic heading is made true here; without a variation it cannot be,
                // and is refused before it could be chosen over a true one.
                Reading::HeadingMagnetic {
                    heading_deg,
                    deviation_deg,
                    variation_deg,
                } => match variation_deg
                    .or(self.variation_deg)
                    .or(self.operator_variation_deg)
                {
                    Some(var) => Reading::HeadingTrue(
                        (heading_deg + deviation_deg.unwrap_or(0.0) + var).rem_euclid(360.0),
                    ),
                    None => {
                        self.counts.no_variation += 1;
                        return;
                    }
                },
                other => other,
            };
            let local = match r {
                Reading::Position { lat_deg, lon_deg } => {
                    Some(self.origin.to_local(lat_deg, lon_deg))
                }
                _ => None,
            };
            if !self.selector.admit(talker, &r, local, now) {
                other += 1;
                continue;
            }
            match r {
                Reading::Position { lat_deg, lon_deg } => {
                    fix.gps_position_m = local;
                    if let Some(f) = self.fixes.as_mut() {
                        f.push((now, lat_deg, lon_deg));
                    }
                }
                Reading::GroundVelocity { sog_mps, cog_deg } => {
                    let c = cog_deg.unwrap_or(0.0).to_radians();
                    fix.gps_velocity_mps = Some([sog_mps * c.sin(), sog_mps * c.cos()]);
                }
                Reading::GroundSpeedAlongKeel(v) => match self.heading_deg {
                    Some(h) => {
                        let h = h.to_radians();
                        fix.gps_velocity_mps = Some([v * h.sin(), v * h.cos()]);
                    }
                    None => continue,
                },
                Reading::HeadingTrue(h) => fix.gyro_rad = Some(self.heading(h, now)),
                Reading::WaterSpeed(v) => fix.speedlog_mps = Some(v),
                Reading::HeadingMagnetic { .. } | Reading::Variation(_) => continue,
            }
            chosen += 1;
        }
        if chosen == 0 {
            if other > 0 {
                self.counts.other_source += 1;
                self.counts.ignored += 1;
            } else {
                // Only a variation (an RMC without a fix cannot get here: it is void).
                self.counts.used += 1;
            }
            return;
        }
        self.apply(now, &fix);
    }

    fn heading(&mut self, deg: f64, now: f64) -> f64 {
        self.heading_deg = Some(deg);
        self.last_heading_s = Some(now);
        deg.to_radians()
    }

    /// Whether a position fix at `at` is where own ship can be; `false` when it is not. A run
    /// of implausible fixes consistent with each other is believed: the filter starts again
    /// there (an event).
    fn plausible(&mut self, at: f64, p: [f64; 2]) -> bool {
        let Some(drkf) = self.drkf.as_ref() else {
            return true;
        };
        let mut predicted = drkf.clone();
        let dt = (at - self.time_s).clamp(0.0, MAX_DEAD_RECKONING_S);
        if dt > 0.0 && predicted.predict(dt).is_err() {
            return true;
        }
        let q = predicted.position_m();
        let c = predicted.covariance();
        let sd = (c[(ix::X, ix::X)] + c[(ix::Y, ix::Y)]).max(0.0).sqrt();
        let since_fix = self.last_position_s.map_or(0.0, |t| (at - t).max(0.0));
        let allowed = PLAUSIBLE_M + 3.0 * sd + MAX_UNMODELLED_SPEED_MPS * since_fix;
        let d = (p[0] - q[0]).hypot(p[1] - q[1]);
        if d <= allowed {
            self.implausible.clear();
            return true;
        }
        // Consistent with the implausible ones before it?
        let consistent = self.implausible.last().is_none_or(|&(t, r)| {
            (p[0] - r[0]).hypot(p[1] - r[1])
                <= PLAUSIBLE_M + MAX_UNMODELLED_SPEED_MPS * (at - t).max(0.0)
        });
        if !consistent {
            self.implausible.clear();
        }
        self.implausible.push((at, p));
        if self.implausible.len() >= CONSISTENT_FIXES_TO_JUMP {
            self.events.push(format!(
                "own ship jumped {:.1} km: {CONSISTENT_FIXES_TO_JUMP} consistent fixes there, filter restarted",
                d / 1000.0
            ));
            self.implausible.clear();
            self.drkf = None;
            return true;
        }
        self.last_implausible_s = Some(at);
        false
    }

    /// Forgets the filter and every time taken on the clock before `t`, s: the clock has
    /// started again.
    fn restart_at(&mut self, t: f64) {
        self.drkf = None;
        self.last_position_s = None;
        self.last_heading_s = None;
        self.heading_deg = None;
        self.last_implausible_s = None;
        self.implausible.clear();
        self.selector.forget_times();
        self.time_s = t;
    }

    fn apply(&mut self, at: f64, fix: &NavFix) {
        // A long gap: the filter's dead reckoning means nothing any more; start again.
        if let (Some(_), Some(last), Some(_)) =
            (fix.gps_position_m, self.last_position_s, &self.drkf)
        {
            if at - last > MAX_DEAD_RECKONING_S {
                self.events.push(format!(
                    "own-ship filter restarted after {:.0} min without a position",
                    (at - last) / 60.0
                ));
                self.drkf = None;
            }
        }
        if let Some(p) = fix.gps_position_m {
            if !self.plausible(at, p) {
                self.counts.implausible += 1;
                return;
            }
        }
        let Some(drkf) = self.drkf.as_mut() else {
            if let Some(v) = fix.gps_velocity_mps {
                self.velocity = Some(v);
            }
            // The first position starts the filter.
            if let Some(p) = fix.gps_position_m {
                let v = fix.gps_velocity_mps.or(self.velocity);
                match Drkf::new(
                    drkf_config(),
                    p,
                    v.unwrap_or([0.0, 0.0]),
                    10.0,
                    if v.is_some() { 0.5 } else { 10.0 },
                ) {
                    Ok(d) => {
                        self.motion_measured = velocity_known(&d);
                        self.drkf = Some(d);
                        self.time_s = at;
                        self.last_position_s = Some(at);
                        self.counts.used += 1;
                    }
                    Err(_) => self.counts.out_of_range += 1,
                }
            } else {
                self.counts.used += 1;
            }
            return;
        };
        if fix.gps_position_m.is_none() && self.last_position_s.is_some_and(|t| at - t > FIX_GAP_S)
        {
            // The fixes have stopped: own ship goes straight on at the last fix's course and
            // speed (own_ship_at), and a heading or log still coming does not steer the
            // filter. On gpsd-bundg_zeus_9 (log 6.6 kn, 5.7 kn over ground) they drained its
            // speed 5.3 → 1.9 kn in 80 s: while the fixes came, its velocity through the
            // water had gone into the current, the log's reading into the log's error state,
            // and below 0.2 m/s through the water neither row applies. The heading is shown.
            self.counts.used += 1;
            return;
        }
        let dt = at - self.time_s;
        if dt > 0.0 {
            if drkf.predict(dt).is_err() {
                self.counts.stale += 1;
                return;
            }
            self.time_s = at;
        }
        match drkf.update(fix) {
            Ok(_) => {
                self.motion_measured |= velocity_known(drkf);
                self.counts.used += 1;
                if fix.gps_position_m.is_some() {
                    self.last_position_s = Some(at);
                }
            }
            Err(_) => self.counts.out_of_range += 1,
        }
    }

    /// Own ship at `time_s` (s since 1970) before its first position (or after the filter
    /// started again) with a heading sensor heard: unknown, at the origin, stopped, with
    /// the heading while it comes (a moored ship's gyro without a GNSS: a head-up radar's
    /// plots are placed with it, and `--fixed-position` shows it); `None` with no heading
    /// heard.
    fn heading_only_at(&self, time_s: f64) -> Option<OwnShip> {
        let age = time_s - self.last_heading_s?;
        if age < -AHEAD_OF_TIME_S {
            return None;
        }
        let mut own = OwnShip::unknown();
        own.heading_rad = self
            .heading_deg
            .filter(|_| age <= HEADING_LOST_S)
            .map(|h| h.to_radians() as f32);
        own.quality.heading_lost = age > HEADING_LOST_S;
        Some(own)
    }

    /// [`OwnShipNav::own_ship_at`], else, before a first position, own ship unknown with the
    /// heading a heading sensor gives; `None` with neither.
    pub fn own_ship_or_heading_at(&self, time_s: f64) -> Option<OwnShip> {
        self.own_ship_at(time_s)
            .or_else(|| self.heading_only_at(time_s))
    }

    /// Own ship at `time_s` (s since 1970), predicted from the last sentence, with what is
    /// known of its quality; `None` before the first position.
    pub fn own_ship_at(&self, time_s: f64) -> Option<OwnShip> {
        let d = self.drkf.as_ref()?;
        let dt = time_s - self.time_s;
        let since_fix = self.last_position_s.map_or(f64::INFINITY, |t| time_s - t);
        // A filter whose fixes are of a later time knows nothing of this one.
        if since_fix < -AHEAD_OF_TIME_S {
            return None;
        }
        // Past the last sentence own ship goes straight on at its velocity over ground then,
        // as a navigator dead-reckons with no sensor: the filter's own prediction would fly
        // on its acceleration (a/β more speed: gpsd-rst39's turning vehicle, last seen at
        // 10.1 kn on 080°, was dead-reckoned at 16.8 kn on 107° 26 s later) and let the
        // current decay (then 15.0 kn on 112°). Bounded: past the limit the position is held.
        let v = d.velocity_over_ground_mps();
        // Dead reckoning ends MAX_DEAD_RECKONING_S after the last fix, not after the last
        // sentence (a heading may outlive the fix); NaN and the past go nowhere.
        let reckoned = self
            .last_position_s
            .map_or(0.0, |t| (self.time_s - t).max(0.0));
        let ahead = if dt > 0.0 {
            dt.min(MAX_DEAD_RECKONING_S - reckoned).max(0.0)
        } else {
            0.0
        };
        let p = d.position_m();
        let p = [p[0] + v[0] * ahead, p[1] + v[1] * ahead];
        if !(p.iter().chain(v.iter()).all(|x| x.is_finite())) {
            return None;
        }
        let heading_age = self
            .last_heading_s
            .map(|t| time_s - t)
            .filter(|a| *a >= -AHEAD_OF_TIME_S);
        Some(OwnShip {
            position_m: [p[0] as f32, p[1] as f32],
            velocity_mps: [v[0] as f32, v[1] as f32],
            heading_rad: self
                .heading_deg
                .filter(|_| heading_age.is_some_and(|a| a <= HEADING_LOST_S))
                .map(|h| h.to_radians() as f32),
            quality: OwnShipQuality {
                dead_reckoning_s: (since_fix > POSITION_LOST_S).then_some(since_fix as f32),
                motion_known: since_fix <= MAX_DEAD_RECKONING_S && self.motion_measured,
                heading_lost: heading_age.is_some_and(|a| a > HEADING_LOST_S),
                no_fix_yet: false,
                implausible_fix: self
                    .last_implausible_s
                    .is_some_and(|t| (0.0..=IMPLAUSIBLE_ALARM_S).contains(&(time_s - t))),
                heading_needed: false,
                heading_from_radar: false,
                fixed_position: false,
                heading_given: false,
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::bridge::own_ship_sentences;
    use crate::nmea::{sentence, ttm};

    /// 2026-01-01 00:00 UTC, s since 1970, and its day.
    const T0: f64 = 1_767_225_600.0;
    const DAY0: i64 = 20_454;

    #[test]
    fn own_ship_sentences_drive_the_dead_reckoning_filter() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin, DAY0, None);
        let v = [0.0, 6.0];
        for k in 0..60 {
            let t = T0 + 10.0 * 3600.0 + f64::from(k);
            for s in own_ship_sentences([0.0, 6.0 * f64::from(k)], v, &origin, t) {
                // Every one of ours passes the independent parser.
                assert!(nmea::parse_str(s.trim()).is_ok(), "{s}");
                nav.feed(&s);
            }
        }
        assert_eq!(nav.counts().used, 300, "{}", nav.counts());
        assert_eq!(nav.counts().rejected(), 0);
        let own = nav.own_ship_at(T0 + 10.0 * 3600.0 + 60.0).unwrap();
        assert!((own.position_m[1] - 360.0).abs() < 2.0, "{own:?}");
        assert!((own.velocity_mps[1] - 6.0).abs() < 0.05 && own.velocity_mps[0].abs() < 0.05);
        assert_eq!(own.quality, OwnShipQuality::default());
        assert!(own.heading_rad.is_some_and(|h| h.abs() < 1e-3));
        // The feed stops: dead reckoning is announced, then the motion is unknown.
        let later = nav.own_ship_at(T0 + 10.0 * 3600.0 + 80.0).unwrap();
        assert!(later.quality.dead_reckoning_s.is_some_and(|a| a > 20.0));
        assert!(later.quality.heading_lost && later.heading_rad.is_none());
        assert!(later.quality.motion_known);
        let gone = nav.own_ship_at(T0 + 10.0 * 3600.0 + 3600.0).unwrap();
        assert!(!gone.quality.motion_known);
        // Held, not flown on for an hour.
        assert!(gone.position_m[1] < 360.0 + 6.0 * MAX_DEAD_RECKONING_S as f32 + 50.0);
    }

    /// Own ship turning at 1.5°/s at 6 m/s (0.16 m/s² towards the centre) for 90 s, every
    /// sentence fed; then until `until_s` after the start only those `keep` keeps (at the
    /// last course and speed: the turn has ended), heard live. The navigator and the start.
    fn turning_ship_whose_fixes_stop(
        keep: impl Fn(&str) -> bool,
        until_s: u32,
    ) -> (OwnShipNav, f64) {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin, DAY0, None);
        let (speed, rate) = (6.0, 1.5f64.to_radians());
        let radius = speed / rate;
        let start = T0 + 10.0 * 3600.0;
        for k in 0..=until_s {
            let a = rate * f64::from(k.min(89));
            let p = [radius * (1.0 - a.cos()), radius * a.sin()];
            let v = [speed * a.sin(), speed * a.cos()];
            let t = start + f64::from(k);
            for s in own_ship_sentences(p, v, &origin, t) {
                if k < 90 {
                    nav.feed(&s);
                } else if keep(&s) {
                    // Untimed (HDT, VHW): heard live, at their time.
                    nav.feed_heard(&s, t);
                }
            }
        }
        (nav, start)
    }

    #[test]
    fn a_heading_or_log_still_coming_does_not_steer_dead_reckoning() {
        // Straight on at the last fix's course and speed, as with nothing coming (before,
        // the filter took them: a log alone carried a turn 7.6° further round in 2 minutes,
        // and on a real recording they drained the speed, FIX_GAP_S); held past the limit.
        for (what, keep) in [
            ("heading", (|s: &str| s.contains("HDT")) as fn(&str) -> bool),
            ("log", |s: &str| s.contains("VHW")),
        ] {
            let at = |k: u32| {
                let (nav, start) = turning_ship_whose_fixes_stop(keep, k);
                nav.own_ship_at(start + f64::from(k)).unwrap()
            };
            // From FIX_GAP_S after the last fix (k = 89) on.
            let (last, dr) = (at(92), at(92 + 120));
            assert!(dr.quality.dead_reckoning_s.is_some(), "{what}: {dr:?}");
            assert_eq!(dr.velocity_mps, last.velocity_mps, "{what}");
            for i in 0..2 {
                let want = last.position_m[i] + last.velocity_mps[i] * 120.0;
                assert!((dr.position_m[i] - want).abs() < 0.5, "{what}: {dr:?}");
            }
            let limit = 89 + MAX_DEAD_RECKONING_S as u32;
            let (held, later) = (at(limit + 10), at(limit + 100));
            assert!(!held.quality.motion_known, "{what}: {held:?}");
            assert_eq!(held.position_m, later.position_m, "{what}");
        }
    }

    #[test]
    fn dead_reckoning_goes_straight_on_at_the_last_velocity_over_ground() {
        // Turning at 1.5°/s at 6 m/s (0.16 m/s² towards the centre) when the feed stops:
        // dead reckoning keeps the course and speed of the last fix, it does not fly on
        // the filter's acceleration (which made 11° more course and 0.2 m/s more speed of
        // them within 30 s here).
        let (nav, start) = turning_ship_whose_fixes_stop(|_| false, 89);
        let last = nav.own_ship_at(start + 89.0).unwrap();
        let course = |v: [f32; 2]| f64::from(v[0].atan2(v[1])).to_degrees();
        assert!((course(last.velocity_mps) - 133.5).abs() < 2.0, "{last:?}");
        for ahead in [30.0, 120.0, 290.0] {
            let dr = nav.own_ship_at(start + 89.0 + ahead).unwrap();
            assert!(dr.quality.motion_known && dr.quality.dead_reckoning_s.is_some());
            assert_eq!(dr.velocity_mps, last.velocity_mps, "{ahead} s: {dr:?}");
            for i in 0..2 {
                let want = last.position_m[i] + last.velocity_mps[i] * ahead as f32;
                assert!((dr.position_m[i] - want).abs() < 0.5, "{ahead} s: {dr:?}");
            }
        }
    }

    #[test]
    fn a_heading_off_the_course_made_good_does_not_turn_the_course_over_ground() {
        // Making good 045° at 5 m/s while heading 065° (set by a current, or leeway): the
        // course and speed over ground are the GNSS's, at and between the fixes; the heading
        // is the heading.
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin, DAY0, None);
        let v = [
            5.0 * 45f64.to_radians().sin(),
            5.0 * 45f64.to_radians().cos(),
        ];
        let start = T0 + 10.0 * 3600.0;
        for k in 0..120 {
            let t = start + f64::from(k);
            let p = [v[0] * f64::from(k), v[1] * f64::from(k)];
            for s in own_ship_sentences(p, v, &origin, t) {
                if !s.starts_with("$HEHDT") && !s.starts_with("$VWVHW") {
                    nav.feed(&s);
                }
            }
            nav.feed(&sentence("HEHDT,065.0,T"));
            if k < 20 {
                continue;
            }
            for after in [0.0, 0.5, 0.9] {
                let own = nav.own_ship_at(t + after).unwrap();
                let [e, n] = own.velocity_mps;
                let cog = f64::from(e).atan2(f64::from(n)).to_degrees();
                let sog = f64::from(e.hypot(n));
                assert!((cog - 45.0).abs() < 0.5, "{k} s + {after}: COG {cog:.2}°");
                assert!(
                    (sog - 5.0).abs() < 0.05,
                    "{k} s + {after}: SOG {sog:.3} m/s"
                );
                let hdg = own.heading_rad.unwrap().to_degrees();
                assert!((hdg - 65.0).abs() < 1e-3, "{hdg}");
            }
        }
    }

    /// A gyro without a GNSS (a ship moored, `--fixed-position`): no own ship from a fix,
    /// but its heading while it comes, then the heading lost.
    #[test]
    fn a_heading_without_a_fix_is_own_ships_heading() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        assert!(nav.own_ship_or_heading_at(T0).is_none(), "nothing heard");
        nav.feed_heard(&sentence("HEHDT,123.4,T"), T0);
        assert!(nav.own_ship_at(T0 + 1.0).is_none());
        let own = nav.own_ship_or_heading_at(T0 + 1.0).unwrap();
        assert!(
            own.quality.no_fix_yet && !own.quality.heading_lost,
            "{own:?}"
        );
        let hdg = own.heading_rad.unwrap().to_degrees();
        assert!((hdg - 123.4).abs() < 1e-3, "{hdg}");
        let later = nav
            .own_ship_or_heading_at(T0 + 1.0 + HEADING_LOST_S)
            .unwrap();
        assert!(
            later.heading_rad.is_none() && later.quality.heading_lost,
            "{later:?}"
        );
    }

    #[test]
    fn untimed_sentences_are_taken_when_heard_and_motion_waits_for_a_velocity() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        // A GLL without a time (as a capture's multiplexer sent it), heard at T0 + 100 s:
        // fresh then, not as old as 1970.
        nav.feed_heard(&sentence("GPGLL,5040.0000,N,00100.0000,W,,A,D"), T0 + 100.0);
        let own = nav.own_ship_at(T0 + 101.0).unwrap();
        assert_eq!(own.quality.dead_reckoning_s, None, "{own:?}");
        // A position alone says nothing of the motion: not a ship stopped.
        assert!(!own.quality.motion_known, "{own:?}");
        nav.feed_heard(&sentence("GPVTG,090.0,T,,M,5.0,N,9.3,K,A"), T0 + 101.0);
        let own = nav.own_ship_at(T0 + 101.5).unwrap();
        assert!(own.quality.motion_known, "{own:?}");
        assert!((own.velocity_mps[0] - 2.572).abs() < 0.1, "{own:?}");
        // The same GLL fed as a recording's line (no arrival time, no timed sentence
        // before it) is taken at the start of the provisional day, not in 1970.
        let mut replay = OwnShipNav::new(Origin::default(), DAY0, None);
        replay.feed(&sentence("GPGLL,5040.0000,N,00100.0000,W,,A,D"));
        assert!(replay
            .own_ship_at(T0)
            .is_some_and(|o| o.quality.dead_reckoning_s.is_none()));
        assert!(replay
            .own_ship_at(T0 + 600.0)
            .is_some_and(|o| o.quality.dead_reckoning_s.is_some()));
    }

    #[test]
    fn a_bridge_clock_far_from_the_arrival_times_restarts_the_filter_on_it() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        nav.feed_heard(
            &sentence("GPGLL,5040.0000,N,00100.0000,W,,A,D"),
            T0 + 17.0 * 3600.0,
        );
        // Then timed sentences 5 hours earlier (a PC clock not set): the filter follows them
        // (the caller hears the rest on the bridge's time once it has one).
        let t = T0 + 12.0 * 3600.0;
        for k in 0..5 {
            let at = t + f64::from(k);
            for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &Origin::default(), at) {
                nav.feed_heard(&l, at);
            }
        }
        assert!(
            nav.events()
                .iter()
                .any(|e| e.contains("restarted") && e.contains("5 h 0 min behind")),
            "{:?}",
            nav.events()
        );
        let own = nav.own_ship_at(t + 5.0).unwrap();
        assert_eq!(own.quality.dead_reckoning_s, None, "{own:?}");
        assert!((own.velocity_mps[1] - 3.0).abs() < 0.1, "{own:?}");
    }

    /// A heading timed after the time own ship is asked for is not of that time: own ship
    /// at its fix, without it; a fix timed after it gives no own ship at all.
    #[test]
    fn a_reading_timed_after_the_time_asked_for_gives_nothing() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        let t = T0 + 10.0 * 3600.0;
        for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &Origin::default(), t) {
            nav.feed(&l);
        }
        assert!(nav.own_ship_at(t + 1.0).unwrap().heading_rad.is_some());
        let hdt = crate::nmea::sentence::sentence("HEHDT,232.5,T");
        nav.feed_heard(&hdt, t + 100.0);
        let own = nav.own_ship_at(t + 1.0).unwrap();
        assert!(
            own.heading_rad.is_none() && !own.quality.heading_lost,
            "{own:?}"
        );
        assert!(own.quality.dead_reckoning_s.is_none(), "{own:?}");
        assert!(nav.own_ship_at(t + 100.0).unwrap().heading_rad.is_some());
        assert!(
            nav.own_ship_at(t - 60.0).is_none(),
            "its fix is a minute later"
        );
    }

    /// Own ship's `AIVDO` heard before any timed sentence starts the filter on its arrival
    /// time, as an untimed line does: a bridge clock hours from it restarts the filter.
    #[test]
    fn an_aivdo_before_the_bridge_clock_is_restarted_like_a_heard_line() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        let vdo = crate::ais::AisReport {
            own_ship: true,
            position_deg: Some((50.67, -1.0)),
            sog_kn: Some(6.0),
            cog_deg: Some(0.0),
            ..crate::ais::AisReport::default()
        };
        nav.feed_ais_own(&vdo, T0 + 17.0 * 3600.0);
        let t = T0 + 12.0 * 3600.0;
        for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &Origin::default(), t) {
            nav.feed_heard(&l, t);
        }
        assert!(
            nav.events().iter().any(|e| e.contains("restarted")),
            "{:?}",
            nav.events()
        );
        assert_eq!(
            nav.own_ship_at(t + 1.0).unwrap().quality.dead_reckoning_s,
            None
        );
    }

    /// A heading heard before any position (a gyro talks before the GNSS has a fix) starts
    /// no filter; a bridge clock that then agrees with its arrival (within a scan's
    /// lateness) restarts nothing. It was compared with the unset filter's time, 1970: a
    /// live feed with correct times announced its UTC 57 years ahead and started again.
    #[test]
    fn the_first_date_heard_replaces_this_computers() {
        // This computer's clock 12 h fast across midnight: its date, taken for the GGA that
        // comes before each RMC, is a day after the bridge's. Every RMC was refused as
        // stale; the first one's date now restarts the filter on the bridge's time.
        let mut nav = OwnShipNav::new(Origin::default(), DAY0 + 1, None);
        let t = T0 + 23.0 * 3600.0;
        for k in 0..10 {
            let at = t + f64::from(k);
            for l in own_ship_sentences(
                [0.0, 5.0 * f64::from(k)],
                [0.0, 5.0],
                &Origin::default(),
                at,
            ) {
                nav.feed(&l);
            }
        }
        assert_eq!(nav.counts().stale, 0, "{}", nav.counts());
        assert!(
            nav.events().iter().any(|e| e.contains("first date")),
            "{:?}",
            nav.events()
        );
        let own = nav.own_ship_at(t + 9.0).expect("own ship");
        assert!((own.position_m[1] - 45.0).abs() < 5.0, "{own:?}");
        assert!((own.velocity_mps[1] - 5.0).abs() < 0.5, "{own:?}");
    }

    #[test]
    fn a_heading_before_the_first_fix_restarts_nothing() {
        let mut nav = OwnShipNav::new(Origin::default(), DAY0, None);
        let t = T0 + 12.0 * 3600.0;
        nav.feed_heard(&sentence("HCHDG,101.0,,,1.0,W"), t);
        // Read at the next scan, 2.5 s after it came: its arrival time is late, not the
        // bridge's clock wrong.
        for k in 0..5 {
            let at = t - 2.0 + f64::from(k);
            for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &Origin::default(), at) {
                nav.feed_heard(&l, at + 2.5);
            }
        }
        assert!(
            !nav.events().iter().any(|e| e.contains("restarted")),
            "{:?}",
            nav.events()
        );
        assert_eq!(nav.counts().rejected(), 0, "{}", nav.counts());
        assert!(nav.own_ship_at(t + 3.0).is_some());
    }

    #[test]
    fn bad_sentences_are_rejected_and_counted() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin, DAY0, None);
        let good = own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, T0 + 100.0);
        nav.feed(&good[0]);
        let before = nav.own_ship_at(T0 + 100.0);
        // Checksum off by one.
        let mut bad = good[0].trim().to_string();
        let last = bad.pop().unwrap();
        bad.push(if last == '0' { '1' } else { '0' });
        nav.feed(&bad);
        // A void RMC and a GGA without fix.
        nav.feed(&sentence("GPRMC,000150.00,V,,,,,,,010126,,,N"));
        nav.feed(&sentence("GPGGA,000150.00,,,,,0,00,99.9,,M,,M,,"));
        // Older than what was used.
        nav.feed(&own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, T0 + 50.0)[0]);
        // Garbage with a good checksum, no sentence at all, one own ship does not need, a
        // comment.
        nav.feed(&sentence("GPGGA,garbage"));
        nav.feed("not nmea at all");
        nav.feed(&ttm(
            &crate::nmea::targets::PlotterTarget {
                name: None,
                number: 7,
                status: 'T',
                data: crate::session::target::example(),
            },
            100.0,
        ));
        nav.feed("# recorded on a Tuesday");
        // A magnetic heading with no variation known.
        nav.feed(&sentence("HCHDM,120.0,M"));
        // 1,000 kn over the ground.
        nav.feed(&sentence("GPVTG,010.0,T,,M,1000.0,N,1852.0,K,A"));
        let c = nav.counts();
        assert_eq!(c.used, 1);
        assert_eq!(c.bad_checksum, 1, "{c}");
        assert_eq!(c.void, 2, "{c}");
        assert_eq!(c.stale, 1, "{c}");
        assert_eq!(c.malformed, 2, "{c}");
        assert_eq!(c.ignored, 1, "{c}");
        assert_eq!(c.ignored_by_type.get("TTM"), Some(&1));
        // The summary names what was ignored.
        assert!(
            c.to_string()
                .contains("1 ignored (TTM 1; 0 of another talker)"),
            "{c}"
        );
        assert_eq!((c.annotations, c.no_variation), (1, 1), "{c}");
        assert_eq!(c.out_of_range, 1, "{c}");
        assert_eq!(nav.own_ship_at(T0 + 100.0), before);
        // With a variation the magnetic heading is used.
        nav.feed(&sentence("HCHDG,120.0,,,2.5,W"));
        assert_eq!(nav.counts().used, 2);
        assert_eq!(nav.counts().blank(), 0);
    }

    #[test]
    fn implausible_fixes_are_refused_and_a_real_jump_is_believed() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin, DAY0, None);
        let v = [0.0, 5.0];
        let feed = |nav: &mut OwnShipNav, k: f64, p: [f64; 2]| {
            for s in own_ship_sentences(p, v, &origin, T0 + k) {
                nav.feed(&s);
            }
        };
        for k in 0..60 {
            let k = f64::from(k);
            feed(&mut nav, k, [0.0, 5.0 * k]);
        }
        let before = nav.own_ship_at(T0 + 60.0).unwrap();
        // A fix 100 NM away, then one at 89°59'S: refused, alarmed; own ship goes on.
        feed(&mut nav, 60.0, [0.0, 185_200.0]);
        let far_south = origin.to_local(-89.99, -1.0);
        feed(&mut nav, 61.0, far_south);
        let own = nav.own_ship_at(T0 + 61.0).unwrap();
        assert!(own.quality.implausible_fix);
        assert!(
            (own.position_m[1] - before.position_m[1] - 5.0).abs() < 5.0,
            "{own:?}"
        );
        // Each set has two fixes (GGA, RMC).
        assert_eq!(nav.counts().implausible, 4, "{}", nav.counts());
        for k in 62..70 {
            let k = f64::from(k);
            feed(&mut nav, k, [0.0, 5.0 * k]);
        }
        assert!(!nav.own_ship_at(T0 + 100.0).unwrap().quality.implausible_fix);
        // The receiver restarts with the ship 30 km east (a wrong first fix corrected, say):
        // five consistent fixes there are believed.
        for k in 70..80 {
            let k = f64::from(k);
            feed(&mut nav, k, [30_000.0, 5.0 * k]);
        }
        let own = nav.own_ship_at(T0 + 80.0).unwrap();
        assert!(
            (f64::from(own.position_m[0]) - 30_000.0).abs() < 50.0,
            "{own:?}"
        );
        assert!(
            nav.events().iter().any(|e| e.contains("jumped")),
            "{:?}",
            nav.events()
        );
        assert_eq!(
            nav.counts().implausible,
            4 + CONSISTENT_FIXES_TO_JUMP as u64 - 1
        );
    }

    #[test]
    fn the_kinds_ignored_most_are_named_in_the_summary() {
        let mut c = NavCounts::default();
        for (kind, n) in [
            ("GSV", 3),
            ("MWV", 5),
            ("XDR", 1),
            ("DBT", 2),
            ("MTW", 2),
            ("P", 4),
        ] {
            for _ in 0..n {
                c.ignore(kind);
            }
        }
        assert_eq!(c.most_ignored(), "MWV 5, P 4, GSV 3, DBT 2, 2 more kinds; ");
        assert_eq!(NavCounts::default().most_ignored(), "");
    }
}
