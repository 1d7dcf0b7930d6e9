//! The AIS target table: one entry per MMSI, updated by its reports, extrapolated to the
//! time it is looked at, and lost after IEC 62388's times (below), which depend on the
//! class and how fast the ship goes (so on how often it reports).
//!
//! | station | lost after no report for |
//! |---|---|
//! | class A at anchor or moored, ≤ 3 kn | 18 min |
//! | class A, ≤ 14 kn | 60 s |
//! | class A, 14–23 kn | 36 s |
//! | class A, > 23 kn | 30 s |
//! | class B, ≤ 2 kn | 18 min |
//! | class B (CS), > 2 kn | 180 s |
//! | long range (27) | 18 min |
//!
//! (IEC 62388 Ed. 2, annex on AIS target presentation; the same table is printed in
//! chart plotters' manuals, e.g. Icom IC-M510's "lost target" criteria.) A target is
//! *sleeping* (a small triangle, no vector) until the operator activates it or it comes
//! within the activation range ([`AIS_ACTIVATION_RANGE_M`]); CPA/TCPA are computed for all
//! once own ship's motion is known.
//!
//! A ship's static and voyage data (messages 5 and 24) heard before its first position
//! is kept for it, up to [`STATIC_WAIT_S`]: it sends them every 6 minutes, and a ship first
//! heard by its name would otherwise go unnamed until the next.
//!
//! Memory is bounded: at most [`MAX_AIS_TARGETS`], and as many ships' static data waiting
//! for a position; a report from a new MMSI when either is full pushes out the one heard
//! from longest ago (counted).

use std::collections::BTreeMap;

use tracker_core::geo::{self, EastNorth};

use super::report::{AisReport, StationClass};
use crate::origin::Origin;
use crate::own_ship::OwnShip;

/// Most AIS targets held.
pub const MAX_AIS_TARGETS: usize = 2_000;

/// A ship's static data heard before any position of it is kept this long for it, s
/// (18 min, the longest lost time above).
pub const STATIC_WAIT_S: f64 = 1_080.0;

/// AIS targets nearer than this are activated (shown with vector and CPA), m: 6 NM.
pub const AIS_ACTIVATION_RANGE_M: f32 = 6.0 * 1852.0;

/// Positions are extrapolated at most this far past a report, s (a target is lost before
/// that anyway, except a slow one).
const MAX_EXTRAPOLATION_S: f64 = 180.0;

const KNOT_MPS: f64 = 1852.0 / 3600.0;

/// One AIS station, as last heard.
#[derive(Clone, Debug, PartialEq)]
pub struct AisTarget {
    /// MMSI.
    pub mmsi: u32,
    /// What it has said, merged: the last position report's position, motion, heading and
    /// rate of turn, and the newest of each static and voyage field from any message
    /// (name, call sign, type, size, status); its class once a message tells.
    pub last: AisReport,
    /// When its last position came, s (the session's clock).
    pub position_time_s: f64,
    /// When anything from it came last, s.
    pub heard_s: f64,
    /// Position reports taken.
    pub reports: u64,
}

impl AisTarget {
    /// Its motion over ground is reported: SOG and COG, or SOG under 0.05 kn (a ship
    /// stopped has no course; SOG 0.0 with COG "not available", 360°, is how many a moored
    /// one reports). Without, [`AisTarget::position_at`]'s velocity is 0 for want of one,
    /// not a ship stopped.
    pub fn motion_reported(&self) -> bool {
        match (self.last.sog_kn, self.last.cog_deg) {
            (Some(_), Some(_)) => true,
            (Some(sog), None) => sog < 0.05,
            (None, _) => false,
        }
    }

    /// Position at `time_s` and velocity over ground in the local frame of `origin`, m and
    /// m/s, seen from own ship at `own_m` (local, m; [`Origin::to_local_near`]: along the
    /// geodesic from own ship, as the radar measures range and bearing), extrapolated along
    /// COG at SOG from the last report (at most 180 s on). The velocity is the report's
    /// motion over a second in that frame: true north at the ship is turned from the
    /// frame's by the meridians' convergence (0.2° 10 NM east of own ship at 50° N; 6 m
    /// across the track over 180 s at 10 m/s, taken unturned). `None` before a position
    /// report.
    pub fn position_at(
        &self,
        origin: &Origin,
        own_m: [f64; 2],
        time_s: f64,
    ) -> Option<([f64; 2], [f64; 2])> {
        let (lat, lon) = self.last.position_deg?;
        let p = origin.to_local_near(lat, lon, own_m);
        let v = match (self.last.sog_kn, self.last.cog_deg) {
            (Some(sog), Some(cog)) => {
                let (lat1, lon1) = crate::origin::along_geodesic(lat, lon, cog, sog * KNOT_MPS);
                let q = origin.to_local_near(lat1, lon1, own_m);
                [q[0] - p[0], q[1] - p[1]]
            }
            _ => [0.0, 0.0],
        };
        let dt = (time_s - self.position_time_s).clamp(0.0, MAX_EXTRAPOLATION_S);
        Some(([p[0] + v[0] * dt, p[1] + v[1] * dt], v))
    }

    /// The hull's centre for the antenna at `antenna_m` (local, m) and how far off it may
    /// be, m ([`AisTargetData::hull_centre_m`]): turned by the heading, else by the COG
    /// while making way (over [`ORIENTED_BY_COG_KN`]).
    pub fn hull_centre(&self, antenna_m: EastNorth) -> (EastNorth, f32) {
        let Some((forward, starboard)) = self.last.centre_from_antenna_m else {
            return (antenna_m, 0.0);
        };
        let by_cog = || {
            let making_way = self.last.sog_kn.is_some_and(|s| s > ORIENTED_BY_COG_KN);
            self.last.cog_deg.filter(|_| making_way)
        };
        let orientation_deg = self.last.heading_deg.map(f64::from).or_else(by_cog);
        match orientation_deg {
            Some(deg) => {
                let (sin, cos) = (deg as f32).to_radians().sin_cos();
                // Forward (sin, cos) east and north; starboard (cos, −sin).
                let east = forward * sin + starboard * cos;
                let north = forward * cos - starboard * sin;
                ([antenna_m[0] + east, antenna_m[1] + north], 0.0)
            }
            None => (antenna_m, forward.hypot(starboard)),
        }
    }

    /// IEC 62388's lost-target time for this target, s (see the module documentation).
    pub fn lost_after_s(&self) -> f64 {
        let sog = self.last.sog_kn.unwrap_or(0.0);
        let anchored = self
            .last
            .nav_status
            .as_deref()
            .is_some_and(|s| s == "AtAnchor" || s == "Moored");
        match self.last.class {
            Some(StationClass::ClassB) if sog <= 2.0 => 1080.0,
            Some(StationClass::ClassB) => 180.0,
            Some(StationClass::LongRange) => 1080.0,
            _ if anchored && sog <= 3.0 => 1080.0,
            _ if sog <= 14.0 => 60.0,
            _ if sog <= 23.0 => 36.0,
            _ => 30.0,
        }
    }

    /// The name if known, else the MMSI.
    pub fn label(&self) -> String {
        self.last
            .name
            .clone()
            .unwrap_or_else(|| super::mmsi_text(self.mmsi))
    }

    /// The target for a message: the name and the MMSI (`KESTREL (MMSI 235000001)`), or
    /// the MMSI alone while no name is known (not `235000001 (MMSI 235000001)`).
    pub fn described(&self) -> String {
        match &self.last.name {
            Some(name) => format!("{name} (MMSI {})", super::mmsi_text(self.mmsi)),
            None => super::mmsi_text(self.mmsi),
        }
    }
}

/// Takes the static and voyage data `r` carries into `last` (fields `r` lacks are kept).
fn keep_static(last: &mut AisReport, r: &AisReport) {
    last.nav_status = r.nav_status.clone().or(last.nav_status.take());
    last.name = r.name.clone().or(last.name.take());
    last.call_sign = r.call_sign.clone().or(last.call_sign.take());
    last.ship_type = r.ship_type.or(last.ship_type);
    // The antenna's place comes with the size: a message with a size and no place (its
    // reference point not given) leaves none, not an older one.
    if r.size_m.is_some() {
        last.centre_from_antenna_m = r.centre_from_antenna_m;
    }
    last.size_m = r.size_m.or(last.size_m);
}

/// An AIS target as seen from own ship at one time.
#[derive(Clone, Debug, PartialEq)]
pub struct AisTargetData {
    /// MMSI.
    pub mmsi: u32,
    /// Name or MMSI.
    pub label: String,
    /// Position extrapolated to the time, local frame, m.
    pub position_m: EastNorth,
    /// Velocity over ground, m/s.
    pub velocity_mps: EastNorth,
    /// Range from own ship, m.
    pub range_m: f32,
    /// True bearing from own ship, rad.
    pub bearing_rad: f32,
    /// Closest point of approach and the time to it; `None` while own ship's motion is
    /// not known ([`crate::own_ship::OwnShipQuality::motion_known`]): an AIS target's
    /// motion relative to own ship needs own ship's, which the radar measures for its
    /// targets and AIS cannot; `None` too while the target's own is not reported
    /// ([`AisTargetData::motion_reported`]).
    pub cpa: Option<geo::Cpa>,
    /// Speed relative to own ship, m/s; `None` as [`AisTargetData::cpa`].
    pub rel_speed_mps: Option<f32>,
    /// Heading, rad true.
    pub heading_rad: Option<f32>,
    /// The hull's centre, local frame, m: `position_m` (the antenna's) moved by the
    /// antenna's place on the hull along the heading (else the COG while making way);
    /// `position_m` when either is unknown. A radar's echo is of the hull.
    pub hull_centre_m: EastNorth,
    /// How far the hull's centre may be from `hull_centre_m` for want of an orientation,
    /// m: the antenna's distance from the centre when the ship's size is known and
    /// neither heading nor COG is, else 0.
    pub hull_centre_unknown_m: f32,
    /// Age of its last position, s.
    pub age_s: f32,
    /// Activated (inside the activation range): shown with its vector.
    pub active: bool,
    /// Its SOG and COG are reported ([`AisTarget::motion_reported`]); without,
    /// `velocity_mps` is 0 for want of one, and its SOG and COG are shown as unknown.
    pub motion_reported: bool,
}

/// What the table has done.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct AisTableCounts {
    /// Targets taken in (first heard).
    pub targets: u64,
    /// Targets lost (IEC 62388 times).
    pub lost: u64,
    /// Targets pushed out because the table was full, and ships' static data waiting for a
    /// position pushed out because as many were waiting.
    pub crowded_out: u64,
    /// Own ship's own reports (`VDO`), not targets.
    pub own_reports: u64,
}

/// Above this SOG, kn, a ship's COG orients its hull when it sends no heading (at rest,
/// or drifting, the COG says nothing of it).
pub const ORIENTED_BY_COG_KN: f64 = 2.0;

/// The table. See the module documentation.
#[derive(Clone, Debug)]
pub struct AisTargets {
    origin: Origin,
    targets: BTreeMap<u32, AisTarget>,
    /// Static data of ships with no position yet, by MMSI, with when it was last heard.
    waiting: BTreeMap<u32, (f64, AisReport)>,
    counts: AisTableCounts,
}

impl AisTargets {
    /// An empty table in the local frame of `origin`.
    pub fn new(origin: Origin) -> Self {
        AisTargets {
            origin,
            targets: BTreeMap::new(),
            waiting: BTreeMap::new(),
            counts: AisTableCounts::default(),
        }
    }

    /// What the table has done.
    pub fn counts(&self) -> AisTableCounts {
        self.counts
    }

    /// The targets held, by MMSI.
    pub fn targets(&self) -> impl Iterator<Item = &AisTarget> {
        self.targets.values()
    }

    /// One target.
    pub fn get(&self, mmsi: u32) -> Option<&AisTarget> {
        self.targets.get(&mmsi)
    }

    /// Targets held.
    pub fn len(&self) -> usize {
        self.targets.len()
    }

    /// True when none is held.
    pub fn is_empty(&self) -> bool {
        self.targets.is_empty()
    }

    /// Takes a report heard at `time_s`. Own ship's (`VDO`) reports are counted, not held.
    pub fn report(&mut self, time_s: f64, r: &AisReport) {
        if r.own_ship {
            self.counts.own_reports += 1;
            return;
        }
        if !self.targets.contains_key(&r.mmsi) {
            // A target exists once it has a position; static data alone waits for one.
            let Some((lat, lon)) = r.position_deg else {
                self.wait(time_s, r);
                return;
            };
            if self.targets.len() >= MAX_AIS_TARGETS {
                if let Some(oldest) = self
                    .targets
                    .values()
                    .min_by(|a, b| a.heard_s.total_cmp(&b.heard_s))
                    .map(|t| t.mmsi)
                {
                    self.targets.remove(&oldest);
                    self.counts.crowded_out += 1;
                }
            }
            self.counts.targets += 1;
            let known = self.waiting.remove(&r.mmsi).map(|(_, k)| k);
            self.targets.insert(
                r.mmsi,
                AisTarget {
                    mmsi: r.mmsi,
                    last: AisReport {
                        mmsi: r.mmsi,
                        position_deg: Some((lat, lon)),
                        ..known.unwrap_or_default()
                    },
                    position_time_s: time_s,
                    heard_s: time_s,
                    reports: 0,
                },
            );
        }
        let Some(t) = self.targets.get_mut(&r.mmsi) else {
            return;
        };
        t.heard_s = time_s;
        let last = &mut t.last;
        last.msg_type = r.msg_type;
        // A long-range report (27) of a known class A or B ship does not make it one: its
        // lost time stays its own.
        last.class = match (r.class, last.class) {
            (Some(StationClass::LongRange), Some(known)) => Some(known),
            (new, old) => new.or(old),
        };
        if let Some((lat, lon)) = r.position_deg {
            last.position_deg = Some((lat, lon));
            last.sog_kn = r.sog_kn;
            last.cog_deg = r.cog_deg;
            last.heading_deg = r.heading_deg;
            last.rot_deg_min = r.rot_deg_min;
            t.position_time_s = time_s;
            t.reports += 1;
        }
        keep_static(last, r);
    }

    /// Keeps the static data of a ship with no position yet ([`STATIC_WAIT_S`]).
    fn wait(&mut self, time_s: f64, r: &AisReport) {
        if !self.waiting.contains_key(&r.mmsi) && self.waiting.len() >= MAX_AIS_TARGETS {
            if let Some(oldest) = self
                .waiting
                .iter()
                .min_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
                .map(|(m, _)| *m)
            {
                self.waiting.remove(&oldest);
                self.counts.crowded_out += 1;
            }
        }
        let (heard, known) = self.waiting.entry(r.mmsi).or_insert_with(|| {
            (
                time_s,
                AisReport {
                    mmsi: r.mmsi,
                    ..AisReport::default()
                },
            )
        });
        *heard = time_s;
        known.class = r.class.or(known.class);
        keep_static(known, r);
    }

    /// Drops the targets lost by `time_s` (no position report for their lost time: static
    /// data alone does not keep a target); their MMSIs.
    pub fn expire(&mut self, time_s: f64) -> Vec<u32> {
        let lost: Vec<u32> = self
            .targets
            .values()
            .filter(|t| time_s - t.position_time_s > t.lost_after_s())
            .map(|t| t.mmsi)
            .collect();
        for m in &lost {
            self.targets.remove(m);
        }
        self.waiting
            .retain(|_, (heard, _)| time_s - *heard <= STATIC_WAIT_S);
        self.counts.lost += lost.len() as u64;
        lost
    }

    /// Every target seen from `own` at `time_s`, nearest first.
    pub fn picture(&self, own: &OwnShip, time_s: f64) -> Vec<AisTargetData> {
        let f = |x: [f64; 2]| [x[0] as f32, x[1] as f32];
        let own_m = [f64::from(own.position_m[0]), f64::from(own.position_m[1])];
        let mut v: Vec<AisTargetData> = self
            .targets
            .values()
            .filter_map(|t| {
                let (p, vel) = t.position_at(&self.origin, own_m, time_s)?;
                let (p, vel) = (f(p), f(vel));
                let (range_m, bearing_rad) = geo::range_bearing(own.position_m, p);
                let cpa = (own.quality.motion_known && t.motion_reported()).then(|| {
                    crate::session::target::cpa_shown(own.position_m, own.velocity_mps, p, vel)
                });
                let rel = geo::relative_velocity(own.velocity_mps, vel);
                let rel_speed_mps = cpa.map(|_| rel[0].hypot(rel[1]));
                let (hull_centre_m, hull_centre_unknown_m) = t.hull_centre(p);
                Some(AisTargetData {
                    mmsi: t.mmsi,
                    label: t.label(),
                    position_m: p,
                    velocity_mps: vel,
                    range_m,
                    bearing_rad,
                    cpa,
                    rel_speed_mps,
                    heading_rad: t.last.heading_deg.map(|h| f32::from(h).to_radians()),
                    hull_centre_m,
                    hull_centre_unknown_m,
                    age_s: (time_s - t.position_time_s) as f32,
                    active: range_m <= AIS_ACTIVATION_RANGE_M,
                    motion_reported: t.motion_reported(),
                })
            })
            .collect();
        v.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_centre_is_the_antenna_moved_along_the_heading_else_the_cog() {
        let mut t = AisTarget {
            mmsi: 235_000_001,
            last: AisReport {
                centre_from_antenna_m: Some((100.0, 10.0)),
                heading_deg: Some(90),
                sog_kn: Some(10.0),
                cog_deg: Some(0.0),
                ..AisReport::default()
            },
            position_time_s: 0.0,
            heard_s: 0.0,
            reports: 1,
        };
        let near = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-3;
        // Heading east: 100 m forward is east, 10 m to starboard is south.
        let (c, unknown) = t.hull_centre([5.0, 5.0]);
        assert!(near(c, [105.0, -5.0]) && unknown == 0.0, "{c:?}");
        // No heading: the COG (north) while making way.
        t.last.heading_deg = None;
        let (c, _) = t.hull_centre([5.0, 5.0]);
        assert!(near(c, [15.0, 105.0]), "{c:?}");
        // At rest with no heading: the antenna, the centre anywhere within 100.5 m of it.
        t.last.sog_kn = Some(0.0);
        let (c, unknown) = t.hull_centre([5.0, 5.0]);
        assert!(near(c, [5.0, 5.0]) && (unknown - 100.0_f32.hypot(10.0)).abs() < 1e-3);
        // Where the antenna sits is not known: the antenna.
        t.last.centre_from_antenna_m = None;
        assert_eq!(t.hull_centre([5.0, 5.0]), ([5.0, 5.0], 0.0));
    }

    fn report(mmsi: u32, lat: f64, sog: f64, class: StationClass) -> AisReport {
        AisReport {
            msg_type: 1,
            mmsi,
            class: Some(class),
            position_deg: Some((lat, -1.0)),
            sog_kn: Some(sog),
            cog_deg: Some(0.0),
            ..AisReport::default()
        }
    }

    #[test]
    fn a_target_far_from_the_origin_is_placed_about_own_ship() {
        // Own ship 60 NM north of the origin; an AIS target 6 NM due east of it (0.1° of
        // latitude's length at 51°N): 11,112 m at 090°, not the 240 m short the origin's
        // east metres would make it.
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let mut t = AisTargets::new(origin);
        // 6 NM of longitude at 51° N on WGS84 (1,169.961 m a minute).
        let lon = -1.0 + 11_112.0 / (60.0 * 1_169.961);
        t.report(
            0.0,
            &AisReport {
                position_deg: Some((51.0, lon)),
                sog_kn: Some(0.0),
                ..report(1, 51.0, 0.0, StationClass::ClassA)
            },
        );
        let own_m = origin.to_local(51.0, -1.0);
        let own = OwnShip::at([own_m[0] as f32, own_m[1] as f32], [0.0, 0.0]);
        let a = &t.picture(&own, 0.0)[0];
        assert!((a.range_m - 11_112.0).abs() < 1.0, "{}", a.range_m);
        // On own ship's parallel, so a little north of east: the meridians converge by the
        // longitude's difference times sin φ, and the geodesic leaves at half of it.
        let convergence = 0.5 * (lon + 1.0) * 51f64.to_radians().sin();
        let bearing = f64::from(a.bearing_rad).to_degrees();
        assert!((bearing - (90.0 - convergence)).abs() < 0.002, "{bearing}");
    }

    #[test]
    fn a_course_true_at_the_ship_is_turned_by_the_meridians_convergence() {
        // A ship 10 NM east of own ship at 50° N steering 000: its meridian leans towards
        // own ship's by the longitude's difference times sin φ, and so does its velocity
        // about own ship.
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let mut t = AisTargets::new(origin);
        let own_m = [0.0, 0.0];
        let (lat, lon) = origin.to_lat_lon_near([18_520.0, 0.0], own_m);
        let ship = AisReport {
            position_deg: Some((lat, lon)),
            ..report(1, lat, 10.0, StationClass::ClassA)
        };
        t.report(0.0, &ship);
        let (p, v) = t.get(1).unwrap().position_at(&origin, own_m, 0.0).unwrap();
        assert!((p[0] - 18_520.0).abs() < 1e-3 && p[1].abs() < 1e-3, "{p:?}");
        let course = v[0].atan2(v[1]).to_degrees();
        let convergence = (lon + 1.0) * lat.to_radians().sin();
        assert!((convergence - 0.198).abs() < 0.001, "{convergence}");
        assert!((course + convergence).abs() < 0.002, "{course}");
        assert!((v[0].hypot(v[1]) - 10.0 * KNOT_MPS).abs() < 1e-4, "{v:?}");
    }

    #[test]
    fn targets_are_extrapolated_lost_on_time_and_bounded() {
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let mut t = AisTargets::new(origin);
        t.report(0.0, &report(1, 50.0, 10.0, StationClass::ClassA));
        t.report(0.0, &report(2, 50.0, 1.0, StationClass::ClassB));
        // 10 kn north for 30 s: 154 m.
        let (p, _) = t
            .get(1)
            .unwrap()
            .position_at(&origin, [0.0, 0.0], 30.0)
            .unwrap();
        assert!((p[1] - 10.0 * KNOT_MPS * 30.0).abs() < 1e-3, "{p:?}");
        // Class A at 10 kn lost after 60 s, class B at 1 kn after 18 min.
        assert!(t.expire(59.0).is_empty());
        assert_eq!(t.expire(61.0), vec![1]);
        assert!(t.expire(1079.0).is_empty());
        assert_eq!(t.expire(1081.0), vec![2]);
        // Static data alone makes no target; a flood is bounded.
        t.report(
            0.0,
            &AisReport {
                mmsi: 9,
                msg_type: 5,
                ..AisReport::default()
            },
        );
        assert!(t.is_empty());
        for m in 0..10_000u32 {
            t.report(
                f64::from(m),
                &report(100 + m, 50.0, 5.0, StationClass::ClassA),
            );
        }
        assert_eq!(t.len(), MAX_AIS_TARGETS);
        assert_eq!(t.counts().crowded_out, 10_000 - MAX_AIS_TARGETS as u64);
        assert!(t.get(100 + 9_999).is_some() && t.get(100).is_none());
    }

    #[test]
    fn a_target_is_described_by_its_name_and_mmsi_or_its_mmsi_once() {
        let mut t = AisTargets::new(Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        });
        t.report(0.0, &report(311_855_000, 50.0, 10.0, StationClass::ClassA));
        assert_eq!(t.get(311_855_000).unwrap().described(), "311855000");
        t.report(
            1.0,
            &AisReport {
                mmsi: 311_855_000,
                msg_type: 5,
                name: Some("KESTREL".into()),
                ..AisReport::default()
            },
        );
        let target = t.get(311_855_000).unwrap();
        assert_eq!(target.described(), "KESTREL (MMSI 311855000)");
        assert_eq!(target.label(), "KESTREL");
        // Nine digits, the leading zeros kept: 002447004 is a coast station's.
        t.report(2.0, &report(2_447_004, 50.0, 0.0, StationClass::ClassA));
        let station = t.get(2_447_004).unwrap();
        assert_eq!(
            (station.label(), station.described()),
            ("002447004".to_string(), "002447004".to_string())
        );
    }

    /// A ship's name heard before its first position names it once the position comes;
    /// static data waits at most [`STATIC_WAIT_S`], and a flood of it is bounded.
    #[test]
    fn static_data_heard_first_names_the_target_its_position_makes() {
        let mut t = AisTargets::new(Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        });
        let named = |mmsi: u32, name: &str| AisReport {
            mmsi,
            msg_type: 24,
            name: Some(name.into()),
            ..AisReport::default()
        };
        t.report(0.0, &named(211_736_530, "LIBERTAS"));
        assert!(t.is_empty(), "no position: no target yet");
        t.report(600.0, &report(211_736_530, 50.0, 5.0, StationClass::ClassB));
        assert_eq!(t.get(211_736_530).unwrap().label(), "LIBERTAS");
        // Static data older than the wait is forgotten.
        t.report(0.0, &named(5, "OLD"));
        t.expire(STATIC_WAIT_S + 1.0);
        t.report(
            STATIC_WAIT_S + 2.0,
            &report(5, 50.0, 5.0, StationClass::ClassB),
        );
        assert_eq!(t.get(5).unwrap().label(), "000000005");
        // A flood of names is bounded.
        for m in 0..10_000u32 {
            t.report(f64::from(m), &named(1_000_000 + m, "X"));
        }
        assert!(t.waiting.len() <= MAX_AIS_TARGETS);
        assert_eq!(t.counts().crowded_out, 10_000 - MAX_AIS_TARGETS as u64);
    }

    /// While own ship's motion is not known no AIS target has a CPA (it would be taken
    /// from own ship stopped); once known, every one has.
    #[test]
    fn cpa_waits_for_own_ships_motion() {
        let mut t = AisTargets::new(Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        });
        t.report(0.0, &report(1, 50.01, 0.0, StationClass::ClassA));
        let unknown = OwnShip::unknown();
        assert!(t.picture(&unknown, 1.0).iter().all(|a| a.cpa.is_none()));
        let known = OwnShip::at([0.0, 0.0], [0.0, 5.0]);
        let seen = t.picture(&known, 1.0);
        let c = seen[0].cpa.expect("a CPA");
        assert!(c.tcpa_s > 0.0 && c.cpa_m < 1.0, "{c:?}");
        let limits = crate::session::target::AlarmLimits::default();
        assert!(crate::display::ais_dangerous(&seen[0], &limits));
    }

    /// A ship reporting 12 kn and no COG (360, "not available") has no motion to work a CPA
    /// from (it was taken as stopped: CPA its range, an alarm missed or false); a ship
    /// reporting 0.0 kn and no COG is stopped.
    #[test]
    fn a_motion_not_reported_is_not_a_ship_stopped() {
        let mut t = AisTargets::new(Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        });
        let mut fast = report(1, 50.01, 12.0, StationClass::ClassA);
        fast.cog_deg = None;
        let mut moored = report(2, 50.02, 0.0, StationClass::ClassA);
        moored.cog_deg = None;
        t.report(0.0, &fast);
        t.report(0.0, &moored);
        let own = OwnShip::at([0.0, 0.0], [0.0, 5.0]);
        let seen = t.picture(&own, 1.0);
        let of = |mmsi: u32| seen.iter().find(|a| a.mmsi == mmsi).unwrap();
        assert!(!of(1).motion_reported && of(1).cpa.is_none(), "{:?}", of(1));
        assert!(of(2).motion_reported && of(2).cpa.is_some(), "{:?}", of(2));
    }

    /// Own ship moored and an AIS target moored 1.1 km off: CPA the range and TCPA 0,
    /// within the limits, but it keeps its range and raises no alarm.
    #[test]
    fn a_moored_ais_target_beside_own_ship_moored_raises_no_alarm() {
        let mut t = AisTargets::new(Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        });
        t.report(0.0, &report(1, 50.01, 0.0, StationClass::ClassA));
        let limits = crate::session::target::AlarmLimits::default();
        let moored = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let seen = t.picture(&moored, 1.0);
        assert_eq!(seen[0].cpa.map(|c| c.tcpa_s), Some(0.0));
        assert!(seen[0].rel_speed_mps.is_some_and(|v| v < 1e-6));
        assert!(!crate::display::ais_dangerous(&seen[0], &limits));
        // Own ship's GNSS moored reads 0.1 kn (the Merrimac's did, and its moored
        // neighbours alarmed with TCPAs jumping from 10.5 to 2.5 min: a new user's trial),
        // towards the target or across its line of sight: still no alarm.
        let v = 0.1 * tracker_core::geo::MPS_PER_KNOT;
        for velocity in [[0.0, v], [v, 0.0], [-v, 0.0]] {
            let jitter = OwnShip::at([0.0, 0.0], velocity);
            let seen = t.picture(&jitter, 1.0);
            assert!(
                !crate::display::ais_dangerous(&seen[0], &limits),
                "{seen:?}"
            );
        }
        // The boat's own SOG 0.1 kn (a step of AIS's), against own ship's 0.1 kn the other
        // way: 0.2 kn apart, neither under way.
        let mut drifting = report(1, 50.01, 0.1, StationClass::ClassA);
        drifting.cog_deg = Some(90.0);
        t.report(1.5, &drifting);
        let west = OwnShip::at([0.0, 0.0], [-v, 0.0]);
        let seen = t.picture(&west, 1.5);
        assert!(
            !crate::display::ais_dangerous(&seen[0], &limits),
            "{seen:?}"
        );
        // A boat coming at 1 kn from 300 m does alarm (TCPA 9.7 min).
        let mut coming = report(2, 50.0027, 1.0, StationClass::ClassA);
        coming.cog_deg = Some(180.0);
        t.report(2.0, &coming);
        let seen = t.picture(&moored, 2.0);
        let coming = seen.iter().find(|a| a.mmsi == 2).expect("the second boat");
        assert!(crate::display::ais_dangerous(coming, &limits), "{coming:?}");
    }
}
