//! Own ship at a fixed position: a shore radar (a port's, a bridge's over a river), or a ship
//! moored without GNSS, whose position the operator knows (`--origin LAT,LON
//! --fixed-position`).
//!
//! **Why.** Without a fix own ship is taken at the origin, stopped, but as *unknown*: the
//! alarm "no position fix yet" stands all run, true vectors are refused (and `TTM` sends
//! relative ones), the header says `NO FIX` and plotters get a void `RMC` without a
//! position. At a radar that does not move all of that is wrong, and an alarm that never
//! clears hides the ones that matter. Here own ship is the origin, stopped, known: true
//! vectors may be shown and are sent (over ground: own ship does not move), CPA and TCPA
//! are from a fixed point. It is for a radar (`track --radar`, own ship from its capture or
//! `--nmea-in`): `demo` and a plots file carry own ship's position already.
//!
//! **What stays honest.** The position is the operator's, not a measurement: the header says
//! `FIXED`, and plotters (with `--nmea-out-own-ship`) get it in `RMC` with mode `M`, manual
//! input, and status `V`, as NMEA 0183 (2.30 and later, the `RMC` mode indicator's note)
//! requires for every mode but autonomous and differential; `OSD` references its course and
//! speed `M`, manually entered. A plotter may draw no own ship from a void `RMC`. A source
//! that does give fixes (`--nmea-in` with a GNSS) takes over from its first fix, told as an event with its distance from the fixed position (over
//! [`FAR_FROM_FIXED_M`] the origin given is likely not the antenna's position, and every
//! track, placed about it, is cancelled: the trial's 600 km slip left targets coasting at
//! 293 NM on the plotter, with CPA alarms, until they were lost): from then on
//! its own ship passes unchanged, a lost fix dead reckoned and then lost with its alarms,
//! as without `--fixed-position` (a ship with a GNSS is not known to stay put), and never
//! fixed again.

use super::{OwnShip, OwnShipSource};
use crate::source::SourceScan;

/// A first fix this far from the fixed position is told as likely a wrong `--origin`, m.
pub const FAR_FROM_FIXED_M: f32 = 100.0;

/// `inner`'s own ship, placed at the origin and stopped until it has a position fix.
pub struct FixedPosition {
    inner: Box<dyn OwnShipSource>,
    /// A fix has come: `inner`'s own ship is passed unchanged from then on.
    fix_came: bool,
    /// … over [`FAR_FROM_FIXED_M`] from the fixed position, not yet taken.
    moved: bool,
    events: Vec<String>,
}

impl FixedPosition {
    /// Own ship from `inner`, fixed at the origin until `inner` has a fix.
    pub fn new(inner: Box<dyn OwnShipSource>) -> Self {
        FixedPosition {
            inner,
            fix_came: false,
            moved: false,
            events: Vec::new(),
        }
    }
}

/// `own` with no fix yet placed at the origin, stopped, its position fixed (heading and
/// heading alarms kept); `own` with a fix unchanged.
pub fn fixed_at_origin(own: OwnShip) -> OwnShip {
    if !own.quality.no_fix_yet {
        return own;
    }
    let mut fixed = own;
    fixed.position_m = [0.0, 0.0];
    fixed.velocity_mps = [0.0, 0.0];
    fixed.quality.no_fix_yet = false;
    fixed.quality.motion_known = true;
    fixed.quality.dead_reckoning_s = None;
    fixed.quality.fixed_position = true;
    fixed
}

impl OwnShipSource for FixedPosition {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let own = self.inner.own_ship(scan)?;
        if self.fix_came {
            return Ok(own);
        }
        if own.quality.no_fix_yet {
            return Ok(fixed_at_origin(own));
        }
        self.fix_came = true;
        let off_m = own.position_m[0].hypot(own.position_m[1]);
        self.moved = off_m > FAR_FROM_FIXED_M;
        let check = if self.moved {
            " (is --origin the antenna's position?); the targets tracked about the fixed position are cancelled and acquired again"
        } else {
            ""
        };
        self.events.push(format!(
            "own ship's first position fix at scan {}, {off_m:.0} m from the fixed position{check}: own ship follows the fixes from now on",
            scan.radar.scan
        ));
        Ok(own)
    }

    fn nmea_counts(&self) -> Option<super::nav::NavCounts> {
        self.inner.nmea_counts()
    }

    fn finish(&mut self) {
        self.inner.finish();
    }

    fn events(&self) -> Vec<String> {
        let mut e = self.inner.events();
        e.extend(self.events.iter().cloned());
        e
    }

    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        self.inner.take_ais()
    }

    fn take_moved(&mut self) -> bool {
        std::mem::take(&mut self.moved) || self.inner.take_moved()
    }

    fn utc_offset_s(&self) -> f64 {
        self.inner.utc_offset_s()
    }

    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        self.inner.ais_counts()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_ship_without_a_fix_stands_at_the_origin_known_and_keeps_its_heading() {
        let mut unknown = OwnShip::unknown();
        unknown.heading_rad = Some(1.0);
        unknown.quality.heading_lost = true;
        let f = fixed_at_origin(unknown);
        assert_eq!(f.position_m, [0.0, 0.0]);
        assert_eq!(f.sog_kn(), Some(0.0));
        assert_eq!(f.cog_deg(), None, "stopped: no course");
        assert_eq!(f.heading_rad, Some(1.0));
        assert!(f.quality.fixed_position && f.quality.motion_known);
        assert!(!f.quality.no_fix_yet && f.quality.heading_lost);
        let alarms = f.alarms();
        assert!(
            alarms.iter().all(|a| !a.contains("fix")),
            "no 'no fix' alarm: {alarms:?}"
        );
        assert!(
            alarms.iter().any(|a| a.contains("heading lost")),
            "{alarms:?}"
        );
    }

    #[test]
    fn a_fix_passes_unchanged() {
        let mut moving = OwnShip::at([100.0, -50.0], [3.0, 1.0]);
        moving.quality.dead_reckoning_s = Some(40.0);
        assert_eq!(fixed_at_origin(moving), moving);
    }

    /// A source that has a fix from its second scan on.
    struct FixLater(u32);
    impl OwnShipSource for FixLater {
        fn own_ship(&mut self, _: &SourceScan) -> anyhow::Result<OwnShip> {
            self.0 += 1;
            Ok(if self.0 > 1 {
                OwnShip::at([5.0, 5.0], [1.0, 0.0])
            } else {
                OwnShip::unknown()
            })
        }
    }

    /// A source that has a fix on its second scan only.
    struct FixOnce(u32);
    impl OwnShipSource for FixOnce {
        fn own_ship(&mut self, _: &SourceScan) -> anyhow::Result<OwnShip> {
            self.0 += 1;
            Ok(if self.0 == 2 {
                OwnShip::at([300.0, 400.0], [0.0, 0.0])
            } else {
                OwnShip::unknown()
            })
        }
    }

    #[test]
    fn a_source_giving_fixes_takes_over_told_once() {
        let mut s = FixedPosition::new(Box::new(FixLater(0)));
        let scan = SourceScan::default();
        let first = s.own_ship(&scan).unwrap();
        assert!(first.quality.fixed_position);
        assert!(s.events().is_empty());
        let second = s.own_ship(&scan).unwrap();
        assert!(!second.quality.fixed_position);
        assert_eq!(second.position_m, [5.0, 5.0]);
        s.own_ship(&scan).unwrap();
        assert!(!s.take_moved(), "7 m: the tracks stand");
        assert_eq!(s.events().len(), 1, "{:?}", s.events());
        assert!(
            s.events()[0].contains(" 7 m from the fixed position:"),
            "{:?}",
            s.events()
        );
        // A fix 500 m off: the origin is questioned; the fix lost again is not fixed anew.
        let mut s = FixedPosition::new(Box::new(FixOnce(0)));
        s.own_ship(&scan).unwrap();
        s.own_ship(&scan).unwrap();
        assert!(s.events()[0].contains("500 m from the fixed position (is --origin"));
        assert!(s.take_moved() && !s.take_moved(), "taken once");
        let lost = s.own_ship(&scan).unwrap();
        assert!(lost.quality.no_fix_yet && !lost.quality.fixed_position);
    }
}
