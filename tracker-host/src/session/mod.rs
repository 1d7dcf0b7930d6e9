//! The tracking session: the host half of a scan and nothing else.
//!
//! A [`Session`] takes own ship and one scan of plots (from any source), drives the device
//! over any link (own ship, plots, rough gates back), applies the refined gate and
//! associates (global nearest neighbour), sends the assignments and the plots that start
//! tracks, and turns the device's track states into target data and alarms: a
//! [`ScanReport`] that sinks (the display, the table, NMEA out, recordings, the scorer)
//! consume. It knows nothing of the simulator, of scoring, of terminals or of NMEA.
//!
//! Stone Soup's parts, on the host: [`associate`] is the hypothesiser (refined gate) and the
//! associator (GNN, two stages); the initiator's choice (which plots start tracks) is made there too; the
//! predictor, updater and deleter run on the device.
//!
//! | module | what |
//! |---|---|
//! | [`device`] | the device's half of the scan over the link, reset recovery, host restart |
//! | [`associate`] | refined gate (Mahalanobis, χ²) and GNN (Kuhn–Munkres) |
//! | [`target`] | range, bearing, course, speed, CPA, TCPA, alarms |
//! | [`numbers`] | the target numbers (01–99) the navigator and plotters know targets by |
//! | [`trend`] | when a target's motion is known well enough to show and to alarm on |
//! | [`stationary`] | whether a target stands still, shown then with no motion and associated where it stands |

pub mod ais;
pub mod associate;
pub mod device;
pub mod numbers;
pub mod stationary;
pub mod target;
pub mod trend;

use std::time::{Duration, Instant};

use anyhow::bail;
use tracker_core::filter::{FilterConfig, FilterKind};
use tracker_core::geo::{self, EastNorth};
use tracker_core::icd::fixed::position_on_grid;
use tracker_core::icd::{
    GatedPlots, Plot, TrackCommand, TrackState, TrackStatus, TrackerConfig, HIDDEN_PLOT,
};
use tracker_core::track::LOST_AFTER_COASTS;

use crate::link::{Client, ClientStats};
use crate::own_ship::OwnShip;
use crate::source::RadarScan;
use associate::{Associated, Association, CHI2_2DOF_99};
use device::DeviceLink;
use numbers::TargetNumbers;
use target::{AlarmLimits, TargetData};
use trend::TrendModel;

/// Scan intervals the trend's interval is the median of ([`Session`]).
const TREND_INTERVALS: usize = 5;

/// A plot's position error at mid range under the IMO sensor model, m: the tracking
/// filters' measurement noise.
pub const PLOT_SIGMA_M: f32 = 40.0;

/// How the session tracks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionConfig {
    /// The device's tracker: the filter every track runs, its gates.
    pub tracker: TrackerConfig,
    /// Refined gate: largest Mahalanobis distance² of a plot a track may take.
    pub refined_gate_d2: f64,
    /// How plots are associated and which start tracks.
    pub association: Association,
    /// CPA/TCPA alarm limits.
    pub alarms: AlarmLimits,
    /// The filter kind `tracker` was made from by [`SessionConfig::tracking_plots_of`], so
    /// that a new plot accuracy can remake it ([`Session::set_plot_sigma_m`]); `None` for a
    /// configuration made by hand, which is kept as it is.
    pub filter_kind: Option<FilterKind>,
    /// The plots' accuracy in range and bearing when known (a simulated radar), for the
    /// association's pair cost ([`associate::PlotCovariances`]); `None`: plots as the
    /// filters take them.
    pub plot_accuracy: Option<associate::PolarAccuracy>,
}

impl SessionConfig {
    /// Tracks with `filter` in [`FilterConfig::tracking`]'s configuration for plots of
    /// [`PLOT_SIGMA_M`], the device's default gates, the χ² 99 % refined gate and the
    /// default alarm limits.
    pub fn tracking(filter: FilterKind) -> Self {
        Self::tracking_plots_of(filter, PLOT_SIGMA_M)
    }

    /// As [`SessionConfig::tracking`], for plots of `plot_sigma_m` (m, one axis): a radar
    /// on a short range scale measures to metres, and gates sized for 40 m would join the
    /// echoes of a harbour's moored boats into tracks that wander between them.
    pub fn tracking_plots_of(filter: FilterKind, plot_sigma_m: f32) -> Self {
        let tracker = TrackerConfig {
            plot_sigma_m,
            ..TrackerConfig::DEFAULT
        };
        SessionConfig {
            tracker: TrackerConfig {
                filter: FilterConfig::tracking(filter, plot_sigma_m, tracker.max_speed_mps),
                ..tracker
            },
            refined_gate_d2: CHI2_2DOF_99,
            association: Association::default(),
            alarms: AlarmLimits::default(),
            filter_kind: Some(filter),
            plot_accuracy: None,
        }
    }
}

/// What one scan came to.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanReport {
    /// Scan number (the source's).
    pub scan: u32,
    /// The scan's time on the source's clock, s.
    pub time_s: f64,
    /// Whether that clock is UTC (s since 1970-01-01): a plots file's times may count from
    /// any epoch, and are then shown as such, not as UTC.
    pub time_is_utc: bool,
    /// The bridge's UTC less `time_s`, s: a live NMEA source's UTC when it is more than 5 s
    /// from this computer's clock, the scans' ([`crate::own_ship::OwnShipSource::utc_offset_s`]);
    /// else 0. Own ship is on the bridge's time; so are the UTC shown and sent
    /// ([`ScanReport::utc_s`]).
    pub utc_offset_s: f64,
    /// Own ship the scan was tracked from.
    pub own: OwnShip,
    /// The scan's plots, as received.
    pub plots: Vec<Plot>,
    /// The same plots in the local frame, m (converted as the device converts them).
    pub plots_m: Vec<EastNorth>,
    /// Every track the device reported, in its order.
    pub tracks: Vec<TrackState>,
    /// Target data of confirmed and coasting tracks, numbered, nearest first.
    pub targets: Vec<TargetData>,
    /// Tentative tracks that have had a second plot (shown as acquiring), nearest first;
    /// without numbers (given when a target is tracked).
    pub acquiring: Vec<TargetData>,
    /// Numbered targets shown last scan and gone now (lost), as last seen, with their
    /// numbers (free from the next scan).
    pub ended: Vec<TargetData>,
    /// What association did.
    pub association: Associated,
    /// Targets of firm tracks whose target was hidden in a plot another firm track took
    /// ([`Association::TwoStageUnresolved`]) and has not been seen apart from it since, as
    /// predicted: held by the tracker with their numbers, not among `targets` (not drawn,
    /// not paired with AIS; not sent to a plotter, nor told lost to it) until their
    /// target is seen apart again or they are lost (the loss is told as any other). A
    /// target whose CPA/TCPA alarm is raised is not among them (it is drawn with its
    /// alarm) unless the target drawn nearest it alarms too.
    pub in_echo: Vec<TargetData>,
    /// The plots' range and bearing accuracy they were associated with, when the source
    /// knew it ([`Session::set_plot_accuracy`]).
    pub plot_accuracy: Option<associate::PolarAccuracy>,
    /// The accuracy the device's filters and gates took the plots at, m (one axis:
    /// [`Session::set_plot_sigma_m`]).
    pub plot_sigma_m: f32,
    /// Host wall time for the scan, link included.
    pub host_time: Duration,
    /// Why the scan was not tracked, when it was not: the device refused it or reported
    /// something that cannot be right (the session goes on with the next scan).
    pub skipped: Option<String>,
    /// AIS targets at the scan's time, nearest first, when AIS is read
    /// ([`ais::AisPicture`]); those paired with a radar target are in `paired` and shown
    /// once ([`ScanReport::targets_drawn`], [`ScanReport::ais_drawn`]).
    pub ais: Vec<crate::ais::AisTargetData>,
    /// Radar targets and the AIS targets of the same ship.
    pub paired: Vec<ais::Pairing>,
    /// Radar targets being confirmed as AIS targets' ships ([`ais::Candidate`]): shown as
    /// the AIS target, not apart.
    pub merged: Vec<ais::Candidate>,
    /// The rotation's echoes, when the plots came from a radar (for the display).
    pub echoes: Option<std::sync::Arc<crate::radar::EchoImage>>,
    /// The radar was silent before this scan for longer than a track coasts: every track
    /// was cancelled first, and the targets shown before are in `ended`.
    pub silence: Option<Silence>,
}

/// A silence of the radar longer than a track coasts ([`Session::scan`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Silence {
    /// Time since the scan before, s.
    pub gap_s: f64,
    /// Rotations missed at the antenna period the scans had before it.
    pub rotations_missed: u32,
    /// Numbered targets lost by it.
    pub targets_lost: usize,
}

impl std::fmt::Display for Silence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "RADAR SILENT: no scan for {:.1} s ({} rotations missed): {} targets lost, acquiring again",
            self.gap_s, self.rotations_missed, self.targets_lost
        )
    }
}

impl Silence {
    /// The alarm in a few words, for a narrow alarm box: the figures first.
    pub fn short(&self) -> String {
        format!(
            "RADAR SILENT {:.0} s: {} LOST",
            self.gap_s, self.targets_lost
        )
    }
}

/// A refusal, a report not believed or an answer that never came whole: it costs the scan,
/// not the session.
fn costs_the_scan(e: &anyhow::Error) -> bool {
    e.downcast_ref::<device::Refused>().is_some()
        || e.downcast_ref::<device::InvalidReport>().is_some()
        || matches!(
            e.downcast_ref::<crate::link::RequestError>(),
            Some(crate::link::RequestError::Lost)
        )
}

impl ScanReport {
    /// The scan's UTC, s since 1970-01-01, on the bridge's time (`time_s` with
    /// `utc_offset_s`); `None` when the scans' clock is not UTC.
    pub fn utc_s(&self) -> Option<f64> {
        self.time_is_utc.then_some(self.time_s + self.utc_offset_s)
    }

    /// The scan's time as shown: UTC on the bridge's time, or the plots file's own clock
    /// (`t hh:mm:ss`).
    pub fn time_label(&self) -> String {
        crate::utc::scan_time_label(self.utc_s().unwrap_or(self.time_s), self.time_is_utc)
    }

    /// The radar targets drawn as radar targets: with the AIS symbol for associated ships
    /// ([`ais::AssociatedSymbol::Ais`]), all but those paired or shown as an AIS target
    /// ([`ScanReport::merged`]), which are drawn as that AIS target; with the radar
    /// symbol, all.
    pub fn targets_drawn(
        &self,
        symbol: ais::AssociatedSymbol,
    ) -> impl Iterator<Item = &TargetData> {
        self.targets.iter().filter(move |t| {
            symbol == ais::AssociatedSymbol::Radar
                || (!self.paired.iter().any(|p| p.track == t.track)
                    && !self.merged.iter().any(|c| c.track == t.track))
        })
    }

    /// The AIS targets drawn as AIS triangles: with the AIS symbol for associated ships,
    /// all; with the radar symbol, those neither paired with a radar target nor shown by
    /// one (that radar target is drawn instead).
    pub fn ais_drawn(
        &self,
        symbol: ais::AssociatedSymbol,
    ) -> impl Iterator<Item = &crate::ais::AisTargetData> {
        self.ais.iter().filter(move |a| {
            symbol == ais::AssociatedSymbol::Ais || self.associated_track(a.mmsi).is_none()
        })
    }

    /// The radar target (track) an AIS target is associated with: its pair, else the radar
    /// target shown as it.
    pub fn associated_track(&self, mmsi: u32) -> Option<u16> {
        self.paired
            .iter()
            .find(|p| p.mmsi == mmsi)
            .map(|p| p.track)
            .or_else(|| self.merged.iter().find(|c| c.mmsi == mmsi).map(|c| c.track))
    }

    /// Targets of confirmed and coasting tracks not shown as acquiring
    /// ([`target::shown_status`]).
    pub fn tracked(&self) -> usize {
        self.targets.len() - self.confirmed_acquiring()
    }

    /// Targets shown as being acquired: tentative tracks with a second plot, and confirmed
    /// ones whose motion's trend is not known yet ([`target::shown_status`]; the plotter is
    /// sent the confirmed ones as `Q`, the tentative ones not at all).
    pub fn acquiring(&self) -> usize {
        self.acquiring.len() + self.confirmed_acquiring()
    }

    fn confirmed_acquiring(&self) -> usize {
        self.targets
            .iter()
            .filter(|t| target::is_acquiring(t))
            .count()
    }
}

/// The numbers of the confirmed and coasting tracks among `tracks`.
fn firm_tracks(tracks: &[TrackState]) -> std::collections::BTreeSet<u16> {
    tracks
        .iter()
        .filter(|t| t.status.is_firm())
        .map(|t| t.track)
        .collect()
}

/// The numbers of the tracks among `tracks` reported lost.
fn lost_tracks(tracks: &[TrackState]) -> std::collections::BTreeSet<u16> {
    tracks
        .iter()
        .filter(|t| t.status == TrackStatus::Lost)
        .map(|t| t.track)
        .collect()
}

/// Tracks among `tracks` the device still holds (not reported lost).
fn held_tracks(tracks: &[TrackState]) -> usize {
    tracks
        .iter()
        .filter(|t| t.status != TrackStatus::Lost)
        .count()
}

/// The host half of the tracker.
pub struct Session {
    device: DeviceLink,
    config: SessionConfig,
    /// The first scan's time, s: the device's clock counts milliseconds from it.
    epoch_s: Option<f64>,
    last_time_ms: Option<u64>,
    host_times: Vec<Duration>,
    numbers: TargetNumbers,
    events: crate::event_log::EventLog,
    skipped: u64,
    warned_slow: bool,
    /// Confirmed and coasting tracks at the last scan: they take plots first.
    firm: std::collections::BTreeSet<u16>,
    /// Tracks the last scan reported lost: the device still gates them this scan and drops
    /// them when it applies it, so they take no plot (a plot given to one would start
    /// nothing and be lost with it).
    lost: std::collections::BTreeSet<u16>,
    /// Firm tracks held as hidden in another's plot ([`ScanReport::in_echo`]), each with
    /// the track drawn on that echo.
    in_echo: std::collections::BTreeMap<u16, u16>,
    /// How well the targets' motion is known, for the scan interval and the plots'
    /// accuracy ([`trend`]).
    trend: Option<TrendModel>,
    /// The last few scan intervals, s: the trend's interval is their median, so that a
    /// scan lost or late does not make it (and the minute it counts) twice as long.
    intervals: std::collections::VecDeque<f64>,
    /// Tracks the device holds after its last report (those reported lost are dropped).
    tracks_held: usize,
    /// A silence whose tracks were cancelled, not told yet (its scan was skipped).
    pending_silence: Option<(f64, u32)>,
    /// Which targets stand still ([`stationary`]).
    stationary: stationary::StationaryTest,
}

impl Session {
    /// Attaches to the device behind `client` and configures it.
    ///
    /// # Errors
    /// The handshake fails or the device refuses the configuration.
    pub fn start(client: Client, config: SessionConfig) -> anyhow::Result<Self> {
        Ok(Session {
            device: DeviceLink::attach(client, config.tracker)?,
            config,
            epoch_s: None,
            last_time_ms: None,
            host_times: Vec::new(),
            numbers: TargetNumbers::new(numbers::MAX_TARGET_NUMBER),
            events: crate::event_log::EventLog::default(),
            skipped: 0,
            warned_slow: false,
            firm: Default::default(),
            lost: Default::default(),
            in_echo: Default::default(),
            trend: None,
            intervals: Default::default(),
            tracks_held: 0,
            pending_silence: None,
            stationary: Default::default(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &SessionConfig {
        &self.config
    }

    /// Weighs the plots by `accuracy` in the association from the next scan on
    /// ([`SessionConfig::plot_accuracy`]); `None`: as the device's filters take them.
    pub fn set_plot_accuracy(&mut self, accuracy: Option<associate::PolarAccuracy>) {
        self.config.plot_accuracy = accuracy;
    }

    /// Tracks plots of `plot_sigma_m` (m, one axis) from now on: the device's filter and
    /// gates remade for them ([`SessionConfig::tracking_plots_of`]) for the tracks it starts
    /// from now (those it holds keep theirs), and an event saying so. A radar's plots are as
    /// accurate as its range scale: a live radar's scale is known from its first spoke, and
    /// the operator changes it. Returns whether anything changed: not for the accuracy
    /// already in use (within 1 %), nor for a configuration made by hand
    /// ([`SessionConfig::filter_kind`] `None`).
    ///
    /// # Errors
    /// `plot_sigma_m` is not finite and positive; the link failed or the device refused the
    /// configuration (the one before stays).
    pub fn set_plot_sigma_m(&mut self, plot_sigma_m: f32) -> anyhow::Result<bool> {
        if !(plot_sigma_m.is_finite() && plot_sigma_m > 0.0) {
            bail!("plot accuracy {plot_sigma_m} m is not a positive distance");
        }
        let Some(kind) = self.config.filter_kind else {
            return Ok(false);
        };
        let now = self.config.tracker.plot_sigma_m;
        if (plot_sigma_m - now).abs() <= 0.01 * now {
            return Ok(false);
        }
        let tracker = SessionConfig::tracking_plots_of(kind, plot_sigma_m).tracker;
        self.device.reconfigure(tracker)?;
        self.config.tracker = tracker;
        self.events.push(format!(
            "plots' accuracy now {plot_sigma_m:.1} m (was {now:.1} m): tracks started from now are filtered and gated for it"
        ));
        Ok(true)
    }

    /// The trend model for the median of the last [`TREND_INTERVALS`] scan intervals (with
    /// `interval_s`, this scan's) and the plots' accuracy now, remade when either changed
    /// by more than 1 %; a model that cannot be made leaves the last one.
    fn update_trend(&mut self, interval_s: Option<f64>) {
        let sigma = self.config.tracker.plot_sigma_m;
        if let Some(dt) = interval_s.filter(|dt| dt.is_finite() && *dt > 0.0) {
            if self.intervals.len() == TREND_INTERVALS {
                self.intervals.pop_front();
            }
            self.intervals.push_back(dt);
        }
        let Some(scan_s) = self.scan_interval_s() else {
            return;
        };
        let close = |a: f64, b: f64| (a - b).abs() <= 0.01 * b;
        if self
            .trend
            .is_some_and(|m| close(m.scan_s(), scan_s) && close(m.plot_sigma_m(), f64::from(sigma)))
        {
            return;
        }
        if let Some(m) = TrendModel::new(sigma, scan_s, self.config.tracker.max_speed_mps) {
            self.trend = Some(m);
        }
    }

    /// The median of the last [`TREND_INTERVALS`] scan intervals, s: the antenna period as
    /// the scans have come; `None` before the second scan.
    fn scan_interval_s(&self) -> Option<f64> {
        let mut sorted: Vec<f64> = self.intervals.iter().copied().collect();
        sorted.sort_by(f64::total_cmp);
        sorted.get(sorted.len() / 2).copied()
    }

    /// Rotations missed before a scan `gap_s` after the one before, when that many that
    /// every track would have been lost had they come empty ([`LOST_AFTER_COASTS`]): the
    /// radar was silent (a power cut, a network down, a transmitter on standby). The tracks
    /// are not believed after it: their gates have grown over the gap until they take any
    /// echo, and a harbour's moored boats became targets at 11–13 kn with a CPA alarm after
    /// 35 s of silence (a user trial, 2026-12-04). A professional ARPA loses them and
    /// acquires again.
    fn rotations_missed(&self, gap_s: f64) -> Option<u32> {
        let period_s = self.scan_interval_s()?;
        let missed = (gap_s / period_s).round() - 1.0;
        (missed >= f64::from(LOST_AFTER_COASTS)).then_some(missed.min(f64::from(u32::MAX)) as u32)
    }

    /// Tracks one scan seen from `own`.
    ///
    /// After a silence of more rotations than a confirmed track coasts
    /// ([`LOST_AFTER_COASTS`], at the median of the last scan intervals), every track is
    /// cancelled first and the targets shown are reported lost
    /// ([`ScanReport::ended`]), with an event: tracking starts again from this scan.
    ///
    /// # Errors
    /// A scan not later than the one before (by at least a millisecond), the link failing,
    /// or the device refusing the scan for a reason other than a reset.
    pub fn scan(&mut self, radar: &RadarScan, own: &OwnShip) -> anyhow::Result<ScanReport> {
        let started = Instant::now();
        let epoch = *self.epoch_s.get_or_insert(radar.time_s);
        let since = radar.time_s - epoch;
        if !(since.is_finite() && since >= 0.0) {
            bail!(
                "scan {}: time {} s is before the first scan's",
                radar.scan,
                radar.time_s
            );
        }
        let time_ms = (since * 1000.0).round() as u64;
        if self.last_time_ms.is_some_and(|last| time_ms <= last) {
            bail!(
                "scan {}: time {} s is not after the scan before",
                radar.scan,
                radar.time_s
            );
        }
        let gap_s = self
            .last_time_ms
            .map(|last| (time_ms - last) as f64 / 1000.0);
        let silence = gap_s
            .filter(|_| self.tracks_held > 0)
            .and_then(|gap| Some((gap, self.rotations_missed(gap)?)));
        if silence.is_some() {
            if let Err(e) = self.device.cancel_all_after_silence(radar.scan) {
                if !costs_the_scan(&e) {
                    return Err(e);
                }
                // Not cancelled: the scan is not tracked and its time not taken, so the next
                // scan finds the silence again and tries again.
                let why = format!("scan {} skipped: {e:#}", radar.scan);
                return Ok(self.skip(radar, own, Vec::new(), started, why));
            }
            self.firm.clear();
            self.lost.clear();
            self.in_echo.clear();
            self.stationary.clear();
            self.tracks_held = 0;
            // Told with the scan that is tracked next (this one, unless it is skipped).
            self.pending_silence = silence;
        }
        // Rounded as the wire rounds them, so the device holds the very same plots.
        let plots_m: Vec<EastNorth> = radar
            .plots
            .iter()
            .map(|p| {
                position_on_grid(geo::polar_to_local_f64(
                    own.position_m,
                    p.range_m,
                    p.bearing_rad,
                ))
            })
            .collect();
        let gate = self.config.refined_gate_d2;
        let mode = self.config.association;
        let (firm, lost) = (&self.firm, &self.lost);
        let accuracy = self.config.plot_accuracy.map(|a| {
            let filter_var_m2 = self.config.tracker.plot_sigma_m.powi(2);
            associate::PlotCovariances::polar(&radar.plots, a, filter_var_m2)
        });
        // A target found standing still is associated at where it stands too.
        let standing = self.stationary.standing_m();
        let done = self.device.scan(radar.scan, time_ms, &plots_m, |gates| {
            let live: Vec<GatedPlots> = gates
                .iter()
                .filter(|g| !lost.contains(&g.track))
                .cloned()
                .collect();
            let gates = &live;
            associate::associate(
                mode,
                gates,
                &plots_m,
                gate,
                |t| firm.contains(&t),
                accuracy.as_ref(),
                &standing,
            )
        });
        self.last_time_ms = Some(time_ms);
        let stats = self.device.client().stats();
        if stats.late_answers > 0 && !self.warned_slow {
            self.warned_slow = true;
            self.events.push(format!(
                "scan {}: the device answers more slowly than the link's {:.1} s time-out (raise it with --link-timeout)",
                radar.scan,
                self.device.client().timeout.as_secs_f64()
            ));
        }
        let (association, tracks) = match done {
            Ok(done) => done,
            Err(e) if costs_the_scan(&e) => {
                let why = format!("scan {} skipped: {e}", radar.scan);
                return Ok(self.skip(radar, own, plots_m, started, why));
            }
            Err(e) => return Err(e),
        };
        self.firm = firm_tracks(&tracks);
        self.lost = lost_tracks(&tracks);
        self.tracks_held = held_tracks(&tracks);
        // A silence is no antenna period: it would make the next one look like one.
        self.update_trend(gap_s.filter(|_| silence.is_none()));
        // A target found standing still is shown with no motion (the device's filter keeps
        // its velocity, which gates its next plots in the device's rough gate).
        self.stationary
            .observe(radar.time_s, &tracks, &association.assignments, &plots_m);
        let shown = self.stationary.shown(&tracks);
        let mut numbered = self
            .numbers
            .scan(own, &shown, &self.config.alarms, self.trend.as_ref());
        // A firm track whose target is hidden in a plot another firm track took (two ships
        // in one resolution cell, [`Association::TwoStageUnresolved`]) is kept but not
        // drawn: the radar shows one echo, and a second symbol coasting beside it would
        // show one ship twice (three times beside its AIS target: docs/ais.md). Held until
        // it and the track drawn on its echo are seen apart (each takes a plot on one scan;
        // two scans in a row was tried, docs/ais.md) or either is gone. While they share
        // the echo its one plot may go to either; the symbol stays the one drawn first, not
        // the two swapping scan by scan (a user trial saw a target blink 17 times in 5
        // minutes, each an `L` and a `T` to the plotter).
        let took: std::collections::BTreeSet<u16> = association
            .assignments
            .iter()
            .filter(|a| a.plot.is_some_and(|p| p != HIDDEN_PLOT))
            .map(|a| a.track)
            .collect();
        for &(hidden, taker) in &association.hidden_in {
            if self.in_echo.get(&taker) != Some(&hidden) {
                self.in_echo.insert(hidden, taker);
            }
        }
        self.in_echo.retain(|held, echo| {
            self.firm.contains(held)
                && self.firm.contains(echo)
                && !(took.contains(held) && took.contains(echo))
        });
        let in_echo;
        (in_echo, numbered.tracked) = std::mem::take(&mut numbered.tracked)
            .into_iter()
            .partition(|t| self.in_echo.contains_key(&t.track));
        // … but an alarm is not lost with it: one whose CPA/TCPA alarm is raised is drawn,
        // alarm and all, unless the target drawn nearest it (on the echo it is hidden in)
        // alarms too. Two ships in one cell can be on different courses.
        let limits = &self.config.alarms;
        let alarmed = |t: &TargetData| {
            t.dangerous(limits)
                && numbered
                    .tracked
                    .iter()
                    .min_by(|a, b| {
                        let d = |x: &TargetData| {
                            (x.position_m[0] - t.position_m[0])
                                .hypot(x.position_m[1] - t.position_m[1])
                        };
                        d(a).total_cmp(&d(b))
                    })
                    .is_none_or(|n| !n.dangerous(limits))
        };
        let (shown, in_echo): (Vec<TargetData>, Vec<TargetData>) =
            in_echo.into_iter().partition(|t| alarmed(t));
        if !shown.is_empty() {
            numbered.tracked.extend(shown);
            numbered
                .tracked
                .sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        }
        let silence = self
            .pending_silence
            .take()
            .map(|(gap_s, rotations_missed)| Silence {
                gap_s,
                rotations_missed,
                targets_lost: numbered.ended.len(),
            });
        if let Some(s) = &silence {
            self.events.push(format!(
                "scan {}: {s}; every track was cancelled",
                radar.scan
            ));
        }
        let host_time = started.elapsed();
        self.host_times.push(host_time);
        Ok(ScanReport {
            tracks,
            targets: numbered.tracked,
            acquiring: numbered.acquiring,
            ended: numbered.ended,
            association,
            in_echo,
            silence,
            plot_accuracy: self.config.plot_accuracy,
            plot_sigma_m: self.config.tracker.plot_sigma_m,
            ..Self::report_of(radar, own, plots_m, host_time)
        })
    }

    /// A scan not tracked: `why` told as an event, counted, and its report.
    fn skip(
        &mut self,
        radar: &RadarScan,
        own: &OwnShip,
        plots_m: Vec<EastNorth>,
        started: Instant,
        why: String,
    ) -> ScanReport {
        self.events.push(why.clone());
        self.skipped += 1;
        ScanReport {
            skipped: Some(why),
            plot_accuracy: self.config.plot_accuracy,
            plot_sigma_m: self.config.tracker.plot_sigma_m,
            ..Self::report_of(radar, own, plots_m, started.elapsed())
        }
    }

    /// A scan's report with its plots and nothing tracked: what the tracked and the
    /// skipped scans' reports fill in.
    fn report_of(
        radar: &RadarScan,
        own: &OwnShip,
        plots_m: Vec<EastNorth>,
        host_time: Duration,
    ) -> ScanReport {
        ScanReport {
            scan: radar.scan,
            time_s: radar.time_s,
            time_is_utc: true,
            utc_offset_s: 0.0,
            own: *own,
            plots: radar.plots.clone(),
            plots_m,
            tracks: Vec::new(),
            targets: Vec::new(),
            acquiring: Vec::new(),
            ended: Vec::new(),
            association: Associated::default(),
            in_echo: Vec::new(),
            plot_accuracy: None,
            plot_sigma_m: crate::session::PLOT_SIGMA_M,
            host_time,
            skipped: None,
            ais: Vec::new(),
            paired: Vec::new(),
            merged: Vec::new(),
            echoes: None,
            silence: None,
        }
    }

    /// Sends an operator command (acquire, cancel) to the device.
    ///
    /// # Errors
    /// The link failed, or the device refused it (an unknown track, a full table).
    pub fn command(&mut self, command: TrackCommand) -> anyhow::Result<()> {
        self.device.command(command)
    }

    /// Restarts the host side on the same link (see [`DeviceLink::restart_host`]); returns
    /// the device's live track table.
    ///
    /// # Errors
    /// The handshake or the track report fails.
    pub fn restart_host(&mut self) -> anyhow::Result<Vec<TrackState>> {
        let tracks = self.device.restart_host()?;
        // The device may have been reset meanwhile and numbered its tracks again.
        self.stationary.clear();
        self.firm = firm_tracks(&tracks);
        self.lost = lost_tracks(&tracks);
        self.in_echo
            .retain(|held, echo| self.firm.contains(held) && self.firm.contains(echo));
        self.tracks_held = held_tracks(&tracks);
        Ok(tracks)
    }

    /// What happened worth telling the operator (resets, restarts, skipped scans).
    pub fn events(&self) -> Vec<String> {
        let mut e = self.device.events();
        e.extend(self.events.lines("session"));
        e
    }

    /// Scans skipped because the device refused them or reported nonsense.
    pub fn scans_skipped(&self) -> u64 {
        self.skipped
    }

    /// The link's counters.
    pub fn link_stats(&self) -> ClientStats {
        self.device.client().stats()
    }

    /// Host time of every scan so far, link included.
    pub fn host_times(&self) -> &[Duration] {
        &self.host_times
    }

    /// Target-scans that waited for a target number (every number was in use).
    pub fn targets_without_number(&self) -> u64 {
        self.numbers.waited
    }
}
