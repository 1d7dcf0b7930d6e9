//! A truth file beside a plots file, for scoring `track` runs.
//!
//! CSV with a header: `t_s,target,east_m,north_m,vx_mps,vy_mps` (s, integer, m, m, m/s,
//! m/s), one row per target per scan, the scan's time in `t_s`; optionally `detected` (1
//! when the scan holds a plot of that target, else 0: the confirmation delay counts from
//! it; without the column every target counts as detected on every scan it is listed).
//! Rows with `target` 0 are own ship's truth; without them own ship's truth is the plots
//! file's own ship. Rows are in time order.

use std::path::Path;

use anyhow::bail;

use crate::csv_input::{self, Header};
use crate::own_ship::OwnShip;
use crate::score::{ScanTruth, TargetTruth};

/// Columns every truth file has.
pub const REQUIRED: [&str; 6] = ["t_s", "target", "east_m", "north_m", "vx_mps", "vy_mps"];

/// Columns a truth file may have.
pub const OPTIONAL: [&str; 1] = ["detected"];

/// Two times this close are the same scan's, s.
const SAME_SCAN_S: f64 = 5e-4;

/// One row.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TruthRow {
    t_s: f64,
    target: u32,
    position_m: [f32; 2],
    velocity_mps: [f32; 2],
    detected: bool,
}

/// A truth file, checked, read in step with the scans.
pub struct TruthFile {
    reader: csv::Reader<std::fs::File>,
    header: Header,
    ahead: Option<TruthRow>,
    last_t: Option<f64>,
}

impl TruthFile {
    /// Opens and checks `path`.
    ///
    /// # Errors
    /// The file does not open, or a line breaks the format (named with its column).
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        let mut check = Self::reopen(path)?;
        while check.next_row()?.is_some() {}
        Self::reopen(path)
    }

    fn reopen(path: &Path) -> anyhow::Result<Self> {
        let (reader, header) = csv_input::open(path, &REQUIRED, &OPTIONAL)?;
        Ok(TruthFile {
            reader,
            header,
            ahead: None,
            last_t: None,
        })
    }

    fn next_row(&mut self) -> anyhow::Result<Option<TruthRow>> {
        if let Some(r) = self.ahead.take() {
            return Ok(Some(r));
        }
        let mut record = csv::StringRecord::new();
        if !csv_input::read(&mut self.reader, &self.header, &mut record)? {
            return Ok(None);
        }
        let row = self.header.row(&record);
        let t_s = row.required_number("t_s")?;
        if self.last_t.is_some_and(|last| t_s < last) {
            return Err(row.error("t_s", "rows must be in time order"));
        }
        self.last_t = Some(t_s);
        let detected = match row.text("detected") {
            None | Some("1") => true,
            Some("0") => false,
            Some(other) => return Err(row.error("detected", &format!("`{other}`: 0 or 1"))),
        };
        let f = |c: &str| row.required_f32(c);
        Ok(Some(TruthRow {
            t_s,
            target: row.required_u32("target")?,
            position_m: [f("east_m")?, f("north_m")?],
            velocity_mps: [f("vx_mps")?, f("vy_mps")?],
            detected,
        }))
    }

    /// The truth at the scan at `time_s`; `own` is own ship as the plots file gives it
    /// (used when the file has no own-ship rows). Earlier rows are skipped.
    ///
    /// # Errors
    /// A read error (the file changed since it was checked); `plots` names the plots file
    /// when the truth file has no row for this scan.
    pub fn at(&mut self, time_s: f64, own: OwnShip, plots: &Path) -> anyhow::Result<ScanTruth> {
        let mut truth = ScanTruth {
            own,
            targets: Vec::new(),
            ids_are_mmsi: false,
        };
        let mut any = false;
        while let Some(r) = self.next_row()? {
            if r.t_s > time_s + SAME_SCAN_S {
                self.ahead = Some(r);
                break;
            }
            if r.t_s < time_s - SAME_SCAN_S {
                continue;
            }
            any = true;
            if r.target == 0 {
                truth.own = OwnShip::at(r.position_m, r.velocity_mps);
            } else {
                truth.targets.push(TargetTruth {
                    id: r.target,
                    position_m: r.position_m,
                    velocity_mps: r.velocity_mps,
                    detected: r.detected,
                    // A truth file does not say the radar's range: every target counts.
                    in_range: true,
                });
            }
        }
        if !any {
            bail!(
                "{}: no truth at t_s = {time_s} (a scan of {})",
                self.header.file(),
                plots.display()
            );
        }
        Ok(truth)
    }
}
