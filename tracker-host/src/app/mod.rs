//! The product's commands as wirings of sources, a session and sinks:
//!
//! - [`demo`]: the simulator (a plot source with truth) + session + scorer (+ display);
//! - [`track`]: a recorded plots file (+ a truth file) + session (+ scorer, display).
//!
//! Own ship and the outputs are chosen the same way for both ([`OwnShipOptions`],
//! [`Outputs`]); [`run::Run`] steps the wiring scan by scan.

pub mod demo;
pub mod interrupt;
pub mod run;
pub mod track;

use std::path::PathBuf;

use crate::nmea::input::NmeaIn;
use crate::nmea::{InSpec, OutSpec};
use crate::origin::Origin;
use crate::own_ship::{FromPlotSource, NmeaOptions, NmeaOwnShip, OwnShipSource, SimulatedBridge};
use crate::record::{PlotsRecorder, TracksRecorder, TruthRecorder};
use crate::sink::ScanSink;

/// Where own ship comes from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OwnShipOptions {
    /// Own ship from these NMEA sentences (through the dead-reckoning filter) instead of the
    /// plot source's.
    pub nmea_in: Option<InSpec>,
    /// Further live NMEA sources whose lines are taken with `nmea_in`'s (the AIS
    /// transponder on a port of its own); `nmea_in` must then be live too.
    pub nmea_in_more: Vec<InSpec>,
    /// Own ship from the plot source's own ship sent as NMEA sentences through the
    /// dead-reckoning filter, the sentences recorded to this file (`nmea_in: file:…`
    /// replays them with the same result).
    pub nmea_record: Option<PathBuf>,
    /// The local frame's origin on the globe; by default an NMEA recording's first fix, else
    /// 50°40′N 001°00′W.
    pub origin: Option<Origin>,
    /// Own ship stands at the origin, stopped, while no fix comes (a shore radar, a ship
    /// moored without GNSS; [`crate::own_ship::fixed`]).
    pub fixed_position: bool,
    /// How NMEA is read (talker priority, magnetic variation).
    pub nmea: NmeaOptions,
    /// `nmea_in` opened already, when the run waited on it for the origin
    /// ([`with_live_origin`]): the run takes it rather than opening it again.
    pub opened: OpenedInput,
}

/// A live NMEA source opened before the run, handed to the run's own-ship source once
/// (shared by the options' clones; the first [`own_ship_source`] takes it).
#[derive(Clone, Default)]
pub struct OpenedInput(std::sync::Arc<std::sync::Mutex<Option<NmeaIn>>>);

impl OpenedInput {
    fn new(input: NmeaIn) -> Self {
        OpenedInput(std::sync::Arc::new(std::sync::Mutex::new(Some(input))))
    }

    /// The source, if opened and not taken yet.
    fn take(&self) -> Option<NmeaIn> {
        self.0.lock().ok()?.take()
    }
}

impl std::fmt::Debug for OpenedInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("OpenedInput")
    }
}

/// Options are alike whatever was opened for them.
impl PartialEq for OpenedInput {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl OwnShipOptions {
    /// The origin, as given or the default.
    pub fn origin(&self) -> Origin {
        self.origin.unwrap_or_default()
    }
}

/// Where a run's results go besides the display.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outputs {
    /// Every target as `TTM` and `TLL` each scan, to chart plotters.
    pub nmea_out: Option<OutSpec>,
    /// With `nmea_out`, own ship too (`RMC`, `HDT`, `OSD`), for a plotter without GNSS.
    pub nmea_out_own_ship: bool,
    /// The scans' plots, as a plots file.
    pub record_plots: Option<PathBuf>,
    /// The source's truth, as a truth file.
    pub record_truth: Option<PathBuf>,
    /// Every track every scan.
    pub record_tracks: Option<PathBuf>,
    /// A PNG of the last scan (echoes, plots, targets, AIS) when the run ends.
    pub snapshot: Option<PathBuf>,
    /// The snapshot's range, NM (by default the radar's, else the range scale holding
    /// every plot and target).
    pub snapshot_range_nm: Option<f64>,
    /// How the snapshot draws a ship with a radar target and an AIS target associated.
    pub associated_symbol: crate::session::ais::AssociatedSymbol,
    /// Whose data such a ship is shown and sent with, and alarms on.
    pub associated_data: crate::session::ais::AssociatedData,
}

/// The own-ship source `o` asks for, in the frame of `origin`.
///
/// # Errors
/// Both NMEA in and a recording of the simulation asked for; the source does not open.
pub fn own_ship_source(
    o: &OwnShipOptions,
    origin: Origin,
) -> anyhow::Result<Box<dyn OwnShipSource>> {
    let source: Box<dyn OwnShipSource> = match (&o.nmea_in, &o.nmea_record) {
        (Some(_), Some(_)) => {
            anyhow::bail!("own ship from NMEA input or a recording of the simulation, not both")
        }
        (Some(spec), None) => {
            // A live source's times before its first date are today's (a recording's are its
            // own first date's, set by whoever read it ahead).
            let mut nmea = o.nmea.clone();
            if spec.is_live() {
                nmea.provisional_day = today();
            }
            let input = match o.opened.take() {
                Some(input) => input,
                None => NmeaIn::open(spec)?,
            };
            Box::new(NmeaOwnShip::of(input, origin, &nmea).with_more(&o.nmea_in_more)?)
        }
        (None, Some(path)) => Box::new(SimulatedBridge::create(path, origin)?),
        (None, None) => Box::new(FromPlotSource),
    };
    Ok(if o.fixed_position {
        Box::new(crate::own_ship::fixed::FixedPosition::new(source))
    } else {
        source
    })
}

/// `o` with its origin set, when not given, to a live own-ship source's first fix
/// ([`crate::own_ship::first_fix`]), waited for at start-up; told on standard error.
///
/// # Errors
/// The source does not open.
pub fn with_live_origin(o: &OwnShipOptions) -> anyhow::Result<OwnShipOptions> {
    let mut o = o.clone();
    let Some(spec) = o
        .nmea_in
        .as_ref()
        .filter(|s| s.is_live() && o.origin.is_none())
    else {
        return Ok(o);
    };
    let wait = crate::own_ship::first_fix::FIRST_FIX_WAIT;
    eprintln!(
        "waiting up to {} s for own ship's first fix on the NMEA input, the local frame's origin (--origin LAT,LON starts at once; Ctrl-C ends the run)",
        wait.as_secs()
    );
    let (fix, input) = crate::own_ship::first_fix::first_live_fix(spec, wait)?;
    o.opened = OpenedInput::new(input);
    match fix {
        Some(fix) => {
            eprintln!(
                "origin: {:.5}, {:.5} (own ship's first fix)",
                fix.lat_deg, fix.lon_deg
            );
            o.origin = Some(fix);
        }
        // Ctrl-C while waiting: the run ends before its first scan, nothing to advise.
        None if crate::app::interrupt::interrupted() => {}
        None => {
            let d = Origin::default();
            eprintln!(
                "no fix in {} s: the origin is {:.5}, {:.5}; give --origin LAT,LON near own ship (far from it a radar's plots are refused, an own-ship alarm says so, and a demo's ships sail about it)",
                wait.as_secs(),
                d.lat_deg,
                d.lon_deg
            );
        }
    }
    Ok(o)
}

/// Today, as days since 1970 (a live source's sentences before their first date).
pub fn today() -> i64 {
    crate::own_ship::clock::day_of_s(crate::utc::now_s())
}

/// What of a run is a simulation's, for the outputs to say so.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Simulated {
    /// The targets (`demo`).
    pub targets: bool,
    /// Own ship (`demo` without `--nmea-in`).
    pub own_ship: bool,
}

/// The sinks `o` asks for; the snapshot draws alarms at `alarms`, the session's limits;
/// `simulated`: the targets are a simulation's (`demo`), named so on plotters
/// ([`crate::nmea::targets::TargetsOut::with_simulated`]), and own ship is one's too
/// (`demo` without `--nmea-in`), sent so.
///
/// # Errors
/// A file cannot be created or a socket not opened.
pub fn sinks(
    o: &Outputs,
    simulated: Simulated,
    origin: Origin,
    origin_known: bool,
    alarms: crate::session::target::AlarmLimits,
) -> anyhow::Result<Vec<Box<dyn ScanSink>>> {
    let mut sinks: Vec<Box<dyn ScanSink>> = Vec::new();
    if let Some(spec) = &o.nmea_out {
        let out = crate::nmea::targets::TargetsOut::open(spec, origin, o.nmea_out_own_ship)?
            .with_origin_known(origin_known)
            .with_simulated(simulated.targets)
            .with_simulated_own_ship(simulated.own_ship);
        if simulated.targets {
            eprintln!(
                "nmea out: the demo's targets are simulated: plotters are sent them named SIMnn (SIM NAME as an AIS target)"
            );
        }
        // The port plotters connect to, told (`tcp:0` takes a free one, which was not said).
        if let (OutSpec::Tcp(_), Ok(addr)) = (spec, out.local_addr()) {
            eprintln!("nmea out: plotters connect to TCP port {}", addr.port());
        }
        sinks.push(Box::new(out));
    }
    if let Some(p) = &o.record_plots {
        sinks.push(Box::new(PlotsRecorder::create(p)?));
    }
    if let Some(p) = &o.record_truth {
        sinks.push(Box::new(TruthRecorder::create(p)?));
    }
    if let Some(p) = &o.record_tracks {
        sinks.push(Box::new(TracksRecorder::create(p)?));
    }
    if let Some(p) = &o.snapshot {
        sinks.push(Box::new(
            crate::record::snapshot::Snapshot::new(p.clone(), alarms, o.associated_symbol)
                .with_range_nm(o.snapshot_range_nm)
                .with_simulated(simulated.targets),
        ));
    }
    Ok(sinks)
}
