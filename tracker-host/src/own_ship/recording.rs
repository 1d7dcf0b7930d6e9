//! A whole own-ship recording read ahead, as the simulator needs it to move the radar
//! picture with the recorded ship: where and when it starts, how long it lasts, and the
//! position fixes it holds (through the same classification, clock and talker choice as the
//! replay, so both see the same fixes).

use std::path::Path;

use super::nav::OwnShipNav;
use super::select::Selector;
use super::sentences::{decode, Decoded};
use super::NmeaOptions;
use crate::nmea::input::{read_bounded_line, MAX_LINE_BYTES};
use crate::nmea::sentence::{self, Line};
use crate::origin::Origin;

/// A recording's own-ship track.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedTrack {
    /// Position fixes: time (s since 1970), latitude, longitude (degrees).
    pub fixes: Vec<(f64, f64, f64)>,
    /// The recording tells UTC (a sentence with a valid time: `RMC`, `GGA`, `GLL` or
    /// `ZDA`); without, its fixes' times are made up (at the start of the day the run was
    /// given), no UTC to show or send as one.
    pub timed: bool,
    /// Fixes set apart from the track: more than [`MAX_FIX_GAP_S`] from the stretch of the
    /// recording that holds the most fixes (a stray sentence of another date).
    pub set_apart: usize,
    /// The day the recording starts on ([`first_day_of`]), days since 1970; `None` when
    /// it gives no date.
    pub first_day: Option<i64>,
}

/// Fixes further apart than this are not one voyage, s (a day). A recording's track is
/// its stretch of fixes with no gap longer than this that holds the most fixes: one stray
/// `RMC` of 1994 before a 2015 log's first fix made the run's origin 600 km off and its
/// span 21 years (a new user's trial: a run of 265 million scans). Real logs' gaps were up
/// to 2.5 h (`../shared/realdata/nmea/`). Not handled: a stray sentence dated *later* than
/// the log, before its first fix, whose date the clock then keeps, refusing the log's own
/// dated sentences as going back.
pub const MAX_FIX_GAP_S: f64 = super::clock::DAY_S;

/// The first and last time of `fixes` (not empty), s since 1970.
fn window_of(fixes: &[(f64, f64, f64)]) -> (f64, f64) {
    (fixes[0].0, fixes[fixes.len() - 1].0)
}

/// The stretch of `fixes` (in time order) with no gap over [`MAX_FIX_GAP_S`] that holds
/// the most, the first of equals: its first and one-past-last index.
fn main_stretch(fixes: &[(f64, f64, f64)]) -> (usize, usize) {
    let mut best = (0, 0);
    let mut start = 0;
    for i in 1..=fixes.len() {
        let ends = i == fixes.len() || fixes[i].0 - fixes[i - 1].0 > MAX_FIX_GAP_S;
        if ends {
            if i - start > best.1 - best.0 {
                best = (start, i);
            }
            start = i;
        }
    }
    best
}

impl RecordedTrack {
    /// Reads `path` whole.
    ///
    /// # Errors
    /// The file does not open, or holds no position fix.
    pub fn read(path: &Path, o: &NmeaOptions) -> anyhow::Result<Self> {
        let open = || crate::nmea::input::open_recording(path).map(std::io::BufReader::new);
        // The fixes, and whether a sentence gave the time, read with the times before the
        // first date on `day`, refusing dated sentences far outside `window` when given.
        let read = |day: i64, window: Option<(f64, f64)>| -> anyhow::Result<OwnShipNav> {
            let mut reader = open()?;
            let mut nav = OwnShipNav::with_selector(
                Origin::default(),
                day,
                o.variation_deg,
                Selector::new(o.priority.clone()),
            )
            .within(window)
            .keep_fixes();
            while let Ok(Some(line)) = read_bounded_line(&mut reader, MAX_LINE_BYTES) {
                nav.feed(&line);
            }
            Ok(nav)
        };
        let day = first_day(open()?);
        let nav = read(day.unwrap_or(o.provisional_day), None)?;
        let fixes = nav.fixes().to_vec();
        if fixes.is_empty() {
            anyhow::bail!(
                "{}: no own-ship position fix (GGA, RMC or GLL) in the recording, whose track the run follows (AIS of other ships alone is not own ship) ({})",
                path.display(),
                nav.counts()
            );
        }
        let timed = nav.newest_s().is_some();
        let (first, end) = main_stretch(&fixes);
        let set_apart = fixes.len() - (end - first);
        let mut fixes = fixes[first..end].to_vec();
        if set_apart > 0 {
            // Read again within the track: the stray sentence's date set the clock's for the
            // undated sentences after it, whose fixes belong to the track.
            let window = window_of(&fixes);
            let again = read(super::clock::day_of_s(window.0), Some(window))?;
            let (a, b) = main_stretch(again.fixes());
            let again = &again.fixes()[a..b];
            // Taken only in time order: undated fixes of the part set apart, put on the
            // track's day, and a clock started again on the track's first date would run
            // back (a genuine second part of the log, more than a day away).
            let in_order = again.windows(2).all(|w| w[0].0 <= w[1].0);
            if in_order && again.len() >= fixes.len() {
                fixes = again.to_vec();
            }
        }
        Ok(RecordedTrack {
            fixes,
            timed,
            set_apart,
            first_day: day,
        })
    }

    /// Says on standard error, when fixes were set apart, how many and what the run
    /// follows (`path`: the recording's).
    pub fn tell_set_apart(&self, path: &Path) {
        if self.set_apart > 0 {
            eprintln!(
                "{}: {} position fix(es) set apart, more than a day from the stretch of the recording that holds the most (a stray sentence of another date, or another voyage); the run follows that stretch's {} fixes",
                path.display(),
                self.set_apart,
                self.fixes.len()
            );
        }
    }

    /// The first fix's time, s since 1970.
    pub fn start_s(&self) -> f64 {
        self.fixes[0].0
    }

    /// The first fix's time and the last's, s since 1970.
    pub fn window_s(&self) -> (f64, f64) {
        window_of(&self.fixes)
    }

    /// From the first fix to the last, s.
    pub fn span_s(&self) -> f64 {
        self.fixes.last().map_or(0.0, |f| f.0) - self.start_s()
    }

    /// The first fix's position: the natural origin of the local frame.
    pub fn first_position(&self) -> Origin {
        Origin {
            lat_deg: self.fixes[0].1,
            lon_deg: self.fixes[0].2,
        }
    }

    /// Own ship's position (local frame of `origin`, m) and velocity (m/s) at `time_s`:
    /// between fixes, on the straight line between them; before the first, at the first;
    /// after the last, straight on at the last velocity. The velocity is taken over fixes
    /// [`VELOCITY_SPAN_S`] apart, so a fix's few metres of noise do not make metres per
    /// second.
    pub fn at(&self, origin: &Origin, time_s: f64) -> ([f64; 2], [f64; 2]) {
        let local = |i: usize| origin.to_local(self.fixes[i].1, self.fixes[i].2);
        let n = self.fixes.len();
        let time = |i: usize| self.fixes[i].0;
        let index_at = |t: f64| self.fixes.partition_point(|f| f.0 <= t);
        let velocity = |t: f64| {
            let a = index_at(t - VELOCITY_SPAN_S / 2.0).saturating_sub(1);
            let b = index_at(t + VELOCITY_SPAN_S / 2.0).min(n - 1);
            let dt = time(b) - time(a);
            if b <= a || dt <= 0.0 {
                return [0.0, 0.0];
            }
            let (pa, pb) = (local(a), local(b));
            [(pb[0] - pa[0]) / dt, (pb[1] - pa[1]) / dt]
        };
        let v = velocity(time_s.min(time(n - 1)));
        let i = index_at(time_s);
        if i == 0 {
            return (local(0), v);
        }
        if i >= n {
            let p = local(n - 1);
            let dt = time_s - time(n - 1);
            return ([p[0] + v[0] * dt, p[1] + v[1] * dt], v);
        }
        let (pa, pb) = (local(i - 1), local(i));
        let f = (time_s - time(i - 1)) / (time(i) - time(i - 1)).max(1e-9);
        (
            [pa[0] + f * (pb[0] - pa[0]), pa[1] + f * (pb[1] - pa[1])],
            v,
        )
    }
}

/// The day the recording at `path` starts on (days since 1970): the first date a sentence
/// gives, the day before when the time of day fell between the first timed sentence and
/// that one (midnight passed); `None` when it gives no date or cannot be read.
pub fn first_day_of(path: &Path) -> Option<i64> {
    crate::nmea::input::open_recording(path)
        .ok()
        .and_then(|f| first_day(std::io::BufReader::new(f)))
}

/// The day the recording starts on: the first date a sentence gives, the day before when
/// the time of day fell between the first timed sentence and that one (midnight passed).
fn first_day(mut reader: impl std::io::BufRead) -> Option<i64> {
    let mut first_tod = None;
    while let Ok(Some(line)) = read_bounded_line(&mut reader, MAX_LINE_BYTES) {
        let Ok(Line::Sentence(s)) = sentence::parse(&line) else {
            continue;
        };
        let stamp = match decode(&s, &line) {
            Decoded::Readings(stamp, _) | Decoded::Time(stamp) => stamp,
            _ => continue,
        };
        let Some(tod) = stamp.time_of_day_s else {
            continue;
        };
        let first = *first_tod.get_or_insert(tod);
        if let Some(day) = stamp.day {
            return Some(if tod < first { day - 1 } else { day });
        }
    }
    None
}

/// Fixes this far apart give own ship's velocity, s.
pub const VELOCITY_SPAN_S: f64 = 10.0;
