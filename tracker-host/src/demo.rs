//! `tracker-host demo`: the main job. A simulated radar picture runs through the tracker,
//! scan by scan, split as the thesis split it: the device (firmware on QEMU or a board, or
//! the same code in-process) predicts and rough-gates; this host refines the gates,
//! associates, and shows the targets.

use std::io::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use tracker_core::geo::{self, EastNorth};
use tracker_core::icd::{
    AssignmentBatch, DeviceToHost, FilterChoice, GatedPlots, HostToDevice, NavSample, PlotBatch,
    TrackState, TrackStatus, TrackerConfig, MAX_ASSIGNMENTS_PER_MESSAGE, MAX_PLOTS_PER_MESSAGE,
};
use tracker_core::sim::{ScanOutput, Scenario, ScenarioConfig, ScenarioKind};

use crate::associate::{self, Association, CHI2_2DOF_99};
use crate::evaluate::{Evaluator, Summary};
use crate::link::Client;
use crate::nmea;
use crate::target::{OwnShip, TargetData};

/// Filters the demo can run, with the parameters it uses for them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoFilter {
    /// CV Kalman, q = 0.05 m²/s³, r = (40 m)².
    KalmanCv,
    /// CA Kalman, q = 0.001 m²/s⁵, r = (40 m)².
    KalmanCa,
    /// α-β, α = 0.5, β = 0.167 (Benedict–Bordner).
    AlphaBeta,
    /// α-β-γ, ξ = 0.6.
    AlphaBetaGamma,
    /// SSWT, M = 4, α = 0.5.
    Sswt,
    /// GRNN, teaching sequences 10 and 45 scans, σ from the measured noise.
    Grnn,
}

impl DemoFilter {
    /// The filter's configuration on the device.
    pub fn choice(self) -> FilterChoice {
        let r = PLOT_SIGMA_M * PLOT_SIGMA_M;
        match self {
            DemoFilter::KalmanCv => FilterChoice::KalmanCv { q: 0.05, r },
            DemoFilter::KalmanCa => FilterChoice::KalmanCa { q: 0.001, r },
            DemoFilter::AlphaBeta => FilterChoice::AlphaBeta {
                alpha: 0.5,
                beta: 0.25 / 1.5,
            },
            DemoFilter::AlphaBetaGamma => FilterChoice::AlphaBetaGamma { xi: 0.6 },
            DemoFilter::Sswt => FilterChoice::Sswt {
                window: 4,
                alpha: 0.5,
            },
            DemoFilter::Grnn => FilterChoice::Grnn {
                short: 10,
                long: 45,
            },
        }
    }
}

/// A plot's position error at mid range under the IMO sensor model, m.
pub const PLOT_SIGMA_M: f32 = 40.0;

/// Demo parameters.
#[derive(Clone, Debug)]
pub struct DemoOptions {
    /// Scenario kind.
    pub scenario: ScenarioKind,
    /// Number of targets.
    pub targets: usize,
    /// Seed.
    pub seed: u64,
    /// Simulated seconds per real second; `None` runs as fast as it can.
    pub speedup: Option<f64>,
    /// Simulated duration, s.
    pub duration_s: f64,
    /// The filter every track runs.
    pub filter: DemoFilter,
}

/// One scan as the demo saw it.
#[derive(Clone, Debug)]
pub struct ScanView {
    /// The simulation's output (plots and truth).
    pub sim: ScanOutput,
    /// Plot positions in the local frame.
    pub plots_m: Vec<EastNorth>,
    /// Own ship.
    pub own: OwnShip,
    /// Every track the device reported.
    pub tracks: Vec<TrackState>,
    /// Target data of confirmed and coasting tracks, nearest first.
    pub targets: Vec<TargetData>,
    /// What association did.
    pub association: Association,
    /// Host wall time for the scan, link included.
    pub host_time: Duration,
}

/// The demo: a scenario, a link, and the scores.
pub struct Demo {
    client: Client,
    scenario: Scenario,
    evaluator: Evaluator,
    options: DemoOptions,
    host_times: Vec<Duration>,
    boot_id: u32,
    events: Vec<String>,
    /// Track numbers in the device's last report.
    last_tracks: Vec<u16>,
    /// NMEA with the bridge, when asked for.
    nmea: Option<NmeaLink>,
}

/// NMEA 0183 with the bridge; everything off unless asked for.
#[derive(Clone, Debug, Default)]
pub struct NmeaOptions {
    /// Send every confirmed target as `TTM` and `TLL` here each scan.
    pub out: Option<nmea::OutSpec>,
    /// Take own ship from these sentences (through the dead-reckoning filter) instead of the
    /// simulation's truth.
    pub own_ship_in: Option<nmea::InSpec>,
    /// Take own ship from the simulation's bridge sensors, as NMEA sentences through the
    /// dead-reckoning filter, and write the sentences to this file (a recording that
    /// `own_ship_in: file:…` replays with the same result).
    pub record: Option<PathBuf>,
    /// The local frame's origin on the globe.
    pub origin: nmea::Origin,
}

/// Where own ship comes from when NMEA is in play.
enum OwnShipFeed {
    /// The simulation's sensors, written to a recording.
    Simulated(std::io::BufWriter<std::fs::File>),
    /// An outside source.
    Input(nmea::NmeaIn),
}

struct NmeaLink {
    origin: nmea::Origin,
    out: Option<nmea::NmeaOut>,
    own: Option<(OwnShipFeed, nmea::OwnShipNav)>,
}

impl NmeaLink {
    fn open(o: &NmeaOptions) -> anyhow::Result<Option<Self>> {
        let feed = match (&o.own_ship_in, &o.record) {
            (Some(_), Some(_)) => {
                bail!("own ship from NMEA input or a recording of the simulation, not both")
            }
            (Some(spec), None) => Some(OwnShipFeed::Input(nmea::NmeaIn::open(spec)?)),
            (None, Some(path)) => {
                let f = std::fs::File::create(path)
                    .with_context(|| format!("creating {}", path.display()))?;
                Some(OwnShipFeed::Simulated(std::io::BufWriter::new(f)))
            }
            (None, None) => None,
        };
        if feed.is_none() && o.out.is_none() {
            return Ok(None);
        }
        Ok(Some(NmeaLink {
            origin: o.origin,
            out: o.out.as_ref().map(nmea::NmeaOut::open).transpose()?,
            own: feed.map(|f| (f, nmea::OwnShipNav::new(o.origin))),
        }))
    }

    /// Own ship at the scan: from the sentences due by then, or the truth when own ship
    /// does not come from NMEA.
    fn own_ship(&mut self, sim: &ScanOutput) -> anyhow::Result<OwnShip> {
        let truth = OwnShip {
            position_m: sim.own_position_m,
            velocity_mps: sim.own_velocity_mps,
        };
        let Some((feed, nav)) = self.own.as_mut() else {
            return Ok(truth);
        };
        let t = sim.time_ms as f64 / 1000.0;
        let lines = match feed {
            OwnShipFeed::Simulated(file) => {
                let p = truth.position_m.map(f64::from);
                let v = truth.velocity_mps.map(f64::from);
                let lines = nmea::own_ship_sentences(p, v, &self.origin, t);
                for l in &lines {
                    file.write_all(l.as_bytes())
                        .context("writing the NMEA recording")?;
                }
                file.flush().context("writing the NMEA recording")?;
                lines
            }
            OwnShipFeed::Input(input) => input.lines_until(t),
        };
        for l in &lines {
            nav.feed(l);
        }
        // Before the first position fix own ship stays at the origin, stopped.
        Ok(nav.own_ship_at(t).unwrap_or_default())
    }
}

impl Demo {
    /// Handshakes, configures the device's tracker and sets up the scenario.
    pub fn new(mut client: Client, options: DemoOptions) -> anyhow::Result<Self> {
        let info = client.hello().context("handshake")?;
        let scenario = Scenario::new(ScenarioConfig {
            kind: options.scenario,
            ..ScenarioConfig::open_sea(options.targets, options.seed)
        });
        let mut demo = Demo {
            client,
            scenario,
            evaluator: Evaluator::default(),
            options,
            host_times: Vec::new(),
            boot_id: info.boot_id,
            events: Vec::new(),
            last_tracks: Vec::new(),
            nmea: None,
        };
        demo.configure()?;
        // Start from an empty table: a board may still hold an earlier run's tracks.
        demo.command(tracker_core::icd::TrackCommand::CancelAll)?;
        Ok(demo)
    }

    fn configure(&mut self) -> anyhow::Result<()> {
        let config = TrackerConfig {
            filter: self.options.filter.choice(),
            plot_sigma_m: PLOT_SIGMA_M,
            ..TrackerConfig::DEFAULT
        };
        expect_ack(
            self.client.request(&HostToDevice::Configure(config))?,
            "configure",
        )
    }

    /// What happened on the link worth telling the operator (a firmware reset, a host
    /// restart), oldest first.
    pub fn events(&self) -> &[String] {
        &self.events
    }

    /// After a refused request: handshakes again, and if the device has a new boot id it
    /// was reset. Then it is configured again and the caller redoes the scan; the tracks
    /// come back through initiation. Returns whether it was a reset.
    fn recover_from_reset(&mut self, scan: u32) -> anyhow::Result<bool> {
        let info = self
            .client
            .hello()
            .context("handshake after a refused request")?;
        if info.boot_id == self.boot_id {
            return Ok(false);
        }
        self.events.push(format!(
            "scan {scan}: firmware reset detected (boot id {:#010x} -> {:#010x}); configured again, re-acquiring",
            self.boot_id, info.boot_id
        ));
        self.boot_id = info.boot_id;
        self.last_tracks.clear();
        self.configure()?;
        Ok(true)
    }

    /// Restarts the host side as a host program restart would: a new client (new decoder,
    /// request ids from 1) on the same link, a handshake, and the device's full, live track
    /// table, which is returned. The device keeps tracking throughout.
    pub fn restart_host(&mut self) -> anyhow::Result<Vec<TrackState>> {
        let placeholder = Client::new(Box::new(crate::link::InprocTransport::new()));
        let old = std::mem::replace(&mut self.client, placeholder);
        let (timeout, retries) = (old.timeout, old.retries);
        let mut client = Client::new(old.into_transport());
        client.timeout = timeout;
        client.retries = retries;
        let info = client.hello().context("handshake after the host restart")?;
        self.events.push(format!(
            "host restarted: re-attached to {} (boot id {:#010x})",
            info.firmware, info.boot_id
        ));
        if info.boot_id != self.boot_id {
            self.events
                .push("the firmware was reset meanwhile".to_string());
            self.boot_id = info.boot_id;
        }
        let mut tracks = Vec::new();
        for reply in client.request_all(&HostToDevice::GetTracks)? {
            match reply {
                DeviceToHost::Tracks(t) => tracks.extend(t.tracks),
                other => bail!("track report answered {other:?}"),
            }
        }
        self.client = client;
        Ok(tracks)
    }

    /// Sends an operator command (acquire, cancel) to the device.
    pub fn command(&mut self, command: tracker_core::icd::TrackCommand) -> anyhow::Result<()> {
        use tracker_core::icd::TrackCommand;
        expect_ack(
            self.client.request(&HostToDevice::Command(command))?,
            "command",
        )?;
        // Tracks the operator dropped are not missing ones.
        match command {
            TrackCommand::CancelAll => self.last_tracks.clear(),
            TrackCommand::Cancel { track } => self.last_tracks.retain(|&t| t != track),
            TrackCommand::Acquire { .. } => {}
        }
        Ok(())
    }

    /// The antenna period, s.
    pub fn scan_s(&self) -> f32 {
        self.scenario.config().scan_s
    }

    /// The link client.
    pub fn client(&self) -> &Client {
        &self.client
    }

    /// Runs one scan through the device and the host.
    pub fn step(&mut self) -> anyhow::Result<ScanView> {
        let started = Instant::now();
        let sim = self.scenario.next_scan();
        let own = match self.nmea.as_mut() {
            Some(n) => n.own_ship(&sim)?,
            None => OwnShip {
                position_m: sim.own_position_m,
                velocity_mps: sim.own_velocity_mps,
            },
        };
        let nav = NavSample {
            time_ms: sim.time_ms,
            gps_position_m: Some(own.position_m),
            gps_velocity_mps: Some(own.velocity_mps),
            ..NavSample::default()
        };
        let (plots_m, association, tracks) = match self.scan_on_device(&sim, &own, nav) {
            Ok(done) => done,
            Err(refused) => {
                let reset = self.recover_from_reset(sim.scan)?;
                // All tracks can also go at once for good reasons (every tentative track
                // failing on the same scan): then the scan is simply redone.
                let vanished = refused.downcast_ref::<TracksGone>().is_some();
                if !reset && !vanished {
                    return Err(refused);
                }
                self.last_tracks.clear();
                self.scan_on_device(&sim, &own, nav)?
            }
        };
        let mut targets: Vec<TargetData> = tracks
            .iter()
            .filter(|t| matches!(t.status, TrackStatus::Confirmed | TrackStatus::Coasting))
            .map(|t| TargetData::new(&own, t))
            .collect();
        targets.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        if let Some(NmeaLink {
            out: Some(out),
            origin,
            ..
        }) = self.nmea.as_mut()
        {
            out.send(&nmea::targets_sentences(
                &targets,
                origin,
                sim.time_ms as f64 / 1000.0,
            ));
        }
        self.evaluator
            .scan(&sim, &tracks, self.scenario.config().scan_s);
        let host_time = started.elapsed();
        self.host_times.push(host_time);
        Ok(ScanView {
            sim,
            plots_m,
            own,
            tracks,
            targets,
            association,
            host_time,
        })
    }

    /// The device's part of a scan: own ship, plots, gates, association, assignments.
    /// Fails when the device refuses a request or has lost every track.
    fn scan_on_device(
        &mut self,
        sim: &ScanOutput,
        own: &OwnShip,
        nav: NavSample,
    ) -> anyhow::Result<(Vec<EastNorth>, Association, Vec<TrackState>)> {
        expect_ack(
            self.client.request(&HostToDevice::OwnShip(nav))?,
            "own ship",
        )?;
        // Plots, in parts; the last part's answer is the rough gates.
        let chunks: Vec<&[tracker_core::icd::Plot]> = if sim.plots.is_empty() {
            vec![&[]]
        } else {
            sim.plots.chunks(MAX_PLOTS_PER_MESSAGE).collect()
        };
        let parts = u8::try_from(chunks.len()).context("too many plot parts")?;
        let mut gates: Vec<GatedPlots> = Vec::new();
        for (i, chunk) in chunks.iter().enumerate() {
            let batch = PlotBatch {
                scan: sim.scan,
                time_ms: sim.time_ms,
                part: i as u8,
                parts,
                plots: chunk.iter().copied().collect(),
            };
            for reply in self.client.request_all(&HostToDevice::Plots(batch))? {
                match reply {
                    DeviceToHost::Ack => {}
                    DeviceToHost::Gated(g) => gates.extend(g.gates),
                    other => bail!("plots of scan {} answered {other:?}", sim.scan),
                }
            }
        }
        // Every track gone at once: the device was probably reset (or its table cleared).
        let known = |id: &u16| gates.iter().any(|g| g.track == *id);
        if !self.last_tracks.is_empty() && !self.last_tracks.iter().any(known) {
            return Err(TracksGone.into());
        }
        // The same conversion as the device's, in the same f32 arithmetic.
        let plots_m: Vec<EastNorth> = sim
            .plots
            .iter()
            .map(|p| geo::polar_to_local(own.position_m, p.range_m, p.bearing_rad))
            .collect();
        let association = associate::associate(&gates, &plots_m, CHI2_2DOF_99);
        let tracks = self.send_assignments(sim.scan, &association)?;
        self.last_tracks = tracks
            .iter()
            .filter(|t| t.status != TrackStatus::Lost)
            .map(|t| t.track)
            .collect();
        Ok((plots_m, association, tracks))
    }

    fn send_assignments(&mut self, scan: u32, a: &Association) -> anyhow::Result<Vec<TrackState>> {
        let per = MAX_ASSIGNMENTS_PER_MESSAGE;
        let parts = a
            .assignments
            .len()
            .div_ceil(per)
            .max(a.initiate.len().div_ceil(per))
            .max(1);
        let parts_u8 = u8::try_from(parts).context("too many assignment parts")?;
        let mut tracks = Vec::new();
        for part in 0..parts {
            let batch = AssignmentBatch {
                scan,
                part: part as u8,
                parts: parts_u8,
                assignments: a
                    .assignments
                    .iter()
                    .skip(part * per)
                    .take(per)
                    .copied()
                    .collect(),
                initiate: a
                    .initiate
                    .iter()
                    .skip(part * per)
                    .take(per)
                    .copied()
                    .collect(),
            };
            for reply in self.client.request_all(&HostToDevice::Assign(batch))? {
                match reply {
                    DeviceToHost::Ack => {}
                    DeviceToHost::Tracks(t) => tracks.extend(t.tracks),
                    other => bail!("assignments of scan {scan} answered {other:?}"),
                }
            }
        }
        Ok(tracks)
    }

    /// Scans until the duration is reached, pacing to the speed-up, calling `show` after
    /// each; returns the scores.
    pub fn run(&mut self, mut show: impl FnMut(&ScanView)) -> anyhow::Result<Summary> {
        let scan_s = f64::from(self.scenario.config().scan_s);
        let scans = (self.options.duration_s / scan_s).ceil() as u64;
        let start = Instant::now();
        for k in 0..scans {
            let view = self.step()?;
            show(&view);
            if let Some(x) = self.options.speedup {
                let due = start + Duration::from_secs_f64((k + 1) as f64 * scan_s / x);
                if let Some(wait) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(wait);
                }
            }
        }
        Ok(self.summary())
    }

    /// Adds NMEA 0183 with the bridge: targets out, own ship in (see [`NmeaOptions`]).
    pub fn with_nmea(mut self, options: &NmeaOptions) -> anyhow::Result<Self> {
        self.nmea = NmeaLink::open(options)?;
        Ok(self)
    }

    /// What became of the own-ship sentences, when own ship comes from NMEA.
    pub fn nmea_counts(&self) -> Option<nmea::NavCounts> {
        self.nmea
            .as_ref()?
            .own
            .as_ref()
            .map(|(_, nav)| nav.counts())
    }

    /// Host time of every scan so far, link included.
    pub fn host_times(&self) -> &[Duration] {
        &self.host_times
    }

    /// Scans the configured duration takes.
    pub fn scans_planned(&self) -> u64 {
        (self.options.duration_s / f64::from(self.scan_s())).ceil() as u64
    }

    /// The scores so far.
    pub fn summary(&self) -> Summary {
        self.evaluator.summary(self.scenario.targets().len())
    }
}

/// Every track the device had a scan ago is gone from its gates.
#[derive(Debug)]
struct TracksGone;

impl std::fmt::Display for TracksGone {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the device's tracks are all gone")
    }
}

impl std::error::Error for TracksGone {}

fn expect_ack(reply: DeviceToHost, what: &str) -> anyhow::Result<()> {
    match reply {
        DeviceToHost::Ack => Ok(()),
        other => bail!("{what}: the device answered {other:?}"),
    }
}
