//! Own ship: where we are and how we move, which every range, bearing, CPA and TCPA is
//! measured from.
//!
//! An [`OwnShipSource`] gives own ship at each scan:
//!
//! | source | what |
//! |---|---|
//! | [`FromPlotSource`] | what the plot source knows: the simulator's truth, a plots file's own-ship columns |
//! | [`NmeaOwnShip`] | NMEA 0183 from the bridge (a recording, UDP, TCP, serial) through the dead-reckoning filter ([`nav`]) |
//! | [`SimulatedBridge`] | the plot source's own ship sent through the same sentences and filter, and recorded |

pub mod nav;

use std::io::Write as _;

use anyhow::Context;
use tracker_core::geo::EastNorth;

use crate::nmea::bridge::own_ship_sentences;
use crate::nmea::{InSpec, NmeaIn};
use crate::origin::Origin;
use crate::source::SourceScan;
use nav::{NavCounts, OwnShipNav};

/// Own ship's state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OwnShip {
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity over ground, m/s.
    pub velocity_mps: EastNorth,
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

/// Own ship from NMEA 0183 through the dead-reckoning filter. A recording is replayed in
/// step with the scans by its sentences' UTC; a live source gives what has arrived.
pub struct NmeaOwnShip {
    input: NmeaIn,
    nav: OwnShipNav,
}

impl NmeaOwnShip {
    /// Opens the source.
    ///
    /// # Errors
    /// The file, socket or port does not open.
    pub fn open(spec: &InSpec, origin: Origin) -> anyhow::Result<Self> {
        Ok(NmeaOwnShip {
            input: NmeaIn::open(spec)?,
            nav: OwnShipNav::new(origin),
        })
    }
}

impl OwnShipSource for NmeaOwnShip {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let t = scan.radar.time_s;
        for line in self.input.lines_until(t) {
            self.nav.feed(&line);
        }
        // Before the first position fix own ship stays at the origin, stopped.
        Ok(self.nav.own_ship_at(t).unwrap_or_default())
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        Some(self.nav.counts())
    }
}

/// The plot source's own ship as the bridge's sensors would send it (`GGA`, `RMC`, `VTG`,
/// `HDT`, `VHW`), through the same parser and dead-reckoning filter as real NMEA, and
/// written to a recording that [`NmeaOwnShip`] replays with the same result.
pub struct SimulatedBridge {
    recording: std::io::BufWriter<std::fs::File>,
    origin: Origin,
    nav: OwnShipNav,
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
            nav: OwnShipNav::new(origin),
        })
    }
}

impl OwnShipSource for SimulatedBridge {
    fn own_ship(&mut self, scan: &SourceScan) -> anyhow::Result<OwnShip> {
        let truth = FromPlotSource.own_ship(scan)?;
        let t = scan.radar.time_s;
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
            self.nav.feed(l);
        }
        self.recording
            .flush()
            .context("writing the NMEA recording")?;
        Ok(self.nav.own_ship_at(t).unwrap_or_default())
    }

    fn nmea_counts(&self) -> Option<NavCounts> {
        Some(self.nav.counts())
    }
}
