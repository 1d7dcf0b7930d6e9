//! Where a scan's plots come from: a [`PlotSource`] hands the session one antenna
//! revolution at a time.
//!
//! | source | module |
//! |---|---|
//! | the scenario simulator (IMO sensor model, clutter) | [`simulator`] |
//! | a recorded plots file (CSV, documented in the README) | [`plots_file`] |
//! | a radar: spokes from a capture or live, plots extracted | [`radar`] (own ship's yaw from the picture when it has no heading: [`radar_yaw`]) |
//! | the simulator through a synthetic radar and the extractor (`demo --video`) | [`video`] |
//! | real traffic: recorded AIS tracks as truth, plots from the radar model, AIS sent (`demo --ais-truth`) | [`ais_truth`] |
//! | no radar: scans without plots, for AIS and own ship alone (`track --nmea-in` alone) | [`no_radar`] |
//!
//! and [`truth_file`] reads the truth beside a plots file, for scoring.
//!
//! A source may also know own ship at the scan (the simulator's truth, a plots file's own-ship
//! columns) and the ground truth (the simulator; a truth file beside a plots file): the
//! session ignores both; own-ship sources and the scorer use them.

pub mod ais_truth;
pub mod no_radar;
pub mod plots_file;
pub mod radar;
pub mod radar_yaw;
pub mod simulator;
pub mod truth_file;
pub mod video;

use tracker_core::icd::Plot;

use crate::own_ship::OwnShip;
use crate::score::ScanTruth;

/// One antenna revolution's plots, as the tracker receives them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RadarScan {
    /// Scan number, non-decreasing (the source's own numbering).
    pub scan: u32,
    /// The scan's time on the source's clock, s. Later scans have later times.
    pub time_s: f64,
    /// The plots: range (m) and true bearing (rad) from own ship.
    pub plots: Vec<Plot>,
}

/// What a plot source yields for one scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceScan {
    /// The plots.
    pub radar: RadarScan,
    /// Own ship at the scan, when the source knows it (the simulator's truth; a plots
    /// file's `own_*` columns).
    pub own_ship: Option<OwnShip>,
    /// Ground truth for scoring, when the source has it.
    pub truth: Option<ScanTruth>,
    /// The rotation's echoes, when the source is a radar (for the display and snapshots).
    pub echoes: Option<std::sync::Arc<crate::radar::EchoImage>>,
    /// Own ship's heading from a sensor the source reads itself, rad true: a heading
    /// sensor wired to the radar, flagged true in its spokes (the last one held for
    /// [`crate::own_ship::nav::HEADING_LOST_S`] after they stop), or one whose
    /// sentences (`HDT`, `HDG`) a capture holds beside the spokes. Never a fixed heading or
    /// one the source was given back by the run.
    pub heading_sensor_rad: Option<f32>,
    /// The heading, rad true, this scan's plots were placed with when no sensor gave it: a
    /// moored ship's fixed heading (`--heading-deg`) turned by the yaw measured from the
    /// picture, at the scan's time; a plots file's recorded `heading_deg`. Own ship without
    /// a heading of its own (NMEA with no `HDT`/`HDG`) shows and sends it, unless its
    /// heading sensor was lost (whose alarm stands).
    pub placed_heading_rad: Option<f32>,
}

/// A source of radar scans.
pub trait PlotSource {
    /// The next scan; `Ok(None)` once the source has no more.
    ///
    /// # Errors
    /// The source failed (a file that cannot be read, a device that went away); a source
    /// that reads recorded data validates it when it is opened, so a bad file fails there.
    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>>;

    /// Whether the scans' times are UTC (s since 1970-01-01); a source whose times count
    /// from an epoch of its own says not.
    fn time_is_utc(&self) -> bool {
        true
    }

    /// True for a source whose scans come as they happen (a radar on the network), where
    /// [`next_scan`](Self::next_scan) may wait for them; recordings and the simulator never
    /// wait.
    fn is_live(&self) -> bool {
        false
    }

    /// A live source: how long [`next_scan`](Self::next_scan) waits for a scan before it
    /// returns `Ok(None)` with the source still on (`None`, the default: until a scan comes
    /// or the run is interrupted). Others ignore it.
    fn set_live_wait(&mut self, _wait: Option<std::time::Duration>) {}

    /// The antenna period, s, when the source knows it (for pacing a run in real time).
    fn scan_period_s(&self) -> Option<f64>;

    /// False for a source of no radar at all (AIS alone: its scans carry no plots, ever).
    fn has_radar(&self) -> bool {
        true
    }

    /// Scans still to come, when the source knows (for progress and the display).
    fn scans_left(&self) -> Option<u64>;

    /// Own ship as the session used it for the scan just given (a simulator that follows a
    /// live own-ship source takes it; a radar takes its heading for spokes without one;
    /// others ignore it). Its heading is `None` unless a sensor of the run's gave it: one
    /// that came from this source's scans is not handed back.
    fn own_ship_estimate(&mut self, _own: &OwnShip) {}

    /// The AIS reports found with the plots since the last call (a capture's AIVDM), each
    /// with its time (s, the scans' clock).
    fn take_ais(&mut self) -> Vec<(f64, crate::ais::AisReport)> {
        Vec::new()
    }

    /// What became of the AIS sentences found with the plots.
    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        None
    }

    /// What happened worth telling (a live radar replaced by another), oldest first.
    fn events(&self) -> Vec<String> {
        Vec::new()
    }

    /// What a radar source counted (scans, plots, extended returns), for the summary.
    fn radar_counts(&self) -> Option<radar::RadarCounts> {
        None
    }

    /// The accuracy of the plots of the scan just given, m (one axis), when the source
    /// knows it and it may change as the run goes on (a radar's, with its range scale);
    /// `None` for a source whose plots are as accurate as the session was told at the start.
    fn plot_sigma_m(&self) -> Option<f32> {
        None
    }

    /// The plots' accuracy in range and bearing, when the source knows it (a simulator's
    /// sensor model), for the association's pair cost
    /// ([`crate::session::associate::PlotCovariances`]); `None` for plots taken as the
    /// filters take them, as accurate on every axis (plots extracted from spokes).
    fn plot_accuracy(&self) -> Option<crate::session::associate::PolarAccuracy> {
        None
    }
}
