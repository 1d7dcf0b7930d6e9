//! Own ship at a fixed position: a shore radar (a port's, a bridge's over a river), or a ship
//! moored without GNSS, whose position the operator knows (`--origin LAT,LON
//! --fixed-position`).
//!
//! **Why.** Without a fix own ship is taken at the origin, stopped, but as *unknown*: the
//! alarm "no position fix yet" stands all run, true vectors are refused, the header says `NO
//! FIX` and plotters get a void `RMC` without a position. At a radar that does not move
//! all of that is wrong, and an alarm that never clears hides the ones that matter. Here
//! own ship is the origin, stopped, known: targets' vectors are true (over ground: own
//! ship does not move), CPA and TCPA are from a fixed point.
//!
//! **What stays honest.** The position is the operator's, not a measurement: the header says
//! `FIXED`, and plotters get it in `RMC` with mode `M`, manual input, and status `V`, as
//! NMEA 0183 (4.10, the `RMC` mode indicator's note) requires for every mode but
//! autonomous and differential. A source that does give fixes (`--nmea-in` with a GNSS)
//! takes over from its first fix: its own ship passes unchanged, dead reckoning and its
//! alarms included.

use super::{OwnShip, OwnShipSource};
use crate::source::SourceScan;

/// `inner`'s own ship, placed at the origin and stopped while it has no position fix.
pub struct FixedPosition {
    inner: Box<dyn OwnShipSource>,
}

impl FixedPosition {
    /// Own ship from `inner`, fixed at the origin while `inner` has no fix.
    pub fn new(inner: Box<dyn OwnShipSource>) -> Self {
        FixedPosition { inner }
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
        self.inner.own_ship(scan).map(fixed_at_origin)
    }

    fn nmea_counts(&self) -> Option<super::nav::NavCounts> {
        self.inner.nmea_counts()
    }

    fn finish(&mut self) {
        self.inner.finish();
    }

    fn events(&self) -> Vec<String> {
        self.inner.events()
    }

    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        self.inner.take_ais()
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

    #[test]
    fn a_source_giving_fixes_takes_over() {
        let mut s = FixedPosition::new(Box::new(FixLater(0)));
        let scan = SourceScan::default();
        let first = s.own_ship(&scan).unwrap();
        assert!(first.quality.fixed_position);
        let second = s.own_ship(&scan).unwrap();
        assert!(!second.quality.fixed_position);
        assert_eq!(second.position_m, [5.0, 5.0]);
    }
}
