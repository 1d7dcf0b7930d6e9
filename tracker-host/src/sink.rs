//! Where a scan's report goes: a [`ScanSink`] takes every scan the session tracked, with the
//! source's scan beside it (for what only the source knows: the truth, own ship's source
//! values).
//!
//! | sink | module |
//! |---|---|
//! | recordings (plots, truth, tracks) | [`crate::record`] |
//! | targets to chart plotters | [`crate::nmea::targets::TargetsOut`] |
//! | the scorer | [`crate::score::ScoreSink`] |
//! | the plain table and progress lines | [`crate::display::plain`] |

use crate::session::ScanReport;
use crate::source::SourceScan;

/// A consumer of scan reports.
pub trait ScanSink {
    /// Takes one tracked scan.
    ///
    /// # Errors
    /// The sink could not write (a full disk, a closed pipe); a sink that talks to the
    /// outside world (NMEA out) keeps going instead and counts what it could not send.
    fn scan(&mut self, scan: &SourceScan, report: &ScanReport) -> anyhow::Result<()>;

    /// The run is over: flush, and move a file written under a temporary name into place.
    ///
    /// # Errors
    /// The final write or rename failed.
    fn finish(&mut self) -> anyhow::Result<()> {
        Ok(())
    }

    /// What a sink that sends targets to chart plotters sent (`None` for the others).
    fn nmea_out(&self) -> Option<crate::nmea::targets::NmeaOutSummary> {
        None
    }
}
