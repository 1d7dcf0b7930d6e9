//! What a navigator reads about each tracked target: range and bearing, CPA and TCPA, true
//! and relative course and speed, and the alarms.

use tracker_core::geo::{self, EastNorth, METRES_PER_NM, MPS_PER_KNOT};
use tracker_core::icd::{TrackState, TrackStatus};

use crate::own_ship::OwnShip;

/// One target's data, as the display shows it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetData {
    /// The device's track number.
    pub track: u16,
    /// The target number the navigator and plotters know it by (01–99; see
    /// [`super::numbers`]); `None` until given one.
    pub number: Option<u8>,
    /// Life-cycle state.
    pub status: TrackStatus,
    /// Range from own ship, m.
    pub range_m: f32,
    /// True bearing from own ship, rad.
    pub bearing_rad: f32,
    /// True course over ground, rad.
    pub course_rad: f32,
    /// Speed over ground, m/s.
    pub speed_mps: f32,
    /// Course relative to own ship, rad.
    pub rel_course_rad: f32,
    /// Speed relative to own ship, m/s.
    pub rel_speed_mps: f32,
    /// Closest point of approach, m.
    pub cpa_m: f32,
    /// Time to CPA, s (negative: passed).
    pub tcpa_s: f32,
    /// Scans since the track started.
    pub age_scans: u16,
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity, m/s.
    pub velocity_mps: EastNorth,
    /// True course and speed are known (own ship's motion is): without, only the relative
    /// ones mean anything.
    pub true_motion_known: bool,
    /// The target's motion is known well enough to show: its vector, course and speed, CPA
    /// and TCPA, and the CPA/TCPA alarm ([`super::trend`]). Taken as known by
    /// [`TargetData::new`]; the session's numbering sets it for each scan's targets.
    pub trend_known: bool,
    /// Its CPA/TCPA alarm was on last scan ([`TargetData::dangerous`] with the session's
    /// limits): held then until the target is clear of the limits widened by
    /// [`ALARM_CLEAR_FACTOR`], or [`ALARM_PASSED_S`] past its CPA. Set by the session's
    /// numbering; `false` from [`TargetData::new`].
    pub alarm_held: bool,
    /// The MMSI of the AIS target whose data this shows, an associated ship's
    /// ([`TargetData::with_ais_data`]); `None`: the radar track's own.
    pub ais_data: Option<u32>,
}

/// Below this relative speed, m/s (0.25 kn), a target keeps its range and is not
/// approaching: no CPA/TCPA alarm. Own ship moored and a target standing still (found so,
/// [`super::stationary`], or an AIS target reporting SOG 0) are such a pair; every moored
/// boat within the CPA limit would alarm otherwise, its CPA its present range and its TCPA
/// whatever the noise's direction makes it. Each speed is known to about 0.1 kn: AIS sends
/// SOG in steps of 0.1 kn (ITU-R M.1371-5, message 1), and a moored ship's GNSS reports
/// 0.0–0.1 kn (the Merrimac's `RMC`s in `../shared/realdata/nmea/signalk-gofree-merrimac.log`),
/// so two moored ships may differ by 0.2 kn; the bound is clear of that. At 1 mm/s (before
/// a new user's trial) the Merrimac, moored, raised alarms on AIS ships moored 0.4–0.5 NM
/// off, their TCPA jumping from 10.5 to 2.5 min. What it costs: a target closing at under
/// 0.25 kn is inside the TCPA limit only within 93 m of own ship (12 minutes at 0.129 m/s).
pub const NO_RELATIVE_MOTION_MPS: f32 = 0.25 * MPS_PER_KNOT;

/// An associated ship moving on an AIS report older than this is shown with its radar
/// track's data, s: a class A ship under way reports every 2–10 s and a class B one over 2 kn
/// every 30 s (ITU-R M.1371-5, table 1); a report missed or two is within it.
pub const AIS_DATA_MAX_AGE_S: f32 = 35.0;

/// Below this speed an AIS target is taken as not moving (its reports every 3 minutes at
/// anchor carry no course to go stale), m/s (1 kn).
pub const AIS_STILL_MPS: f32 = MPS_PER_KNOT;

/// An alarm once on stays on until the target's CPA or TCPA is this many times its limit.
/// A CPA near the limit moves across it with the velocity's noise from scan to scan: on
/// the Solent an alarm was raised again and again on one target (21 times in 20 minutes on
/// the worst, 201 raises on 23 targets), each one a new alarm for the navigator.
pub const ALARM_CLEAR_FACTOR: f32 = 1.2;

/// … or once it is this long past its CPA, s (a TCPA that jitters about zero while the
/// target is abeam does not end the alarm).
pub const ALARM_PASSED_S: f32 = 60.0;

/// CPA (m) and TCPA (s) of a target at `target` moving at `target_v`, seen from own ship at
/// `own` moving at `own_v` (positions m, velocities m/s, east and north; [`geo::cpa`]), as
/// shown and sent: below [`NO_RELATIVE_MOTION_MPS`]
/// the target keeps its range, so its CPA is its present range and its TCPA 0 (the
/// relative velocity's noise made a moored boat's CPA 0.00 NM and its TCPA −177 min, on the
/// display and in `TTM`, in a new user's trial).
pub fn cpa_shown(
    own: EastNorth,
    own_v: EastNorth,
    target: EastNorth,
    target_v: EastNorth,
) -> geo::Cpa {
    let rel = geo::relative_velocity(own_v, target_v);
    if libm::hypotf(rel[0], rel[1]) < NO_RELATIVE_MOTION_MPS {
        let (range_m, _) = geo::range_bearing(own, target);
        return geo::Cpa {
            cpa_m: range_m,
            tcpa_s: 0.0,
        };
    }
    geo::cpa(own, own_v, target, target_v)
}

impl TargetData {
    /// Computes the target data of a track seen from own ship.
    pub fn new(own: &OwnShip, t: &TrackState) -> Self {
        let d = TargetData {
            track: t.track,
            number: None,
            status: t.status,
            range_m: 0.0,
            bearing_rad: 0.0,
            course_rad: 0.0,
            speed_mps: 0.0,
            rel_course_rad: 0.0,
            rel_speed_mps: 0.0,
            cpa_m: 0.0,
            tcpa_s: 0.0,
            age_scans: t.age_scans,
            position_m: t.position_m,
            velocity_mps: t.velocity_mps,
            true_motion_known: own.quality.motion_known,
            trend_known: true,
            alarm_held: false,
            ais_data: None,
        };
        // Relative to the frame the track was formed in (own ship held: none).
        d.seen_from(own.position_m, own.track_frame_velocity_mps())
    }

    /// This target's range, bearing, course and speed, relative motion, CPA and TCPA from
    /// its position and velocity, seen from own ship at `own_m` moving at `own_v` (m, m/s).
    fn seen_from(self, own_m: EastNorth, own_v: EastNorth) -> Self {
        let (range_m, bearing_rad) = geo::range_bearing(own_m, self.position_m);
        let (course_rad, speed_mps) = geo::course_speed(self.velocity_mps);
        let rel = geo::relative_velocity(own_v, self.velocity_mps);
        let (rel_course_rad, rel_speed_mps) = geo::course_speed(rel);
        let c = cpa_shown(own_m, own_v, self.position_m, self.velocity_mps);
        TargetData {
            range_m,
            bearing_rad,
            course_rad,
            speed_mps,
            rel_course_rad,
            rel_speed_mps,
            cpa_m: c.cpa_m,
            tcpa_s: c.tcpa_s,
            ..self
        }
    }

    /// This target shown with the data of `a`, the AIS target of the same ship (IEC 62388
    /// §11.4: an associated target's alphanumeric data are the AIS target's by default,
    /// [`super::ais::AssociatedData`]): its position, course and speed over ground, and its
    /// relative motion, CPA and TCPA from own ship `own`, as the AIS target is shown. Its
    /// number, status, age and held alarm stay the track's (the AIS picture holds the alarm
    /// on the data shown). `None`, the radar's data standing, while the AIS target's CPA is
    /// not known (own ship's motion unknown, or no motion reported), or while it moves on
    /// a report older than [`AIS_DATA_MAX_AGE_S`]: a ship's last course and speed carried
    /// that far are worse than its fresh track in a turn.
    pub fn with_ais_data(&self, own: &OwnShip, a: &crate::ais::AisTargetData) -> Option<Self> {
        let moving = libm::hypotf(a.velocity_mps[0], a.velocity_mps[1]) >= AIS_STILL_MPS;
        if moving && a.age_s > AIS_DATA_MAX_AGE_S {
            return None;
        }
        a.cpa?;
        // The AIS velocity is over ground: relative to own ship's (as the AIS target's CPA
        // is, `AisTargets::picture`).
        let d = TargetData {
            position_m: a.position_m,
            velocity_mps: a.velocity_mps,
            true_motion_known: true,
            trend_known: true,
            ais_data: Some(a.mmsi),
            ..*self
        };
        Some(d.seen_from(own.position_m, own.velocity_mps))
    }

    /// True for a target moving under [`NO_RELATIVE_MOTION_MPS`] relative to own ship: it
    /// keeps its range, and has no relative course to show or send.
    pub fn keeps_range(&self) -> bool {
        self.rel_speed_mps < NO_RELATIVE_MOTION_MPS
    }

    /// False for a target shown with no motion ([`super::stationary`]), or whose speed
    /// shows as 0.0 kn: it has no course over ground to show, as own ship has none under
    /// [`crate::own_ship::COG_FROM_KN`] (a plotter was sent `0.0` kn with a course of
    /// 45.0°).
    pub fn moving(&self) -> bool {
        f64::from(self.speed_mps) / f64::from(MPS_PER_KNOT) >= crate::own_ship::COG_FROM_KN
    }

    /// The target's number as the navigator reads it (`07`), or `--` while it has none.
    pub fn label(&self) -> String {
        self.number.map_or("--".to_string(), |n| format!("{n:02}"))
    }

    /// True when the target will pass closer than `cpa_limit_m` within `tcpa_limit_s`, its
    /// motion being known ([`TargetData::trend_known`]); an alarm held from the last scan
    /// ([`TargetData::alarm_held`]) within the limits widened by [`ALARM_CLEAR_FACTOR`]
    /// and until [`ALARM_PASSED_S`] past its CPA. A target with no motion relative to own
    /// ship ([`NO_RELATIVE_MOTION_MPS`]) keeps its range and raises none.
    pub fn dangerous(&self, limits: &AlarmLimits) -> bool {
        let c = geo::Cpa {
            cpa_m: self.cpa_m,
            tcpa_s: self.tcpa_s,
        };
        let within =
            |factor: f32, passed_s: f32| limits.within(c, self.rel_speed_mps, factor, passed_s);
        self.trend_known
            && (within(1.0, 0.0) || self.alarm_held && within(ALARM_CLEAR_FACTOR, ALARM_PASSED_S))
    }
}

/// CPA/TCPA alarm limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlarmLimits {
    /// CPA below this alarms, m.
    pub cpa_m: f32,
    /// … when TCPA is below this, s.
    pub tcpa_s: f32,
}

impl AlarmLimits {
    /// True when a target at `c` moving at `rel_speed_mps` (m/s) relative to own ship is
    /// within the limits scaled by `factor`: CPA under the CPA limit, TCPA from
    /// −`passed_s` (s) to the TCPA limit. A target keeping its range (under
    /// [`NO_RELATIVE_MOTION_MPS`]) never is. The one rule for radar targets
    /// ([`TargetData::dangerous`]), AIS targets and the scorer's truth.
    pub fn within(&self, c: geo::Cpa, rel_speed_mps: f32, factor: f32, passed_s: f32) -> bool {
        rel_speed_mps >= NO_RELATIVE_MOTION_MPS
            && c.cpa_m < self.cpa_m * factor
            && c.tcpa_s >= -passed_s
            && c.tcpa_s < self.tcpa_s * factor
    }
}

impl Default for AlarmLimits {
    /// 1 NM within 12 minutes: a common bridge setting.
    fn default() -> Self {
        AlarmLimits {
            cpa_m: METRES_PER_NM,
            tcpa_s: 12.0 * 60.0,
        }
    }
}

/// The target table as text, one line per target, in navigator's units (NM, kn, degrees
/// true, minutes); the motion of a target whose trend is not known yet is `---`.
pub fn table(targets: &[TargetData], limits: &AlarmLimits) -> String {
    table_with_ais(targets, limits, None)
}

/// A TCPA in minutes as the tables print it, to a tenth: one just past (−0.04 min) reads
/// 0.0, not −0.0.
pub fn tcpa_minutes(tcpa_s: f32) -> f32 {
    crate::nmea::shown_signed(f64::from(tcpa_s) / 60.0, 1) as f32
}

/// The largest TCPA the tables show, min (IEC 62388 asks for CPA and TCPA, not how far; an
/// ARPA's field is commonly three figures): beyond it the target has next to no motion
/// relative to own ship, and its TCPA runs to hours either way (−900 min for a moored boat
/// 1 NM off whose track drifts 0.07 kn relative; a new user's trial) without meaning
/// anything to a navigator.
pub const TCPA_SHOWN_MIN: f32 = 99.9;

/// A TCPA as the tables show it: minutes to a tenth ([`tcpa_minutes`]), or `>99.9` and
/// `<-99.9` beyond [`TCPA_SHOWN_MIN`].
pub fn tcpa_text(tcpa_s: f32) -> String {
    let minutes = tcpa_minutes(tcpa_s);
    if minutes > TCPA_SHOWN_MIN {
        format!(">{TCPA_SHOWN_MIN:.1}")
    } else if minutes < -TCPA_SHOWN_MIN {
        format!("<-{TCPA_SHOWN_MIN:.1}")
    } else {
        format!("{minutes:.1}")
    }
}

/// TCPA as an alarm's words: `in 3.4 min`, or once the closest point is passed (an alarm
/// is held a while after it, [`ALARM_PASSED_S`]) `passed 0.3 min ago` (it read `in -0.3
/// min`).
pub fn tcpa_words(tcpa_s: f32) -> String {
    let text = tcpa_text(tcpa_s);
    if text.starts_with('-') || text.starts_with("<-") {
        format!("passed {} min ago", tcpa_text(-tcpa_s))
    } else {
        format!("in {text} min")
    }
}

/// [`table`] with an AIS column (when `ais` is given): what `ais` says of each track
/// number, the paired AIS target's name for instance, at most 20 characters.
pub fn table_with_ais(
    targets: &[TargetData],
    limits: &AlarmLimits,
    ais: Option<&dyn Fn(u16) -> String>,
) -> String {
    // Rounded, then wrapped: 359.96° is 0.0, never 360.0.
    let deg = |r: f32| crate::nmea::shown_angle_deg(f64::from(r).to_degrees(), 1) as f32;
    let mut s = String::from(
        " TGT STATUS     RNG NM  BRG °T  CRS °T   SPD kn  CPA NM  TCPA min  RCRS °T  RSPD kn  AGE",
    );
    if ais.is_some() {
        s += "  AIS";
    }
    s.push('\n');
    for t in targets {
        // A column is `---` when what it shows is not known: the motion before the trend
        // is, the true course and speed without own ship's motion, the course of a target
        // shown still, the relative course of one keeping its range.
        let known = |ok: bool, width: usize, v: f32, places: usize| {
            if ok {
                format!("{v:>width$.places$}")
            } else {
                format!("{:>width$}", "---")
            }
        };
        let (trend, truth) = (t.trend_known, t.trend_known && t.true_motion_known);
        let tcpa = if trend {
            tcpa_text(t.tcpa_s)
        } else {
            "---".to_string()
        };
        let name = ais.map(|f| format!("  {:<20}", f(t.track)));
        let line = format!(
            "{:>4} {:<9} {:>7.2} {:>7.1} {} {} {} {:>9} {} {} {:>4}{}{}",
            t.label(),
            shown_status(t),
            t.range_m / METRES_PER_NM,
            deg(t.bearing_rad),
            known(truth && t.moving(), 7, deg(t.course_rad), 1),
            known(truth, 8, t.speed_mps / MPS_PER_KNOT, 1),
            known(trend, 7, t.cpa_m / METRES_PER_NM, 2),
            tcpa,
            known(trend && !t.keeps_range(), 8, deg(t.rel_course_rad), 1,),
            known(trend, 8, t.rel_speed_mps / MPS_PER_KNOT, 1),
            t.age_scans,
            name.unwrap_or_default(),
            if t.dangerous(limits) {
                "  ALARM CPA/TCPA"
            } else {
                ""
            },
        );
        s += line.trim_end();
        s.push('\n');
    }
    s
}

/// A shown target's status as a navigator reads it, as the plotter is told it (`TTM`'s
/// `Q` and `T`): acquiring until its motion's trend is known (IEC 62388 draws no vector
/// before), tracked after.
pub fn shown_status(t: &TargetData) -> &'static str {
    if is_acquiring(t) {
        "acquiring"
    } else {
        status_name(t.status)
    }
}

/// A firm target (confirmed, or coasting through a miss) whose motion's trend is not known
/// yet: shown as acquiring ([`shown_status`]). Shown `coasting`, one that missed its
/// second scan in a row then went from the display without an alarm (its acquisition
/// failed, [`crate::session::numbers::ACQUISITION_MISSES`]): on the 3G capture's change of
/// range scale, a new user read them as tracked targets lost silently.
pub fn is_acquiring(t: &TargetData) -> bool {
    t.status.is_firm() && !t.trend_known
}

/// The status as a navigator reads it.
pub fn status_name(s: TrackStatus) -> &'static str {
    match s {
        TrackStatus::Tentative => "acquiring",
        TrackStatus::Confirmed => "tracked",
        TrackStatus::Coasting => "coasting",
        TrackStatus::Lost => "LOST",
    }
}

/// A confirmed target 5 km off (3 km east, 4 km north) heading west at 5 m/s, own ship
/// north at 6 m/s: for tests of what is made of target data.
#[cfg(test)]
pub(crate) fn example() -> TargetData {
    let own = OwnShip::at([0.0, 0.0], [0.0, 6.0]);
    TargetData::new(&own, &example_track())
}

/// The track of [`example`].
#[cfg(test)]
pub(crate) fn example_track() -> TrackState {
    TrackState {
        track: 7,
        status: TrackStatus::Confirmed,
        position_m: [3000.0, 4000.0],
        velocity_mps: [-5.0, 0.0],
        age_scans: 12,
        hit_history: 0xFFF,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A target whose speed shows as 0.0 kn has no course to show or send.
    #[test]
    fn a_target_at_0_0_kn_has_no_course() {
        let mut t = TargetData::new(&OwnShip::at([0.0, 0.0], [0.0, 0.0]), &example_track());
        t.speed_mps = 0.04 * MPS_PER_KNOT;
        assert!(!t.moving());
        t.speed_mps = 0.06 * MPS_PER_KNOT;
        assert!(t.moving());
    }

    /// An alarm's TCPA reads as words, once passed too (it read `in -0.3 min`).
    #[test]
    fn an_alarms_tcpa_reads_passed_once_passed() {
        assert_eq!(tcpa_words(204.0), "in 3.4 min");
        assert_eq!(tcpa_words(-18.0), "passed 0.3 min ago");
        assert_eq!(tcpa_words(-1.0), "in 0.0 min");
        assert_eq!(tcpa_words(-1e6), "passed >99.9 min ago");
    }

    /// Track 3, confirmed for 40 scans, at `position_m` moving at `velocity_mps`.
    fn settled(position_m: EastNorth, velocity_mps: EastNorth) -> TrackState {
        TrackState {
            track: 3,
            status: TrackStatus::Confirmed,
            position_m,
            velocity_mps,
            age_scans: 40,
            hit_history: 0x3ff,
        }
    }

    #[test]
    fn a_target_is_shown_acquiring_until_its_trend_is_known() {
        let mut t = example();
        t.trend_known = false;
        assert_eq!(shown_status(&t), "acquiring");
        t.trend_known = true;
        assert_eq!(shown_status(&t), "tracked");
        t.status = TrackStatus::Coasting;
        assert_eq!(shown_status(&t), "coasting");
        // Coasting before its trend is known: still acquiring (it goes without an alarm
        // if its acquisition fails).
        t.trend_known = false;
        assert_eq!(shown_status(&t), "acquiring");
        assert_eq!(format!("{:.1}", tcpa_minutes(-2.0)), "0.0");
        assert_eq!(format!("{:.1}", tcpa_minutes(-4.0)), "-0.1");
        assert_eq!(format!("{:.1}", tcpa_minutes(90.0)), "1.5");
    }

    #[test]
    fn a_target_seen_from_own_ship_held_past_dead_reckoning_is_relative_already() {
        // Own ship last at 5 m/s east, its position held (dead reckoning ended): the plots
        // stand about a position that does not move, so a track closing from dead ahead at
        // 5 m/s is closing at 5 m/s relative: CPA 0 in 200 s. Own ship's last velocity
        // taken off it again made it 7.1 m/s on 225°, CPA 707 m in 100 s.
        let mut own = OwnShip::at([0.0, 0.0], [5.0, 0.0]);
        own.quality.dead_reckoning_s = Some(400.0);
        own.quality.motion_known = false;
        let t = settled([0.0, 1000.0], [0.0, -5.0]);
        let d = TargetData::new(&own, &t);
        assert!(d.cpa_m < 1.0 && (d.tcpa_s - 200.0).abs() < 0.5, "{d:?}");
        assert!((d.rel_speed_mps - 5.0).abs() < 1e-3, "{d:?}");
        assert!(!d.true_motion_known);
        // Dead reckoning still on (the position moves on at the last velocity): the tracks
        // are over ground, own ship's velocity is taken off.
        own.quality.dead_reckoning_s = Some(60.0);
        own.quality.motion_known = true;
        let d = TargetData::new(&own, &t);
        assert!((d.rel_speed_mps - 50f32.sqrt()).abs() < 1e-3, "{d:?}");
        // Lost 60 s after the first fix, the motion not yet measured: dead reckoned all the
        // same (straight on at the estimate), so the estimate is taken off.
        own.quality.motion_known = false;
        let d = TargetData::new(&own, &t);
        assert!((d.rel_speed_mps - 50f32.sqrt()).abs() < 1e-3, "{d:?}");
        // No fix yet: at the origin, stopped, whatever velocity it holds.
        let mut unknown = OwnShip::unknown();
        unknown.velocity_mps = [5.0, 0.0];
        let d = TargetData::new(&unknown, &t);
        assert!(d.cpa_m < 1.0, "{d:?}");
    }

    #[test]
    fn a_target_with_next_to_no_relative_motion_shows_no_tcpa_of_hours() {
        // Both stopped, the target's track drifting 0.07 kn away 1 NM off (its velocity's
        // noise): it keeps its range, so its CPA is that range and its TCPA 0, and its
        // relative course is not shown (the trial's moored boat read CPA 0.00 NM, TCPA
        // −177 min, relative course 316.4).
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let still = TargetData::new(&own, &settled([0.0, 1852.0], [0.0, 0.0343]));
        assert_eq!((still.cpa_m, still.tcpa_s), (1852.0, 0.0));
        let row = |d: TargetData| table(&[d], &AlarmLimits::default());
        let fields: Vec<String> = row(still)
            .lines()
            .nth(1)
            .unwrap()
            .split_whitespace()
            .map(String::from)
            .collect();
        assert_eq!(
            fields[6..10],
            ["1.00", "0.0", "---", "0.1"],
            "{}",
            row(still)
        );
        // Drifting away at 0.3 kn: its TCPA is −200 min, shown as beyond the field; one
        // minute off is shown as it is.
        let t = settled([0.0, 1852.0], [0.0, 0.3 * MPS_PER_KNOT]);
        let d = TargetData::new(&own, &t);
        assert!((tcpa_minutes(d.tcpa_s) + 200.0).abs() < 1.0, "{}", d.tcpa_s);
        assert!(row(d).contains(" <-99.9 "), "{}", row(d));
        let coming = TargetData {
            tcpa_s: -d.tcpa_s,
            ..d
        };
        assert!(row(coming).contains(" >99.9 "), "{}", row(coming));
        let soon = TargetData { tcpa_s: 60.0, ..d };
        assert!(row(soon).contains(" 1.0 "), "{}", row(soon));
        assert_eq!(tcpa_text(99.9 * 60.0), "99.9");
        assert_eq!(tcpa_text(-100.0 * 60.0), "<-99.9");
    }

    #[test]
    fn a_target_keeping_its_range_raises_no_alarm() {
        // Own ship moored and a moored boat 200 m off found standing still: no relative
        // motion, TCPA 0 and CPA the range, inside the limits, but not approaching. The
        // same boat drifting 1 kn towards own ship does alarm.
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let t = settled([0.0, 200.0], [0.0, 0.0]);
        let d = TargetData::new(&own, &t);
        assert_eq!((d.cpa_m, d.tcpa_s), (200.0, 0.0));
        assert!(!d.dangerous(&AlarmLimits::default()));
        // Shown still, it has no course to show: `---` where a moving one shows 000.0.
        let row = table(&[d], &AlarmLimits::default());
        let fields: Vec<&str> = row.lines().nth(1).unwrap().split_whitespace().collect();
        assert_eq!((fields[4], fields[5]), ("---", "0.0"), "{row}");
        let drifting = TargetData::new(
            &own,
            &TrackState {
                velocity_mps: [0.0, -0.5],
                ..t
            },
        );
        assert!(drifting.dangerous(&AlarmLimits::default()));
        // Own ship's GNSS moored reads 0.1 kn in some direction (a new user's trial): the
        // boat still keeps its range, whichever way the noise points (at 1 mm/s it alarmed).
        for course_deg in [0.0f32, 90.0, 180.0, 270.0] {
            let c = course_deg.to_radians();
            let v = 0.1 * MPS_PER_KNOT;
            let jitter = OwnShip::at([0.0, 0.0], [v * c.sin(), v * c.cos()]);
            let d = TargetData::new(&jitter, &t);
            assert!(!d.dangerous(&AlarmLimits::default()), "{course_deg}: {d:?}");
        }
    }

    #[test]
    fn a_head_on_target_alarms() {
        let own = OwnShip::at([0.0, 0.0], [0.0, 5.0]);
        let t = settled([0.0, 4000.0], [0.0, -5.0]);
        let d = TargetData::new(&own, &t);
        assert!((d.range_m - 4000.0).abs() < 1e-3);
        assert!(d.bearing_rad.abs() < 1e-6);
        assert!((d.tcpa_s - 400.0).abs() < 1e-3 && d.cpa_m < 1.0);
        assert!((d.rel_speed_mps - 10.0).abs() < 1e-5);
        assert!((d.rel_course_rad.to_degrees() - 180.0).abs() < 1e-3);
        assert!(d.dangerous(&AlarmLimits::default()));
        let text = table(&[d], &AlarmLimits::default());
        assert!(text.contains("ALARM"), "{text}");
        assert!(text.contains("  -- tracked"), "{text}");
        // Before its trend is known the same target shows no motion and does not alarm.
        let young = TargetData {
            trend_known: false,
            ..d
        };
        assert!(!young.dangerous(&AlarmLimits::default()));
        let text = table(&[young], &AlarmLimits::default());
        assert!(!text.contains("ALARM"), "{text}");
        assert_eq!(
            text.lines().nth(1).unwrap().matches("---").count(),
            6,
            "{text}"
        );
    }

    #[test]
    fn the_plain_table_names_a_targets_ais_ship_before_its_alarm() {
        let own = OwnShip::at([0.0, 0.0], [0.0, 5.0]);
        let t = |track: u16, x: f32| TrackState {
            track,
            status: TrackStatus::Confirmed,
            position_m: [x, 4000.0],
            velocity_mps: [0.0, -5.0],
            age_scans: 40,
            hit_history: 0x3ff,
        };
        let targets = [
            TargetData::new(&own, &t(3, 0.0)),
            TargetData::new(&own, &t(4, 9000.0)),
        ];
        let name = |track: u16| {
            if track == 3 {
                "RED FUNNEL".to_string()
            } else {
                String::new()
            }
        };
        let text = table_with_ais(&targets, &AlarmLimits::default(), Some(&name));
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[0].ends_with("AGE  AIS"), "{text}");
        assert!(
            lines[1].ends_with("RED FUNNEL            ALARM CPA/TCPA"),
            "{text}"
        );
        // No name, no alarm: nothing after the age, no trailing blanks.
        assert!(lines[2].ends_with("  40"), "{text}");
    }
}
