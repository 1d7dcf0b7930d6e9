//! A recorded plots file as a plot source.
//!
//! The format (CSV with a header; other tools write it, so it is exactly this):
//!
//! | column | unit | |
//! |---|---|---|
//! | `scan` | integer | non-decreasing; the rows of a scan are together |
//! | `t_s` | s | the scan's time, the same on all its rows; later scans later |
//! | `range_m` | m | plot range from own ship; empty on a scan's only row when it has no plot |
//! | `bearing_deg` | degrees true | 0 ≤ b < 360; empty with `range_m` |
//! | `own_east_m`, `own_north_m` | m | own ship in the local frame of `--origin` |
//! | `own_vx_mps`, `own_vy_mps` | m/s | optional, both or neither: own ship's velocity over ground (without them: from successive positions with a fix, else 0) |
//! | `heading_deg` | degrees true | optional: own ship's heading |
//! | `range_sigma_m`, `bearing_sigma_deg` | m, degrees | optional, both or neither: the plot's accuracy (standard deviations) in range and bearing, the same on every row of a scan; empty on a row without it (`demo --record-plots` writes the simulator's) |
//! | `own_fix` | `1`, `0` or `M` | optional: how own ship's position was known ([`OwnFix`]): `0` no fix (none yet, or dead reckoned past its limit: own ship stood where the file places it, its motion unknown; tracked again, `NO FIX` and relative motion only); `M` a position given, not measured (`--fixed-position`: stopped); `1`, empty or absent: a fix |
//! | `plot_sigma_m` | m | optional: the accuracy (one axis) the filters and gates take the scan's plots at, the same on every row of a scan (`--record-plots` writes the one tracked with: a radar's follows its range scale); empty: the last given (before the first, the first); absent: 40 m; `--plot-sigma-m` overrides it |
//!
//! The file is read twice: once whole to check it (a bad file is refused before anything
//! is tracked or written, with its line and column), then scan by scan, so memory does not
//! grow with its length.

use std::path::{Path, PathBuf};

use anyhow::bail;
use tracker_core::icd::Plot;

use super::{PlotSource, RadarScan, SourceScan};
use crate::csv_input::{self, Header};
use crate::own_ship::OwnShip;
use crate::session::associate::PolarAccuracy;
use crate::source::truth_file::TruthFile;

/// Columns every plots file has.
pub const REQUIRED: [&str; 6] = [
    "scan",
    "t_s",
    "range_m",
    "bearing_deg",
    "own_east_m",
    "own_north_m",
];

/// Columns a plots file may have.
pub const OPTIONAL: [&str; 7] = [
    "own_vx_mps",
    "own_vy_mps",
    "heading_deg",
    "range_sigma_m",
    "bearing_sigma_deg",
    "plot_sigma_m",
    "own_fix",
];

/// How own ship's position in a plots file was known: its `own_fix` column, which
/// `--record-plots` writes from own ship's quality ([`crate::own_ship::OwnShipQuality`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OwnFix {
    /// `1` (empty or absent too): a position fix, or dead reckoned from one within its
    /// limit.
    Fix,
    /// `0`: no fix (none yet, or dead reckoned past its limit): own ship stood where the
    /// file places it, its motion over ground unknown; the plots and tracks move relative
    /// to it.
    NoFix,
    /// `M` (NMEA's mode for manual input): a position given, not measured
    /// (`--fixed-position`), own ship stopped there.
    Given,
}

impl OwnFix {
    /// How `own`'s position was known: no fix while it is held in the frame
    /// ([`OwnShip::position_held`]), given for `--fixed-position`, else a fix. (A fix whose
    /// motion is not yet measured, its first scans, is a fix.)
    pub fn of(own: &OwnShip) -> Self {
        if own.position_held() {
            OwnFix::NoFix
        } else if own.quality.fixed_position {
            OwnFix::Given
        } else {
            OwnFix::Fix
        }
    }

    /// The column's text for it (`1`, `0`, `M`).
    pub fn code(self) -> &'static str {
        match self {
            OwnFix::Fix => "1",
            OwnFix::NoFix => "0",
            OwnFix::Given => "M",
        }
    }
}

/// Longest plot range accepted, m (200 km: beyond any marine radar).
pub const MAX_RANGE_M: f64 = 200_000.0;

/// Plots one scan may hold: the device's limit.
pub const MAX_PLOTS_PER_SCAN: usize = tracker_core::tracker::MAX_PLOTS_PER_SCAN;

/// One scan as read from the file.
#[derive(Clone, Debug, PartialEq)]
pub struct FileScan {
    /// Its plots and time.
    pub radar: RadarScan,
    /// Own ship's position, m.
    pub own_position_m: [f32; 2],
    /// Own ship's velocity from the file's columns, m/s.
    pub own_velocity_mps: Option<[f32; 2]>,
    /// Own ship's heading, degrees true.
    pub heading_deg: Option<f64>,
    /// How own ship's position was known (`own_fix`).
    pub own_fix: OwnFix,
    /// The plots' accuracy, when the file gives it.
    pub accuracy: Option<PolarAccuracy>,
    /// The accuracy the filters take the plots at, m, when the file gives it.
    pub plot_sigma_m: Option<f32>,
}

/// Reads scans one at a time.
struct ScanReader {
    reader: csv::Reader<std::fs::File>,
    header: Header,
    /// The first row of the next scan, read ahead.
    ahead: Option<csv::StringRecord>,
    last: Option<(u32, f64)>,
    has_velocity: bool,
}

impl ScanReader {
    fn open(path: &Path) -> anyhow::Result<Self> {
        let (reader, header) = csv_input::open(path, &REQUIRED, &OPTIONAL)?;
        let (vx, vy) = (header.has("own_vx_mps"), header.has("own_vy_mps"));
        if vx != vy {
            bail!(
                "{}: line 1: own_vx_mps and own_vy_mps go together (one is missing)",
                header.file()
            );
        }
        Ok(ScanReader {
            reader,
            header,
            ahead: None,
            last: None,
            has_velocity: vx,
        })
    }

    fn next_record(&mut self) -> anyhow::Result<Option<csv::StringRecord>> {
        if let Some(r) = self.ahead.take() {
            return Ok(Some(r));
        }
        let mut r = csv::StringRecord::new();
        Ok(csv_input::read(&mut self.reader, &self.header, &mut r)?.then_some(r))
    }

    /// The next scan, checked; `None` at the end of the file.
    fn next_scan(&mut self) -> anyhow::Result<Option<FileScan>> {
        let Some(first) = self.next_record()? else {
            return Ok(None);
        };
        let row = self.header.row(&first);
        let scan = row.required_u32("scan")?;
        let t_s = row.required_number("t_s")?;
        if let Some((last_scan, last_t)) = self.last {
            if scan < last_scan {
                return Err(row.error(
                    "scan",
                    &format!("scan {scan} after scan {last_scan}: scans must not decrease"),
                ));
            }
            if scan == last_scan {
                return Err(row.error(
                    "scan",
                    &format!("scan {scan} again after other rows: a scan's rows go together"),
                ));
            }
            if t_s <= last_t {
                return Err(row.error(
                    "t_s",
                    &format!("{t_s} s is not after the scan before ({last_t} s)"),
                ));
            }
        }
        let own = [
            row.required_f32("own_east_m")?,
            row.required_f32("own_north_m")?,
        ];
        let velocity = if self.has_velocity {
            Some([
                row.required_f32("own_vx_mps")?,
                row.required_f32("own_vy_mps")?,
            ])
        } else {
            None
        };
        let plot_sigma_m = sigma_m(&row, "plot_sigma_m")?;
        let heading_deg = row.number("heading_deg")?;
        if let Some(h) = heading_deg {
            if !(0.0..360.0).contains(&h) {
                return Err(row.error("heading_deg", &format!("{h}: must be 0 ≤ h < 360")));
            }
        }
        let own_fix = own_fix_of(&row)?;
        let mut plots = Vec::new();
        let mut accuracy = None;
        let mut record = Some(first);
        while let Some(r) = record.take() {
            let row = self.header.row(&r);
            if row.required_u32("scan")? != scan {
                self.ahead = Some(r);
                break;
            }
            if row.required_number("t_s")? != t_s {
                return Err(row.error(
                    "t_s",
                    &format!("every row of scan {scan} must have the same time ({t_s} s)"),
                ));
            }
            if own_fix_of(&row)? != own_fix {
                return Err(row.error(
                    "own_fix",
                    &format!("every row of scan {scan} must have the same own_fix"),
                ));
            }
            if row.number_f32("plot_sigma_m")? != plot_sigma_m {
                return Err(row.error(
                    "plot_sigma_m",
                    &format!("every row of scan {scan} must have the same plot_sigma_m"),
                ));
            }
            match (row.number_f32("range_m")?, row.number("bearing_deg")?) {
                (None, None) => {}
                (Some(range), Some(bearing)) => {
                    if !(0.0..=MAX_RANGE_M).contains(&f64::from(range)) {
                        return Err(
                            row.error("range_m", &format!("{range}: must be 0 to {MAX_RANGE_M} m"))
                        );
                    }
                    if !(0.0..360.0).contains(&bearing) {
                        return Err(
                            row.error("bearing_deg", &format!("{bearing}: must be 0 ≤ b < 360"))
                        );
                    }
                    if plots.len() == MAX_PLOTS_PER_SCAN {
                        return Err(row.error(
                            "range_m",
                            &format!("scan {scan} has more than {MAX_PLOTS_PER_SCAN} plots, the device's limit"),
                        ));
                    }
                    let a = plot_accuracy(&row)?;
                    if !plots.is_empty() && a != accuracy {
                        return Err(row.error(
                            "range_sigma_m",
                            &format!("every plot of scan {scan} must have the same accuracy"),
                        ));
                    }
                    accuracy = a;
                    plots.push(Plot {
                        range_m: range,
                        bearing_rad: bearing.to_radians() as f32,
                    });
                }
                (None, Some(_)) => return Err(row.error("range_m", "empty beside a bearing")),
                (Some(_), None) => return Err(row.error("bearing_deg", "empty beside a range")),
            }
            record = self.next_record()?;
        }
        self.last = Some((scan, t_s));
        Ok(Some(FileScan {
            radar: RadarScan {
                scan,
                time_s: t_s,
                plots,
            },
            own_position_m: own,
            own_velocity_mps: velocity,
            heading_deg,
            own_fix,
            accuracy,
            plot_sigma_m,
        }))
    }
}

/// A row's standard deviation in metres in `column`: empty, or over 0 and at most
/// [`MAX_RANGE_M`].
fn sigma_m(row: &csv_input::Row<'_>, column: &str) -> anyhow::Result<Option<f32>> {
    let s = row.number_f32(column)?;
    match s {
        Some(s) if !(s > 0.0 && f64::from(s) <= MAX_RANGE_M) => Err(row.error(
            column,
            &format!("{s}: must be over 0 m and at most {MAX_RANGE_M} m"),
        )),
        _ => Ok(s),
    }
}

/// A row's `range_sigma_m` and `bearing_sigma_deg`: both or neither, each positive (the
/// bearing's under 10°).
fn plot_accuracy(row: &csv_input::Row<'_>) -> anyhow::Result<Option<PolarAccuracy>> {
    match (
        sigma_m(row, "range_sigma_m")?,
        row.number("bearing_sigma_deg")?,
    ) {
        (None, None) => Ok(None),
        (Some(r), Some(b)) => {
            if !(b > 0.0 && b < 10.0) {
                return Err(row.error(
                    "bearing_sigma_deg",
                    &format!("{b}: must be over 0 and under 10 degrees"),
                ));
            }
            Ok(Some(PolarAccuracy {
                range_sigma_m: r,
                bearing_sigma_rad: b.to_radians() as f32,
            }))
        }
        (None, Some(_)) => Err(row.error("range_sigma_m", "empty beside a bearing_sigma_deg")),
        (Some(_), None) => Err(row.error("bearing_sigma_deg", "empty beside a range_sigma_m")),
    }
}

/// A plots file, checked, read scan by scan.
pub struct PlotsFileSource {
    path: PathBuf,
    reader: ScanReader,
    scans: u64,
    read: u64,
    /// The scan after the current one (own ship's velocity from positions needs it for the
    /// first scan).
    ahead: Option<FileScan>,
    previous: Option<FileScan>,
    /// The file's first `plot_sigma_m`.
    first_plot_sigma_m: Option<f32>,
    /// The operator's plot accuracy, m, in place of the file's.
    plot_sigma_given_m: Option<f32>,
    truth: Option<TruthFile>,
    period_s: Option<f64>,
    /// Whether the times are UTC ([`UTC_FROM_S`] on).
    time_is_utc: bool,
}

/// A plots file's times from this on (2001-09-09, 10⁹ s) are taken as UTC: the file's epoch
/// may be any, but elapsed times do not reach 31 years.
pub const UTC_FROM_S: f64 = 1e9;

impl PlotsFileSource {
    /// Opens and checks `path`.
    ///
    /// # Errors
    /// The file does not open, or any line breaks the format: the error names the line and
    /// the column.
    pub fn open(path: &Path) -> anyhow::Result<Self> {
        let mut check = ScanReader::open(path)?;
        let mut scans = 0u64;
        let (mut first_t, mut last_t) = (None, None);
        let mut first_plot_sigma_m = None;
        while let Some(s) = check.next_scan()? {
            scans += 1;
            first_plot_sigma_m = first_plot_sigma_m.or(s.plot_sigma_m);
            first_t.get_or_insert(s.radar.time_s);
            last_t = Some(s.radar.time_s);
        }
        if scans == 0 {
            bail!("{}: no scans", path.display());
        }
        let period_s = match (first_t, last_t) {
            (Some(a), Some(b)) if scans > 1 => Some((b - a) / (scans - 1) as f64),
            _ => None,
        };
        Ok(PlotsFileSource {
            path: path.to_path_buf(),
            reader: ScanReader::open(path)?,
            scans,
            read: 0,
            ahead: None,
            previous: None,
            first_plot_sigma_m,
            plot_sigma_given_m: None,
            truth: None,
            period_s,
            time_is_utc: first_t.is_some_and(|t| t >= UTC_FROM_S),
        })
    }

    /// Attaches the truth of a truth file to the scans, for scoring.
    pub fn with_truth(mut self, truth: TruthFile) -> Self {
        self.truth = Some(truth);
        self
    }

    /// Takes the plots at `sigma_m` (m, one axis) whatever the file's `plot_sigma_m` says
    /// (`--plot-sigma-m`); `None` leaves the file's.
    pub fn with_plot_sigma_m(mut self, sigma_m: Option<f32>) -> Self {
        self.plot_sigma_given_m = sigma_m;
        self
    }

    /// The accuracy the filters start at, m: the operator's, else the file's first
    /// `plot_sigma_m`, else `None` (the default's).
    pub fn first_plot_sigma_m(&self) -> Option<f32> {
        self.plot_sigma_given_m.or(self.first_plot_sigma_m)
    }

    /// Scans in the file.
    pub fn scans(&self) -> u64 {
        self.scans
    }

    fn read(&mut self) -> anyhow::Result<Option<FileScan>> {
        match self.ahead.take() {
            Some(s) => Ok(Some(s)),
            None => self.reader.next_scan(),
        }
    }
}

impl PlotSource for PlotsFileSource {
    /// A plots file's `t_s` counts from any epoch (docs/formats.md): UTC from
    /// [`UTC_FROM_S`] on.
    fn time_is_utc(&self) -> bool {
        self.time_is_utc
    }

    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        let Some(scan) = self.read()? else {
            return Ok(None);
        };
        self.read += 1;
        // Own ship's velocity: the file's, else from the position before (the first scan,
        // and the first fix after scans without one, take the one after), between fixes
        // only (a scan without a fix stood at the origin).
        let fix = |s: &FileScan| s.own_fix == OwnFix::Fix;
        let velocity = match scan.own_velocity_mps {
            Some(v) => v,
            None => match self.previous.as_ref().filter(|p| fix(p) && fix(&scan)) {
                Some(p) => finite_difference(p, &scan),
                None => {
                    self.ahead = self.reader.next_scan()?;
                    self.ahead
                        .as_ref()
                        .filter(|next| fix(next) && fix(&scan))
                        .map_or([0.0, 0.0], |next| finite_difference(&scan, next))
                }
            },
        };
        let mut own = OwnShip {
            heading_rad: scan.heading_deg.map(|h| h.to_radians() as f32),
            ..OwnShip::at(scan.own_position_m, velocity)
        };
        match scan.own_fix {
            OwnFix::Fix => {}
            // Recorded without a fix: own ship stood where the file places it, its motion
            // unknown (a run tracked again showed `fix` and `SOG 0.0`, and true vectors).
            OwnFix::NoFix => {
                own.velocity_mps = [0.0, 0.0];
                own.quality.no_fix_yet = true;
                own.quality.motion_known = false;
            }
            // A position given: stopped there, and known.
            OwnFix::Given => {
                own.velocity_mps = [0.0, 0.0];
                own.quality.fixed_position = true;
            }
        }
        let truth = match self.truth.as_mut() {
            Some(t) => Some(t.at(scan.radar.time_s, own, &self.path)?),
            None => None,
        };
        let out = SourceScan {
            radar: scan.radar.clone(),
            own_ship: Some(own),
            truth,
            echoes: None,
            heading_sensor_rad: None,
            placed_heading_rad: own.heading_rad,
        };
        self.previous = Some(scan);
        Ok(Some(out))
    }

    fn scan_period_s(&self) -> Option<f64> {
        self.period_s
    }

    fn scans_left(&self) -> Option<u64> {
        Some(self.scans - self.read)
    }

    /// The file's `range_sigma_m` and `bearing_sigma_deg` for the scan just given.
    fn plot_accuracy(&self) -> Option<PolarAccuracy> {
        self.previous.as_ref().and_then(|s| s.accuracy)
    }

    /// The operator's plot accuracy, else the file's `plot_sigma_m` for the scan just
    /// given (a radar's changes with its range scale).
    fn plot_sigma_m(&self) -> Option<f32> {
        self.plot_sigma_given_m
            .or(self.previous.as_ref().and_then(|s| s.plot_sigma_m))
    }
}

/// A row's `own_fix`.
fn own_fix_of(row: &csv_input::Row<'_>) -> anyhow::Result<OwnFix> {
    let Some(text) = row.text("own_fix") else {
        return Ok(OwnFix::Fix);
    };
    // `1.0` and `0.0` as other tools may write them, too.
    match (text, text.parse::<f64>().ok()) {
        (_, Some(1.0)) => Ok(OwnFix::Fix),
        (_, Some(0.0)) => Ok(OwnFix::NoFix),
        ("M", _) => Ok(OwnFix::Given),
        (x, _) => Err(row.error("own_fix", &format!("`{x}`: must be 1, 0 or M"))),
    }
}

fn finite_difference(a: &FileScan, b: &FileScan) -> [f32; 2] {
    let dt = (b.radar.time_s - a.radar.time_s) as f32;
    [
        (b.own_position_m[0] - a.own_position_m[0]) / dt,
        (b.own_position_m[1] - a.own_position_m[1]) / dt,
    ]
}
