//! The device's half of a scan, driven over the link (thesis §2.4): own ship and plots
//! out, rough gates back; assignments out, track states back. And what keeps that going
//! when either side restarts: a reset device is noticed (a refused request, or every track
//! gone at once, then a new boot id in the handshake), configured again and its targets
//! re-acquired; a restarted host re-attaches to the live track table.

use std::collections::HashMap;

use anyhow::{bail, Context};
use tracker_core::geo::EastNorth;
use tracker_core::icd::records::{self, GateReference, StateOnGrid};
use tracker_core::icd::varint::Reader;
use tracker_core::icd::{
    AssignmentBatch, Bytes, ErrorCode, GatedPlots, HostToDevice, PlotBatch, TrackCommand,
    TrackState, TrackStatus, TrackerConfig, MAX_ASSIGNMENT_BYTES, MAX_PLOTS_PER_MESSAGE,
    MAX_PLOT_BYTES,
};

use super::associate::Associated;
use crate::link::{Client, DeviceInfo, InprocTransport, Reply, ReportPart};

/// The tracker device at the other end of the link.
pub struct DeviceLink {
    client: Client,
    config: TrackerConfig,
    boot_id: u32,
    /// The device's track table size (its handshake's).
    max_tracks: usize,
    /// Track numbers in the device's last report (to notice them all gone at once).
    last_tracks: Vec<u16>,
    /// The device's last report as held here: the base of the next scan's records.
    held: Held,
    events: crate::event_log::EventLog,
}

/// What the host holds of the device's last whole report ([`tracker_core::icd::records`]):
/// the states it carried and the factors of the gates sent at its scan. The device codes
/// the next scan's gates and states against it when the host names it.
#[derive(Clone, Debug, Default)]
struct Held {
    /// The report's scan, and that scan's time (ms).
    scan: Option<(u32, u64)>,
    states: HashMap<u16, StateOnGrid>,
    factors: HashMap<u16, [i32; 3]>,
}

impl Held {
    /// The base a reply says its records are coded against, if it is the one held.
    fn base(&self, named: Option<u32>) -> Result<Option<(u32, u64)>, InvalidReport> {
        match (named, self.scan) {
            (None, _) => Ok(None),
            (Some(n), Some((scan, t))) if n == scan => Ok(Some((scan, t))),
            (Some(n), _) => Err(InvalidReport(format!(
                "records coded against scan {n}'s report, which the host does not hold"
            ))),
        }
    }
}

/// The device answered a request with an error: it refused it, its state unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Refused {
    /// What was asked.
    pub what: &'static str,
    /// The device's reason.
    pub code: ErrorCode,
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the device refused the {}: {}", self.what, self.code)
    }
}

impl std::error::Error for Refused {}

/// A report from the device that cannot be right (a value not finite or out of range, a
/// plot index past the scan's plots, more tracks than its table holds): not believed.
#[derive(Debug, Clone, PartialEq)]
pub struct InvalidReport(pub String);

impl std::fmt::Display for InvalidReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the device's report is invalid: {}", self.0)
    }
}

impl std::error::Error for InvalidReport {}

/// Largest coordinate believed in a device report, m (the filters' own bound).
const MAX_REPORTED_POSITION_M: f32 = 1.0e7;

/// Fastest target believed in a device report, m/s (about 390 kn).
const MAX_REPORTED_SPEED_MPS: f32 = 200.0;

/// Checks the rough gates against what was sent: at most one per track the device holds,
/// plot indices within the scan's `plots`, finite predictions and positive definite
/// innovation covariances.
fn check_gates(gates: &[GatedPlots], plots: usize, max_tracks: usize) -> Result<(), InvalidReport> {
    if gates.len() > max_tracks {
        return Err(InvalidReport(format!(
            "{} gates for a table of {max_tracks}",
            gates.len()
        )));
    }
    for g in gates {
        let s = g.innovation_cov_m2;
        let finite = g.predicted_m.iter().chain(s.iter()).all(|v| v.is_finite());
        let definite = s[0] > 0.0 && s[2] > 0.0 && s[0] * s[2] > s[1] * s[1];
        let near = g
            .predicted_m
            .iter()
            .all(|v| v.abs() <= MAX_REPORTED_POSITION_M);
        if !(finite && definite && near) {
            return Err(InvalidReport(format!("track {}'s gate {g:?}", g.track)));
        }
        if let Some(p) = g.plots.iter().find(|&&p| usize::from(p) >= plots) {
            return Err(InvalidReport(format!(
                "track {} gated plot {p} of {plots}",
                g.track
            )));
        }
    }
    Ok(())
}

/// Checks track states: at most the table's size, every number finite and in range.
fn check_tracks(tracks: &[TrackState], max_tracks: usize) -> Result<(), InvalidReport> {
    if tracks.len() > max_tracks {
        return Err(InvalidReport(format!(
            "{} tracks for a table of {max_tracks}",
            tracks.len()
        )));
    }
    for t in tracks {
        let finite = t
            .position_m
            .iter()
            .chain(&t.velocity_mps)
            .all(|v| v.is_finite());
        let sane = t
            .position_m
            .iter()
            .all(|v| v.abs() <= MAX_REPORTED_POSITION_M)
            && t.velocity_mps[0].hypot(t.velocity_mps[1]) <= MAX_REPORTED_SPEED_MPS;
        if !(finite && sane) {
            return Err(InvalidReport(format!("track {}: {t:?}", t.track)));
        }
    }
    Ok(())
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

impl DeviceLink {
    /// Handshakes, configures the device's tracker with `config` and empties its table (a
    /// board may still hold an earlier run's tracks).
    ///
    /// # Errors
    /// The handshake fails (no answer, another protocol version) or the device refuses the
    /// configuration.
    pub fn attach(mut client: Client, config: TrackerConfig) -> anyhow::Result<Self> {
        let info = client.hello().context("handshake")?;
        let mut device = DeviceLink {
            client,
            config,
            boot_id: info.boot_id,
            max_tracks: usize::from(info.max_tracks),
            last_tracks: Vec::new(),
            held: Held::default(),
            events: crate::event_log::EventLog::default(),
        };
        device.configure()?;
        device.command(TrackCommand::CancelAll)?;
        Ok(device)
    }

    /// Runs `config` from now on: tracks started from now are made with it, tracks already
    /// held keep the filter they were made with; a device that resets is configured with it.
    ///
    /// # Errors
    /// The link failed or the device refused the configuration (the one before stays).
    pub fn reconfigure(&mut self, config: TrackerConfig) -> anyhow::Result<()> {
        let before = std::mem::replace(&mut self.config, config);
        let done = self.configure();
        if done.is_err() {
            self.config = before;
        }
        done
    }

    fn configure(&mut self) -> anyhow::Result<()> {
        expect_ack(
            self.client.request(&HostToDevice::Configure(self.config))?,
            "configure",
        )
    }

    /// The link client.
    pub fn client(&self) -> &Client {
        &self.client
    }

    /// The configuration the device runs.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// What happened on the link worth telling the operator (a firmware reset, a host
    /// restart), oldest first.
    pub fn events(&self) -> Vec<String> {
        self.events.lines("link")
    }

    /// Sends an operator command (acquire, cancel) to the device.
    ///
    /// # Errors
    /// The link failed, or the device refused the command (an unknown track, a full
    /// table).
    pub fn command(&mut self, command: TrackCommand) -> anyhow::Result<()> {
        let reply = self.client.request(&HostToDevice::Command(command))?;
        // The operator is told what the refusal means for the command given.
        if let Reply::Error(code) = reply {
            let why = match (command, code) {
                // The device's track number, not the target number the operator sees.
                (TrackCommand::Cancel { .. }, ErrorCode::InvalidValue) => {
                    "cancel refused: the target is no longer in the device's table".to_string()
                }
                (TrackCommand::Acquire { .. }, ErrorCode::InvalidValue) => {
                    "acquire refused: the device cannot start a track on that plot".to_string()
                }
                (TrackCommand::Acquire { .. }, ErrorCode::CapacityExceeded) => {
                    "acquire refused: the device's track table is full".to_string()
                }
                _ => {
                    return Err(Refused {
                        what: "command",
                        code,
                    }
                    .into())
                }
            };
            bail!(why);
        }
        expect_ack(reply, "command")?;
        // Tracks the operator dropped are not missing ones.
        match command {
            TrackCommand::CancelAll => self.last_tracks.clear(),
            TrackCommand::Cancel { track } => self.last_tracks.retain(|&t| t != track),
            TrackCommand::Acquire { .. } => {}
        }
        Ok(())
    }

    /// Drops every track after a silence of the radar: first a handshake, since a power
    /// cut that silenced the radar may have reset the device too (its tracks gone, so the
    /// every-track-gone check would not see it after a cancel): a reset device is
    /// configured again, holding no tracks; else its tracks are cancelled.
    ///
    /// # Errors
    /// The link failed, or the device refused the configuration or the cancel.
    pub fn cancel_all_after_silence(&mut self, scan: u32) -> anyhow::Result<()> {
        if !self.recover_from_reset(scan)? {
            self.command(TrackCommand::CancelAll)?;
        }
        Ok(())
    }

    /// One scan through the device: the plots (`plots_m`, local frame, already on the
    /// wire's grid so that both sides hold the same values), the rough gates, `associate`'s
    /// choice, the track states. A device that was reset meanwhile is configured again and
    /// the scan redone.
    ///
    /// # Errors
    /// The link failed, or the device refused a request for a reason other than a reset.
    pub fn scan(
        &mut self,
        scan: u32,
        time_ms: u64,
        plots_m: &[EastNorth],
        associate: impl Fn(&[GatedPlots]) -> Associated,
    ) -> anyhow::Result<(Associated, Vec<TrackState>)> {
        match self.scan_once(scan, time_ms, plots_m, &associate) {
            Ok(done) => Ok(done),
            Err(refused) => {
                let reset = self.recover_from_reset(scan)?;
                // All tracks can also go at once for good reasons (every tentative track
                // failing on the same scan): then the scan is simply redone.
                let vanished = refused.downcast_ref::<TracksGone>().is_some();
                if !reset && !vanished {
                    return Err(refused);
                }

                self.last_tracks.clear();
                self.scan_once(scan, time_ms, plots_m, &associate)
            }
        }
    }

    /// Fails when the device refuses a request or has lost every track.
    fn scan_once(
        &mut self,
        scan: u32,
        time_ms: u64,
        plots: &[EastNorth],
        associate: &impl Fn(&[GatedPlots]) -> Associated,
    ) -> anyhow::Result<(Associated, Vec<TrackState>)> {
        // The base is what was held when the scan began; whatever goes wrong from here, the
        // next scan asks for whole records.
        let held = std::mem::take(&mut self.held);
        // Plots, in parts; the last part's answer is the rough gates.
        let chunks: Vec<&[EastNorth]> = if plots.is_empty() {
            vec![&[]]
        } else {
            plots.chunks(MAX_PLOTS_PER_MESSAGE).collect()
        };
        let parts = u8::try_from(chunks.len()).context("too many plot parts")?;
        let mut gate_parts: Vec<ReportPart> = Vec::new();
        for (i, chunk) in chunks.iter().enumerate() {
            let mut buf = [0u8; MAX_PLOT_BYTES];
            let head = PlotBatch {
                scan,
                time_ms,
                part: i as u8,
                parts,
                base_scan: held.scan.map(|(s, _)| s),
                plots: Bytes(&[]),
            };
            let batch = PlotBatch::pack(head, chunk, &mut buf);
            for reply in self.client.request_all(&HostToDevice::Plots(batch))? {
                match reply {
                    Reply::Ack => {}
                    Reply::Gated(g) => gate_parts.push(g),
                    Reply::Error(code) => {
                        return Err(Refused {
                            what: "plots",
                            code,
                        }
                        .into())
                    }
                    other => bail!("plots of scan {scan} answered {other}"),
                }
            }
        }
        let plot_tenths: Vec<[i32; 2]> = plots.iter().map(|&p| records::tenths(p)).collect();
        let (gates, factors, live) = decode_gates(&held, &gate_parts, &plot_tenths, time_ms)?;
        check_gates(&gates, plots.len(), self.max_tracks)?;
        // Every track gone at once: the device was probably reset (or its table cleared).
        if !self.last_tracks.is_empty() && live == 0 {
            return Err(TracksGone.into());
        }
        let association = associate(&gates);
        let state_parts = self.send_assignments(scan, &association)?;
        let states = decode_states(&held, &state_parts, time_ms)?;
        let tracks: Vec<TrackState> = states.iter().map(StateOnGrid::state).collect();
        check_tracks(&tracks, self.max_tracks)?;
        self.last_tracks = tracks
            .iter()
            .filter(|t| t.status != TrackStatus::Lost)
            .map(|t| t.track)
            .collect();
        let report_scan = state_parts.first().map_or(scan, |p| p.scan);
        self.held = Held {
            scan: Some((report_scan, time_ms)),
            // A lost track is reported once: it is no one's base.
            states: states
                .into_iter()
                .filter(|s| s.status != TrackStatus::Lost)
                .map(|s| (s.track, s))
                .collect(),
            factors,
        };
        Ok((association, tracks))
    }

    fn send_assignments(&mut self, scan: u32, a: &Associated) -> anyhow::Result<Vec<ReportPart>> {
        // The device coasts every track not named: only the updates go on the wire.
        let updates: Vec<(u16, u16)> = a
            .assignments
            .iter()
            .filter_map(|x| x.plot.map(|p| (x.track, p)))
            .collect();
        let parts = AssignmentBatch::parts(updates.len(), a.initiate.len());
        let mut states = Vec::new();
        for part in 0..parts {
            let mut buf = [0u8; MAX_ASSIGNMENT_BYTES];
            let batch = AssignmentBatch::pack(scan, (part, parts), &updates, &a.initiate, &mut buf);
            for reply in self.client.request_all(&HostToDevice::Assign(batch))? {
                match reply {
                    Reply::Ack => {}
                    Reply::Tracks(t) => states.push(t),
                    Reply::Error(code) => {
                        return Err(Refused {
                            what: "assignments",
                            code,
                        }
                        .into())
                    }
                    other => bail!("assignments of scan {scan} answered {other}"),
                }
            }
        }
        Ok(states)
    }

    /// After a refused request (or a silence of the radar): handshakes again, and if the
    /// device has a new boot id it was reset. Then it is configured again and the caller redoes the scan; the tracks
    /// come back through initiation. Returns whether it was a reset.
    fn recover_from_reset(&mut self, scan: u32) -> anyhow::Result<bool> {
        let info = self
            .client
            .hello()
            .context("handshake to check for a device reset")?;
        if info.boot_id == self.boot_id {
            return Ok(false);
        }
        self.events.push(format!(
            "scan {scan}: firmware reset detected (boot id {:#010x} -> {:#010x}); configured again, re-acquiring",
            self.boot_id, info.boot_id
        ));
        self.boot_id = info.boot_id;
        self.last_tracks.clear();
        self.held = Held::default();
        self.configure()?;
        Ok(true)
    }

    /// Restarts the host side as a host program restart would: a new client (new decoder,
    /// request ids from 1) on the same link, a handshake, and the device's full, live track
    /// table, which is returned. The device keeps tracking throughout.
    ///
    /// # Errors
    /// The handshake or the track report fails.
    pub fn restart_host(&mut self) -> anyhow::Result<Vec<TrackState>> {
        let placeholder = Client::new(Box::new(InprocTransport::new()));
        let old = std::mem::replace(&mut self.client, placeholder);
        let (timeout, retries) = (old.timeout, old.retries);
        let mut client = Client::new(old.into_transport());
        client.timeout = timeout;
        client.retries = retries;
        let info: DeviceInfo = client.hello().context("handshake after the host restart")?;
        self.held = Held::default();
        self.events.push(format!(
            "host restarted: re-attached to {} (boot id {:#010x})",
            info.firmware, info.boot_id
        ));
        if info.boot_id != self.boot_id {
            self.events
                .push("the firmware was reset meanwhile".to_string());
            self.boot_id = info.boot_id;
        }
        let mut parts = Vec::new();
        for reply in client.request_all(&HostToDevice::GetTracks)? {
            match reply {
                Reply::Tracks(t) => parts.push(t),
                other => bail!("track report answered {other}"),
            }
        }
        self.client = client;
        // Whole records: nothing held is needed to read them (the time is not used).
        let states = decode_states(&Held::default(), &parts, 0)?;
        Ok(states.iter().map(StateOnGrid::state).collect())
    }
}

/// A scan's gates as the host reads them: the gates, the Cholesky factors they sent by
/// track (the next base's), and the device's track count.
type Gates = (Vec<GatedPlots>, HashMap<u16, [i32; 3]>, u16);

/// The gates of a scan's gate report, decoded against `held` and the scan's plots (tenths).
fn decode_gates(
    held: &Held,
    parts: &[ReportPart],
    plot_tenths: &[[i32; 2]],
    time_ms: u64,
) -> Result<Gates, InvalidReport> {
    let mut gates = Vec::new();
    let mut factors = HashMap::new();
    let mut live = 0;
    for part in parts {
        live = part.live_tracks;
        let base = held.base(part.base_scan)?;
        let dt_s = base.map_or(0.0, |(_, t)| records::interval_s(t, time_ms));
        let reference = |track: u16| match base {
            Some(_) => GateReference {
                moved_on: held.states.get(&track).map(|s| s.moved_on(dt_s)),
                cholesky_cm: held.factors.get(&track).copied(),
            },
            None => GateReference::default(),
        };
        let plot = |i: u16| plot_tenths.get(usize::from(i)).copied();
        let mut r = Reader::new(&part.records);
        let mut prev = 0;
        while !r.is_empty() {
            let g = records::read_gate(&mut r, prev, reference, plot).map_err(|_| {
                InvalidReport(format!("scan {}: a gate record does not decode", part.scan))
            })?;
            prev = g.track;
            factors.insert(g.track, g.cholesky_cm);
            gates.push(g.gated());
        }
    }
    Ok((gates, factors, live))
}

/// The states of a state report, decoded against `held`.
fn decode_states(
    held: &Held,
    parts: &[ReportPart],
    time_ms: u64,
) -> Result<Vec<StateOnGrid>, InvalidReport> {
    let mut states = Vec::new();
    for part in parts {
        let base = held.base(part.base_scan)?;
        let dt_s = base.map_or(0.0, |(_, t)| records::interval_s(t, time_ms));
        let mut r = Reader::new(&part.records);
        let mut prev = 0;
        while !r.is_empty() {
            let s = records::read_state(
                &mut r,
                prev,
                |track| base.and(held.states.get(&track).copied()),
                dt_s,
            )
            .map_err(|_| {
                InvalidReport(format!(
                    "scan {}: a state record does not decode",
                    part.scan
                ))
            })?;
            prev = s.track;
            states.push(s);
        }
    }
    Ok(states)
}

fn expect_ack(reply: Reply, what: &'static str) -> anyhow::Result<()> {
    match reply {
        Reply::Ack => Ok(()),
        Reply::Error(code) => Err(Refused { what, code }.into()),
        other => bail!("{what}: the device answered {other}"),
    }
}
