//! Recordings of a run, as sinks: the scans' plots (a plots file `track --plots` reads
//! back), the truth (a truth file `track --truth` reads back), every track every scan.
//!
//! Numbers are written so they read back bit for bit: `f32` values in their shortest
//! exact form, times as `f64`.

use std::fs::File;
use std::io::{BufWriter, Write};
pub mod snapshot;

use std::path::Path;

use anyhow::{bail, Context};
use tracker_core::icd::TrackStatus;

use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::{plots_file, truth_file, SourceScan};

/// Checks a file can be written at `path` without writing it: its directory exists and
/// lets a file be made there, or the file exists and can be written to. Run before a run
/// starts, so that a typo in an output's path is told at once, not after the run; nothing
/// is left behind (a file made to try is removed, an existing one is not changed).
///
/// # Errors
/// The path is a directory, its directory does not exist or is not one, or the file
/// cannot be made or written (the system's reason).
pub fn check_writable(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        bail!("{} is a directory, not a file", path.display());
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        let why = if dir.exists() {
            "is not a directory"
        } else {
            "does not exist"
        };
        bail!("{}: directory {} {why}", path.display(), dir.display());
    }
    let mut options = std::fs::OpenOptions::new();
    if path.exists() {
        options
            .append(true)
            .open(path)
            .with_context(|| format!("{} cannot be written", path.display()))?;
    } else {
        options
            .write(true)
            .create_new(true)
            .open(path)
            .with_context(|| format!("{} cannot be created", path.display()))?;
        let _ = std::fs::remove_file(path);
    }
    Ok(())
}

/// A run's clock as its recordings write it: a UTC clock as it is; any other (a recording
/// without a time, a capture's own clock) as the time since the run's first scan, so that
/// reading the file back does not take it for UTC (a plots file's times from
/// [`plots_file::UTC_FROM_S`], 10⁹ s, on are). Decided on the first scan; the plots, truth
/// and tracks recorders of a run all see it, so their times agree.
#[derive(Clone, Copy, Debug, Default)]
struct RecordClock {
    /// Taken off every time, s: 0 for a UTC clock, else the first scan's time.
    offset_s: Option<f64>,
}

impl RecordClock {
    /// `time_s` (the scan's time on the run's clock) as written, s.
    fn t_s(&mut self, r: &ScanReport, time_s: f64) -> f64 {
        let offset = *self
            .offset_s
            .get_or_insert(if r.time_is_utc { 0.0 } else { r.time_s });
        time_s - offset
    }
}

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

/// An angle, rad, as a plots file's degrees in [0, 360) (its bearing and heading columns).
fn file_degrees(rad: f32) -> f64 {
    let deg = f64::from(rad).to_degrees().rem_euclid(360.0);
    // A hair under 0 wraps to 360.0 in f64, which the file refuses.
    if deg < 360.0 {
        deg
    } else {
        0.0
    }
}

/// Writes the scans' plots as a plots file ([`plots_file`]'s format), with own ship as the
/// session used it (position and velocity).
pub struct PlotsRecorder(CsvOut, RecordClock);

impl PlotsRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        // Every column (own ship's heading empty while it has none).
        let header: Vec<&str> = plots_file::REQUIRED
            .iter()
            .chain(plots_file::OPTIONAL.iter())
            .copied()
            .collect();
        Ok(PlotsRecorder(
            CsvOut::create(path, &header.join(","))?,
            RecordClock::default(),
        ))
    }
}

impl ScanSink for PlotsRecorder {
    fn scan(&mut self, _: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        let t = self.1.t_s(r, r.time_s);
        // Own ship's heading, degrees in [0, 360) (a head-up radar's plots were placed
        // with it, and the display and plotters show it).
        let heading = r
            .own
            .heading_rad
            .map_or(String::new(), |h| file_degrees(h).to_string());
        // Own ship's velocity as its tracks were formed with: zero while its position
        // stood still in the frame (no fix, or held past dead reckoning's limit), so that
        // CPA and relative motion come out the same when the file is tracked again.
        let velocity = r.own.track_frame_velocity_mps();
        let own = format!(
            "{},{},{},{},{heading}",
            r.own.position_m[0], r.own.position_m[1], velocity[0], velocity[1]
        );
        // The accuracy the plots were associated with, so that `track` weighs them alike.
        let accuracy = r.plot_accuracy.map_or(",".to_string(), |a| {
            format!(
                "{},{}",
                a.range_sigma_m,
                f64::from(a.bearing_sigma_rad).to_degrees()
            )
        });
        // … and the one the filters took them at (a radar's follows its range scale).
        let sigma = r.plot_sigma_m;
        // How own ship's position was known: without a fix the plots were placed about a
        // ship standing where it is written, and tracked again they are relative; a
        // position given is sent as manual input, not as a fix.
        let fix = plots_file::OwnFix::of(&r.own).code();
        if r.plots.is_empty() {
            return self
                .0
                .line(&format!("{},{t},,,{own},,,{sigma},{fix}", r.scan));
        }
        for p in &r.plots {
            let bearing_deg = file_degrees(p.bearing_rad);
            self.0.line(&format!(
                "{},{t},{},{bearing_deg},{own},{accuracy},{sigma},{fix}",
                r.scan, p.range_m
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
pub struct TruthRecorder(CsvOut, RecordClock);

impl TruthRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        let header = [&truth_file::REQUIRED[..], &truth_file::OPTIONAL[..]].concat();
        Ok(TruthRecorder(
            CsvOut::create(path, &header.join(","))?,
            RecordClock::default(),
        ))
    }
}

impl ScanSink for TruthRecorder {
    fn scan(&mut self, s: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        // The clock is decided on the run's first scan, with or without truth.
        let t = self.1.t_s(r, s.radar.time_s);
        let Some(truth) = &s.truth else {
            return Ok(());
        };
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
pub const TRACKS_HEADER: &str = "scan,t_s,track,status,east_m,north_m,vx_mps,vy_mps,held";

/// Writes every track every scan:
/// `scan,t_s,track,status,east_m,north_m,vx_mps,vy_mps,held`, status as the device reports
/// it (`tentative`, `confirmed`, `coasting`, `lost`); `held` 1 for a firm track held as
/// hidden in another's echo and not drawn ([`ScanReport::in_echo`]; a held track whose
/// CPA/TCPA alarm draws it is 0), else 0.
pub struct TracksRecorder(CsvOut, RecordClock);

impl TracksRecorder {
    /// Creates `path`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(path: &Path) -> anyhow::Result<Self> {
        Ok(TracksRecorder(
            CsvOut::create(path, TRACKS_HEADER)?,
            RecordClock::default(),
        ))
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
        let time_s = self.1.t_s(r, r.time_s);
        for t in &r.tracks {
            let held = r.in_echo.iter().any(|h| h.track == t.track);
            self.0.line(&format!(
                "{},{},{},{},{},{},{},{},{}",
                r.scan,
                time_s,
                t.track,
                status_word(t.status),
                t.position_m[0],
                t.position_m[1],
                t.velocity_mps[0],
                t.velocity_mps[1],
                u8::from(held)
            ))?;
        }
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        self.0.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_path_is_checked_without_a_trace() {
        let dir = tempfile::tempdir().unwrap();
        let new = dir.path().join("new.csv");
        check_writable(&new).unwrap();
        assert!(!new.exists(), "the file made to try is removed");
        let old = dir.path().join("old.csv");
        std::fs::write(&old, "kept").unwrap();
        check_writable(&old).unwrap();
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "kept");
        let e = |p: &Path| format!("{:#}", check_writable(p).unwrap_err());
        let nowhere = dir.path().join("no-such-dir").join("s.json");
        assert!(e(&nowhere).contains("does not exist"), "{}", e(&nowhere));
        assert!(
            e(dir.path()).contains("is a directory"),
            "{}",
            e(dir.path())
        );
        let under_a_file = old.join("s.json");
        assert!(
            e(&under_a_file).contains("is not a directory"),
            "{}",
            e(&under_a_file)
        );
    }
}
