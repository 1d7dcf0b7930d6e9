//! Recordings of a run, as sinks: the scans' plots (a plots file `track --plots` reads
//! back), the truth (a truth file `track --truth` reads back), every track every scan.
//!
//! Numbers are written so they read back bit for bit: `f32` values in their shortest
//! exact form, times as `f64`.

use std::fs::File;
use std::io::{BufWriter, Write};
pub mod snapshot;

use std::path::Path;

use anyhow::Context;
use tracker_core::icd::TrackStatus;

use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::{plots_file, truth_file, SourceScan};

/// A CSV file being written.
struct CsvOut {
    out: BufWriter<File>,
    path: String,
}

impl CsvOut {
    fn create(path: &Path, header: &str) -> anyhow::Result<Self> {
        let file = File::create(path).with_context(|| format!("creating {}", path.display()))?;
        let mut out = CsvOut {
            out: BufWriter::new(file),
            path: path.display().to_string(),
        };
        out.line(header)?;
        Ok(out)
    }

    fn line(&mut self, text: &str) -> anyhow::Result<()> {
        writeln!(self.out, "{text}").with_context(|| format!("writing {}", self.path))
    }

    fn flush(&mut self) -> anyhow::Result<()> {
        self.out
            .flush()
            .with_context(|| format!("writing {}", self.path))
    }
}

/// Writes the scans' plots as a plots file ([`plots_file`]'s format), with own ship as the
/// session used it (position and velocity).
pub struct PlotsRecorder(CsvOut);

impl PlotsRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let header = [&plots_file::REQUIRED[..], &plots_file::OPTIONAL[..2]].concat();
        Ok(PlotsRecorder(CsvOut::create(path, &header.join(","))?))
    }
}

impl ScanSink for PlotsRecorder {
    fn scan(&mut self, _: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        let own = format!(
            "{},{},{},{}",
            r.own.position_m[0], r.own.position_m[1], r.own.velocity_mps[0], r.own.velocity_mps[1]
        );
        if r.plots.is_empty() {
            return self.0.line(&format!("{},{},,,{own}", r.scan, r.time_s));
        }
        for p in &r.plots {
            let bearing_deg = f64::from(p.bearing_rad).to_degrees().rem_euclid(360.0);
            self.0.line(&format!(
                "{},{},{},{bearing_deg},{own}",
                r.scan, r.time_s, p.range_m
            ))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        self.0.flush()
    }
}

/// Writes the source's truth as a truth file ([`truth_file`]'s format, own ship as target
/// 0). Scans without truth write nothing.
pub struct TruthRecorder(CsvOut);

impl TruthRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let header = [&truth_file::REQUIRED[..], &truth_file::OPTIONAL[..]].concat();
        Ok(TruthRecorder(CsvOut::create(path, &header.join(","))?))
    }
}

impl ScanSink for TruthRecorder {
    fn scan(&mut self, s: &SourceScan, _: &ScanReport) -> anyhow::Result<()> {
        let Some(truth) = &s.truth else {
            return Ok(());
        };
        let t = s.radar.time_s;
        let own = truth.own;
        self.0.line(&format!(
            "{t},0,{},{},{},{},1",
            own.position_m[0], own.position_m[1], own.velocity_mps[0], own.velocity_mps[1]
        ))?;
        for x in &truth.targets {
            self.0.line(&format!(
                "{t},{},{},{},{},{},{}",
                x.id,
                x.position_m[0],
                x.position_m[1],
                x.velocity_mps[0],
                x.velocity_mps[1],
                u8::from(x.detected)
            ))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        self.0.flush()
    }
}

/// Columns of a tracks recording.
pub const TRACKS_HEADER: &str = "scan,t_s,track,status,east_m,north_m,vx_mps,vy_mps";

/// Writes every track every scan: `scan,t_s,track,status,east_m,north_m,vx_mps,vy_mps`,
/// status as the device reports it (`tentative`, `confirmed`, `coasting`, `lost`).
pub struct TracksRecorder(CsvOut);

impl TracksRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        Ok(TracksRecorder(CsvOut::create(path, TRACKS_HEADER)?))
    }
}

/// A track status as a tracks recording spells it.
pub fn status_word(s: TrackStatus) -> &'static str {
    match s {
        TrackStatus::Tentative => "tentative",
        TrackStatus::Confirmed => "confirmed",
        TrackStatus::Coasting => "coasting",
        TrackStatus::Lost => "lost",
    }
}

impl ScanSink for TracksRecorder {
    fn scan(&mut self, _: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        for t in &r.tracks {
            self.0.line(&format!(
                "{},{},{},{},{},{},{},{}",
                r.scan,
                r.time_s,
                t.track,
                status_word(t.status),
                t.position_m[0],
                t.position_m[1],
                t.velocity_mps[0],
                t.velocity_mps[1]
            ))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        self.0.flush()
    }
}
