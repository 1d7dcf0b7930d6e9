//! Own ship: where we are and how we move, which every range, bearing, CPA and TCPA is
//! measured from, and how far that can be trusted.
//!
//! An [`OwnShipSource`] gives own ship at each scan:
//!
//! | source | what |
//! |---|---|
//! | [`FromPlotSource`] | what the plot source knows: the simulator's truth, a plots file's own-ship columns |
//! | [`NmeaOwnShip`] | NMEA 0183 from the bridge (a recording, UDP, TCP, serial) through the dead-reckoning filter ([`nav`]) |
//! | [`SimulatedBridge`] | the plot source's own ship sent through the same sentences and filter, and recorded |
//!
//! [`sentences`] says what each sentence means, [`clock`] keeps the bridge's UTC, [`select`]
//! chooses one talker per quantity, [`recording`] reads a whole recording ahead (its start,
//! its fixes).

pub mod clock;
pub mod nav;
pub mod recording;
pub mod select;
pub mod sentences;

use std::io::Write as _;

use anyhow::Context;
use tracker_core::geo::EastNorth;

use crate::nmea::bridge::own_ship_sentences;
use crate::nmea::{InSpec, NmeaIn};
use crate::origin::Origin;
use crate::source::SourceScan;
use nav::{NavCounts, OwnShipNav};
use select::Selector;

/// How far own ship can be trusted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OwnShipQuality {
    /// Seconds since the last position fix, once that is longer than
    /// [`nav::POSITION_LOST_S`]: own ship is dead reckoned. `None`: measured.
    pub dead_reckoning_s: Option<f32>,
    /// Own ship's motion over ground is known (measured, or dead reckoned within
    /// [`nav::MAX_DEAD_RECKONING_S`]). Without it targets' true course and speed are not.
    pub motion_known: bool,
    /// A heading was received and has stopped.
    pub heading_lost: bool,
    /// No position yet: own ship is taken at the origin, stopped.
    pub no_fix_yet: bool,
    /// A position fix was refused as implausible lately (far from where own ship can be).
    pub implausible_fix: bool,
}

impl Default for OwnShipQuality {
    /// Measured, motion known (the simulator's truth, a plots file).
    fn default() -> Self {
        OwnShipQuality {
            dead_reckoning_s: None,
            motion_known: true,
            heading_lost: false,
            no_fix_yet: false,
            implausible_fix: false,
        }
    }
}

/// Own ship's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OwnShip {
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity over ground, m/s.
    pub velocity_mps: EastNorth,
    /// Heading, rad true, when a heading sensor gives it.
    pub heading_rad: Option<f32>,
    /// How far it can be trusted.
    pub quality: OwnShipQuality,
}

impl OwnShip {
    /// Measured `position_m` and `velocity_mps`, no heading.
    pub fn at(position_m: EastNorth, velocity_mps: EastNorth) -> Self {
        OwnShip {
            position_m,
            velocity_mps,
            ..OwnShip::default()
        }
    }

    /// Unknown: at the origin, stopped, no fix yet.
    pub fn unknown() -> Self {
        OwnShip {
            quality: OwnShipQuality {
                motion_known: false,
                no_fix_yet: true,
                ..OwnShipQuality::default()
            },
            ..OwnShip::default()
        }
    }

    /// The alarms own ship raises, as the operator reads them.
    pub fn alarms(&self) -> Vec<String> {
        let q = self.quality;
        let mut a = Vec::new();
        if q.no_fix_yet {
            a.push("OWN SHIP: no position fix yet".to_string());
        } else if let Some(age) = q.dead_reckoning_s {
            if q.motion_known {
                a.push(format!(
                    "OWN SHIP: position lost, dead reckoning for {age:.0} s"
                ));
            } else {
                a.push(format!(
                    "OWN SHIP: position lost {:.0} min ago, motion unknown: true vectors off",
                    age / 60.0
                ));
            }
        }
        if q.heading_lost {
            a.push("OWN SHIP: heading lost".to_string());
        }
        if q.implausible_fix {
            a.push("OWN SHIP: implausible position fix refused".to_string());
        }
        a
    }
}

/// A source of own ship, asked once a scan.
pub trait OwnShipSource {
    /// Own ship at the time of `scan`.
    ///
    /// # Errors
    /// The source cannot give own ship at all (a plot source without own-ship data and no
    /// other source), or writing its recording failed.
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip>;

    /// What became of the sentences, for sources that read NMEA.
    fn nmea_counts(&self) -> Option<NavCounts> {
        None
    }

    /// What happened worth telling (a change of source, a disagreement, a reconnection).
    fn events(&self) -> Vec<String> {
        Vec::new()
    }

    /// The AIS reports among the sentences read since the last call, each with its time
    /// (s, the session's clock).
    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        Vec::new()
    }

    /// What became of the AIS sentences, for sources that read NMEA.
    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        None
    }
}

/// Own ship as the plot source knows it.
#[derive(Clone, Copy, Debug, Default)]
pub struct FromPlotSource;

impl OwnShipSource for FromPlotSource {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        scan.own_ship.with_context(|| {
            format!(
                "scan {}: the plot source gives no own ship (take it from NMEA with --nmea-in)",
                scan.radar.scan
            )
        })
    }
}

/// How own-ship NMEA is read.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NmeaOptions {
    /// Talker priority per quantity (the first delivering one is used).
    pub priority: std::collections::BTreeMap<sentences::Quantity, Vec<String>>,
    /// The operator's magnetic variation, degrees east, for magnetic headings that come
    /// with none.
    pub variation_deg: Option<f64>,
    /// Times before the first dated sentence count from this day (days since 1970).
    pub provisional_day: i64,
}

/// A timed sentence this far ahead of the clock, whose next timed neighbour is back before
/// it, is out of sequence (one corrupt time with a valid checksum), s.
const OUT_OF_SEQUENCE_S: f64 = 60.0;

/// Timed sentences looked at past an outlying one.
const LOOK_AHEAD_LINES: usize = 64;

/// Own ship from NMEA 0183 through the dead-reckoning filter. A recording is replayed in
/// step with the scans by its sentences' UTC; a live source gives what has arrived.
pub struct NmeaOwnShip {
    input: NmeaIn,
    nav: OwnShipNav,
    ais: crate::ais::AisDecoder,
    heard: Vec<(f64, crate::ais::AisReport)>,
}

impl NmeaOwnShip {
    /// Opens the source.
    ///
    /// # Errors
    /// The file, socket or port does not open.
    pub fn open(spec: &InSpec, origin: Origin, o: &NmeaOptions) -> anyhow::Result<Self> {
        Ok(NmeaOwnShip {
            input: NmeaIn::open(spec)?,
            nav: OwnShipNav::with_selector(
                origin,
                o.provisional_day,
                o.variation_deg,
                Selector::new(o.priority.clone()),
            ),
            ais: crate::ais::AisDecoder::new(),
            heard: Vec::new(),
        })
    }

    /// Feeds every line of a recording due by `time_s`: untimed lines as they come, a timed
    /// one once its time has come. A timed line far ahead whose next timed neighbour is back
    /// before it is out of sequence: refused, and the replay goes on.
    fn replay_until(&mut self, time_s: f64) {
        let NmeaIn::File(file) = &mut self.input else {
            return;
        };
        while let Some(line) = file.peek(0) {
            let Some(t) = self.nav.time_of(line) else {
                if let Some(line) = file.next_line() {
                    take(&mut self.nav, &mut self.ais, &mut self.heard, &line, time_s);
                }
                continue;
            };
            let reference = self.nav.newest_s().unwrap_or(t).min(time_s);
            if t > reference + OUT_OF_SEQUENCE_S {
                let back = (1..LOOK_AHEAD_LINES)
                    .filter_map(|i| file.peek(i).map(|l| self.nav.time_of(l)))
                    .flatten()
                    .next()
                    .is_some_and(|next| next < t - 1.0);
                if back {
                    file.next_line();
                    self.nav.refuse_out_of_sequence();
                    continue;
                }
            }
            if t > time_s + 1e-6 {
                break;
            }
            if let Some(line) = file.next_line() {
                take(&mut self.nav, &mut self.ais, &mut self.heard, &line, time_s);
            }
        }
    }
}

impl OwnShipSource for NmeaOwnShip {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let t = scan.radar.time_s;
        match &mut self.input {
            NmeaIn::File(_) => self.replay_until(t),
            NmeaIn::Live(live) => {
                for line in live.available() {
                    take(&mut self.nav, &mut self.ais, &mut self.heard, &line, t);
                }
            }
        }
        Ok(self.nav.own_ship_at(t).unwrap_or_else(OwnShip::unknown))
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        Some(self.nav.counts().clone())
    }

    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        std::mem::take(&mut self.heard)
    }

    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        Some(self.ais.counts())
    }

    fn events(&self) -> Vec<String> {
        let mut e = self.nav.events();
        if let NmeaIn::Live(live) = &self.input {
            if live.drops > 0 {
                e.push(format!(
                    "NMEA source dropped {} times, reconnected {} times",
                    live.drops, live.reconnects
                ));
            }
        }
        e
    }
}

/// One line: AIS sentences to the AIS decoder (heard at `time_s`; own ship's `AIVDO` also
/// to the dead-reckoning filter, as one more sensor), the rest to the filter.
fn take(
    nav: &mut OwnShipNav,
    ais: &mut crate::ais::AisDecoder,
    heard: &mut Vec<(f64, crate::ais::AisReport)>,
    line: &str,
    time_s: f64,
) {
    if crate::ais::fragment::is_ais(line) {
        if let Some(r) = ais.feed(line) {
            nav.feed_ais_own(&r, time_s);
            heard.push((time_s, r));
        }
    } else {
        nav.feed(line);
    }
}

/// The plot source's own ship as the bridge's sensors would send it (`GGA`, `RMC`, `VTG`,
/// `HDT`, `VHW`), through the same parser and dead-reckoning filter as real NMEA, and
/// written to a recording that [`NmeaOwnShip`] replays with the same result.
pub struct SimulatedBridge {
    recording: std::io::BufWriter<std::fs::File>,
    origin: Origin,
    /// Made at the first scan, whose date it starts from (as a replay's would).
    nav: Option<OwnShipNav>,
}

impl SimulatedBridge {
    /// Creates the recording at `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &std::path::Path, origin: Origin) -> anyhow::Result<Self> {
        let f =
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?;
        Ok(SimulatedBridge {
            recording: std::io::BufWriter::new(f),
            origin,
            nav: None,
        })
    }
}

impl OwnShipSource for SimulatedBridge {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let truth = FromPlotSource.own_ship(scan)?;
        let t = scan.radar.time_s;
        let origin = self.origin;
        let nav = self
            .nav
            .get_or_insert_with(|| OwnShipNav::new(origin, (t / 86_400.0).floor() as i64, None));
        let lines = own_ship_sentences(
            truth.position_m.map(f64::from),
            truth.velocity_mps.map(f64::from),
            &self.origin,
            t,
        );
        for l in &lines {
            self.recording
                .write_all(l.as_bytes())
                .context("writing the NMEA recording")?;
            nav.feed(l);
        }
        self.recording
            .flush()
            .context("writing the NMEA recording")?;
        Ok(nav.own_ship_at(t).unwrap_or_else(OwnShip::unknown))
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        self.nav.as_ref().map(|n| n.counts().clone())
    }
}
