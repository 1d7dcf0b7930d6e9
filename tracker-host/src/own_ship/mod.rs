//! Own ship: where we are and how we move, which every range, bearing, CPA and TCPA is
//! measured from, and how far that can be trusted.
//!
//! An [`OwnShipSource`] gives own ship at each scan:
//!
//! | source | what |
//! |---|---|
//! | [`FromPlotSource`] | what the plot source knows: the simulator's truth, a plots file's own-ship columns |
//! | [`NmeaOwnShip`] | NMEA 0183 from the bridge (a recording, UDP, TCP, serial) through the dead-reckoning filter ([`nav`]) |
//! | [`SimulatedBridge`] | the plot source's own ship sent through the same sentences and filter, and recorded |
//! | [`fixed::FixedPosition`] | another source's own ship, placed at the origin and stopped while it has no fix (a shore radar, a ship moored without GNSS) |
//!
//! [`sentences`] says what each sentence means, [`clock`] keeps the bridge's UTC, [`select`]
//! chooses one talker per quantity, [`recording`] reads a whole recording ahead (its start,
//! its fixes).

pub mod clock;
pub mod first_fix;
pub mod fixed;
pub mod nav;
pub mod recording;
pub mod select;
pub mod sentences;

use std::io::Write as _;

use anyhow::Context;
use tracker_core::geo::{self, EastNorth};

use crate::nmea::bridge::own_ship_sentences;
use crate::nmea::{InSpec, NmeaIn};
use crate::origin::Origin;
use crate::source::SourceScan;
use nav::{NavCounts, OwnShipNav};
use select::Selector;

/// Own ship this far from the local frame's origin raises an alarm, m: the frame is flat
/// (its east metres are the origin's latitude's), and the device refuses plots beyond
/// [`tracker_core::filter::MAX_POSITION_M`] (10,000 km), so every scan would be skipped. The
/// origin is own ship's first fix, or `--origin`, or (a live source without either) the
/// default's, which may be across the world.
pub const FAR_FROM_ORIGIN_M: f32 = 1.0e6;

/// How far own ship can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OwnShipQuality {
    /// Seconds since the last position fix, once that is longer than
    /// [`nav::POSITION_LOST_S`]: own ship is dead reckoned. `None`: measured.
    pub dead_reckoning_s: Option<f32>,
    /// Own ship's motion over ground is known (measured, or dead reckoned within
    /// [`nav::MAX_DEAD_RECKONING_S`]). Without it targets' true course and speed are not.
    pub motion_known: bool,
    /// A heading was received and has stopped.
    pub heading_lost: bool,
    /// No position yet: own ship is taken at the origin, stopped.
    pub no_fix_yet: bool,
    /// A position fix was refused as implausible lately (far from where own ship can be).
    pub implausible_fix: bool,
    /// A head-up radar's plots were dropped this scan for want of a heading: none from
    /// NMEA, none in the spokes, no fixed heading given.
    pub heading_needed: bool,
    /// Own ship's heading sensor (NMEA) was lost and the radar's (in its spokes, or the
    /// heading sentences of its capture) stands in: the heading has changed source, which
    /// the navigator is told.
    pub heading_from_radar: bool,
    /// Own ship stands at a position given, not measured (`--fixed-position`: a shore
    /// radar, a ship moored without GNSS), stopped ([`fixed`]).
    pub fixed_position: bool,
    /// The heading is one given (`--heading-deg`, turned by own ship's yaw measured from
    /// the radar picture), not a heading sensor's: shown as such (`MAN`).
    pub heading_given: bool,
}

impl Default for OwnShipQuality {
    /// Measured, motion known (the simulator's truth, a plots file).
    fn default() -> Self {
        OwnShipQuality {
            dead_reckoning_s: None,
            motion_known: true,
            heading_lost: false,
            no_fix_yet: false,
            implausible_fix: false,
            heading_needed: false,
            heading_from_radar: false,
            fixed_position: false,
            heading_given: false,
        }
    }
}

/// The speed under which own ship's course is not shown or sent, kn: a speed that shows as
/// 0.0 kn has no course.
pub const COG_FROM_KN: f64 = 0.05;

/// Own ship's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OwnShip {
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity over ground, m/s.
    pub velocity_mps: EastNorth,
    /// Heading, rad true, when a heading sensor gives it.
    pub heading_rad: Option<f32>,
    /// How far it can be trusted.
    pub quality: OwnShipQuality,
}

impl OwnShip {
    /// Measured `position_m` and `velocity_mps`, no heading.
    pub fn at(position_m: EastNorth, velocity_mps: EastNorth) -> Self {
        OwnShip {
            position_m,
            velocity_mps,
            ..OwnShip::default()
        }
    }

    /// Unknown: at the origin, stopped, no fix yet.
    pub fn unknown() -> Self {
        OwnShip {
            quality: OwnShipQuality {
                motion_known: false,
                no_fix_yet: true,
                ..OwnShipQuality::default()
            },
            ..OwnShip::default()
        }
    }

    /// Own ship without a heading of its own takes `heading_rad` (rad, true) from another sensor
    /// (`radar`: the radar's heading sensor): a lost heading's alarm gives way, told as the
    /// radar's standing in when it is.
    pub fn stand_in_heading(&mut self, heading_rad: Option<f32>, radar: bool) {
        self.heading_rad = heading_rad;
        self.quality.heading_given = false;
        self.quality.heading_from_radar =
            self.quality.heading_lost && radar && heading_rad.is_some();
        self.quality.heading_lost &= heading_rad.is_none();
    }

    /// The velocity of the frame radar tracks are formed in, m/s (east, north): own ship's
    /// velocity over ground while own ship's position moves with it; zero while it does
    /// not (no fix yet: own ship at the origin; dead reckoning ended: the position held).
    /// Plots are placed about own ship's position, so with it standing still the tracks'
    /// velocities are their motion relative to own ship already, and own ship's last
    /// velocity is not to be taken off them again: CPA, TCPA and relative motion take this.
    pub fn track_frame_velocity_mps(&self) -> EastNorth {
        if self.position_held() {
            [0.0, 0.0]
        } else {
            self.velocity_mps
        }
    }

    /// Own ship's position stands still in the local frame, not from a fix: no fix yet (at
    /// the origin), or dead reckoned past [`nav::MAX_DEAD_RECKONING_S`] (held where it
    /// stopped; within it, the position moves on at the velocity).
    pub fn position_held(&self) -> bool {
        let q = self.quality;
        q.no_fix_yet
            || q.dead_reckoning_s
                .is_some_and(|s| f64::from(s) > nav::MAX_DEAD_RECKONING_S)
    }

    /// Speed over ground, kn; `None` while the motion is unknown
    /// ([`OwnShipQuality::motion_known`]).
    pub fn sog_kn(&self) -> Option<f64> {
        let (_, speed_mps) = geo::course_speed(self.velocity_mps);
        self.quality
            .motion_known
            .then(|| f64::from(speed_mps / geo::MPS_PER_KNOT))
    }

    /// Course over ground, degrees true in [0, 360); `None` while the motion is unknown or
    /// the speed shows as 0.0 kn (under [`COG_FROM_KN`]), where a course means nothing.
    pub fn cog_deg(&self) -> Option<f64> {
        let (course_rad, _) = geo::course_speed(self.velocity_mps);
        self.sog_kn()
            .filter(|&kn| kn >= COG_FROM_KN)
            .map(|_| f64::from(course_rad).to_degrees())
    }

    /// The alarms own ship raises, as the operator reads them.
    pub fn alarms(&self) -> Vec<String> {
        let q = self.quality;
        let mut a = Vec::new();
        if q.no_fix_yet {
            a.push("OWN SHIP: no position fix yet".to_string());
        } else if let Some(age) = q.dead_reckoning_s {
            if q.motion_known {
                a.push(format!(
                    "OWN SHIP: position lost, dead reckoning for {age:.0} s"
                ));
            } else {
                // Days for a recording's fix of another voyage (it said 791660 min).
                let ago = if age >= 2.0 * 86_400.0 {
                    format!("{:.0} days", age / 86_400.0)
                } else {
                    format!("{:.0} min", age / 60.0)
                };
                a.push(format!(
                    "OWN SHIP: position lost {ago} ago, motion unknown: true vectors off"
                ));
            }
        }
        if q.heading_lost {
            a.push("OWN SHIP: heading lost".to_string());
        }
        if q.heading_from_radar {
            a.push("OWN SHIP: heading sensor lost, the radar's heading in use".to_string());
        }
        if q.implausible_fix {
            a.push("OWN SHIP: implausible position fix refused".to_string());
        }
        let from_origin_m = libm::hypotf(self.position_m[0], self.position_m[1]);
        if !q.no_fix_yet && from_origin_m > FAR_FROM_ORIGIN_M {
            a.push(format!(
                "OWN SHIP: {:.0} km from the frame's origin (the device refuses plots beyond {:.0} km): restart with --origin LAT,LON near own ship",
                from_origin_m / 1000.0,
                tracker_core::filter::MAX_POSITION_M / 1000.0
            ));
        }
        if q.heading_needed {
            a.push(
                "OWN SHIP: no heading: the head-up radar's plots are not placed (--heading-deg DEG for a ship at a fixed heading, or a heading sensor on --nmea-in)"
                    .to_string(),
            );
        }
        a
    }
}

/// A source of own ship, asked once a scan.
pub trait OwnShipSource {
    /// Own ship at the time of `scan`.
    ///
    /// # Errors
    /// The source cannot give own ship at all (a plot source without own-ship data and no
    /// other source), or writing its recording failed.
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip>;

    /// What became of the sentences, for sources that read NMEA.
    fn nmea_counts(&self) -> Option<NavCounts> {
        None
    }

    /// The run has ended: a recording counts the lines it did not reach.
    fn finish(&mut self) {}

    /// What happened worth telling (a change of source, a disagreement, a reconnection).
    fn events(&self) -> Vec<String> {
        Vec::new()
    }

    /// The AIS reports among the sentences read since the last call, each with its time
    /// (s, the session's clock).
    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        Vec::new()
    }

    /// Own ship was found, at the last call of [`OwnShipSource::own_ship`], to be far
    /// from where it had been taken to be (a fixed position's first fix, [`fixed`]): every
    /// track, placed about the old position, is wrong and is to be cancelled. Once.
    fn take_moved(&mut self) -> bool {
        false
    }

    /// The bridge's UTC less the scans' clock, s: added to a scan's time for the UTC shown
    /// and sent to plotters, so that they carry the time own ship is on. Non-zero only
    /// for a live NMEA source whose UTC is more than [`CLOCK_APPLIED_S`] from this
    /// computer's clock (a PC on board without a time server); 0 otherwise.
    fn utc_offset_s(&self) -> f64 {
        0.0
    }

    /// What became of the AIS sentences, for sources that read NMEA.
    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        None
    }
}

/// Own ship as the plot source knows it.
#[derive(Clone, Copy, Debug, Default)]
pub struct FromPlotSource;

impl OwnShipSource for FromPlotSource {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        scan.own_ship.with_context(|| {
            format!(
                "scan {}: the plot source gives no own ship (take it from NMEA with --nmea-in)",
                scan.radar.scan
            )
        })
    }
}

/// How own-ship NMEA is read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NmeaOptions {
    /// Talker priority per quantity (the first delivering one is used).
    pub priority: std::collections::BTreeMap<sentences::Quantity, Vec<String>>,
    /// The operator's magnetic variation, degrees east, for magnetic headings that come
    /// with none.
    pub variation_deg: Option<f64>,
    /// Times before the first dated sentence count from this day (days since 1970).
    pub provisional_day: i64,
    /// A recording's track, its first and last fix (s since 1970), when it was read ahead
    /// ([`recording::RecordedTrack`]): a dated sentence more than
    /// [`recording::MAX_FIX_GAP_S`] outside it is refused as a time jump (a stray sentence
    /// of another date would set the clock's date and put every later fix years off).
    pub recording_window_s: Option<(f64, f64)>,
}

/// A timed sentence this far ahead of the clock, whose next timed neighbour is back before
/// it, is out of sequence (one corrupt time with a valid checksum), s.
const OUT_OF_SEQUENCE_S: f64 = 60.0;

/// A recording's AIS is taken only when the recording heard it within this of the scan it
/// is read at, s (by the recording's own times): dead reckoning's reach, past which own
/// ship's position from the same recording is lost too.
const RECORDED_AIS_WINDOW_S: f64 = nav::MAX_DEAD_RECKONING_S;

/// Lines looked ahead for a recording's first time (the time of its AIS before it), at
/// most: a receiver's cold start of a minute at 50 AIS lines a second, and more.
const FIRST_TIME_LOOK_AHEAD_LINES: usize = 8192;

/// The time of the first timed sentence among the next [`FIRST_TIME_LOOK_AHEAD_LINES`]
/// lines of `file` (one its next timed neighbour is back before skipped), s; `None` when
/// there is none within them. The lines looked at stay
/// buffered in `file` until read (about 80 bytes each).
fn first_time_ahead(file: &mut crate::nmea::input::FileLines, nav: &OwnShipNav) -> Option<f64> {
    let mut times = (0..FIRST_TIME_LOOK_AHEAD_LINES)
        .map_while(|i| file.peek(i).map(|l| nav.time_in_window_of(l)))
        .flatten()
        .peekable();
    // A time the next timed sentence is back before by over a second is out of sequence
    // (a corrupt time with a valid checksum, as the replay refuses it), not the first; by
    // half a day or more it is midnight (undated times read on one day, 23:59:59 then
    // 00:00:00).
    while let Some(t) = times.next() {
        let back_s = times.peek().map_or(0.0, |next| t - *next);
        if !(1.0..clock::DAY_S / 2.0).contains(&back_s) {
            return Some(t);
        }
    }
    None
}

/// A recording's lines counted past the run's last scan, at most (a count this large reads
/// "at least").
pub const MAX_UNREAD_COUNTED: u64 = 1_000_000;

/// Timed sentences looked at past an outlying one.
const LOOK_AHEAD_LINES: usize = 64;

/// Own ship from NMEA 0183 through the dead-reckoning filter. A recording is replayed in
/// step with the scans by its sentences' UTC; a live source gives what has arrived.
pub struct NmeaOwnShip {
    input: NmeaIn,
    /// Further live sources, read with `input` (which is live then).
    more: Vec<crate::nmea::input::LiveLines>,
    nav: OwnShipNav,
    ais: crate::ais::AisDecoder,
    heard: Vec<(f64, crate::ais::AisReport)>,
    /// A live source's UTC less the session's time (this computer's clock), s, from the
    /// newest timed sentence (late by up to a scan: the lines of a scan are read together).
    offset_s: Option<f64>,
    /// The session's time of the last read that brought a new timed sentence.
    timed_read_s: Option<f64>,
    /// The offset last told of, when it was more than [`CLOCK_NOTE_S`].
    offset_told_s: Option<f64>,
    /// The session's time the first timed sentence was read.
    first_timed_read_s: Option<f64>,
    /// A recording read to its end without a timed sentence has been told of.
    untimed_told: bool,
    /// Whether the recording was told not to cover the scans' time.
    apart_told: bool,
    /// Whether the recording was told to have ended before the run.
    ended_told: bool,
    /// A recording's AIS sentences not taken: heard, by the recording's own times, more
    /// than [`RECORDED_AIS_WINDOW_S`] from the scan they were read at.
    ais_stale: u64,
    /// A recording's first time, s, once looked for ([`first_time_ahead`]): the time of its
    /// AIS before any timed sentence.
    first_time_s: Option<Option<f64>>,
    clock_events: crate::event_log::EventLog,
}

/// A live source's UTC this far from this computer's clock is told of (an event), s: a
/// PC on board without a time server is often hours out; own ship follows the bridge's
/// time either way.
pub const CLOCK_NOTE_S: f64 = 30.0;

/// The offset is told once the date is heard (`RMC`, `ZDA`), or after this long, s, from a
/// source that gives none: before the date, times are on this computer's date, and an
/// offset told then (hours) would be told again, years off, a second later.
pub const DATE_WAIT_S: f64 = 10.0;

/// A live source's UTC this far from this computer's clock is followed (own ship asked for
/// on the bridge's time), s; nearer, the two are taken to agree.
pub const CLOCK_APPLIED_S: f64 = 5.0;

impl NmeaOwnShip {
    /// Opens the source.
    ///
    /// # Errors
    /// The file, socket or port does not open.
    pub fn open(spec: &InSpec, origin: Origin, o: &NmeaOptions) -> anyhow::Result<Self> {
        Ok(Self::of(NmeaIn::open(spec)?, origin, o))
    }

    /// As [`NmeaOwnShip::open`], on a source opened already.
    pub fn of(input: NmeaIn, origin: Origin, o: &NmeaOptions) -> Self {
        let replayed = matches!(input, NmeaIn::File(_));
        NmeaOwnShip {
            input,
            more: Vec::new(),
            nav: OwnShipNav::with_selector(
                origin,
                o.provisional_day,
                o.variation_deg,
                Selector::new(o.priority.clone()),
            )
            .within(o.recording_window_s)
            .replayed(replayed),
            ais: crate::ais::AisDecoder::new(),
            heard: Vec::new(),
            offset_s: None,
            timed_read_s: None,
            offset_told_s: None,
            first_timed_read_s: None,
            untimed_told: false,
            apart_told: false,
            ais_stale: 0,
            first_time_s: None,
            ended_told: false,
            clock_events: crate::event_log::EventLog::default(),
        }
    }

    /// Adds further live sources whose lines are taken with the first's (a bridge that
    /// sends its GNSS and gyro on one port and its AIS transponder on another).
    ///
    /// # Errors
    /// One of `more` is a recording, or the first source is (a recording is replayed on its
    /// own times, live lines on their arrival: the two do not mix); a socket or port does
    /// not open.
    pub fn with_more(mut self, more: &[InSpec]) -> anyhow::Result<Self> {
        if more.is_empty() {
            return Ok(self);
        }
        if matches!(self.input, NmeaIn::File(_)) || more.iter().any(|m| !m.is_live()) {
            anyhow::bail!(
                "--nmea-in given more than once: every source must then be live (udp:, tcp:, serial:), not a file"
            );
        }
        for spec in more {
            if let NmeaIn::Live(live) = NmeaIn::open(spec)? {
                self.more.push(live);
            }
        }
        Ok(self)
    }

    /// The offset own ship is asked for at: the bridge's UTC less this computer's clock
    /// when they differ by more than [`CLOCK_APPLIED_S`], else none (the clocks agree: the
    /// offset measured is late by the age of the newest sentence at the read, a second or
    /// two, and would put own ship that far behind).
    fn clock_offset_s(&self) -> f64 {
        self.offset_s
            .filter(|o| o.abs() > CLOCK_APPLIED_S)
            .unwrap_or(0.0)
    }

    /// Takes a live source's lines that arrived by the session's time `time_s` (read
    /// together once a scan), learning the offset of the bridge's UTC from it on every new
    /// timed sentence. A sentence without a time is taken at the newest timed one while
    /// those come (as a recording's), and at its arrival on the bridge's time when none has
    /// come for [`nav::POSITION_LOST_S`] (a heading sensor outliving the GNSS) or ever
    /// (a multiplexer's `GLL` without times).
    fn take_live(&mut self, lines: Vec<String>, time_s: f64) {
        for line in lines {
            // On the bridge's time for the filter; AIS targets on the session's.
            let bridge_s = time_s + self.clock_offset_s();
            let timed_lately = self
                .timed_read_s
                .is_some_and(|r| time_s - r <= nav::POSITION_LOST_S);
            let newest = self.nav.newest_s();
            let untimed = (!timed_lately).then_some(bridge_s);
            take(
                &mut self.nav,
                &mut self.ais,
                &mut self.heard,
                &line,
                (time_s, bridge_s),
                untimed,
            );
            if let Some(n) = self.nav.newest_s().filter(|n| Some(*n) != newest) {
                self.offset_s = Some(n - time_s);
                self.timed_read_s = Some(time_s);
                self.first_timed_read_s.get_or_insert(time_s);
            }
        }
        let Some(offset) = self.offset_s else {
            return;
        };
        let dated = self.nav.date_known()
            || self
                .first_timed_read_s
                .is_some_and(|first| time_s - first >= DATE_WAIT_S);
        let told = self.offset_told_s.unwrap_or(0.0);
        if dated && (offset - told).abs() > CLOCK_NOTE_S {
            self.clock_events.push(format!(
                "the NMEA source's UTC is {} this computer's clock: own ship follows the NMEA's time",
                crate::utc::offset_label(offset)
            ));
            self.offset_told_s = Some(offset);
        }
    }

    /// Feeds every line of a recording due by `time_s`: untimed lines as they come, a timed
    /// one once its time has come. A timed line far ahead whose next timed neighbour is back
    /// before it is out of sequence: refused, and the replay goes on.
    fn replay_until(&mut self, time_s: f64) {
        let NmeaIn::File(file) = &mut self.input else {
            return;
        };
        while let Some(line) = file.peek(0) {
            let timed = self.nav.time_of(line);
            // Untimed lines are taken as they come; a timed one is checked first.
            if let Some(t) = timed {
                let reference = self.nav.newest_s().unwrap_or(t).min(time_s);
                if t > reference + OUT_OF_SEQUENCE_S {
                    let back = (1..LOOK_AHEAD_LINES)
                        .filter_map(|i| file.peek(i).map(|l| self.nav.time_of(l)))
                        .flatten()
                        .next()
                        .is_some_and(|next| next < t - 1.0);
                    if back {
                        file.next_line();
                        self.nav.refuse_out_of_sequence();
                        continue;
                    }
                }
                if t > time_s + 1e-6 {
                    break;
                }
            }
            if let Some(line) = file.next_line() {
                // AIS the recording heard far from this scan's time is not heard now: its
                // ships are not here (a log of another voyage read with a capture brought
                // its ships into the capture's picture). Its time is the timed sentence's
                // before it, or, before any, the recording's first time.
                if crate::ais::fragment::is_ais(&line) {
                    let sent_s = self.nav.newest_s().or_else(|| {
                        *self
                            .first_time_s
                            .get_or_insert_with(|| first_time_ahead(file, &self.nav))
                    });
                    if sent_s.is_some_and(|at| (time_s - at).abs() > RECORDED_AIS_WINDOW_S) {
                        self.ais_stale += 1;
                        continue;
                    }
                }
                // A sentence without a time before any timed one is taken at the
                // recording's first time, or, in a recording with none, at the scan's (at
                // the start of its day it made a log of GLL without times, read with its
                // capture, a position lost 566 min before the first scan; a year's
                // headings of another voyage's log were held over a capture).
                let untimed = self.nav.newest_s().is_none().then(|| {
                    self.first_time_s
                        .get_or_insert_with(|| first_time_ahead(file, &self.nav))
                        .unwrap_or(time_s)
                });
                // The transponder's own report (AIVDO) is an own-ship sensor at the time
                // the recording heard it, the newest timed sentence's, not the scan's: at
                // the scan's it stood 12 s after the GNSS's first fixes read for the same
                // scan, and the talker choice took the GNSS as silent.
                let recorded_s = self.nav.newest_s().or(untimed).unwrap_or(time_s);
                take(
                    &mut self.nav,
                    &mut self.ais,
                    &mut self.heard,
                    &line,
                    (time_s, recorded_s),
                    untimed,
                );
            }
        }
        // A recording with nothing near the scans' time (a radar capture of 2015 with a log
        // of another voyage gave own ship no fix on any scan, and said nothing): told once,
        // when its sentences before the scan (if any) are older, and those after it (if
        // any) newer, than dead reckoning reaches.
        // (A recording told ended, below, is not told apart too when the run goes on past
        // dead reckoning's reach: it is the same news.)
        if !self.apart_told && !self.ended_told {
            let next = file.peek(0).and_then(|l| self.nav.time_of(l));
            let last = self.nav.newest_s();
            let far = |at: f64| (at - time_s).abs() > nav::MAX_DEAD_RECKONING_S;
            let apart = (next.is_some() || last.is_some())
                && last.is_none_or(far)
                && (next.is_some_and(far) || file.peek(0).is_none());
            if apart {
                self.apart_told = true;
                let at = |what: &str, t: f64| {
                    format!(
                        "{what} at {} ({} it)",
                        crate::utc::date_time_label(t),
                        crate::utc::offset_label(t - time_s)
                    )
                };
                let around: Vec<String> = last
                    .map(|t| at("its last time before it", t))
                    .into_iter()
                    .chain(next.map(|t| at("its next", t)))
                    .collect();
                self.clock_events.push(format!(
                    "the recording has no time within {:.0} min of the scan at {} (told once; another voyage's log, or a gap): {}",
                    nav::MAX_DEAD_RECKONING_S / 60.0,
                    crate::utc::date_time_label(time_s),
                    around.join(", ")
                ));
            }
        }
        // Read to its end with no time in it: played at once, not on its own clock.
        let ended = file.peek(0).is_none();
        // Read to its end before the run's (a `--duration` past it): own ship is dead
        // reckoned, then lost, and the alarms alone did not say why.
        if let Some(last) = self.nav.newest_s().filter(|_| ended && !self.ended_told) {
            if time_s - last > nav::POSITION_LOST_S {
                self.ended_told = true;
                self.clock_events.push(format!(
                    "the recording ended at {}, {} the scan at {}: own ship's data end with it (dead reckoned from a last fix, then lost)",
                    crate::utc::date_time_label(last),
                    crate::utc::offset_label(last - time_s),
                    crate::utc::date_time_label(time_s),
                ));
            }
        }
        if ended && self.nav.newest_s().is_none() && !self.untimed_told {
            self.untimed_told = true;
            self.clock_events.push(
                "the recording has no usable time (no RMC, GGA, GLL or ZDA with a valid one): its sentences were taken as they came, at the first scan's time, not in step with the scans".to_string(),
            );
        }
    }
}

impl OwnShipSource for NmeaOwnShip {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let t = scan.radar.time_s;
        match &mut self.input {
            NmeaIn::File(_) => self.replay_until(t),
            NmeaIn::Live(live) => {
                let mut batches = vec![live.available()];
                batches.extend(self.more.iter_mut().map(|m| m.available()));
                let lines = interleave(&self.nav, batches);
                self.take_live(lines, t);
            }
        }
        let bridge_s = t + self.clock_offset_s();
        Ok(self
            .nav
            .own_ship_or_heading_at(bridge_s)
            .unwrap_or_else(OwnShip::unknown))
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        Some(self.nav.counts().clone())
    }

    fn utc_offset_s(&self) -> f64 {
        self.clock_offset_s()
    }

    fn finish(&mut self) {
        if let NmeaIn::File(file) = &mut self.input {
            // Bounded: an operator who quits early does not wait for a huge file.
            let mut n = 0;
            while n < MAX_UNREAD_COUNTED && file.next_line().is_some() {
                n += 1;
            }
            self.nav.note_unread(n);
        }
    }

    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        std::mem::take(&mut self.heard)
    }

    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        Some(self.ais.counts())
    }

    fn events(&self) -> Vec<String> {
        let mut e = self.nav.events();
        e.extend(self.clock_events.lines("clock"));
        if self.ais_stale > 0 {
            e.push(format!(
                "{} AIS sentences of the recording not taken: heard more than {:.0} min from the scan they were read at (another voyage's log, or a gap)",
                self.ais_stale,
                RECORDED_AIS_WINDOW_S / 60.0
            ));
        }
        let first = match &self.input {
            NmeaIn::Live(live) => Some(live),
            NmeaIn::File(_) => None,
        };
        let several = !self.more.is_empty();
        for (i, live) in first.into_iter().chain(&self.more).enumerate() {
            let which = if several {
                format!(" {}", i + 1)
            } else {
                String::new()
            };
            if live.drops > 0 {
                let times = |n: u64| {
                    if n == 1 {
                        "once".to_string()
                    } else {
                        format!("{n} times")
                    }
                };
                e.push(format!(
                    "NMEA source{which} dropped {}, reconnected {}",
                    times(live.drops),
                    times(live.reconnects)
                ));
            }
            if live.kernel_drops > 0 {
                e.push(format!(
                    "NMEA source{which}: {} datagrams lost before they were read (the socket's buffer was full)",
                    live.kernel_drops
                ));
            }
        }
        e
    }
}

/// The lines several live sources gave in one read, as one stream in time order: each
/// source's lines in their own order, cut before each timed sentence, the pieces merged by
/// their times (a piece before any timed sentence first). Taken one source after the other,
/// a second source's timed sentences older than the first's newest would be refused as
/// steps back.
fn interleave(nav: &OwnShipNav, mut batches: Vec<Vec<String>>) -> Vec<String> {
    if batches.len() <= 1 {
        return batches.pop().unwrap_or_default();
    }
    // Per source: (time, lines) pieces.
    let mut pieces: Vec<std::collections::VecDeque<(f64, Vec<String>)>> = batches
        .into_iter()
        .map(|lines| {
            let mut out: std::collections::VecDeque<(f64, Vec<String>)> = Default::default();
            for line in lines {
                match (nav.time_of(&line), out.back_mut()) {
                    (None, Some((_, piece))) => piece.push(line),
                    (None, None) => out.push_back((f64::NEG_INFINITY, vec![line])),
                    (Some(t), _) => out.push_back((t, vec![line])),
                }
            }
            out
        })
        .collect();
    let mut merged = Vec::new();
    // The source whose next piece is earliest (the first source on a tie), until all are
    // empty: each source's order is kept.
    while let Some(i) = (0..pieces.len())
        .filter_map(|i| pieces[i].front().map(|(t, _)| (i, *t)))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map(|(i, _)| i)
    {
        if let Some((_, lines)) = pieces[i].pop_front() {
            merged.extend(lines);
        }
    }
    merged
}

/// One line: AIS sentences to the AIS decoder (heard at `session_s`; own ship's `AIVDO`
/// also to the dead-reckoning filter at `bridge_s`, as one more sensor), the rest to the
/// filter: a sentence without a time at `untimed_at` (its arrival, on the bridge's time)
/// when given, else at the newest time (a recording's lines are in the order they were
/// sent).
fn take(
    nav: &mut OwnShipNav,
    ais: &mut crate::ais::AisDecoder,
    heard: &mut Vec<(f64, crate::ais::AisReport)>,
    line: &str,
    (session_s, bridge_s): (f64, f64),
    untimed_at: Option<f64>,
) {
    if crate::ais::fragment::is_ais(line) {
        if let Some(r) = ais.feed(line) {
            nav.feed_ais_own(&r, bridge_s);
            heard.push((session_s, r));
        }
    } else if let Some(at) = untimed_at {
        nav.feed_heard(line, at);
    } else {
        nav.feed(line);
    }
}

/// The plot source's own ship as the bridge's sensors would send it (`GGA`, `RMC`, `VTG`,
/// `HDT`, `VHW`), through the same parser and dead-reckoning filter as real NMEA, and
/// written to a recording that [`NmeaOwnShip`] replays with the same result.
pub struct SimulatedBridge {
    recording: std::io::BufWriter<std::fs::File>,
    origin: Origin,
    /// Made at the first scan, whose date it starts from (as a replay's would).
    nav: Option<OwnShipNav>,
}

impl SimulatedBridge {
    /// Creates the recording at `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &std::path::Path, origin: Origin) -> anyhow::Result<Self> {
        let f =
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        Ok(SimulatedBridge {
            recording: std::io::BufWriter::new(f),
            origin,
            nav: None,
        })
    }
}

impl OwnShipSource for SimulatedBridge {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let truth = FromPlotSource.own_ship(scan)?;
        let t = scan.radar.time_s;
        let origin = self.origin;
        let nav = self
            .nav
            .get_or_insert_with(|| OwnShipNav::new(origin, clock::day_of_s(t), None));
        // A source without a fix (a radar's own ship unknown, a plots file's `own_fix` 0)
        // sends no position: a GNSS fix at the origin was made up and recorded before. A
        // position given (`--fixed-position`, `own_fix` M) is not a GNSS's either: own
        // ship is the source's, stood there.
        if truth.quality.fixed_position {
            return Ok(truth);
        }
        if truth.position_held() {
            return Ok(nav.own_ship_at(t).unwrap_or_else(OwnShip::unknown));
        }
        let lines = own_ship_sentences(
            truth.position_m.map(f64::from),
            truth.velocity_mps.map(f64::from),
            &self.origin,
            t,
        );
        for l in &lines {
            self.recording
                .write_all(l.as_bytes())
                .context("writing the NMEA recording")?;
            nav.feed(l);
        }
        self.recording
            .flush()
            .context("writing the NMEA recording")?;
        Ok(nav.own_ship_at(t).unwrap_or_else(OwnShip::unknown))
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        self.nav.as_ref().map(|n| n.counts().clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scan at `time_s` (s since 1970) with no plots and no own ship of its own.
    fn scan_at(scan: u32, time_s: f64) -> SourceScan {
        SourceScan {
            radar: crate::source::RadarScan {
                scan,
                time_s,
                plots: Vec::new(),
            },
            ..SourceScan::default()
        }
    }

    /// A source without a fix gives the recording no position (it was a GNSS fix at the
    /// origin); one with a fix does.
    #[test]
    fn a_recording_of_a_source_without_a_fix_holds_no_position() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bridge.nmea");
        let mut bridge = SimulatedBridge::create(&path, Origin::default()).unwrap();
        let scan = |t: f64, own: OwnShip| SourceScan {
            own_ship: Some(own),
            ..scan_at(1, t)
        };
        let t0 = 1.5e9;
        for k in 0..3 {
            let own = bridge
                .own_ship(&scan(t0 + 2.5 * f64::from(k), OwnShip::unknown()))
                .unwrap();
            assert!(own.quality.no_fix_yet, "{own:?}");
        }
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "");
        let mut given = OwnShip::at([100.0, 0.0], [0.0, 0.0]);
        given.quality.fixed_position = true;
        let own = bridge.own_ship(&scan(t0 + 7.5, given)).unwrap();
        assert!(own.quality.fixed_position, "{own:?}");
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "");
        let own = bridge
            .own_ship(&scan(t0 + 10.0, OwnShip::at([0.0, 0.0], [0.0, 5.0])))
            .unwrap();
        assert!(!own.quality.no_fix_yet, "{own:?}");
        assert!(std::fs::read_to_string(&path).unwrap().contains("RMC,"));
    }

    #[test]
    fn own_ship_far_from_the_frames_origin_raises_an_alarm() {
        let near = OwnShip::at([300_000.0, 400_000.0], [0.0, 0.0]);
        assert!(near.alarms().is_empty(), "{:?}", near.alarms());
        let far = OwnShip::at([0.0, -16_000_000.0], [0.0, 0.0]);
        assert!(
            far.alarms()
                .iter()
                .any(|a| a.contains("16000 km from the frame's origin") && a.contains("--origin")),
            "{:?}",
            far.alarms()
        );
        // Before a fix own ship is at the origin: no alarm of this kind.
        assert!(OwnShip::unknown()
            .alarms()
            .iter()
            .all(|a| !a.contains("origin")));
    }
    use crate::nmea::bridge::own_ship_sentences;

    /// The events of `own` that contain `text`.
    fn events_with(own: &NmeaOwnShip, text: &str) -> Vec<String> {
        own.events()
            .into_iter()
            .filter(|e| e.contains(text))
            .collect()
    }

    /// Own ship from NMEA as a live source is read (`take_live`), this computer's clock at
    /// `pc_s` (its date the provisional one); the file it was opened on, kept while used.
    fn live_on(pc_s: f64) -> (tempfile::NamedTempFile, NmeaOwnShip) {
        let file = tempfile::NamedTempFile::new().unwrap();
        let spec = InSpec::File(file.path().to_path_buf());
        let options = NmeaOptions {
            provisional_day: clock::day_of_s(pc_s),
            ..NmeaOptions::default()
        };
        let own = NmeaOwnShip::open(&spec, Origin::default(), &options).unwrap();
        (file, own)
    }

    #[test]
    fn clocks_that_agree_are_taken_to_agree() {
        let origin = Origin::default();
        let t: f64 = 1_767_225_600.0 + 12.0 * 3600.0;
        let (_file, mut own) = live_on(t);
        // The newest sentence 1.5 s old when read: the same clock, not an offset.
        own.take_live(
            own_ship_sentences([0.0, 0.0], [0.0, 4.0], &origin, t),
            t + 1.5,
        );
        assert_eq!(own.offset_s, Some(-1.5));
        assert_eq!(own.clock_offset_s(), 0.0);
        assert!(own.events().iter().all(|e| !e.contains("computer's clock")));
    }

    #[test]
    fn a_clock_offset_is_told_once_on_the_date_heard_not_first_on_this_computers() {
        let origin = Origin::default();
        // This computer on 2026-01-01 12:00; the bridge 2018-01-01 at 19:00 (a recording
        // replayed live): its GGA alone, on this computer's date, is 7 h ahead; its date,
        // heard two reads later, puts it years behind.
        let pc_s: f64 = 1_767_225_600.0 + 12.0 * 3600.0;
        let bridge_s: f64 = 1_514_764_800.0 + 19.0 * 3600.0;
        let (_file, mut own) = live_on(pc_s);
        for k in 0..4 {
            let k = f64::from(k);
            let mut lines = own_ship_sentences([0.0, 0.0], [0.0, 4.0], &origin, bridge_s + k);
            if k < 2.0 {
                lines.retain(|l| l.contains("GGA"));
            }
            own.take_live(lines, pc_s + k + 0.5);
        }
        let told = events_with(&own, "this computer's clock");
        assert_eq!(told.len(), 1, "{:?}", own.events());
        assert!(told[0].contains("days behind"), "{told:?}");
    }

    #[test]
    fn a_source_without_a_date_has_its_offset_told_after_a_wait() {
        let origin = Origin::default();
        let pc_s: f64 = 1_767_225_600.0 + 12.0 * 3600.0;
        let bridge_s = pc_s - 3.0 * 3600.0;
        let (_file, mut own) = live_on(pc_s);
        let told =
            |own: &NmeaOwnShip| events_with(own, "3 h 0 min behind this computer's clock").len();
        for k in 0..=DATE_WAIT_S as u32 {
            let k = f64::from(k);
            let mut lines = own_ship_sentences([0.0, 0.0], [0.0, 4.0], &origin, bridge_s + k);
            lines.retain(|l| l.contains("GGA"));
            own.take_live(lines, pc_s + k + 0.5);
            let waited = k >= DATE_WAIT_S;
            assert_eq!(
                told(&own),
                usize::from(waited),
                "read {k}: {:?}",
                own.events()
            );
        }
    }

    #[test]
    fn a_recording_without_times_is_told_once_and_a_timed_one_not() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        for timed in [false, true] {
            let mut file = tempfile::NamedTempFile::new().unwrap();
            for k in 0..3 {
                let lines = own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t0 + f64::from(k));
                for l in lines
                    .iter()
                    .filter(|l| timed || l.contains("HDT") || l.contains("VTG"))
                {
                    file.write_all(l.as_bytes()).unwrap();
                }
            }
            file.flush().unwrap();
            let spec = InSpec::File(file.path().to_path_buf());
            let mut own = NmeaOwnShip::open(&spec, origin, &NmeaOptions::default()).unwrap();
            for scan in 0..3 {
                let scan = scan_at(scan, t0 + 2.5 * f64::from(scan));
                own.own_ship(&scan).unwrap();
            }
            let told = own
                .events()
                .iter()
                .filter(|e| e.contains("has no usable time"))
                .count();
            assert_eq!(told, usize::from(!timed), "{:?}", own.events());
        }
    }

    /// `file`'s lines replayed as `track` reads a recording, its times before its first
    /// date on the day of `day_of_s` (s since 1970).
    fn replayed(file: &mut tempfile::NamedTempFile, day_of_s: f64) -> NmeaOwnShip {
        use std::io::Write as _;
        file.flush().unwrap();
        let spec = InSpec::File(file.path().to_path_buf());
        let o = NmeaOptions {
            provisional_day: clock::day_of_s(day_of_s),
            ..NmeaOptions::default()
        };
        NmeaOwnShip::open(&spec, Origin::default(), &o).unwrap()
    }

    /// A recording's lines without a time before its first timed one are of that time,
    /// and in a recording with no time at all of the first scan's. A log of another
    /// voyage, its headings first and its fixes a year after the scans, gives own ship no
    /// heading at the scans (they were held all run, their age negative, and turned a
    /// head-up radar's picture); a log of `GLL` without times and headings gives a fix at
    /// the first scans (it was taken at midnight, lost hours before the first scan).
    #[test]
    fn untimed_lines_are_of_the_recordings_first_time_or_else_the_scans() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        let year = 365.0 * clock::DAY_S;
        let hdt = crate::nmea::sentence::sentence("HEHDT,232.5,T");
        let gll = crate::nmea::sentence::sentence("GPGLL,5040.0000,N,00100.0000,W,,A,A");
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for _ in 0..5 {
            file.write_all(hdt.as_bytes()).unwrap();
            file.write_all(gll.as_bytes()).unwrap();
        }
        for k in 0..5 {
            for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t0 + year + f64::from(k)) {
                file.write_all(l.as_bytes()).unwrap();
            }
        }
        // As `track` reads it: its times before its first date on that date.
        let mut own = replayed(&mut file, t0 + year);
        for scan in 0..4 {
            let got = own
                .own_ship(&scan_at(scan, t0 + 2.5 * f64::from(scan)))
                .unwrap();
            assert!(
                got.heading_rad.is_none() && got.quality.no_fix_yet,
                "scan {scan}: {got:?}"
            );
        }
        assert_eq!(
            events_with(&own, "no time within").len(),
            1,
            "{:?}",
            own.events()
        );

        // No time at all: GLL without one, and headings.
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for _ in 0..5 {
            file.write_all(hdt.as_bytes()).unwrap();
            file.write_all(gll.as_bytes()).unwrap();
        }
        let mut own = replayed(&mut file, t0);
        for scan in 0..3 {
            let got = own
                .own_ship(&scan_at(scan, t0 + 2.5 * f64::from(scan)))
                .unwrap();
            assert!(
                !got.quality.no_fix_yet && got.quality.dead_reckoning_s.is_none(),
                "scan {scan}: {got:?}"
            );
            let hdg = got.heading_rad.map(f32::to_degrees);
            assert!(
                hdg.is_some_and(|h| (h - 232.5).abs() < 0.01),
                "scan {scan}: {got:?}"
            );
        }
    }

    /// A recording's first time is its first timed sentence's, but for one its next timed
    /// neighbour is back before by over a second (a corrupt time), and not for midnight
    /// between undated times read on one day (23:59:59, then 00:00:00).
    #[test]
    fn a_recordings_first_time_skips_a_corrupt_one_not_midnight() {
        use std::io::Write as _;
        let day0: i32 = 20_454;
        let day_s = f64::from(day0) * clock::DAY_S;
        let gga = |hhmmss: &str| {
            crate::nmea::sentence::sentence(&format!(
                "GPGGA,{hhmmss},5040.0000,N,00100.0000,W,1,08,1.0,10.0,M,47.0,M,,"
            ))
        };
        let hdt = crate::nmea::sentence::sentence("HEHDT,010.0,T");
        for (times, first_s) in [
            (["235959", "000000", "000001"], day_s + 86_399.0),
            (["110000", "100000", "100001"], day_s + 36_000.0),
            (["100000", "100000", "100001"], day_s + 36_000.0),
        ] {
            let mut file = tempfile::NamedTempFile::new().unwrap();
            file.write_all(hdt.as_bytes()).unwrap();
            for t in times {
                file.write_all(gga(t).as_bytes()).unwrap();
            }
            file.flush().unwrap();
            let nav = OwnShipNav::new(Origin::default(), i64::from(day0), None);
            let NmeaIn::File(mut lines) =
                NmeaIn::open(&InSpec::File(file.path().to_path_buf())).unwrap()
            else {
                panic!("a file");
            };
            assert_eq!(
                first_time_ahead(&mut lines, &nav),
                Some(first_s),
                "{times:?}"
            );
        }
    }

    /// Own ship's AIS transponder's report (`AIVDO`) in a recording is a sensor at the
    /// recording's time (the timed sentence's before it), not at the scan it is read for:
    /// read 12 s after the recording's start, it stood 12 s after the GNSS's fixes read
    /// with it, and the GNSS was told silent, then another voyage's.
    #[test]
    fn a_recorded_aivdo_is_at_the_recordings_time() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        let vdo = {
            use aivdm::message::PositionReportClassA;
            let msg = aivdm::AisMessage::PositionReportClassA(PositionReportClassA {
                message_type: 1,
                repeat_indicator: 0,
                mmsi: aivdm::Mmsi::from_raw(235_000_001),
                navigation_status: aivdm::NavigationStatus::UnderWayUsingEngine,
                rate_of_turn: aivdm::RateOfTurn::from_raw(-128),
                sog: aivdm::Sog::from_raw(58),
                position_accuracy: false,
                longitude: aivdm::Longitude::from_raw(-600_000),
                latitude: aivdm::Latitude::from_raw(30_400_000),
                cog: aivdm::Cog::from_raw(0),
                heading: aivdm::Heading::from_raw(511),
                timestamp: aivdm::Timestamp::Second(0),
                maneuver_indicator: aivdm::ManeuverIndicator::NotAvailable,
                raim: false,
                radio_status: 0,
            });
            let mut buf = [0u8; 64];
            let (payload, fill) = aivdm::encode_payload(&msg, &mut buf).unwrap();
            let body = format!(
                "AIVDO,1,1,,,{},{fill}",
                std::str::from_utf8(payload).unwrap()
            );
            format!("!{body}*{:02X}\r\n", crate::nmea::checksum(&body))
        };
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for k in 0..30 {
            let at = t0 + f64::from(k);
            for l in own_ship_sentences([0.0, 3.0 * f64::from(k)], [0.0, 3.0], &origin, at) {
                file.write_all(l.as_bytes()).unwrap();
            }
            if k % 3 == 0 {
                file.write_all(vdo.as_bytes()).unwrap();
            }
        }
        let mut own = replayed(&mut file, t0);
        for scan in 0..6 {
            let got = own
                .own_ship(&scan_at(scan, t0 + 12.0 + 2.5 * f64::from(scan)))
                .unwrap();
            assert_eq!(got.quality.dead_reckoning_s, None, "scan {scan}: {got:?}");
        }
        assert!(own.nav.counts().used > 0);
        let told = |text: &str| events_with(&own, text);
        assert!(
            told("silent").is_empty()
                && told("not taken").is_empty()
                && told("now talker AI").is_empty(),
            "{:?}",
            own.events()
        );
    }

    /// A run past its recording's end (`--duration` longer) is told once why own ship
    /// is dead reckoned: the recording ended, at its last time.
    #[test]
    fn a_run_past_the_recordings_end_is_told_once() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for k in 0..10 {
            for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t0 + f64::from(k)) {
                file.write_all(l.as_bytes()).unwrap();
            }
        }
        file.flush().unwrap();
        let spec = InSpec::File(file.path().to_path_buf());
        // The first GGA, before a date, on the recording's day (as `demo` reads one ahead).
        let o = NmeaOptions {
            provisional_day: clock::day_of_s(t0),
            ..NmeaOptions::default()
        };
        let mut own = NmeaOwnShip::open(&spec, origin, &o).unwrap();
        let ended = |own: &NmeaOwnShip| {
            own.events()
                .iter()
                .filter(|e| e.contains("the recording ended at"))
                .count()
        };
        // Past dead reckoning's reach too (5 min): told ended, not also "apart".
        for scan in 0..140u32 {
            let time_s = t0 + 2.5 * f64::from(scan);
            let got = own.own_ship(&scan_at(scan, time_s)).unwrap();
            // Told once dead reckoning has begun, not while the recording still reaches.
            let reckoned = got.quality.dead_reckoning_s.is_some();
            assert_eq!(ended(&own), usize::from(reckoned), "scan {scan}: {got:?}");
        }
        assert!(
            own.events().iter().any(|e| e.contains("10:00:09Z")),
            "{:?}",
            own.events()
        );
        assert!(
            !own.events().iter().any(|e| e.contains("no time within")),
            "{:?}",
            own.events()
        );
    }

    /// A recording's AIS is heard at the recording's own times: before its first timed
    /// sentence at that sentence's time, after it at the last one's. Far (over 5 min) from
    /// the scan it is read at, it is not taken but counted and told (a log of another
    /// voyage brought its ships into a radar capture's picture); near, it is taken. An
    /// untimed line before a corrupt time far ahead does not hold the replay up.
    #[test]
    fn a_recordings_ais_far_from_the_scan_is_not_taken() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        // A class A position report (pyais's sample).
        let vdm = "!AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa,0*5C\r\n";
        let run = |first_fix_s: f64, scans_from_s: f64, lines_before: &[String]| {
            let mut file = tempfile::NamedTempFile::new().unwrap();
            for l in lines_before {
                file.write_all(l.as_bytes()).unwrap();
            }
            file.write_all(vdm.as_bytes()).unwrap();
            for k in 0..20 {
                let t = first_fix_s + f64::from(k);
                for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t) {
                    file.write_all(l.as_bytes()).unwrap();
                }
                // AIS after each epoch: heard then.
                file.write_all(vdm.as_bytes()).unwrap();
            }
            file.flush().unwrap();
            let o = NmeaOptions {
                provisional_day: clock::day_of_s(first_fix_s),
                ..NmeaOptions::default()
            };
            let spec = InSpec::File(file.path().to_path_buf());
            let mut own = NmeaOwnShip::open(&spec, origin, &o).unwrap();
            let (mut heard, mut fixed) = (0, 0);
            for scan in 0..10u32 {
                let time_s = scans_from_s + 2.5 * f64::from(scan);
                let got = own.own_ship(&scan_at(scan, time_s)).unwrap();
                fixed +=
                    usize::from(got.quality.dead_reckoning_s.is_none() && !got.quality.no_fix_yet);
                heard += own.take_ais().len();
            }
            (heard, fixed, own.ais_stale, own.events())
        };
        // Played from its start: all 21 reports heard, none refused.
        let (heard, fixed, stale, _) = run(t0, t0, &[]);
        assert_eq!((heard, stale), (21, 0));
        assert!(fixed >= 8, "{fixed}");
        // An hour before its first fix (the report before it) and a day after its last.
        for scans_from_s in [t0 - 3600.0, t0 + 86_400.0] {
            let (heard, _, stale, events) = run(t0, scans_from_s, &[]);
            let before = usize::from(scans_from_s < t0);
            assert_eq!(
                (heard, stale),
                (0, 21 - 20 * before as u64),
                "{scans_from_s}"
            );
            assert!(
                events
                    .iter()
                    .any(|e| e.contains("AIS sentences of the recording not taken")),
                "{events:?}"
            );
        }
        // An untimed line, then a corrupt time an hour ahead (valid checksum) whose next
        // timed neighbour is back: refused, and the replay goes on.
        let corrupt = own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t0 + 3600.0);
        let lines = [
            crate::nmea::sentence::sentence("HEHDT,000.0,T"),
            corrupt[0].clone(),
        ];
        let (heard, fixed, stale, _) = run(t0, t0, &lines);
        assert_eq!((heard, stale), (21, 0));
        assert!(fixed >= 8, "{fixed}");
    }

    #[test]
    fn a_recordings_lines_after_the_last_scan_are_counted_at_the_end() {
        use std::io::Write as _;
        let origin = Origin::default();
        let t0 = 1_767_225_600.0 + 10.0 * 3600.0;
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for t in [t0, t0 + 100.0] {
            for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t) {
                file.write_all(l.as_bytes()).unwrap();
            }
        }
        file.flush().unwrap();
        let per_epoch = own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t0).len() as u64;
        let spec = InSpec::File(file.path().to_path_buf());
        let options = NmeaOptions {
            provisional_day: clock::day_of_s(t0),
            ..NmeaOptions::default()
        };
        let mut own = NmeaOwnShip::open(&spec, origin, &options).unwrap();
        let scan = scan_at(0, t0 + 1.0);
        own.own_ship(&scan).unwrap();
        assert_eq!(own.nmea_counts().unwrap().lines, per_epoch);
        own.finish();
        let c = own.nmea_counts().unwrap();
        assert_eq!((c.lines, c.after_last_scan), (per_epoch, per_epoch), "{c}");
        assert!(c
            .to_string()
            .ends_with(&format!("; {per_epoch} after the last scan, not read")));
    }

    /// Two sources' timed sentences read in one go are taken in time order, each source's
    /// untimed lines after its timed one before them: one source after the other, the
    /// second's older sentences were refused as steps back.
    #[test]
    fn several_sources_lines_are_interleaved_in_time() {
        let origin = Origin::default();
        let nav = OwnShipNav::new(origin, 20_454, None);
        let t0 = 1_767_225_600.0 + 3600.0;
        let at = |t: f64| {
            own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, t)
                .into_iter()
                .find(|l| l.starts_with("$GPRMC") || l.starts_with("$RARMC"))
                .expect("an RMC")
        };
        let hdt = crate::nmea::sentence::sentence("HEHDT,010.0,T");
        let first = vec![hdt.clone(), at(t0), at(t0 + 2.0)];
        let second = vec![at(t0 + 1.0), hdt.clone(), at(t0 + 3.0)];
        let merged = interleave(&nav, vec![first, second]);
        let times: Vec<f64> = merged.iter().filter_map(|l| nav.time_of(l)).collect();
        assert_eq!(times, [t0, t0 + 1.0, t0 + 2.0, t0 + 3.0], "{merged:?}");
        // The first source's leading heading first; the second's after its own RMC.
        assert_eq!(merged[0], hdt);
        assert_eq!(merged[3], hdt, "{merged:?}");
        let mut fed = OwnShipNav::new(origin, 20_454, None);
        for l in &merged {
            fed.feed(l);
        }
        assert_eq!(fed.counts().stale, 0, "{}", fed.counts());
    }

    /// Two live sources, the GNSS on one UDP port and the AIS transponder on another (the
    /// usual bridge layout): own ship from the first, AIS targets from the second, read
    /// together. A recording with another source is refused.
    #[test]
    fn two_live_sources_are_read_together() {
        use std::net::UdpSocket;
        let origin = Origin::default();
        let mut own = NmeaOwnShip::open(&InSpec::Udp(0), origin, &NmeaOptions::default())
            .unwrap()
            .with_more(&[InSpec::Udp(0)])
            .unwrap();
        let port = |input: &crate::nmea::input::LiveLines| input.udp_addr().unwrap().port();
        let NmeaIn::Live(first) = &own.input else {
            panic!("live")
        };
        let (gnss, ais) = (port(first), port(&own.more[0]));
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let now = crate::utc::now_s();
        for l in own_ship_sentences([0.0, 0.0], [0.0, 3.0], &origin, now) {
            tx.send_to(l.as_bytes(), ("127.0.0.1", gnss)).unwrap();
        }
        // A class A position report (pyais's sample).
        let vdm = "!AIVDM,1,1,,B,15M67FC000G?ufbE`FepT@3n00Sa,0*5C\r\n";
        tx.send_to(vdm.as_bytes(), ("127.0.0.1", ais)).unwrap();
        let scan = scan_at(0, now + 0.5);
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
        let (mut fixed, mut heard) = (false, Vec::new());
        while (!fixed || heard.is_empty()) && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(20));
            fixed |= !own.own_ship(&scan).unwrap().quality.no_fix_yet;
            heard.extend(own.take_ais());
        }
        assert!(fixed, "own ship from the first source");
        assert_eq!(heard.len(), 1, "the AIS report from the second");
        // A recording does not mix with a live source.
        let file = tempfile::NamedTempFile::new().unwrap();
        let recording = InSpec::File(file.path().to_path_buf());
        let e = NmeaOwnShip::open(&recording, origin, &NmeaOptions::default())
            .unwrap()
            .with_more(&[InSpec::Udp(0)])
            .err()
            .unwrap();
        assert!(e.to_string().contains("must then be live"), "{e}");
    }

    #[test]
    fn a_live_source_on_its_own_utc_is_followed_and_told_of() {
        // The session's clock (this computer's) is 3 h ahead of the bridge's UTC.
        let file = tempfile::NamedTempFile::new().unwrap();
        let origin = Origin::default();
        let spec = InSpec::File(file.path().to_path_buf());
        let mut own = NmeaOwnShip::open(&spec, origin, &NmeaOptions::default()).unwrap();
        let pc_s = 1_767_225_600.0 + 12.0 * 3600.0;
        let bridge_s = pc_s - 3.0 * 3600.0;
        // Each read brings a heading without a time, then the epoch's sentences.
        let hdt = crate::nmea::sentence::sentence("HEHDT,000.0,T");
        for k in 0..10 {
            let k = f64::from(k);
            let mut lines = vec![hdt.clone()];
            lines.extend(own_ship_sentences(
                [0.0, 4.0 * k],
                [0.0, 4.0],
                &origin,
                bridge_s + k,
            ));
            own.take_live(lines, pc_s + k + 0.5);
        }
        let offset = own.offset_s.unwrap();
        assert!((offset + 3.0 * 3600.0 + 0.5).abs() < 1e-6, "{offset}");
        assert_eq!(own.clock_offset_s(), offset);
        assert_eq!(
            OwnShipSource::utc_offset_s(&own),
            offset,
            "the UTC sent and shown"
        );
        // On the bridge's time, at the last epoch: where the sentences put it (the
        // headings, untimed, did not carry the filter ahead of them).
        let at = own.nav.own_ship_at(bridge_s + 9.0).unwrap();
        assert_eq!(at.quality.dead_reckoning_s, None, "{at:?}");
        assert!((at.position_m[1] - 36.0).abs() < 2.0, "{at:?}");
        assert!(at.quality.motion_known && (at.velocity_mps[1] - 4.0).abs() < 0.1);
        assert!(
            at.heading_rad.is_some() && !at.quality.heading_lost,
            "{at:?}"
        );
        let told = events_with(&own, "3 h 0 min behind this computer's clock");
        assert_eq!(told.len(), 1, "{:?}", own.events());
    }
}
