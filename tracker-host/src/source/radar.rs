//! A radar as a plot source: spokes ([`SpokeSource`]: a capture or the radar live) through
//! the core's plot extractor ([`Extractor`]: CFAR, blobs, point vs extended), one scan per
//! antenna rotation.
//!
//! - **Scan**: the plots of the blobs that closed between two passes of the antenna through
//!   the bow (north when north-up); the scan's time is the time of the spoke after the wrap,
//!   so the rotation period comes from the data (2.0–2.8 s on the real captures), not from a
//!   setting. A blob across the wrap closes a few spokes later and goes with the next scan.
//! - **Plot time**: a plot is measured at its own time (its spokes' mean time), up to a
//!   rotation before the scan's. Own ship moves meanwhile, so the plot's offset from own ship
//!   is moved by own ship's displacement from the plot's time to the scan's; the target's
//!   own motion over that interval is the tracker's to absorb (as with any radar's plots).
//! - **Heading**: a head-up spoke takes the heading the radar sent with it (flagged true),
//!   else own ship's heading from the NMEA in the same capture (`HDT`, or `HDG`/`HDM` with
//!   variation), else from the own-ship source of the run (the previous scan's), else the
//!   fixed heading set for a moored ship ([`RadarOptions::fixed_heading_rad`]), turned by own
//!   ship's yaw measured from the picture ([`super::radar_yaw`]: a moored ship swings, and
//!   head-up its whole picture turns the other way). Without any, the blobs' bearings are
//!   relative and their plots are not tracked (counted).
//! - **Own ship**: from the NMEA lines found in the capture, through the same dead-reckoning
//!   filter as `--nmea-in` (their UTC tied to the capture clock by the lines' capture
//!   times); without a fix, own ship is at the origin, stopped, and the display says so.
//!   `--nmea-in` replaces it.
//! - **Capacity**: at most [`MAX_PLOTS_PER_SCAN`] plots a scan, the device's limit; past it
//!   the nearest are kept (the dangerous ones) and the rest counted.

use std::collections::VecDeque;

use tracker_core::geo;
use tracker_core::icd::Plot;
use tracker_core::radar::{Event, Extractor, ExtractorConfig, ExtractorStats, RadarPlot, Spoke};
use tracker_core::tracker::MAX_PLOTS_PER_SCAN;

use super::radar_yaw::PictureYaw;
use super::{PlotSource, RadarScan, SourceScan};
use crate::origin::Origin;
use crate::own_ship::nav::{OwnShipNav, HEADING_LOST_S};
use crate::own_ship::OwnShip;
use crate::radar::{CaptureOptions, EchoImage, RadarKind, RadarSpec, RadarStats, SpokeSource};

/// How a radar is read.
#[derive(Clone, Debug, PartialEq)]
pub struct RadarOptions {
    /// Where the spokes come from.
    pub spec: RadarSpec,
    /// The extractor's settings for Navico spokes.
    pub navico: ExtractorConfig,
    /// … and for Garmin spokes.
    pub garmin: ExtractorConfig,
    /// Own ship's heading, rad true, when neither the radar nor NMEA gives one (a moored
    /// ship, a radar without a heading sensor).
    pub fixed_heading_rad: Option<f32>,
    /// Whether the fixed heading is turned by own ship's yaw measured from the picture
    /// ([`super::radar_yaw::PictureYaw`]); on by default.
    pub picture_yaw: bool,
    /// The plots' accuracy, m (one axis), for the tracker's filters and gates; by default
    /// [`plot_sigma_m`] of the range scale in use (a capture's first range at the start; a
    /// live radar's from its first rotation, 40 m before it; anew when the scale changes).
    pub plot_sigma_m: Option<f32>,
}

impl RadarOptions {
    /// The plots' accuracy, m, on a range scale of `range_m` (`None`: not known yet): the
    /// one given ([`RadarOptions::plot_sigma_m`]), else [`plot_sigma_m`] of the scale.
    pub fn plot_sigma_on(&self, range_m: Option<f32>) -> Option<f32> {
        self.plot_sigma_m.or(range_m.map(plot_sigma_m))
    }

    /// The defaults per brand for `spec`.
    pub fn new(spec: RadarSpec) -> Self {
        RadarOptions {
            spec,
            navico: ExtractorConfig::navico_4bit(),
            garmin: ExtractorConfig::garmin_xhd(),
            fixed_heading_rad: None,
            picture_yaw: true,
            plot_sigma_m: None,
        }
    }
}

/// What the radar source has counted, for the summary.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct RadarCounts {
    /// Scans handed to the tracker (rotations, the first partial one included; a capture's
    /// last, ended mid-rotation, only when no whole rotation came before it).
    pub scans: u64,
    /// How far the spokes of the last scan reached, m (the radar's range scale as its spokes
    /// give it; a new user's trial found no capture's range in the summary).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spoke_range_m: Option<f32>,
    /// The ranges a Navico reported as chosen by its user, m, in the order first reported
    /// (its state report; the spokes reach 1.6–2 times it), or the one a Garmin's last spoke
    /// gave: the range scale a navigator knows the radar by.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub range_settings_m: Vec<f32>,
    /// Times the spokes' range stood outside 1.25–2.5 times the range reported as chosen
    /// for 10 s: a range likely misread (each told as an event).
    pub range_disagreements: u64,
    /// Point plots extracted from a capture's last rotation, ended mid-rotation by the
    /// capture: not tracked (the targets in the sector it did not sweep would each count a
    /// miss). NMEA and AIS heard during it are counted, and not taken.
    pub last_rotation_cut_plots: u64,
    /// Plots handed to the tracker.
    pub plots: u64,
    /// Point plots with a relative bearing only (no heading): not tracked.
    pub plots_without_heading: u64,
    /// Point plots past the per-scan limit (the farthest), not tracked.
    pub plots_over_limit: u64,
    /// Extended returns (coast, jetties, rain): shown, not tracked.
    pub extended: u64,
    /// Spokes given a heading from NMEA, the run's own ship or the fixed heading.
    pub spokes_heading_added: u64,
    /// NMEA lines found in the capture.
    pub nmea_lines: u64,
    /// What became of the capture's own-ship sentences (its AIS is counted with AIS), when
    /// it holds NMEA: without it the summary did not say where own ship's heading came
    /// from (a new user's trial on the 4G capture).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture_nmea: Option<crate::own_ship::nav::NavCounts>,
    /// Spokes of a second brand in the same capture (only the first brand met is read).
    pub other_brand_spokes: u64,
    /// Spokes pushed through the extractor.
    pub spokes: u64,
    /// Detected cells.
    pub detections: u64,
    /// Blobs too small to be a plot (noise).
    pub too_small: u64,
    /// Blobs dropped: the extractor's open blobs were full.
    pub blobs_dropped: u64,
    /// Range scale and spoke format changes and out-of-order spokes that restarted
    /// extraction (the rotation's open blobs dropped, a new rotation begun).
    pub restarts: u64,
    /// Rotations whose turn was measured from the picture (the fixed heading in use).
    pub yaw_measured: u64,
    /// … and those with too few plots matched, taken as not turned.
    pub yaw_unmatched: u64,
    /// Own ship's heading change measured from the picture since the first rotation, °.
    pub yaw_deg: f32,
    /// The capture file ends in the middle of a record, or its gzip stream is cut short:
    /// read up to there ([`crate::radar::CaptureStats::truncated_file`]).
    pub capture_truncated: bool,
    /// Spoke datagrams from a second radar on the same groups, ignored (only the first
    /// sender's are tracked).
    pub other_radar_datagrams: u64,
    /// That second radar's address.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub other_radar: Option<std::net::Ipv4Addr>,
    /// Times the radar tracked changed address (silent 10 s while another sent).
    pub radar_changes: u64,
    /// A live radar's datagrams: received, dropped by the reader, dropped by the kernel.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub live: Option<crate::radar::live::LiveStats>,
    /// Datagrams on the radar's groups that were neither brand's spokes (its state
    /// reports, other traffic, junk).
    pub not_spokes: u64,
    /// Spoke packets refused (unknown, truncated or inconsistent), both brands.
    pub spoke_packets_refused: u64,
    /// The plots against the truth, when the radar is the simulator's (`demo --video`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub plot_scores: Option<super::video::PlotScores>,
}

impl RadarCounts {
    /// Point plots a scan, mean.
    pub fn plots_per_scan(&self) -> f64 {
        self.plots as f64 / self.scans.max(1) as f64
    }

    /// Extended returns a scan, mean.
    pub fn extended_per_scan(&self) -> f64 {
        self.extended as f64 / self.scans.max(1) as f64
    }
}

/// The range scales the radar reported, for the summary: ` (the radar on 0.5 NM, 1 NM)`, in
/// the order first reported.
fn range_settings_text(settings_m: &[f32]) -> String {
    let list: Vec<String> = settings_m
        .iter()
        .map(|r| crate::radar::source::range_scale_label(*r))
        .collect();
    if list.is_empty() {
        String::new()
    } else {
        format!(" (the radar on {})", list.join(", "))
    }
}

impl std::fmt::Display for RadarCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} scans, {} spokes{}, {:.1} point plots and {:.1} extended returns a scan; {} plots without heading, {} over the {} limit, {} blobs dropped, {} extraction restarts (a new range scale or spoke format, spokes out of order)",
            self.scans,
            self.spokes,
            self.spoke_range_m
                .map(|r| format!(" reaching {r:.0} m"))
                .unwrap_or_default()
                + &range_settings_text(&self.range_settings_m),
            self.plots_per_scan(),
            self.extended_per_scan(),
            self.plots_without_heading,
            self.plots_over_limit,
            MAX_PLOTS_PER_SCAN,
            self.blobs_dropped,
            self.restarts
        )?;
        if self.range_disagreements > 0 {
            write!(
                f,
                "; the spokes' range disagreed with the radar's {}: it may be misread (events)",
                if self.range_disagreements == 1 {
                    "once".to_string()
                } else {
                    format!("{} times", self.range_disagreements)
                }
            )?;
        }
        if self.yaw_measured + self.yaw_unmatched > 0 {
            write!(
                f,
                "; own ship's yaw from the picture {:+.1}° ({} rotations measured, {} with too few plots)",
                self.yaw_deg, self.yaw_measured, self.yaw_unmatched
            )?;
        }
        if self.last_rotation_cut_plots > 0 {
            write!(
                f,
                "; the capture's last rotation, ended mid-rotation, not tracked ({} plots)",
                self.last_rotation_cut_plots
            )?;
        }
        if let Some(p) = &self.plot_scores {
            write!(f, "; plots against truth: {p}")?;
        }
        if let Some(other) = self.other_radar {
            write!(
                f,
                "; {} spoke datagrams from a second radar at {other} ignored (one radar is tracked: the first heard)",
                self.other_radar_datagrams
            )?;
        }
        if self.radar_changes > 0 {
            write!(
                f,
                "; the radar tracked changed {} times (silent 10 s while another sent)",
                self.radar_changes
            )?;
        }
        if let Some(live) = &self.live {
            write!(f, "; live: {live}")?;
        }
        if self.spoke_packets_refused > 0 || self.live.is_some() {
            write!(
                f,
                "; {} spoke packets refused (unknown, truncated or inconsistent), {} datagrams not a radar's spokes",
                self.spoke_packets_refused, self.not_spokes
            )?;
        }
        if self.capture_truncated {
            write!(
                f,
                "; the capture file is cut short (it ends in the middle of a record): read up to there"
            )?;
        }
        Ok(())
    }
}

/// One rotation's extracted returns, kept for the display and snapshots.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RotationPicture {
    /// The scan they went with.
    pub scan: u32,
    /// Point plots (true bearing unless flagged relative).
    pub plots: Vec<RadarPlot>,
    /// Extended returns.
    pub extended: Vec<RadarPlot>,
}

/// A radar, as a [`PlotSource`]. See the module documentation.
pub struct RadarPlotSource {
    spokes: SpokeSource,
    options: RadarOptions,
    extractor: Option<(RadarKind, Box<Extractor>)>,
    nav: OwnShipNav,
    /// Capture NMEA's UTC minus the capture clock, s (from the newest timed line).
    nmea_offset_s: Option<f64>,
    /// NMEA lines met, not yet due.
    nmea: VecDeque<(f64, String)>,
    /// Own ship as the run used it last (its heading, for spokes when NMEA has none: only
    /// a heading from a sensor of the run's, [`PlotSource::own_ship_estimate`]).
    run_own: Option<OwnShip>,
    /// This rotation's returns so far.
    current: RotationPicture,
    /// The last complete rotation's.
    last: RotationPicture,
    scan: u32,
    last_scan_s: Option<f64>,
    counts: RadarCounts,
    finished: bool,
    /// The spoke being extracted's samples, copied out of the source's buffer.
    samples: Vec<u8>,
    /// The radar picture, each bearing as the sweep last painted it, for the eye.
    image: EchoImage,
    /// The picture at the last wrap, for the scan that wrap closes.
    finished_picture: Option<EchoImage>,
    /// The capture's AIS sentences.
    ais: crate::ais::AisDecoder,
    heard: Vec<(f64, crate::ais::AisReport)>,
    /// The heading for spokes without one, and when it was worked out (capture time, s):
    /// finding it predicts own ship's filter, too much to do for each of 2,048 spokes, and
    /// it changes only with a sentence, at the end of the radar's own heading's hold, or
    /// within a second of NMEA's heading-lost time.
    /// The flag: the heading is the fixed one (turned by the yaw).
    heading_cache: Option<(f64, Option<(f32, bool)>)>,
    /// Own ship's yaw measured from the picture, for the fixed heading.
    yaw: PictureYaw,
    /// A spoke of this rotation was given the fixed heading.
    fixed_heading_seen: bool,
    /// The true heading the radar sent with its last spoke that had one, rad, and that
    /// spoke's capture time, s: held for spokes without one for [`HEADING_LOST_S`], as a
    /// heading sensor's is, then lost.
    radar_heading: Option<(f32, f64)>,
    /// The range scale of the rotation being gathered, m (its last spoke's range).
    range_m: Option<f32>,
    /// The range scale of the scan last given, m.
    scan_range_m: Option<f32>,
}

/// The cached heading is worked out again after this long without a new sentence, s.
const HEADING_CACHE_S: f64 = 1.0;

/// A spoke without its samples (they stay in the source's buffer, borrowed).
#[derive(Clone, Copy, Debug)]
struct SpokeHeader {
    angle: u16,
    spokes_per_rotation: u16,
    north_up: bool,
    heading_rad: Option<f32>,
    range_m: f32,
    time_ms: u64,
    max_sample: u8,
}

impl SpokeHeader {
    fn of(s: &Spoke<'_>) -> Self {
        SpokeHeader {
            angle: s.angle,
            spokes_per_rotation: s.spokes_per_rotation,
            north_up: s.north_up,
            heading_rad: s.heading_rad,
            range_m: s.range_m,
            time_ms: s.time_ms,
            max_sample: s.max_sample,
        }
    }

    fn with(self, heading_rad: Option<f32>, samples: &[u8]) -> Spoke<'_> {
        Spoke {
            angle: self.angle,
            spokes_per_rotation: self.spokes_per_rotation,
            north_up: self.north_up,
            heading_rad,
            range_m: self.range_m,
            time_ms: self.time_ms,
            samples,
            max_sample: self.max_sample,
        }
    }
}

impl std::fmt::Debug for RadarPlotSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RadarPlotSource")
            .field("counts", &self.counts)
            .finish_non_exhaustive()
    }
}

impl RadarPlotSource {
    /// Opens the radar `o` names; own ship from the capture's NMEA is in the frame of
    /// `origin`.
    ///
    /// # Errors
    /// The capture does not open or is not one; a live socket cannot be joined; an
    /// extractor setting is out of range.
    pub fn open(o: &RadarOptions, origin: Origin) -> anyhow::Result<Self> {
        for c in [&o.navico, &o.garmin] {
            c.validate()
                .map_err(|e| anyhow::anyhow!("radar extractor settings: {e}"))?;
        }
        let spokes = SpokeSource::open(&o.spec)?;
        Ok(RadarPlotSource {
            spokes,
            options: o.clone(),
            extractor: None,
            nav: OwnShipNav::new(origin, crate::app::today(), None),
            nmea_offset_s: None,
            nmea: VecDeque::new(),
            run_own: None,
            current: RotationPicture::default(),
            last: RotationPicture::default(),
            scan: 0,
            last_scan_s: None,
            counts: RadarCounts::default(),
            finished: false,
            samples: Vec::new(),
            image: EchoImage::default(),
            finished_picture: None,
            ais: crate::ais::AisDecoder::new(),
            heard: Vec::new(),
            heading_cache: None,
            radar_heading: None,
            yaw: PictureYaw::new(),
            fixed_heading_seen: false,
            range_m: None,
            scan_range_m: None,
        })
    }

    /// What has been counted so far.
    pub fn counts(&self) -> RadarCounts {
        let mut c = self.counts.clone();
        if let Some((_, x)) = &self.extractor {
            let s: &ExtractorStats = x.stats();
            c.spokes = s.spokes;
            c.detections = s.detections;
            c.too_small = s.small_blobs;
            c.blobs_dropped = s.blobs_dropped;
            c.restarts = s.range_changes + s.out_of_order + s.format_changes;
        }
        // Built once: it copies the spoke streams' counts.
        let stats = self.spokes.stats();
        c.capture_truncated = stats.capture.is_some_and(|x| x.truncated_file);
        c.live = stats.live;
        if let Some((other, n)) = stats.other_radar {
            c.other_radar = Some(other);
            c.other_radar_datagrams = n;
        }
        c.radar_changes = stats.radar_changes;
        c.not_spokes = stats.other_datagrams;
        c.spoke_packets_refused = stats.bad_packets();
        (c.yaw_measured, c.yaw_unmatched) = self.yaw.counts();
        c.yaw_deg = self.yaw.yaw_rad().to_degrees();
        c.capture_nmea = Some(self.nav.counts().clone()).filter(|n| n.lines > 0);
        c.spoke_range_m = self.scan_range_m;
        c.range_settings_m = stats.navico_range_settings_m.clone();
        // A Garmin gives the range chosen in every spoke: the last.
        if let (true, Some(m @ 1..)) =
            (c.range_settings_m.is_empty(), stats.garmin.selected_range_m)
        {
            c.range_settings_m.push(m as f32);
        }
        c.range_disagreements = stats.range_disagreements;
        c
    }

    /// The spoke source's counts (packets, faults, rotations).
    pub fn spoke_stats(&self) -> RadarStats {
        self.spokes.stats()
    }

    /// The last complete rotation's returns.
    pub fn picture(&self) -> &RotationPicture {
        &self.last
    }

    /// Own ship from the capture's NMEA at capture time `time_s`, if it has a fix or a
    /// heading sensor (without a fix: unknown, with the heading).
    fn nmea_own_ship(&self, time_s: f64) -> Option<OwnShip> {
        self.nav
            .own_ship_or_heading_at(time_s + self.nmea_offset_s.unwrap_or(0.0))
    }

    /// Feeds the capture's NMEA lines due by capture time `time_s`.
    fn feed_nmea(&mut self, time_s: f64) {
        self.nmea.extend(self.spokes.nmea_lines());
        while self.nmea.front().is_some_and(|(t, _)| *t <= time_s) {
            let Some((t, line)) = self.nmea.pop_front() else {
                break;
            };
            self.counts.nmea_lines += 1;
            if crate::ais::fragment::is_ais(&line) {
                if let Some(r) = self.ais.feed(&line) {
                    self.nav
                        .feed_ais_own(&r, t + self.nmea_offset_s.unwrap_or(0.0));
                    self.heard.push((t, r));
                }
                continue;
            }
            let newest = self.nav.newest_s();
            // Untimed sentences (a capture's GLL without times) at their capture time.
            self.nav
                .feed_heard(&line, t + self.nmea_offset_s.unwrap_or(0.0));
            self.heading_cache = None;
            if let Some(n) = self.nav.newest_s().filter(|n| Some(*n) != newest) {
                self.nmea_offset_s = Some(n - t);
            }
        }
    }

    /// The heading for a head-up spoke without one, rad true, and whether it is the fixed
    /// heading (turned by the yaw measured from the picture).
    fn heading_for(&mut self, time_s: f64) -> Option<(f32, bool)> {
        if let Some((at, heading)) = self.heading_cache {
            // Not across the end of the radar's own heading's hold.
            let held = |t| self.radar_heading_at(t).is_some();
            if (0.0..HEADING_CACHE_S).contains(&(time_s - at)) && held(at) == held(time_s) {
                return heading;
            }
        }
        let heading = self
            .nmea_own_ship(time_s)
            .and_then(|o| o.heading_rad)
            // The run's own ship's heading, when from a sensor of its own (`Run` hands back
            // none that came from this source's scans: a heading that stopped would be
            // held for ever).
            .or_else(|| self.run_own.and_then(|o| o.heading_rad))
            .or_else(|| self.radar_heading_at(time_s))
            .map(|h| (h, false))
            .or_else(|| self.fixed_heading_rad().map(|h| (h, true)));
        self.heading_cache = Some((time_s, heading));
        heading
    }

    /// The fixed heading (`--heading-deg`) turned by the yaw measured from the picture, rad
    /// true.
    fn fixed_heading_rad(&self) -> Option<f32> {
        let yaw = if self.options.picture_yaw {
            self.yaw.yaw_rad()
        } else {
            0.0
        };
        self.options
            .fixed_heading_rad
            .map(|h| geo::wrap_2pi(h + yaw))
    }

    /// Pushes spokes until a rotation ends (`Some(scan time)`) or the input does (`None`).
    fn pump(&mut self) -> anyhow::Result<Option<f64>> {
        loop {
            let (header, time_s) = {
                let Some((spoke, time_s)) = self.spokes.next_spoke()? else {
                    return Ok(None);
                };
                self.samples.clear();
                self.samples.extend_from_slice(spoke.samples);
                (SpokeHeader::of(&spoke), time_s)
            };
            let kind = self
                .spokes
                .last_spoke()
                .map_or(RadarKind::Navico, |(k, _)| k);
            self.feed_nmea(time_s);
            let mut heading_rad = header.heading_rad;
            if let Some(h) = heading_rad {
                self.radar_heading = Some((h, time_s));
            }
            if !header.north_up && heading_rad.is_none() {
                let found = self.heading_for(time_s);
                heading_rad = found.map(|(h, _)| h);
                self.counts.spokes_heading_added += u64::from(found.is_some());
                self.fixed_heading_seen |= found.is_some_and(|(_, fixed)| fixed);
            }
            match &self.extractor {
                Some((k, _)) if *k != kind => {
                    // One brand at a time: a capture with both is read for the first.
                    self.counts.other_brand_spokes += 1;
                    continue;
                }
                Some(_) => {}
                None => {
                    let config = match kind {
                        RadarKind::Navico => self.options.navico,
                        RadarKind::Garmin => self.options.garmin,
                    };
                    let x = Extractor::new(config)
                        .map_err(|e| anyhow::anyhow!("radar extractor settings: {e}"))?;
                    self.extractor = Some((kind, Box::new(x)));
                }
            }
            let Some((_, extractor)) = &mut self.extractor else {
                continue;
            };
            let spoke = header.with(heading_rad, &self.samples);
            let mut wrapped = None;
            let current = &mut self.current;
            extractor.push(&spoke, |e| match e {
                Event::Plot(p) => current.plots.push(p),
                Event::Extended(p) => current.extended.push(p),
                Event::Wrap { time_ms, .. } => wrapped = Some(time_ms as f64 / 1000.0),
            });
            if wrapped.is_some() {
                // The picture of the rotation that ended, before this spoke (the next
                // rotation's first) is painted into the next.
                self.finished_picture = Some(self.image.clone());
                self.image.next_rotation();
            }
            if let Some(b) = spoke.bearing_rad() {
                self.image
                    .add(b, spoke.range_m, spoke.samples, spoke.max_sample);
            }
            let range_m = Some(spoke.range_m);
            if let Some(t) = wrapped {
                // The wrap is reported before the spoke after it is processed: blobs closed
                // by that spoke belong to the rotation that just ended, the spoke to the next.
                self.scan_range_m = self.range_m.or(range_m);
                self.range_m = range_m;
                return Ok(Some(t));
            }
            self.range_m = range_m;
        }
    }

    /// Closes the rotation gathered so far as a scan at `time_s`.
    fn close_scan(&mut self, time_s: f64) -> SourceScan {
        let mut picture = std::mem::take(&mut self.current);
        let fixed_heading_seen = std::mem::take(&mut self.fixed_heading_seen);
        if fixed_heading_seen && self.options.picture_yaw {
            self.turn_by_picture(&mut picture);
        }
        let own_nmea = self.nmea_own_ship(time_s);
        let velocity = own_nmea
            .or(self.run_own)
            .filter(|o| o.quality.motion_known)
            .map_or([0.0, 0.0], |o| o.velocity_mps);
        let mut plots: Vec<Plot> = Vec::with_capacity(picture.plots.len());
        let without_heading = self.counts.plots_without_heading;
        for p in &picture.plots {
            let Some(plot) = p.to_icd() else {
                self.counts.plots_without_heading += 1;
                continue;
            };
            let dt = (time_s - p.time_ms as f64 / 1000.0) as f32;
            plots.push(moved_by_own_ship(plot, velocity, dt));
        }
        if plots.len() > MAX_PLOTS_PER_SCAN {
            plots.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
            self.counts.plots_over_limit += (plots.len() - MAX_PLOTS_PER_SCAN) as u64;
            plots.truncate(MAX_PLOTS_PER_SCAN);
        }
        self.counts.scans += 1;
        self.counts.plots += plots.len() as u64;
        self.counts.extended += picture.extended.len() as u64;
        self.scan += 1;
        self.last = RotationPicture {
            scan: self.scan,
            ..picture
        };
        self.last_scan_s = Some(time_s);
        // Own ship's heading: NMEA's, else the radar's own (a heading sensor wired to the
        // radar, flagged true in its spokes), else what head-up spokes were given.
        let mut own = own_nmea.unwrap_or_else(OwnShip::unknown);
        let mut placed_heading_rad = None;
        let radar_heading = self.radar_heading_at(time_s);
        if own.heading_rad.is_none() {
            // The source's own: not the run's own ship's (which spokes without a heading
            // take, `heading_for`), which would come back to the run as this source's.
            let found = radar_heading
                .map(|h| (h, false))
                .or_else(|| self.fixed_heading_rad().map(|h| (h, true)));
            // The plots were placed with the fixed heading only if a spoke took it (not
            // with a gyro on `--nmea-in`, the run's).
            placed_heading_rad = found
                .filter(|(_, fixed)| *fixed && fixed_heading_seen)
                .map(|(h, _)| h);
            match found {
                // A heading sensor lost and the radar's own standing in is told, as when
                // own ship comes from `--nmea-in` (`Run`): the heading has changed source.
                Some((h, false)) => own.stand_in_heading(Some(h), true),
                // The fixed heading stands in for no sensor: a lost one keeps its alarm.
                Some((h, true)) => {
                    own.heading_rad = Some(h);
                    own.quality.heading_given = true;
                }
                None => own.heading_rad = None,
            }
            // The radar's own heading stopped: lost, as a sensor's is, whether nothing
            // stands in or the fixed heading does (the picture is no longer placed with a
            // measured heading).
            own.quality.heading_lost |= radar_heading.is_none() && self.radar_heading.is_some();
        }
        // Whether the alarm stands (no heading for own ship at all) is the run's to say.
        own.quality.heading_needed = self.counts.plots_without_heading > without_heading;
        let own_ship = Some(own);
        // The picture as the sweep left it (taken at the wrap; a capture's last rotation
        // ended mid-way, now, when it is tracked); the next rotation repaints it bearing by
        // bearing.
        let echoes = self.finished_picture.take().unwrap_or_else(|| {
            let picture = self.image.clone();
            self.image.next_rotation();
            picture
        });
        SourceScan {
            radar: RadarScan {
                scan: self.scan,
                time_s,
                plots,
            },
            own_ship,
            truth: None,
            echoes: Some(std::sync::Arc::new(echoes)),
            // A heading sensor: the radar's own (held as long as a sensor's is), else one
            // whose sentences the capture holds (an own-ship source of the run's without a
            // heading takes it: the plots were placed with it, and it is shown and sent as
            // own ship's heading).
            heading_sensor_rad: radar_heading.or(own_nmea.and_then(|o| o.heading_rad)),
            placed_heading_rad,
        }
    }
}

impl RadarPlotSource {
    /// The radar's own heading at capture time `time_s`, rad true: the last one its spokes
    /// carried, for [`HEADING_LOST_S`].
    fn radar_heading_at(&self, time_s: f64) -> Option<f32> {
        self.radar_heading
            .filter(|(_, at)| time_s - at <= HEADING_LOST_S)
            .map(|(h, _)| h)
    }

    /// Measures own ship's turn over this rotation from its point plots (extracted with the
    /// fixed heading and the yaw so far) and turns the rotation's returns by it, so that
    /// they are as the heading at the scan gives them (the echo image stays as drawn).
    fn turn_by_picture(&mut self, picture: &mut RotationPicture) {
        let plots: Vec<(f32, f32)> = picture
            .plots
            .iter()
            .filter(|p| !p.relative_bearing)
            .map(|p| (p.range_m, p.bearing_rad))
            .collect();
        let step = self.yaw.measure(&plots);
        // The next spokes take the new yaw.
        self.heading_cache = None;
        if step == 0.0 {
            return;
        }
        for p in picture.plots.iter_mut().chain(picture.extended.iter_mut()) {
            if !p.relative_bearing {
                p.bearing_rad = geo::wrap_2pi(p.bearing_rad + step);
            }
        }
    }
}

/// What a capture holds before it is tracked: the first position fix in its NMEA (the
/// natural origin of its local frame) and the range of its first spoke.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CaptureSurvey {
    /// The first fix, if the capture's NMEA has one.
    pub first_fix: Option<Origin>,
    /// The first spoke's range, m, if it has spokes.
    pub first_range_m: Option<f32>,
    /// The first spoke's time, s since 1970 (the capture's clock, UTC).
    pub first_spoke_s: Option<f64>,
    /// The file ended inside a record (or its gzip stream was cut short) before the survey
    /// was done: with no spoke, a capture cut short rather than one of something else.
    pub cut_short: bool,
}

impl CaptureSurvey {
    /// Reads a capture until both are found, or through its first [`SURVEY_S`] (a bridge
    /// sends a fix every second or so: one not found by then is not used for the origin,
    /// and a long capture without NMEA is not read twice at start-up).
    ///
    /// # Errors
    /// The capture does not open or cannot be read.
    pub fn of(path: &std::path::Path) -> anyhow::Result<Self> {
        let mut spokes = SpokeSource::from_capture(path, CaptureOptions::default())?;
        let mut nav = OwnShipNav::new(Origin::default(), crate::app::today(), None).keep_fixes();
        let mut survey = CaptureSurvey::default();
        let mut first_s = None;
        loop {
            let spoke = spokes.next_spoke()?.map(|(s, t)| (s.range_m, t));
            survey.first_range_m = survey.first_range_m.or(spoke.map(|(r, _)| r));
            survey.first_spoke_s = survey.first_spoke_s.or(spoke.map(|(_, t)| t));
            for (_, line) in spokes.nmea_lines() {
                nav.feed(&line);
                if let Some(&(_, lat_deg, lon_deg)) = nav.fixes().first() {
                    survey.first_fix = Some(Origin { lat_deg, lon_deg });
                    break;
                }
            }
            let Some((_, t)) = spoke else {
                survey.cut_short = spokes.stats().capture.is_some_and(|c| c.truncated_file);
                return Ok(survey);
            };
            let first = *first_s.get_or_insert(t);
            let found = survey.first_fix.is_some() && survey.first_range_m.is_some();
            if found || t - first > SURVEY_S {
                return Ok(survey);
            }
        }
    }
}

/// How far into a capture [`CaptureSurvey::of`] looks for a fix, s of capture time.
pub const SURVEY_S: f64 = 60.0;

/// The accuracy of a radar's plots on a range scale of `range_m`, m (one axis):
/// [`PLOT_SIGMA_OF_RANGE`] of the range, at least [`MIN_PLOT_SIGMA_M`] and at most the 40 m
/// the session uses for plots of unknown origin.
pub fn plot_sigma_m(range_m: f32) -> f32 {
    (PLOT_SIGMA_OF_RANGE * range_m).clamp(MIN_PLOT_SIGMA_M, crate::session::PLOT_SIGMA_M)
}

/// The plots' accuracy as a fraction of the range scale: 0.25 %, a quarter of the range
/// term (1 % of range) of the IMO performance standard's accuracy, which is what a radar must
/// at worst achieve, not what it does (the standard's bound is the greater of that term and
/// a fixed distance of tens of metres, far above any plot's scatter on short scales).
///
/// Measured on the real captures (`tests/radar_tracking.rs`: the plots of stationary point
/// echoes about their own mean position, every whole scan), the median distance from the
/// mean is 1.7 m on the 195 m scale (4G), 1.2 m on 796 m (HALO), 3.2 m on the 3G (a first
/// range of 1.6 km, plots to 3.2 km), 4.2 m on the Garmin (4.2 km, plots to 1.3 km; its yaw
/// measured from the picture), 43 m on 25 km (HALO, 2–3 scans): a σ of 1.4, 1.0, 2.7, 3.6
/// and 36 m (a median distance of 1.18 σ for Gaussian plots), against 2, 2, 4, 10.4 and
/// 40 m here, so still above the scatter on every scale. With 1 % (8 m on the HALO's 796 m)
/// a one-plot track's gate in a harbour spanned tens of metres of other echoes and
/// confirmed tracks of tens of knots were started between them; from 4.4 m up they are
/// back. Chosen on those same captures (docs/radar.md has the sweep).
pub const PLOT_SIGMA_OF_RANGE: f32 = 0.0025;

/// The smallest plot accuracy [`plot_sigma_m`] gives, m (1 % of range on the 200 m scale,
/// [`PLOT_SIGMA_OF_RANGE`] of it on 800 m). It was 5 m while a plot was a CFAR blob (a
/// fragment of an echo's edge, which wandered over the echo); a plot is now the whole echo's
/// centroid, and on the 195 m scale its scatter is 1.7 m (median distance from its mean). A
/// 5 m σ makes the refined gate (about 16 m) take in the neighbouring boats of a pontoon,
/// 8 m apart.
pub const MIN_PLOT_SIGMA_M: f32 = 2.0;

/// `plot` (measured `dt_s` before the scan, range m and true bearing rad from own ship
/// then) as seen from own ship at the scan, own ship moving at `velocity_mps` (east, north).
fn moved_by_own_ship(plot: Plot, velocity_mps: [f32; 2], dt_s: f32) -> Plot {
    if dt_s <= 0.0 || velocity_mps == [0.0, 0.0] {
        return plot;
    }
    // Exact trigonometry (not geo's table sines): a plot's offset is kept to the
    // millimetre, whatever its range.
    let (s, c) = plot.bearing_rad.sin_cos();
    let east = plot.range_m * s - velocity_mps[0] * dt_s;
    let north = plot.range_m * c - velocity_mps[1] * dt_s;
    Plot {
        range_m: east.hypot(north),
        bearing_rad: geo::wrap_2pi(east.atan2(north)),
    }
}

impl PlotSource for RadarPlotSource {
    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        if self.finished {
            return Ok(None);
        }
        match self.pump()? {
            Some(t) => Ok(Some(self.close_scan(t))),
            None if self.spokes.is_live() => Ok(None),
            None => {
                // The capture ended mid-rotation: what closed is the last rotation, cut
                // short. Tracked, the targets in the sector it did not sweep would each miss
                // a plot and show as coasting in the last picture: it is counted and left,
                // once a whole rotation has been tracked (scan 1 is the capture's first,
                // partial one).
                self.finished = true;
                self.scan_range_m = self.range_m;
                if let Some((_, x)) = &mut self.extractor {
                    let current = &mut self.current;
                    x.flush(|e| match e {
                        Event::Plot(p) => current.plots.push(p),
                        Event::Extended(p) => current.extended.push(p),
                        Event::Wrap { .. } => {}
                    });
                }
                if self.scan >= 2 {
                    self.counts.last_rotation_cut_plots = self.current.plots.len() as u64;
                    return Ok(None);
                }
                let time_s = self
                    .current
                    .plots
                    .iter()
                    .map(|p| p.time_ms as f64 / 1000.0)
                    .fold(self.last_scan_s.unwrap_or(0.0), f64::max);
                if self.current.plots.is_empty() || Some(time_s) <= self.last_scan_s {
                    return Ok(None);
                }
                Ok(Some(self.close_scan(time_s)))
            }
        }
    }

    fn scan_period_s(&self) -> Option<f64> {
        let s = self.spokes.stats();
        s.navico_spokes
            .mean_rotation_s()
            .or(s.garmin_spokes.mean_rotation_s())
    }

    fn scans_left(&self) -> Option<u64> {
        None
    }

    fn own_ship_estimate(&mut self, own: &OwnShip) {
        self.run_own = Some(*own);
        self.heading_cache = None;
    }

    fn radar_counts(&self) -> Option<RadarCounts> {
        Some(self.counts())
    }

    /// The spoke streams' events, and the capture's own-ship NMEA's (a change of source,
    /// sources that disagree), marked as the capture's.
    fn events(&self) -> Vec<String> {
        let mut events = self.spokes.events();
        let nmea = self.nav.events();
        events.extend(nmea.into_iter().map(|e| format!("the capture's NMEA: {e}")));
        events
    }

    fn is_live(&self) -> bool {
        self.spokes.is_live()
    }

    fn set_live_wait(&mut self, wait: Option<std::time::Duration>) {
        self.spokes.set_live_wait(wait);
    }

    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        std::mem::take(&mut self.heard)
    }

    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        (self.ais.counts().sentences > 0).then(|| self.ais.counts())
    }

    /// The `--plot-sigma-m` given, else [`plot_sigma_m`] of the range scale in use (a live
    /// radar's is known from its first spoke on, and the operator changes it).
    fn plot_sigma_m(&self) -> Option<f32> {
        self.options.plot_sigma_on(self.scan_range_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plot_is_moved_back_by_own_ships_motion_since() {
        // Own ship 10 m/s north for 2 s: a plot dead ahead at 1,000 m is 980 m ahead now.
        let p = Plot {
            range_m: 1000.0,
            bearing_rad: 0.0,
        };
        let q = moved_by_own_ship(p, [0.0, 10.0], 2.0);
        assert!((q.range_m - 980.0).abs() < 1e-3);
        assert!(q.bearing_rad.abs() < 1e-6);
        // Abeam to starboard, own ship east: the offset shrinks the same way.
        let p = Plot {
            range_m: 500.0,
            bearing_rad: core::f32::consts::FRAC_PI_2,
        };
        let q = moved_by_own_ship(p, [5.0, 0.0], 4.0);
        assert!((q.range_m - 480.0).abs() < 1e-3);
        // Stopped, or a plot from the scan's own time: unchanged.
        assert_eq!(moved_by_own_ship(p, [0.0, 0.0], 2.0), p);
        assert_eq!(moved_by_own_ship(p, [3.0, 3.0], 0.0), p);
    }
}
