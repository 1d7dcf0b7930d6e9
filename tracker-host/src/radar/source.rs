//! [`SpokeSource`]: spokes with their time, from a capture file or from the radar live.
//!
//! ```no_run
//! use tracker_host::radar::{RadarSpec, SpokeSource};
//!
//! let spec: RadarSpec = "pcap:radar.pcap.gz".parse().map_err(anyhow::Error::msg)?;
//! let mut source = SpokeSource::open(&spec)?;
//! while let Some((spoke, time_s)) = source.next_spoke()? {
//!     // spoke.samples borrows the source's buffer: use or copy it before the next call.
//!     let _ = (spoke.angle, spoke.range_m, time_s);
//! }
//! for (time_s, line) in source.nmea_lines() {
//!     let _ = (time_s, line); // own ship from the same capture
//! }
//! println!("{}", source.stats().navico_spokes.rotations);
//! # Ok::<(), anyhow::Error>(())
//! ```
//!
//! Datagrams are told apart by structure (a Navico frame's length and header byte, a
//! Garmin packet type) and, for the spoke ports, by port: so a capture's other traffic
//! (state reports, NMEA, anything) passes as "other", while a damaged packet on a spoke port
//! is counted as the decoder's fault. A Navico scanner-type report sets the model the Navico
//! ranges are read with; a Navico range report (on [`NAVICO_REPORT_GROUPS`]) gives the range
//! the user chose, told when it changes and held against the spokes' own range: spokes that
//! reach outside [`navico::SPOKE_REACH_PER_RANGE_SETTING`] times it for
//! [`RANGE_DISAGREEMENT_S`] are told as a range likely misread.

use std::net::Ipv4Addr;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::bail;
use tracker_core::radar::Spoke;

use super::capture::{CaptureOptions, CaptureReader, CaptureStats};
use super::garmin::{self, GarminCounts, GarminDecoder};
use super::live::{
    Endpoint, LiveReceiver, LiveStats, GARMIN_SPOKE_GROUPS, NAVICO_REPORT_GROUPS,
    NAVICO_SPOKE_GROUPS,
};
use super::navico::{self, NavicoCounts, NavicoDecoder};
use super::spec::{RadarKind, RadarSpec};
use super::stats::{SpokeMeta, SpokeStats};

/// Spoke packets the decoders refused (unknown, truncated or inconsistent), both brands.
fn refused(navico: &NavicoCounts, garmin: &GarminCounts) -> u64 {
    navico.frame_faults.total() + garmin.faults.total()
}

/// Everything a [`SpokeSource`] has counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RadarStats {
    /// The capture's packets, fragments, reassemblies, datagrams and NMEA (capture only).
    pub capture: Option<CaptureStats>,
    /// Datagrams received and dropped (live only).
    pub live: Option<LiveStats>,
    /// UDP datagrams looked at.
    pub datagrams: u64,
    /// Datagrams that were neither brand's spokes (state reports, NMEA, other traffic).
    pub other_datagrams: u64,
    /// Navico scanner-type reports taken.
    pub navico_reports: u64,
    /// Navico range reports taken (the range the user chose, on the report group paired
    /// with the spokes taken).
    pub navico_range_reports: u64,
    /// The ranges the radar reported as chosen, m, in the order first reported (the first
    /// [`super::stats::KEPT_RANGES`]).
    pub navico_range_settings_m: Vec<f32>,
    /// Times the spokes' range stood outside
    /// [`navico::SPOKE_REACH_PER_RANGE_SETTING`] times the range reported as chosen for
    /// [`RANGE_DISAGREEMENT_S`]: a range likely misread (each told as an event).
    pub range_disagreements: u64,
    /// The radar tracked: the sender of the first spoke datagram.
    pub radar_address: Option<Ipv4Addr>,
    /// Spoke datagrams from another sender on the same groups (a second radar on the
    /// network), ignored, and the first such sender.
    pub other_radar: Option<(Ipv4Addr, u64)>,
    /// Times the radar tracked changed: it was silent [`RADAR_GONE_S`] while another sent.
    pub radar_changes: u64,
    /// The Navico decoder's counts: frames, spokes, faults by kind, headings.
    pub navico: NavicoCounts,
    /// The Navico spoke stream: rotations, ranges, order.
    pub navico_spokes: SpokeStats,
    /// The Garmin decoder's counts: spokes, faults by kind.
    pub garmin: GarminCounts,
    /// The Garmin spoke stream.
    pub garmin_spokes: SpokeStats,
}

impl RadarStats {
    /// Datagrams refused as spoke packets (unknown, truncated or inconsistent), both brands.
    pub fn bad_packets(&self) -> u64 {
        refused(&self.navico, &self.garmin)
    }

    /// Spokes skipped inside accepted Navico frames (status 0x82, bad header, no range).
    pub fn skipped_spokes(&self) -> u64 {
        self.navico.spoke_faults.total()
    }

    /// One brand's spoke stream.
    pub fn spokes(&self, kind: RadarKind) -> &SpokeStats {
        match kind {
            RadarKind::Navico => &self.navico_spokes,
            RadarKind::Garmin => &self.garmin_spokes,
        }
    }
}

/// A radar silent this long gives way to another sender on its groups, s (the display's
/// no-radar-data alarm comes at the same time).
pub const RADAR_GONE_S: f64 = 10.0;

/// The spokes' range must disagree with the range reported as chosen this long, s, before
/// it is told: a range change reaches the spokes and the report at different moments (the
/// 3G capture's report 20 ms before its spokes; a 4G reports every 5 s).
pub const RANGE_DISAGREEMENT_S: f64 = 10.0;

/// The range the radar reports as chosen, and the spokes' range held against it.
#[derive(Clone, Debug, Default)]
struct RangeSetting {
    reports: u64,
    now_m: Option<f32>,
    seen_m: Vec<f32>,
    /// Since when (capture or arrival time, s) the spokes have disagreed with it, and
    /// whether this disagreement was told.
    disagreeing_since: Option<(f64, bool)>,
    disagreements: u64,
    /// Before the radar tracked is known: each sender's last range report (sender, m, s).
    pending: Vec<(Ipv4Addr, f32, f64)>,
}

/// Senders whose range reports are kept before the first spoke.
const MAX_PENDING_REPORTERS: usize = 8;

enum Input {
    Capture(Box<CaptureReader>),
    Live(LiveReceiver),
}

impl RangeSetting {
    /// Takes a range the radar reports as chosen at `time_s`; a new one is told (on
    /// standard error too when `told`).
    fn note(
        &mut self,
        range_m: f32,
        time_s: f64,
        told: bool,
        events: &mut crate::event_log::EventLog,
    ) {
        self.reports += 1;
        if self.now_m == Some(range_m) {
            return;
        }
        let first = self.now_m.is_none();
        self.now_m = Some(range_m);
        self.disagreeing_since = None;
        if !self.seen_m.contains(&range_m) && self.seen_m.len() < super::stats::KEPT_RANGES {
            self.seen_m.push(range_m);
        }
        let event = format!(
            "{}: the radar {} {}",
            crate::utc::date_time_label(time_s),
            if first {
                "reports its range scale as"
            } else {
                "changed its range scale to"
            },
            range_scale_in_metres(range_m)
        );
        tell(events, told, event);
    }

    /// Holds the range of a rotation's first spoke, taken at `time_s`, against the range
    /// reported as chosen; a disagreement that stands [`RANGE_DISAGREEMENT_S`] is counted
    /// and told once (on standard error too when `told`).
    fn check(
        &mut self,
        spoke_range_m: f32,
        time_s: f64,
        told: bool,
        events: &mut crate::event_log::EventLog,
    ) {
        let Some(setting_m) = self.now_m else {
            return;
        };
        let ratio = f64::from(spoke_range_m) / f64::from(setting_m);
        if navico::SPOKE_REACH_PER_RANGE_SETTING.contains(&ratio) {
            self.disagreeing_since = None;
            return;
        }
        let (since, said) = self.disagreeing_since.get_or_insert((time_s, false));
        if *said || time_s - *since < RANGE_DISAGREEMENT_S {
            return;
        }
        *said = true;
        self.disagreements += 1;
        let (lo, hi) = (
            navico::SPOKE_REACH_PER_RANGE_SETTING.start(),
            navico::SPOKE_REACH_PER_RANGE_SETTING.end(),
        );
        let event = format!(
            "{}: the spokes reach {spoke_range_m:.0} m, {ratio:.2} times the radar's range scale of {} (expected {lo}–{hi} times): the spokes' range may be misread, and every range and speed with it",
            crate::utc::date_time_label(time_s),
            range_scale_in_metres(setting_m)
        );
        tell(events, told, event);
    }
}

/// Logs `event`, and with `told` (a live radar without the display) says it on standard
/// error as it happens.
fn tell(events: &mut crate::event_log::EventLog, told: bool, event: String) {
    if told {
        eprintln!("{event}");
    }
    events.push(event);
}

/// Spokes from a capture file or the radar, one at a time. See the module documentation.
pub struct SpokeSource {
    input: Input,
    navico: NavicoDecoder,
    garmin: GarminDecoder,
    /// The decoder holding the datagram being handed out.
    active: Option<RadarKind>,
    time_s: f64,
    navico_spokes: SpokeStats,
    garmin_spokes: SpokeStats,
    datagrams: u64,
    other_datagrams: u64,
    navico_reports: u64,
    range_setting: RangeSetting,
    radar_address: Option<Ipv4Addr>,
    other_radar: Option<(Ipv4Addr, u64)>,
    radar_changes: u64,
    last: Option<(RadarKind, SpokeMeta)>,
    live_deadline: Option<Instant>,
    /// When the last spoke was given (or the source opened), and the notes of no spokes
    /// told since: datagrams that are not spokes keep the receiver's own silence note
    /// from being told (a new user's trial sent junk to the group and heard nothing).
    spoke_at: Instant,
    spokeless_notes: u32,
    /// What happened worth telling: the radar tracked changed.
    events: crate::event_log::EventLog,
}

impl std::fmt::Debug for SpokeSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpokeSource")
            .field("stats", &self.stats())
            .finish_non_exhaustive()
    }
}

impl SpokeSource {
    /// Opens the source a [`RadarSpec`] names: a capture with the default
    /// [`CaptureOptions`], or the brand's spoke groups joined live.
    ///
    /// # Errors
    /// The capture cannot be opened or is not one; a live socket cannot be bound or joined.
    pub fn open(spec: &RadarSpec) -> anyhow::Result<Self> {
        match spec {
            RadarSpec::Capture(path) => Self::from_capture(path, CaptureOptions::default()),
            RadarSpec::Live { kind, interface } => {
                Self::from_live(kind.live_endpoints(), *interface)
            }
        }
    }

    /// Reads a capture file.
    ///
    /// # Errors
    /// As [`CaptureReader::open`].
    pub fn from_capture(path: &Path, options: CaptureOptions) -> anyhow::Result<Self> {
        let reader = CaptureReader::open(path, options)?;
        Ok(Self::with_input(Input::Capture(Box::new(reader))))
    }

    /// Receives live from these groups on the interface with address `interface`.
    ///
    /// # Errors
    /// As [`LiveReceiver::open`].
    pub fn from_live(endpoints: &[Endpoint], interface: Ipv4Addr) -> anyhow::Result<Self> {
        Ok(Self::with_input(Input::Live(LiveReceiver::open(
            endpoints, interface,
        )?)))
    }

    fn with_input(input: Input) -> Self {
        SpokeSource {
            input,
            navico: NavicoDecoder::new(),
            garmin: GarminDecoder::new(),
            active: None,
            time_s: 0.0,
            navico_spokes: SpokeStats::default(),
            garmin_spokes: SpokeStats::default(),
            datagrams: 0,
            other_datagrams: 0,
            navico_reports: 0,
            range_setting: RangeSetting::default(),
            radar_address: None,
            other_radar: None,
            radar_changes: 0,
            last: None,
            live_deadline: None,
            spoke_at: Instant::now(),
            spokeless_notes: 0,
            events: crate::event_log::EventLog::default(),
        }
    }

    /// The radar changes told (see [`RadarStats::radar_changes`]), oldest first.
    pub fn events(&self) -> Vec<String> {
        self.events.lines("radar")
    }

    /// How long [`next_spoke`](Self::next_spoke) may wait for live data, from now, before
    /// it returns `Ok(None)`: one deadline for every call until the next setting (a loop of
    /// calls that each find a datagram still ends by then); `None` (the default): until a
    /// spoke comes. A capture never waits.
    pub fn set_live_wait(&mut self, wait: Option<Duration>) {
        self.live_deadline = wait.map(|w| Instant::now() + w);
    }

    /// True for a live source (where `Ok(None)` from [`next_spoke`](Self::next_spoke) means "nothing
    /// yet", not the end).
    pub fn is_live(&self) -> bool {
        matches!(self.input, Input::Live(_))
    }

    /// The next spoke and its time (capture or arrival time, s since 1970; the spoke's
    /// `time_ms` is the same in ms). The spoke borrows the source until the next call.
    /// `Ok(None)`: the capture has ended, or (live, with a wait set) nothing came in time.
    ///
    /// # Errors
    /// The capture cannot be read further (see [`CaptureReader::next_datagram`]); a live
    /// socket failed.
    pub fn next_spoke(&mut self) -> anyhow::Result<Option<(Spoke<'_>, f64)>> {
        loop {
            let ready = match self.active {
                Some(RadarKind::Navico) => self.navico.advance(),
                Some(RadarKind::Garmin) => self.garmin.advance(),
                None => false,
            };
            if ready {
                break;
            }
            self.active = None;
            // Told on standard error as they happen: a live radar waited on as long as it
            // takes (plain output; the display shows the silence itself).
            let told = self.is_live() && self.live_deadline.is_none();
            let datagram = match &mut self.input {
                Input::Capture(c) => c.next_datagram()?,
                Input::Live(l) => l.next_datagram(
                    self.live_deadline
                        .map(|d| d.saturating_duration_since(Instant::now())),
                )?,
            };
            let Some(d) = datagram else {
                self.last = None;
                return Ok(None);
            };
            self.datagrams += 1;
            // Datagrams coming, none of them a spoke: told as the receiver tells silence.
            let note = super::live::SILENCE_NOTE * (self.spokeless_notes + 1);
            if told && self.spoke_at.elapsed() >= note {
                self.spokeless_notes += 1;
                eprintln!(
                    "no radar spokes for {} s though datagrams come ({} not a radar's spokes, {} spoke packets refused so far): is this the radar's spoke group, and is the radar transmitting (not in standby)?",
                    self.spoke_at.elapsed().as_secs(),
                    self.other_datagrams,
                    refused(self.navico.counts(), self.garmin.counts())
                );
            }
            // Saturating: a time before 1970 becomes 0.
            let time_ms = (d.time_s * 1000.0).round() as u64;
            let kind = route(d.payload, d.dst.port());
            // One radar's spokes: a second radar sending to the same group (two scanners on
            // one network) would mix two pictures into one rotation. The first sender whose
            // spokes decode is tracked; the others' are counted and told, unless the one
            // tracked has been silent for RADAR_GONE_S (a radar back from a power cycle
            // with another address): then the next to decode is.
            let from = *d.src.ip();
            if kind.is_some() && self.radar_address.is_some_and(|a| a != from) {
                // `time_s` is the last datagram decoded: the radar tracked's.
                let gone = d.time_s - self.time_s > RADAR_GONE_S;
                if !gone {
                    let other = self.other_radar.get_or_insert((from, 0));
                    other.1 += 1;
                    continue;
                }
                let change = format!(
                    "{}: the radar at {} silent {:.0} s: now tracking the radar at {from}",
                    crate::utc::date_time_label(d.time_s),
                    self.radar_address
                        .map_or("?".to_string(), |a| a.to_string()),
                    d.time_s - self.time_s
                );
                tell(&mut self.events, told, change);
                self.radar_address = None;
                // The new radar's range scale is its own, from its next report.
                self.range_setting.now_m = None;
                self.range_setting.disagreeing_since = None;
                self.radar_changes += 1;
            }
            let fed = match kind {
                Some(RadarKind::Navico) => self.navico.feed(d.payload, time_ms).is_ok(),
                Some(RadarKind::Garmin) => self.garmin.feed(d.payload, time_ms).is_ok(),
                None => {
                    self.other_datagrams += 1;
                    self.navico_reports += u64::from(self.navico.note_report(d.payload));
                    // The range scale of the radar tracked only (a second radar on the
                    // network reports to the same group); before its first spoke, each
                    // sender's last is kept until it is known which one is tracked.
                    let range = NAVICO_REPORT_GROUPS
                        .iter()
                        .any(|e| e.port == d.dst.port())
                        .then(|| navico::range_setting_report_m(d.payload))
                        .flatten();
                    match (range, self.radar_address) {
                        (Some(m), Some(a)) if a == from => {
                            let (r, events) = (&mut self.range_setting, &mut self.events);
                            r.note(m as f32, d.time_s, told, events);
                        }
                        (Some(m), None) => {
                            let p = &mut self.range_setting.pending;
                            p.retain(|(s, _, _)| *s != from);
                            if p.len() < MAX_PENDING_REPORTERS {
                                p.push((from, m as f32, d.time_s));
                            }
                        }
                        _ => {}
                    }
                    false
                }
            };
            if fed {
                self.active = kind;
                self.time_s = d.time_s;
                if self.radar_address.is_none() {
                    self.radar_address = Some(from);
                    // Its range scale, if it reported one before its first spoke.
                    let pending = std::mem::take(&mut self.range_setting.pending);
                    if let Some(&(_, m, t)) = pending.iter().find(|p| p.0 == from) {
                        let (r, events) = (&mut self.range_setting, &mut self.events);
                        r.note(m, t, told, events);
                    }
                }
            }
        }
        let (kind, spoke, stream) = match self.active {
            Some(RadarKind::Navico) => (
                RadarKind::Navico,
                self.navico.spoke(),
                &mut self.navico_spokes,
            ),
            Some(RadarKind::Garmin) => (
                RadarKind::Garmin,
                self.garmin.spoke(),
                &mut self.garmin_spokes,
            ),
            None => bail!("radar source: no decoder holds a spoke"),
        };
        let Some(spoke) = spoke else {
            bail!("radar source: the {kind} decoder lost its spoke");
        };
        let meta = stream.observe(&spoke, self.time_s);
        self.last = Some((kind, meta));
        if kind == RadarKind::Navico && meta.new_rotation {
            let told = matches!(self.input, Input::Live(_)) && self.live_deadline.is_none();
            self.range_setting
                .check(spoke.range_m, self.time_s, told, &mut self.events);
        }
        if matches!(self.input, Input::Live(_)) {
            self.spoke_at = Instant::now();
            self.spokeless_notes = 0;
        }
        Ok(Some((spoke, self.time_s)))
    }

    /// The brand of the spoke [`next_spoke`](Self::next_spoke) gave last, and what it meant for its
    /// stream (a new rotation, a range change, out of order).
    pub fn last_spoke(&self) -> Option<(RadarKind, SpokeMeta)> {
        self.last
    }

    /// The NMEA lines met in the capture since the last call (capture time s since 1970,
    /// line without its end of line), oldest first; empty for a live source. Lines come
    /// as the capture is read, so a line is met about when the spokes around its time are.
    pub fn nmea_lines(&mut self) -> Vec<(f64, String)> {
        match &mut self.input {
            Input::Capture(c) => c
                .take_nmea_lines()
                .into_iter()
                .map(|l| (l.time_s, l.text))
                .collect(),
            Input::Live(_) => Vec::new(),
        }
    }

    /// True once a capture has been read to its end (never for a live source).
    pub fn is_finished(&self) -> bool {
        match &self.input {
            Input::Capture(c) => c.is_done() && self.active.is_none(),
            Input::Live(_) => false,
        }
    }

    /// Everything counted so far.
    pub fn stats(&self) -> RadarStats {
        let (capture, live) = match &self.input {
            Input::Capture(c) => (Some(c.stats()), None),
            Input::Live(l) => (None, Some(l.stats())),
        };
        RadarStats {
            capture,
            live,
            datagrams: self.datagrams,
            other_datagrams: self.other_datagrams,
            radar_address: self.radar_address,
            other_radar: self.other_radar,
            radar_changes: self.radar_changes,
            navico_reports: self.navico_reports,
            navico_range_reports: self.range_setting.reports,
            navico_range_settings_m: self.range_setting.seen_m.clone(),
            range_disagreements: self.range_setting.disagreements,
            navico: *self.navico.counts(),
            navico_spokes: self.navico_spokes.clone(),
            garmin: *self.garmin.counts(),
            garmin_spokes: self.garmin_spokes.clone(),
        }
    }
}

/// A range scale as a navigator names it: `0.5 NM` (a whole number of eighths of a mile,
/// to the metre), else `100 m`.
pub fn range_scale_label(range_m: f32) -> String {
    let nm = f64::from(tracker_core::geo::METRES_PER_NM);
    let eighths = (f64::from(range_m) / nm * 8.0).round();
    if eighths >= 1.0 && (eighths * nm / 8.0 - f64::from(range_m)).abs() < 1.0 {
        format!("{} NM", eighths / 8.0)
    } else {
        format!("{range_m:.0} m")
    }
}

/// A range scale named, with its metres when it is named in miles: `0.5 NM (926 m)`,
/// `100 m`.
fn range_scale_in_metres(range_m: f32) -> String {
    let label = range_scale_label(range_m);
    if label.ends_with(" NM") {
        format!("{label} ({range_m:.0} m)")
    } else {
        label
    }
}

/// Which decoder a datagram goes to: by structure, or by a spoke port (where a datagram
/// of the wrong shape is a fault to count, not other traffic).
fn route(payload: &[u8], dst_port: u16) -> Option<RadarKind> {
    let on = |groups: &[Endpoint]| groups.iter().any(|e| e.port == dst_port);
    if navico::looks_like_frame(payload) || on(&NAVICO_SPOKE_GROUPS) {
        Some(RadarKind::Navico)
    } else if garmin::looks_like_spoke(payload) || on(&GARMIN_SPOKE_GROUPS) {
        Some(RadarKind::Garmin)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_scale_is_named_as_a_navigator_names_it() {
        assert_eq!(range_scale_label(926.0), "0.5 NM");
        assert_eq!(range_scale_label(14_816.0), "8 NM");
        assert_eq!(range_scale_label(463.0), "0.25 NM");
        assert_eq!(range_scale_label(100.0), "100 m");
        assert_eq!(range_scale_label(1500.0), "1500 m");
    }

    /// The spokes' range against the range reported as chosen: a 4G on 100 m whose spokes
    /// reach 195 m agrees; read as 780 m (`small` taken for metres) it is told once, after
    /// 10 s; a range change that reaches the report a few seconds before the spokes is not.
    #[test]
    fn spokes_reaching_far_past_the_range_chosen_are_told_once() {
        let mut events = crate::event_log::EventLog::default();
        let mut r = RangeSetting::default();
        r.check(780.0, 0.0, false, &mut events);
        assert_eq!(
            r.disagreements, 0,
            "no report yet: nothing to hold it against"
        );
        r.note(100.0, 0.0, false, &mut events);
        r.note(100.0, 5.0, false, &mut events);
        assert_eq!((r.reports, r.seen_m.as_slice()), (2, &[100.0][..]));
        for k in 0..10 {
            r.check(195.0, 2.5 * f64::from(k), false, &mut events);
        }
        assert_eq!(r.disagreements, 0);
        for k in 0..20 {
            r.check(780.0, 30.0 + 2.5 * f64::from(k), false, &mut events);
        }
        assert_eq!(r.disagreements, 1);
        // The range chosen changes; the spokes follow 5 s later: no disagreement.
        r.note(1852.0, 100.0, false, &mut events);
        r.check(195.0, 101.0, false, &mut events);
        r.check(195.0, 103.5, false, &mut events);
        r.check(3274.0, 106.0, false, &mut events);
        r.check(3274.0, 120.0, false, &mut events);
        assert_eq!(r.disagreements, 1);
        let told: Vec<&String> = events
            .as_slice()
            .iter()
            .filter(|e| e.contains("misread"))
            .collect();
        assert_eq!(told.len(), 1, "{:?}", events.as_slice());
        assert!(
            told[0].contains("7.80 times the radar's range scale of 100 m"),
            "{}",
            told[0]
        );
        assert!(events
            .as_slice()
            .iter()
            .any(|e| e.contains("changed its range scale to 1 NM (1852 m)")));
    }
}
