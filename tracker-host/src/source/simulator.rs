//! The scenario simulator as a plot source: `tracker_core::sim`'s targets and radar (the IMO
//! sensor model, P_d, clutter, resolution-cell merging), scan by scan, with own ship's and
//! every target's truth attached for scoring.

use tracker_core::sim::{ScanOutput, Scenario, ScenarioConfig, ScenarioKind};

use super::{PlotSource, RadarScan, SourceScan};
use crate::own_ship::OwnShip;
use crate::score::{ScanTruth, TargetTruth};

/// What to simulate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimulatorOptions {
    /// Scenario kind.
    pub scenario: ScenarioKind,
    /// Number of targets (at most [`tracker_core::sim::MAX_TARGETS`]).
    pub targets: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// Simulated duration, s: the source ends after the scans that fit in it.
    pub duration_s: f64,
}

/// The simulator, producing `scans` scans.
pub struct SimulatorSource {
    scenario: Scenario,
    scans_left: u64,
}

impl SimulatorSource {
    /// Places own ship and the targets.
    pub fn new(o: &SimulatorOptions) -> Self {
        let scenario = Scenario::new(ScenarioConfig {
            kind: o.scenario,
            ..ScenarioConfig::open_sea(o.targets, o.seed)
        });
        let scan_s = f64::from(scenario.config().scan_s);
        SimulatorSource {
            scenario,
            scans_left: (o.duration_s / scan_s).ceil().max(0.0) as u64,
        }
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
}

/// One simulated scan as the session's input, with its truth.
pub fn source_scan(out: &ScanOutput) -> SourceScan {
    let own = OwnShip {
        position_m: out.own_position_m,
        velocity_mps: out.own_velocity_mps,
    };
    let targets = out
        .truth
        .iter()
        .map(|t| TargetTruth {
            id: u32::from(t.id),
            position_m: t.position_m,
            velocity_mps: t.velocity_mps,
            // Detected means a plot of it is in the scan (not merged into another's).
            detected: out.plot_source.contains(&Some(t.id)),
        })
        .collect();
    SourceScan {
        radar: RadarScan {
            scan: out.scan,
            time_s: out.time_ms as f64 / 1000.0,
            plots: out.plots.to_vec(),
        },
        own_ship: Some(own),
        truth: Some(ScanTruth { own, targets }),
    }
}

impl PlotSource for SimulatorSource {
    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        if self.scans_left == 0 {
            return Ok(None);
        }
        self.scans_left -= 1;
        Ok(Some(source_scan(&self.scenario.next_scan())))
    }

    fn scan_period_s(&self) -> Option<f64> {
        Some(f64::from(self.scenario.config().scan_s))
    }

    fn scans_left(&self) -> Option<u64> {
        Some(self.scans_left)
    }
}
