//! `tracker-host demo`: the main job. A simulated radar picture runs through the tracker,
//! scan by scan, split as the thesis split it: the device (firmware on QEMU or a board, or
//! the same code in-process) predicts and rough-gates; this host refines the gates,
//! associates, and shows the targets; the scorer holds the tracks to the simulation's truth.

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;

use super::run::Run;
use super::{own_ship_source, sinks, Outputs, OwnShipOptions};
use crate::link::Client;
use crate::session::{Session, SessionConfig};
use crate::source::simulator::{SimulatorOptions, SimulatorSource};

/// What the demo runs.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoOptions {
    /// The simulated picture.
    pub simulator: SimulatorOptions,
    /// The filter every track runs.
    pub filter: FilterKind,
    /// Where own ship comes from (by default the simulation's truth).
    pub own_ship: OwnShipOptions,
    /// Where results go.
    pub outputs: Outputs,
}

impl DemoOptions {
    /// `targets` targets of `scenario` from `seed` for `duration_s`, tracked with `filter`,
    /// own ship from the simulation, no outputs.
    pub fn new(
        scenario: ScenarioKind,
        targets: usize,
        seed: u64,
        duration_s: f64,
        filter: FilterKind,
    ) -> Self {
        DemoOptions {
            simulator: SimulatorOptions {
                scenario,
                targets,
                seed,
                duration_s,
            },
            filter,
            own_ship: OwnShipOptions::default(),
            outputs: Outputs::default(),
        }
    }
}

/// Wires the demo: the simulator, the session over `client`, the outputs.
///
/// # Errors
/// The device does not attach, or an own-ship source or output does not open.
pub fn start(client: Client, o: &DemoOptions) -> anyhow::Result<Run> {
    let source = SimulatorSource::new(&o.simulator);
    let own_ship = own_ship_source(&o.own_ship)?;
    let session = Session::start(client, SessionConfig::tracking(o.filter))?;
    Ok(Run::new(
        Box::new(source),
        own_ship,
        session,
        sinks(&o.outputs, o.own_ship.origin)?,
    ))
}
