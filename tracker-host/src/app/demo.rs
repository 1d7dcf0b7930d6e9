//! `tracker-host demo`: the main job. A simulated radar picture runs through the tracker,
//! scan by scan, split as the thesis split it: the device (firmware on QEMU or a board, or
//! the same code in-process) predicts and rough-gates; this host refines the gates,
//! associates, and shows the targets; the scorer holds the tracks to the simulation's truth.
//!
//! With own ship from an NMEA recording (`--nmea-in file:PATH`), the run plays on the
//! recording's clock (it starts at the first fix's date and time) and the simulated picture
//! moves with the recorded ship: the simulator's own ship follows the recording's fixes, so
//! the targets' plots are relative to where the recording says we are. The local frame's
//! origin is the first fix unless `--origin` says otherwise, and the run lasts the
//! recording unless `--duration` says otherwise. With a live NMEA source the picture
//! follows own ship as the source estimates it.

use tracker_core::filter::FilterKind;

use crate::session::associate::Association;
use tracker_core::sim::ScenarioKind;

use super::run::Run;
use super::{own_ship_source, sinks, Outputs, OwnShipOptions};
use crate::link::Client;
use crate::nmea::InSpec;
use crate::own_ship::recording::RecordedTrack;
use crate::session::target::AlarmLimits;
use crate::session::{Session, SessionConfig};
use crate::source::simulator::{OwnShipTruth, SimulatorOptions, SimulatorSource};

/// The demo's default start: 2026-01-01 00:00:00 UTC (s since 1970).
pub const DEFAULT_EPOCH_S: f64 = 1_767_225_600.0;

/// What the demo runs.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoOptions {
    /// The simulated picture.
    pub simulator: SimulatorOptions,
    /// With own ship from an NMEA recording, run for the recording's length instead of
    /// `simulator.duration_s`.
    pub duration_from_recording: bool,
    /// The filter every track runs.
    pub filter: FilterKind,
    /// How plots are associated and which start tracks.
    pub association: Association,
    /// The CPA/TCPA alarm limits.
    pub alarms: AlarmLimits,
    /// Where own ship comes from (by default the simulation's truth).
    pub own_ship: OwnShipOptions,
    /// Where results go.
    pub outputs: Outputs,
    /// Plots from synthetic spokes through the plot extractor instead of the plot model.
    pub video: bool,
    /// Real traffic instead of the scenario: recorded AIS tracks as the truth.
    pub ais_truth: Option<crate::source::ais_truth::AisTruthOptions>,
}

impl DemoOptions {
    /// `targets` targets of `scenario` from `seed` for `duration_s`, tracked with `filter`,
    /// starting at [`DEFAULT_EPOCH_S`], own ship from the simulation, no outputs.
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
                epoch_s: DEFAULT_EPOCH_S,
            },
            duration_from_recording: false,
            filter,
            association: Association::default(),
            alarms: AlarmLimits::default(),
            own_ship: OwnShipOptions::default(),
            outputs: Outputs::default(),
            video: false,
            ais_truth: None,
        }
    }
}

/// Wires the demo: the simulator, the session over `client`, the outputs.
///
/// # Errors
/// The device does not attach, a recording holds no fix, or an own-ship source or output
/// does not open.
pub fn start(client: Client, o: &DemoOptions) -> anyhow::Result<Run> {
    let mut simulator = o.simulator;
    let mut own_ship = crate::app::with_live_origin(&o.own_ship)?;
    let truth = match &o.own_ship.nmea_in {
        Some(InSpec::File(path)) => {
            let track = RecordedTrack::read(path, &o.own_ship.nmea)?;
            track.tell_set_apart(path);
            let origin = o.own_ship.origin.unwrap_or(track.first_position());
            own_ship.origin = Some(origin);
            own_ship.nmea.provisional_day = crate::own_ship::clock::day_of_s(track.start_s());
            own_ship.nmea.recording_window_s = Some(track.window_s());
            simulator.epoch_s = track.start_s();
            if o.duration_from_recording {
                // Through the last fix: the last scan at or after it, so the recording is
                // read to its end (scans every period from the first fix; a span of 4 s
                // ended at the scan of 2.5 s, a third of a 10 Hz recording unread).
                let scan_s = f64::from(tracker_core::sim::ScenarioConfig::open_sea(0, 0).scan_s);
                simulator.duration_s = track.span_s().max(1.0) + scan_s;
            }
            OwnShipTruth::Recorded(track, origin)
        }
        Some(_) => OwnShipTruth::Estimated,
        None => OwnShipTruth::Scenario,
    };
    let origin = own_ship.origin();
    let source: Box<dyn crate::source::PlotSource> = match &o.ais_truth {
        Some(a) => Box::new(crate::source::ais_truth::AisTruthSource::open(a, &origin)?),
        None => {
            let mut source = SimulatorSource::with_own_ship(&simulator, truth);
            if o.video {
                source = source.with_video(simulator.seed)?;
            }
            Box::new(source)
        }
    };
    let own = own_ship_source(&own_ship, origin)?;
    let config = SessionConfig {
        association: o.association,
        alarms: o.alarms,
        ..SessionConfig::tracking(o.filter)
    };
    let session = Session::start(client, config)?;
    // The origin is own ship's when given or a recording's first fix (the simulator's own
    // ship always has a fix).
    let simulated = super::Simulated {
        targets: true,
        own_ship: o.own_ship.nmea_in.is_none(),
    };
    let sinks = sinks(
        &o.outputs,
        simulated,
        origin,
        own_ship.origin.is_some(),
        o.alarms,
    )?;
    Ok(Run::new(source, own, session, sinks)
        .with_origin(origin)
        .with_associated_data(o.outputs.associated_data))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::InprocTransport;
    use crate::nmea::bridge::own_ship_sentences;
    use crate::origin::Origin;
    use std::io::Write as _;

    /// Run for a recording's length, the demo reads it to its end: the last scan comes at
    /// or after the last fix (a 4 s recording at 10 Hz ended at the scan of 2.5 s, its last
    /// third unread).
    #[test]
    fn a_recording_is_read_to_its_end() {
        let origin = Origin::default();
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for k in 0..=40 {
            let t = DEFAULT_EPOCH_S + 0.1 * f64::from(k);
            for l in own_ship_sentences([0.0, 0.3 * f64::from(k)], [0.0, 3.0], &origin, t) {
                file.write_all(l.as_bytes()).unwrap();
            }
        }
        file.flush().unwrap();
        let mut o = DemoOptions::new(ScenarioKind::OpenSea, 2, 1, 600.0, FilterKind::KalmanCv);
        o.duration_from_recording = true;
        o.own_ship.nmea_in = Some(InSpec::File(file.path().to_path_buf()));
        let mut run = start(Client::new(Box::new(InprocTransport::new())), &o).unwrap();
        while run.step().unwrap().is_some() {}
        run.finish().unwrap();
        let c = run.nmea_counts().unwrap();
        assert_eq!(c.after_last_scan, 0, "{c}");
        assert!(c.used > 0, "{c}");
    }
}
