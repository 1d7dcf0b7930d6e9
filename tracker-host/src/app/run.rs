//! A run: a plot source and an own-ship source feeding a [`Session`], its reports going to
//! sinks, scan after scan until the source ends.

use std::time::{Duration, Instant};

use serde::Serialize;

use crate::own_ship::nav::NavCounts;
use crate::own_ship::OwnShipSource;
use crate::score::{ScoreSink, Summary};
use crate::session::ais::{AisPicture, PairingCounts, PairingGates};
use crate::session::{ScanReport, Session};
use crate::sink::ScanSink;
use crate::source::PlotSource;

/// A paced run's wait for a scan's time is slept in slices of this, so that Ctrl-C is
/// answered within one.
const WAIT_SLICE: Duration = Duration::from_millis(100);

/// What [`Run::poll`] came to.
#[derive(Debug)]
pub enum Polled {
    /// A scan tracked.
    Scan(Box<ScanReport>),
    /// A live source gave no scan in the time allowed; the run goes on.
    Waiting,
    /// The source has ended, or the run was interrupted (the sinks are finished).
    Ended,
}

/// Sources, session and sinks, wired.
pub struct Run {
    plots: Box<dyn PlotSource>,
    own_ship: Box<dyn OwnShipSource>,
    session: Session,
    sinks: Vec<Box<dyn ScanSink>>,
    score: ScoreSink,
    scans: u64,
    finished: bool,
    /// Tracks the device holds that have been shown as targets (by track id), and how
    /// many tracks ever were.
    shown: std::collections::HashSet<u16>,
    targets_seen: u64,
    target_scans_in_echo: u64,
    /// AIS targets and their pairing with radar targets, once AIS is heard.
    ais: Option<AisPicture>,
    ais_duplicates: crate::ais::AisDuplicates,
    origin: crate::origin::Origin,
    associated_data: crate::session::ais::AssociatedData,
}

impl Run {
    /// Wires a run; the scorer scores the scans whose source carries truth.
    pub fn new(
        plots: Box<dyn PlotSource>,
        own_ship: Box<dyn OwnShipSource>,
        session: Session,
        sinks: Vec<Box<dyn ScanSink>>,
    ) -> Self {
        let scan_s = plots.scan_period_s().unwrap_or(2.5) as f32;
        let limits = session.config().alarms;
        Run {
            plots,
            own_ship,
            session,
            sinks,
            score: ScoreSink::new(scan_s).with_alarms(limits),
            scans: 0,
            finished: false,
            shown: std::collections::HashSet::new(),
            targets_seen: 0,
            target_scans_in_echo: 0,
            ais: None,
            ais_duplicates: crate::ais::AisDuplicates::default(),
            origin: crate::origin::Origin::default(),
            associated_data: crate::session::ais::AssociatedData::default(),
        }
    }

    /// A ship whose radar target is associated with an AIS target is shown with `data`'s
    /// data (the AIS target's by default).
    pub fn with_associated_data(mut self, data: crate::session::ais::AssociatedData) -> Self {
        self.associated_data = data;
        self
    }

    /// AIS heard by the sources is placed in the local frame of `origin`.
    pub fn with_origin(mut self, origin: crate::origin::Origin) -> Self {
        self.origin = origin;
        self
    }

    /// The AIS picture, once AIS has been heard.
    pub fn ais(&self) -> Option<&AisPicture> {
        self.ais.as_ref()
    }

    /// Adds a sink.
    pub fn add_sink(&mut self, sink: Box<dyn ScanSink>) {
        self.sinks.push(sink);
    }

    /// Tracks the next scan; `Ok(None)` once the source has ended (the sinks are then
    /// finished).
    ///
    /// # Errors
    /// A source, the session or a sink failed.
    pub fn step(&mut self) -> anyhow::Result<Option<ScanReport>> {
        self.step_at(|_| {})
    }

    /// As [`Run::step`], calling `before` with the scan's time (s) once the source has given
    /// it and before it is tracked: a real-time run waits there until the scan is due.
    ///
    /// # Errors
    /// A source, the session or a sink failed.
    pub fn step_at(&mut self, before: impl FnOnce(f64)) -> anyhow::Result<Option<ScanReport>> {
        Ok(match self.next(before, None)? {
            Polled::Scan(report) => Some(*report),
            Polled::Waiting | Polled::Ended => None,
        })
    }

    /// As [`Run::step`], but a live source's scan is waited for at most `wait`: for a loop
    /// that must go on meanwhile (the display, answering keys while the radar is silent).
    ///
    /// # Errors
    /// As [`Run::step`].
    pub fn poll(&mut self, wait: Duration) -> anyhow::Result<Polled> {
        self.next(|_| {}, Some(wait))
    }

    /// True when the scans come from a live source (a radar on the network).
    pub fn is_live(&self) -> bool {
        self.plots.is_live()
    }

    fn next(&mut self, before: impl FnOnce(f64), wait: Option<Duration>) -> anyhow::Result<Polled> {
        if self.finished {
            return Ok(Polled::Ended);
        }
        // Ctrl-C or SIGTERM: the run ends here, as at its source's end.
        if super::interrupt::interrupted() {
            self.finish()?;
            return Ok(Polled::Ended);
        }
        let waits = wait.is_some() && self.plots.is_live();
        if waits {
            self.plots.set_live_wait(wait);
        }
        let scan = self.plots.next_scan();
        if waits {
            self.plots.set_live_wait(None);
        }
        let Some(scan) = scan? else {
            if waits && !super::interrupt::interrupted() {
                return Ok(Polled::Waiting);
            }
            self.finish()?;
            return Ok(Polled::Ended);
        };
        before(scan.radar.time_s);
        let mut own = self.own_ship.own_ship(&scan)?;
        // Own ship found far from where its tracks were placed about (a fixed position's
        // first fix): they are wrong, and go; this scan's plots start them again.
        if self.own_ship.take_moved() {
            self.session
                .command(tracker_core::icd::TrackCommand::CancelAll)?;
        }
        // An own-ship source without a heading (NMEA with no HDT/HDG): the radar's heading
        // sensor, when its spokes carried one this rotation (the plots were placed with it).
        // One whose heading was lost is told so: the heading has changed source.
        if own.heading_rad.is_none() {
            if let Some(h) = scan.heading_sensor_rad {
                own.stand_in_heading(Some(h), true);
            } else if !own.quality.heading_lost {
                // … else the heading the source placed them with, when not a sensor's (a
                // moored ship's `--heading-deg` turned by its yaw): shown and sent as own
                // ship's, as without `--nmea-in` (it was `HDG ---` with a GNSS giving no
                // heading). A heading sensor lost keeps its alarm.
                own.heading_rad = scan.placed_heading_rad;
                own.quality.heading_given = scan.placed_heading_rad.is_some()
                    && scan.own_ship.is_some_and(|o| o.quality.heading_given);
            }
        }
        // Own ship's heading is the plot source's own (its own ship's, its radar's sensor's,
        // or the one it placed its plots with; the same value passed on this scan) or none:
        // then the source's lost heading (a radar's that stopped coming in its spokes) is
        // own ship's alarm too, and the heading is not handed back to the source as if a
        // sensor of the run's gave it (a heading that stopped would be held for ever).
        let from_source = [
            scan.own_ship.and_then(|o| o.heading_rad),
            scan.heading_sensor_rad,
            scan.placed_heading_rad,
        ];
        let heading_from_source = own
            .heading_rad
            .is_none_or(|h| from_source.contains(&Some(h)));
        own.quality.heading_lost |=
            heading_from_source && scan.own_ship.is_some_and(|o| o.quality.heading_lost);
        // The plot source knows whether its plots wanted a heading, whoever gives own ship;
        // an alarm only while own ship has none.
        own.quality.heading_needed =
            scan.own_ship.is_some_and(|o| o.quality.heading_needed) && own.heading_rad.is_none();
        let mut estimate = own;
        if heading_from_source {
            estimate.heading_rad = None;
        }
        self.plots.own_ship_estimate(&estimate);
        // A radar's plots are as accurate as its range scale, which a live radar tells with
        // its first spoke and the operator changes.
        if let Some(sigma_m) = self.plots.plot_sigma_m() {
            self.session.set_plot_sigma_m(sigma_m)?;
        }
        // The plots' range and bearing accuracy, when the source knows it, weighs them in
        // the association.
        self.session.set_plot_accuracy(self.plots.plot_accuracy());
        let mut report = self.session.scan(&scan.radar, &own)?;
        report.echoes = scan.echoes.clone();
        report.time_is_utc = self.plots.time_is_utc();
        if report.time_is_utc {
            report.utc_offset_s = self.own_ship.utc_offset_s();
        }
        let heard = self
            .ais_duplicates
            .merge(self.plots.take_ais(), self.own_ship.take_ais());
        if !heard.is_empty() || self.ais.is_some() {
            let (origin, data) = (self.origin, self.associated_data);
            let limits = self.session.config().alarms;
            self.ais
                .get_or_insert_with(|| {
                    AisPicture::new(origin, PairingGates::default())
                        .with_associated_data(data)
                        .with_alarm_limits(limits)
                })
                .scan(&mut report, &heard);
        }
        for sink in &mut self.sinks {
            sink.scan(&scan, &report)?;
        }
        self.score.scan(&scan, &report)?;
        // A track counts once however often it is shown (a failed acquisition that takes a
        // plot again is shown again): forgotten once the device has dropped it.
        self.shown
            .retain(|id| report.tracks.iter().any(|t| t.track == *id));
        for t in &report.targets {
            self.targets_seen += u64::from(self.shown.insert(t.track));
        }
        self.target_scans_in_echo += report.in_echo.len() as u64;
        self.scans += 1;
        Ok(Polled::Scan(Box::new(report)))
    }

    /// Finishes every sink (flushes recordings, takes the targets off the plotters), each
    /// whatever the others did; later steps return `None`.
    ///
    /// # Errors
    /// A sink's final write failed (the first such error; the other sinks are finished).
    pub fn finish(&mut self) -> anyhow::Result<()> {
        let mut first = Ok(());
        if !self.finished {
            self.finished = true;
            self.own_ship.finish();
            for sink in &mut self.sinks {
                let done = sink.finish();
                if first.is_ok() {
                    first = done;
                }
            }
        }
        first
    }

    /// Runs to the source's end, calling `show` after each scan. With `speedup`, scans are
    /// paced at the source's clock divided by it (1: real time).
    ///
    /// # Errors
    /// As [`Run::step`].
    pub fn run_to_end(
        &mut self,
        speedup: Option<f64>,
        mut show: impl FnMut(&ScanReport),
    ) -> anyhow::Result<()> {
        let start = Instant::now();
        let mut first_time_s = None;
        // A scan is tracked (and sent on) when its time has come, not before; Ctrl-C ends
        // the wait (a long one ignored it: a run paced at 10⁻⁹ waited on after Ctrl-C).
        let wait = |time_s: f64, first: &mut Option<f64>| {
            let Some(x) = speedup else { return };
            let t0 = *first.get_or_insert(time_s);
            // A due time past the clock's reach is never.
            let due = Duration::try_from_secs_f64(((time_s - t0) / x).max(0.0))
                .ok()
                .and_then(|d| start.checked_add(d));
            while !super::interrupt::interrupted() {
                let left = due.map_or(WAIT_SLICE, |d| d.saturating_duration_since(Instant::now()));
                if left.is_zero() {
                    break;
                }
                std::thread::sleep(left.min(WAIT_SLICE));
            }
        };
        while let Some(report) = self.step_at(|t| wait(t, &mut first_time_s))? {
            show(&report);
        }
        Ok(())
    }

    /// The session.
    pub fn session(&self) -> &Session {
        &self.session
    }

    /// The session, to send operator commands.
    pub fn session_mut(&mut self) -> &mut Session {
        &mut self.session
    }

    /// The scores so far; `None` when the source carries no truth.
    pub fn summary(&self) -> Option<Summary> {
        self.score.summary()
    }

    /// What became of the own-ship sentences, when own ship comes from NMEA.
    pub fn nmea_counts(&self) -> Option<NavCounts> {
        self.own_ship.nmea_counts()
    }

    /// The source's antenna period, s.
    pub fn scan_period_s(&self) -> Option<f64> {
        self.plots.scan_period_s()
    }

    /// Scans tracked so far.
    pub fn scans(&self) -> u64 {
        self.scans
    }

    /// Scans still to come, when the source knows.
    pub fn scans_left(&self) -> Option<u64> {
        self.plots.scans_left()
    }

    /// False when the run has no radar (`track --nmea-in` alone: AIS targets only).
    pub fn has_radar(&self) -> bool {
        self.plots.has_radar()
    }

    /// The end-of-run report.
    pub fn report(&self, link: &str) -> RunReport {
        let mut times: Vec<Duration> = self.session.host_times().to_vec();
        times.sort();
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let mean = times.iter().sum::<Duration>() / times.len().max(1) as u32;
        let stats = self.session.link_stats();
        RunReport {
            link: link.to_string(),
            filter: self
                .session
                .config()
                .tracker
                .filter
                .kind()
                .name()
                .to_string(),
            association: self.session.config().association.name().to_string(),
            command: Vec::new(),
            scans: self.scans,
            without_radar: !self.has_radar(),
            targets_seen: self.targets_seen,
            target_scans_in_echo: self.target_scans_in_echo,
            scores: self.summary(),
            radar: self.plots.radar_counts(),
            ais: self.ais_summary(),
            host_ms_per_scan_mean: ms(mean),
            host_ms_per_scan_max: ms(times.last().copied().unwrap_or_default()),
            link_frames_sent: stats.frames_sent,
            link_frames_received: stats.frames_received,
            link_frames_damaged: stats.frames_damaged,
            link_retries: stats.retries,
            link_bytes_sent: stats.bytes_sent,
            link_bytes_received: stats.bytes_received,
            link_bytes_per_scan: (stats.bytes_sent + stats.bytes_received) as f64
                / (self.scans.max(1) as f64),
            own_ship_nmea: self.nmea_counts(),
            nmea_out: self.sinks.iter().find_map(|s| s.nmea_out()),
            events: {
                let mut e = self.session.events();
                e.extend(self.plots.events());
                e.extend(self.own_ship.events());
                if let Some(a) = &self.ais {
                    e.extend(a.events().iter().cloned());
                }
                e
            },
        }
    }
}

/// What AIS came to in a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct AisSummary {
    /// The sentences read (from the plot source and the own-ship source together).
    pub sentences: crate::ais::AisCounts,
    /// Messages heard from both sources (a capture's AIS and `--nmea-in`) and taken once.
    pub heard_twice: u64,
    /// AIS targets held at the end.
    pub targets_now: usize,
    /// The table's counts (targets, lost, crowded out, own ship's reports).
    pub table: crate::ais::targets::AisTableCounts,
    /// Radar/AIS pairs made and parted.
    pub pairing: PairingCounts,
}

impl Run {
    fn ais_summary(&self) -> Option<AisSummary> {
        let counts = [self.plots.ais_counts(), self.own_ship.ais_counts()];
        let mut sentences: Option<crate::ais::AisCounts> = None;
        for c in counts.into_iter().flatten() {
            sentences.get_or_insert_with(Default::default).add(&c);
        }
        let sentences = sentences.filter(|s| s.sentences > 0)?;
        Some(AisSummary {
            sentences,
            heard_twice: self.ais_duplicates.duplicates,
            targets_now: self.ais.as_ref().map_or(0, |a| a.table().len()),
            table: self
                .ais
                .as_ref()
                .map(|a| a.table().counts())
                .unwrap_or_default(),
            pairing: self.ais.as_ref().map(|a| a.counts()).unwrap_or_default(),
        })
    }
}

/// Events the text summary lists at most (a long run with AIS pairs hundreds); the JSON
/// summary has them all.
pub const EVENTS_IN_TEXT: usize = 20;

/// The end of a run, for the operator and (`--summary-json`) for other tools: one JSON
/// object with stable snake_case keys, units in the names. The scores' keys are present
/// when the run had truth to score against.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunReport {
    /// The link the device was reached over.
    pub link: String,
    /// The filter every track ran.
    pub filter: String,
    /// How plots were associated (`--association`).
    pub association: String,
    /// The command line that made the run (program name first), so that a summary says
    /// which scenario, seed and options it scores; empty when the run was not started
    /// from a command line.
    pub command: Vec<String>,
    /// Scans tracked.
    pub scans: u64,
    /// The run had no radar (`track --nmea-in` alone: AIS targets only).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub without_radar: bool,
    /// Targets shown over the run (tracks that were confirmed), each counted once.
    pub targets_seen: u64,
    /// Target-scans not drawn because the track's target was hidden in a plot another
    /// track took (two ships in one resolution cell; [`crate::session::ScanReport::in_echo`]).
    pub target_scans_in_echo: u64,
    /// What the radar source counted, when the plots came from a radar.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radar: Option<crate::source::radar::RadarCounts>,
    /// What AIS came to, when AIS was heard.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ais: Option<AisSummary>,
    /// Scores against the truth.
    #[serde(flatten)]
    pub scores: Option<Summary>,
    /// Host time per scan, link included, mean, ms.
    pub host_ms_per_scan_mean: f64,
    /// … and the largest, ms.
    pub host_ms_per_scan_max: f64,
    /// Frames the host sent.
    pub link_frames_sent: u64,
    /// Frames the host received intact.
    pub link_frames_received: u64,
    /// Frames that arrived damaged.
    pub link_frames_damaged: u64,
    /// Requests sent again after a lost answer.
    pub link_retries: u64,
    /// Bytes the host sent.
    pub link_bytes_sent: u64,
    /// Bytes the host received.
    pub link_bytes_received: u64,
    /// Bytes both ways per scan, mean (frames, CRC and COBS included).
    pub link_bytes_per_scan: f64,
    /// What became of the own-ship sentences, when own ship came from NMEA.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub own_ship_nmea: Option<NavCounts>,
    /// What NMEA out sent to chart plotters, with `--nmea-out`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nmea_out: Option<crate::nmea::targets::NmeaOutSummary>,
    /// What happened on the link worth telling (resets, restarts).
    pub events: Vec<String>,
}

impl RunReport {
    /// The report as text.
    pub fn text(&self) -> String {
        let mut s = format!(
            "== summary ({} link, filter {}, association {}) ==\n",
            self.link, self.filter, self.association
        );
        match &self.scores {
            Some(scores) => s += &scores.report(),
            None if self.without_radar => {
                s += &format!("scans: {} (no radar: AIS targets only)", self.scans)
            }
            None => {
                s += &format!(
                    "scans: {}, {} targets shown over the run (no truth to score against)",
                    self.scans, self.targets_seen
                )
            }
        }
        s.push('\n');
        if self.target_scans_in_echo > 0 {
            s += &format!(
                "{} target-scans held but not drawn: the target hidden in another's echo\n",
                self.target_scans_in_echo
            );
        }
        if let Some(r) = &self.radar {
            s += &format!("radar: {r}\n");
            if let Some(c) = &r.capture_nmea {
                s += &format!("own-ship NMEA in the radar capture: {c}\n");
            }
        }
        if let Some(a) = &self.ais {
            let twice = if a.heard_twice > 0 {
                format!(
                    "; {} messages heard from both the plot source (a radar capture) and --nmea-in, taken once",
                    a.heard_twice
                )
            } else {
                String::new()
            };
            s += &format!(
                "AIS: {}{twice}; {} targets taken (a ship lost and heard again is taken again), {} lost, {} held at the end; {} radar/AIS pairs made, {} parted\n",
                a.sentences, a.table.targets, a.table.lost, a.targets_now, a.pairing.paired, a.pairing.parted
            );
        }
        if let Some(c) = &self.own_ship_nmea {
            s += &format!("own-ship NMEA: {c}\n");
        }
        if let Some(c) = &self.nmea_out {
            s += &format!("NMEA out: {c}\n");
        }
        for e in self.events.iter().take(EVENTS_IN_TEXT) {
            s += &format!("event: {e}\n");
        }
        if self.events.len() > EVENTS_IN_TEXT {
            s += &format!(
                "… and {} more events (all those kept, in --summary-json's `events`)\n",
                self.events.len() - EVENTS_IN_TEXT
            );
        }
        s += &format!(
            "host time per scan (link included): mean {:.2} ms, max {:.2} ms\n",
            self.host_ms_per_scan_mean, self.host_ms_per_scan_max
        );
        // A run that ended before its first scan has no bytes per scan to tell.
        let per_scan = if self.scans > 0 {
            format!(" ({:.0} B per scan)", self.link_bytes_per_scan)
        } else {
            String::new()
        };
        s += &format!(
            "link: {} frames sent, {} received, {} damaged, {} requests retried; {} bytes sent, {} received{per_scan}\n",
            self.link_frames_sent,
            self.link_frames_received,
            self.link_frames_damaged,
            self.link_retries,
            self.link_bytes_sent,
            self.link_bytes_received,
        );
        s
    }

    /// The report as one JSON object.
    pub fn json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::demo::{self, DemoOptions};
    use crate::link::{Client, InprocTransport};
    use tracker_core::filter::FilterKind;

    /// A short demo's report: 4 targets, 30 s, no truth scored 3 minutes on.
    fn report() -> RunReport {
        let options = DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            4,
            1,
            30.0,
            FilterKind::KalmanCv,
        );
        let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        run.run_to_end(None, |_| {}).unwrap();
        run.report("inproc")
    }

    #[test]
    fn the_summary_tells_what_nmea_out_sent_and_whether_a_plotter_connected() {
        let mut options = DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            4,
            1,
            30.0,
            FilterKind::KalmanCv,
        );
        options.outputs.nmea_out = Some(crate::nmea::out::OutSpec::Tcp(0));
        let mut run = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        run.run_to_end(None, |_| {}).unwrap();
        let report = run.report("inproc");
        let out = report.nmea_out.expect("NMEA out in the summary");
        assert!(out.sent.targets_sent > 0, "{out:?}");
        assert_eq!(out.tcp.map(|c| c.accepted), Some(0), "no plotter connected");
        assert!(report.text().contains("NMEA out: "), "{}", report.text());
        let json = serde_json::to_value(&report).unwrap();
        assert!(
            json["nmea_out"]["targets_sent"].as_u64().unwrap() > 0,
            "{json}"
        );
        // Without --nmea-out, no such line.
        assert!(self::report().nmea_out.is_none());
    }

    /// A scan whose source read a heading sensor (a radar's spokes), or not, and an own-ship
    /// source that knows only a position (NMEA without a heading sentence).
    struct Radar {
        heading: Option<f32>,
        placed: Option<f32>,
    }
    impl PlotSource for Radar {
        fn next_scan(&mut self) -> anyhow::Result<Option<crate::source::SourceScan>> {
            // The source's own idea of own ship (fed back, or fixed) is not a sensor.
            let mut own = crate::own_ship::OwnShip::unknown();
            own.heading_rad = Some(2.0);
            Ok(Some(crate::source::SourceScan {
                own_ship: Some(own),
                heading_sensor_rad: self.heading,
                placed_heading_rad: self.placed,
                ..Default::default()
            }))
        }
        fn scan_period_s(&self) -> Option<f64> {
            None
        }
        fn scans_left(&self) -> Option<u64> {
            None
        }
    }
    /// An own-ship source with a position only: its heading lost (`true`: it had one), or
    /// never one (NMEA without a heading sentence).
    struct PositionOnly(bool);
    impl OwnShipSource for PositionOnly {
        fn own_ship(
            &mut self,
            _: &crate::source::SourceScan,
        ) -> anyhow::Result<crate::own_ship::OwnShip> {
            let mut own = crate::own_ship::OwnShip::at([10.0, 20.0], [1.0, 0.0]);
            own.quality.heading_lost = self.0;
            Ok(own)
        }
    }

    #[test]
    fn own_ship_without_a_heading_takes_the_radars_sensor_else_the_placed_heading() {
        // (radar's sensor, the heading its plots were placed with, own ship's heading lost:
        // shown heading, lost, changed source)
        let cases = [
            (Some(0.5), None, true, Some(0.5), false, true),
            (None, None, true, None, true, false),
            (Some(0.5), None, false, Some(0.5), false, false),
            (None, None, false, None, false, false),
            // A fixed heading (`--heading-deg`) the plots were placed with: shown, but not
            // over a lost sensor's alarm; a sensor's first.
            (None, Some(1.5), false, Some(1.5), false, false),
            (None, Some(1.5), true, None, true, false),
            (Some(0.5), Some(1.5), false, Some(0.5), false, false),
        ];
        for (sensor, placed, had_one, heading, lost, changed) in cases {
            let client = Client::new(Box::new(InprocTransport::new()));
            let config =
                crate::session::SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 40.0);
            let mut run = Run::new(
                Box::new(Radar {
                    heading: sensor,
                    placed,
                }),
                Box::new(PositionOnly(had_one)),
                Session::start(client, config).unwrap(),
                Vec::new(),
            );
            let report = run.step().unwrap().unwrap();
            assert_eq!(report.own.heading_rad, heading);
            assert_eq!(report.own.quality.heading_lost, lost);
            assert_eq!(report.own.quality.heading_from_radar, changed);
            assert_eq!(report.own.position_m, [10.0, 20.0]);
            let told = report
                .own
                .alarms()
                .iter()
                .any(|a| a.contains("the radar's heading in use"));
            assert_eq!(told, changed, "{:?}", report.own.alarms());
        }
    }

    /// One echo 1 km north of the radar, every 2.5 s, for 14 scans.
    struct OneEcho(u32);
    impl PlotSource for OneEcho {
        fn next_scan(&mut self) -> anyhow::Result<Option<crate::source::SourceScan>> {
            self.0 += 1;
            if self.0 > 14 {
                return Ok(None);
            }
            let mut own = crate::own_ship::OwnShip::unknown();
            own.heading_rad = Some(0.0);
            Ok(Some(crate::source::SourceScan {
                radar: crate::source::RadarScan {
                    scan: self.0,
                    time_s: 2.5 * f64::from(self.0),
                    plots: vec![tracker_core::icd::Plot {
                        range_m: 1000.0,
                        bearing_rad: 0.0,
                    }],
                },
                own_ship: Some(own),
                ..Default::default()
            }))
        }
        fn scan_period_s(&self) -> Option<f64> {
            Some(2.5)
        }
        fn scans_left(&self) -> Option<u64> {
            None
        }
    }
    /// No fix until scan `.0`, then one 5 km north of the origin.
    struct FixFrom(u32);
    impl OwnShipSource for FixFrom {
        fn own_ship(
            &mut self,
            scan: &crate::source::SourceScan,
        ) -> anyhow::Result<crate::own_ship::OwnShip> {
            Ok(if scan.radar.scan >= self.0 {
                crate::own_ship::OwnShip::at([0.0, 5000.0], [0.0, 0.0])
            } else {
                crate::own_ship::OwnShip::unknown()
            })
        }
    }

    /// A fixed position whose first fix is 5 km off: the target tracked about the fixed
    /// position is cancelled (told as lost), not left coasting 5 km from own ship with the
    /// echo tracked again beside it.
    #[test]
    fn tracks_placed_about_a_wrong_fixed_position_go_at_the_first_fix() {
        let client = Client::new(Box::new(InprocTransport::new()));
        let config = crate::session::SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 40.0);
        let mut run = Run::new(
            Box::new(OneEcho(0)),
            Box::new(crate::own_ship::fixed::FixedPosition::new(Box::new(
                FixFrom(8),
            ))),
            Session::start(client, config).unwrap(),
            Vec::new(),
        );
        let mut ended = 0;
        while let Some(r) = run.step().unwrap() {
            if r.scan < 8 {
                assert!(r.own.quality.fixed_position);
            }
            if r.scan == 7 {
                assert_eq!(r.targets.len(), 1, "tracked at the fixed position");
            }
            if r.scan >= 8 {
                assert!(
                    r.targets.iter().all(|t| t.range_m < 1500.0),
                    "scan {}: {:?}",
                    r.scan,
                    r.targets
                );
                ended += r.ended.len();
            }
        }
        assert_eq!(ended, 1, "the old target told ended once");
        assert_eq!(run.report("inproc").targets_seen, 2);
    }

    #[test]
    fn the_text_summary_names_the_association_and_counts_the_events_it_leaves_out() {
        let mut r = report();
        r.events = (0..EVENTS_IN_TEXT + 5)
            .map(|i| format!("happening {i}"))
            .collect();
        let text = r.text();
        assert!(text.contains("association two-stage-unresolved"), "{text}");
        assert!(
            text.contains(&format!("happening {}", EVENTS_IN_TEXT - 1)),
            "{text}"
        );
        assert!(
            !text.contains(&format!("happening {EVENTS_IN_TEXT}")),
            "{text}"
        );
        assert!(text.contains("… and 5 more events"), "{text}");
        // The JSON keeps every one.
        let json: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
        assert_eq!(json["events"].as_array().unwrap().len(), EVENTS_IN_TEXT + 5);
        assert_eq!(json["association"], "two-stage-unresolved");
    }

    #[test]
    fn cpa_errors_of_a_run_too_short_to_score_them_are_none_not_zero() {
        let r = report();
        let scores = r.scores.as_ref().expect("a demo is scored");
        assert_eq!(scores.cpa_error_p95_m, None);
        assert_eq!(scores.tcpa_error_p95_s, None);
        assert!(r.text().contains("none scored"), "{}", r.text());
        let json: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
        assert!(json["cpa_error_p95_m"].is_null());
    }
}
