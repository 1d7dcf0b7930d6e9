//! `tracker-host track`: the tracker on recorded plots (a plots file, and beside it a
//! truth file to score against), with the same session, display, table and outputs as
//! `demo`.

use std::path::PathBuf;

use tracker_core::filter::FilterKind;

use super::run::Run;
use super::{own_ship_source, sinks, Outputs, OwnShipOptions};
use crate::link::Client;
use crate::session::{Session, SessionConfig};
use crate::source::plots_file::PlotsFileSource;
use crate::source::truth_file::TruthFile;

/// What `track` runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOptions {
    /// The plots file.
    pub plots: PathBuf,
    /// The truth file, for a scored summary.
    pub truth: Option<PathBuf>,
    /// The filter every track runs.
    pub filter: FilterKind,
    /// Where own ship comes from (by default the plots file's own-ship columns).
    pub own_ship: OwnShipOptions,
    /// Where results go.
    pub outputs: Outputs,
}

/// Wires `track`: the files are checked before the device is touched or anything written.
///
/// # Errors
/// A file breaks its format (the error names the line and column), the device does not
/// attach, or an own-ship source or output does not open.
pub fn start(client: Client, o: &TrackOptions) -> anyhow::Result<Run> {
    let mut source = PlotsFileSource::open(&o.plots)?;
    if let Some(truth) = &o.truth {
        source = source.with_truth(TruthFile::open(truth)?);
    }
    let origin = o.own_ship.origin();
    let own_ship = own_ship_source(&o.own_ship, origin)?;
    let session = Session::start(client, SessionConfig::tracking(o.filter))?;
    Ok(Run::new(
        Box::new(source),
        own_ship,
        session,
        sinks(&o.outputs, origin)?,
    ))
}
