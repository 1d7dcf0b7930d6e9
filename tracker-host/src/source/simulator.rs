//! The scenario simulator as a plot source: `tracker_core::sim`'s targets and radar (the IMO
//! sensor model, P_d, clutter, resolution-cell merging), scan by scan, with own ship's and
//! every target's truth attached for scoring.

use tracker_core::sim::{ScanOutput, Scenario, ScenarioConfig, ScenarioKind};

use super::{PlotSource, RadarScan, SourceScan};
use crate::origin::Origin;
use crate::own_ship::recording::RecordedTrack;
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
    /// UTC of the first scan, s since 1970 (the scans' times count from it).
    pub epoch_s: f64,
}

/// Where the simulated own ship goes.
#[derive(Clone, Debug, PartialEq)]
pub enum OwnShipTruth {
    /// The scenario's own ship: 12 kn on a steady course.
    Scenario,
    /// A recorded track (an NMEA recording's fixes), in the local frame of `origin`: the
    /// picture moves with the recorded ship.
    Recorded(RecordedTrack, Origin),
    /// Own ship as the own-ship source estimates it, a scan late (a live NMEA source, whose
    /// future the simulator cannot know).
    Estimated,
}

/// The simulator.
pub struct SimulatorSource {
    scenario: Scenario,
    scans_left: u64,
    scans_done: u64,
    epoch_s: f64,
    own: OwnShipTruth,
    estimate: Option<OwnShip>,
    /// `demo --video`: plots from synthetic spokes instead of the plot model.
    video: Option<super::video::Video>,
}

impl SimulatorSource {
    /// Places own ship and the targets.
    pub fn new(o: &SimulatorOptions) -> Self {
        SimulatorSource::with_own_ship(o, OwnShipTruth::Scenario)
    }

    /// Places the targets around own ship, which goes as `own` says.
    pub fn with_own_ship(o: &SimulatorOptions, own: OwnShipTruth) -> Self {
        let mut scenario = Scenario::new(ScenarioConfig {
            kind: o.scenario,
            ..ScenarioConfig::open_sea(o.targets, o.seed)
        });
        if let OwnShipTruth::Recorded(track, origin) = &own {
            // The targets were placed around (0, 0): start the recording there too.
            let (p, v) = track.at(origin, o.epoch_s);
            scenario.set_own_ship(p.map(|c| c as f32), v.map(|c| c as f32));
        }
        let scan_s = f64::from(scenario.config().scan_s);
        SimulatorSource {
            scenario,
            scans_left: (o.duration_s / scan_s).ceil().max(0.0) as u64,
            scans_done: 0,
            epoch_s: o.epoch_s,
            own,
            estimate: None,
            video: None,
        }
    }

    /// Plots from the synthetic radar's spokes through the plot extractor instead of the
    /// plot model ([`super::video`]); the noise drawn from `seed`.
    ///
    /// # Errors
    /// A synthetic radar setting out of range (none with the defaults).
    pub fn with_video(mut self, seed: u64) -> anyhow::Result<Self> {
        let c = self.scenario.config();
        self.video = Some(super::video::Video::new(
            c.scan_s,
            c.sensor.min_range_m,
            seed,
        )?);
        Ok(self)
    }

    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
}

/// One simulated scan as the session's input, with its truth; `epoch_s` is the UTC of the
/// scenario's start.
pub fn source_scan(out: &ScanOutput, epoch_s: f64) -> SourceScan {
    let v = out.own_velocity_mps;
    let own = OwnShip {
        // The simulated ship steers its course: no current, no leeway.
        heading_rad: Some(tracker_core::geo::course_speed(v).0),
        ..OwnShip::at(out.own_position_m, v)
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
            in_range: t.in_range,
        })
        .collect();
    SourceScan {
        radar: RadarScan {
            scan: out.scan,
            time_s: epoch_s + out.time_ms as f64 / 1000.0,
            plots: out.plots.to_vec(),
        },
        own_ship: Some(own),
        truth: Some(ScanTruth {
            own,
            targets,
            ids_are_mmsi: false,
        }),
        echoes: None,
        heading_sensor_rad: None,
        placed_heading_rad: None,
    }
}

impl PlotSource for SimulatorSource {
    /// UTC from the scenario's epoch or a timed recording's first fix; not from a
    /// recording without a time (its scans count from midnight of a day it never said: a
    /// new user's trial saw `00:00:00Z`, and `RMC` with that time and today's date sent to
    /// the plotter as valid).
    fn time_is_utc(&self) -> bool {
        match &self.own {
            OwnShipTruth::Recorded(track, _) => track.timed,
            OwnShipTruth::Scenario | OwnShipTruth::Estimated => true,
        }
    }

    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        if self.scans_left == 0 {
            return Ok(None);
        }
        self.scans_left -= 1;
        let scan_s = f64::from(self.scenario.config().scan_s);
        let now_s = self.epoch_s + self.scans_done as f64 * scan_s;
        match &self.own {
            OwnShipTruth::Scenario => {}
            OwnShipTruth::Recorded(track, origin) => {
                let (p, v) = track.at(origin, now_s);
                self.scenario
                    .set_own_ship(p.map(|c| c as f32), v.map(|c| c as f32));
            }
            OwnShipTruth::Estimated => {
                if let Some(e) = self.estimate.filter(|e| !e.quality.no_fix_yet) {
                    self.scenario.set_own_ship(e.position_m, e.velocity_mps);
                }
            }
        }
        self.scans_done += 1;
        // The radar sees the scene the scan's truth describes: before it moves on.
        let video_plots = match &mut self.video {
            Some(video) => Some(video.rotation(&self.scenario)?),
            None => None,
        };
        let mut scan = source_scan(&self.scenario.next_scan(), self.epoch_s);
        if let Some(plots) = video_plots {
            if let Some(truth) = &mut scan.truth {
                let points = super::video::plot_points(truth.own.position_m, &plots);
                for t in &mut truth.targets {
                    t.detected = super::video::detects(&points, t.position_m);
                }
            }
            scan.radar.plots = plots;
        }
        Ok(Some(scan))
    }

    fn radar_counts(&self) -> Option<super::radar::RadarCounts> {
        let v = self.video.as_ref()?;
        let s = v.scores();
        Some(super::radar::RadarCounts {
            scans: s.scans,
            plots: s.plots,
            extended: s.extended,
            spokes: s.spokes,
            plot_scores: Some(s),
            ..super::radar::RadarCounts::default()
        })
    }

    fn own_ship_estimate(&mut self, own: &OwnShip) {
        self.estimate = Some(*own);
    }

    /// The sensor model's, for its plots; `None` for plots extracted from synthetic spokes
    /// (`demo --video`), whose accuracy the extractor sets, not the model.
    fn plot_accuracy(&self) -> Option<crate::session::associate::PolarAccuracy> {
        self.video.is_none().then(|| {
            crate::session::associate::PolarAccuracy::of_sensor(&self.scenario.config().sensor)
        })
    }

    fn scan_period_s(&self) -> Option<f64> {
        Some(f64::from(self.scenario.config().scan_s))
    }

    fn scans_left(&self) -> Option<u64> {
        Some(self.scans_left)
    }
}
