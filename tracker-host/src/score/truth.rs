//! Ground truth for scoring: own ship and every target at a scan.

use tracker_core::geo::EastNorth;

use crate::own_ship::OwnShip;

/// One target's truth at a scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TargetTruth {
    /// The target's identity (the simulator's number, an MMSI, a truth file's `target`).
    pub id: u32,
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity, m/s.
    pub velocity_mps: EastNorth,
    /// True when the scan holds a plot of this target (not missed, not merged into
    /// another's): the confirmation delay counts from its first detection.
    pub detected: bool,
    /// Inside the radar's range (between its blind range and its maximum): OSPA, GOSPA and
    /// continuity count only such targets.
    pub in_range: bool,
}

/// The truth at one scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanTruth {
    /// Own ship's true state (CPA and TCPA are scored from it).
    pub own: OwnShip,
    /// Every target.
    pub targets: Vec<TargetTruth>,
    /// The targets' ids are their MMSIs (real traffic with AIS): radar/AIS pairing can be
    /// scored.
    pub ids_are_mmsi: bool,
}
