//! Arguments shared by the commands that run the tracker (`demo`, `track`).

use std::path::{Path, PathBuf};

use anyhow::Context;

use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::Args;
use tracker_core::filter::FilterKind;
use tracker_core::geo::METRES_PER_NM;

use crate::app::{Outputs, OwnShipOptions};
use crate::nmea::{InSpec, OutSpec};
use crate::origin::Origin;
use crate::own_ship::sentences::Quantity;
use crate::own_ship::NmeaOptions;
use crate::session::target::AlarmLimits;

/// `--filter NAME`: one of [`FilterKind::ALL`], by name.
pub fn filter_parser() -> impl TypedValueParser<Value = FilterKind> {
    PossibleValuesParser::new(FilterKind::ALL.map(FilterKind::name))
        .try_map(|name| name.parse::<FilterKind>())
}

/// The slowest `--speedup`: a source second in 1,000 real ones.
pub const MIN_SPEEDUP: f64 = 1e-3;
/// The fastest `--speedup` short of `max`.
pub const MAX_SPEEDUP: f64 = 1e6;

/// `--speedup X` or `--speedup max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speedup(pub Option<f64>);

impl std::str::FromStr for Speedup {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "max" {
            return Ok(Speedup(None));
        }
        // Bounded: at 10⁻⁹ a run waited years for its second scan (a new user's trial),
        // and past the bounds a scan's due time no longer fits the clock.
        match s.parse::<f64>() {
            Ok(x) if (MIN_SPEEDUP..=MAX_SPEEDUP).contains(&x) => Ok(Speedup(Some(x))),
            _ => Err(format!(
                "`{s}`: expected a number from {MIN_SPEEDUP} to {MAX_SPEEDUP:.0} (1: real time) or `max`"
            )),
        }
    }
}

/// `--association`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AssociationArg {
    /// Firm tracks first, then tentative ones; every plot no track took starts a track.
    TwoStage,
    /// One stage; only plots in no rough gate start tracks.
    Joint,
    /// Two-stage, and a firm track whose target is hidden in a plot another firm track
    /// took (two ships in one resolution cell) is held without the miss counting towards
    /// its loss, not drawn, for up to 16 scans (the default).
    TwoStageUnresolved,
}

impl From<AssociationArg> for crate::session::associate::Association {
    fn from(a: AssociationArg) -> Self {
        match a {
            AssociationArg::TwoStage => Self::TwoStage,
            AssociationArg::Joint => Self::Joint,
            AssociationArg::TwoStageUnresolved => Self::TwoStageUnresolved,
        }
    }
}

/// `--associated-symbol` and `--associated-data`: which source an associated ship is drawn
/// by, and shown with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AssociatedArg {
    /// The AIS target's (IEC 62388's default).
    Ais,
    /// The radar track's.
    Radar,
}

impl From<AssociatedArg> for crate::session::ais::AssociatedSymbol {
    fn from(a: AssociatedArg) -> Self {
        match a {
            AssociatedArg::Ais => Self::Ais,
            AssociatedArg::Radar => Self::Radar,
        }
    }
}

impl From<AssociatedArg> for crate::session::ais::AssociatedData {
    fn from(a: AssociatedArg) -> Self {
        match a {
            AssociatedArg::Ais => Self::Ais,
            AssociatedArg::Radar => Self::Radar,
        }
    }
}

/// How a tracking run is shown, where own ship comes from, where results go.
#[derive(Clone, Debug, Args)]
pub struct RunArgs {
    /// The filter every track runs.
    #[arg(long, value_parser = filter_parser(), default_value = "kalman-cv")]
    pub filter: FilterKind,
    /// How plots are associated and which start tracks: `two-stage-unresolved` (the
    /// default: firm tracks take their plots first, tentative ones from what is left, every
    /// plot no track took starts a track; and a firm track whose target is hidden in a plot
    /// another firm track took is held, not drawn, for up to 16 scans instead of 6: both
    /// ships of a merge stay tracked), `two-stage` (without the hold) or `joint` (one
    /// assignment over all tracks; only plots in no rough gate start tracks: the earlier
    /// rule).
    #[arg(long, value_enum, default_value_t = AssociationArg::TwoStageUnresolved)]
    pub association: AssociationArg,
    /// Source seconds per real second, or `max` (the default; 1, real time, with a live
    /// NMEA source).
    #[arg(long, allow_negative_numbers = true)]
    pub speedup: Option<Speedup>,
    /// Print the target table every scan as plain text (without it: the radar display in a
    /// terminal, progress lines otherwise).
    #[arg(long)]
    pub plain: bool,
    /// How the display and the snapshot draw a ship whose radar target and AIS target are
    /// associated (paired, or the radar target shown as the AIS target): once, as `ais`
    /// (the AIS triangle, IEC 62388's default) or `radar` (the radar target's symbol and
    /// vector). The table and `TTM` keep the radar number and the AIS name either way.
    #[arg(long, value_enum, default_value_t = AssociatedArg::Ais)]
    pub associated_symbol: AssociatedArg,
    /// Whose data a ship with its radar target associated with one AIS target is shown
    /// with (position, course, speed, CPA, TCPA: in the table, `TTM` and `TLL`) and
    /// alarms on, once: `ais` (the AIS target's, IEC 62388's default) or `radar` (the
    /// radar track's). By default the source `--associated-symbol` draws (a radar symbol
    /// on AIS data would be drawn off its echo).
    #[arg(long, value_enum)]
    pub associated_data: Option<AssociatedArg>,
    /// The CPA/TCPA alarm's CPA limit, nautical miles: a target (radar or activated AIS)
    /// whose CPA is below it within the TCPA limit alarms (a bridge's open-water setting is
    /// 1 NM; in a harbour or a traffic separation scheme far less).
    #[arg(long, allow_negative_numbers = true, value_name = "NM", default_value_t = 1.0, value_parser = cpa_limit_nm)]
    pub cpa_nm: f64,
    /// The CPA/TCPA alarm's TCPA limit, minutes.
    #[arg(long, allow_negative_numbers = true, value_name = "MIN", default_value_t = 12.0, value_parser = tcpa_limit_min)]
    pub tcpa_min: f64,
    /// Send every target to a chart plotter as NMEA 0183 `TTM` and `TLL` sentences each
    /// scan: `udp:HOST:PORT`, `tcp:PORT` (a server plotters connect to) or
    /// `serial:DEVICE@BAUD` (38400 baud, IEC 61162-2, carries a scan of 40 targets; 4800
    /// does not, and the oldest sentences are dropped, counted).
    #[arg(long, value_name = "udp:HOST:PORT|tcp:PORT|serial:DEVICE@BAUD")]
    pub nmea_out: Option<OutSpec>,
    /// With --nmea-out, send own ship too (`RMC`, `HDT`, `OSD`), for a plotter that has no
    /// GNSS of its own.
    #[arg(long, requires = "nmea_out")]
    pub nmea_out_own_ship: bool,
    /// The talkers to take a quantity from, in order of preference, e.g.
    /// `--nmea-source heading=HE,GP` (quantities: position, velocity, heading,
    /// water-speed). Without it the first talker heard is used.
    #[arg(long, value_name = "QUANTITY=TALKER,…", value_parser = parse_source)]
    pub nmea_source: Vec<(Quantity, Vec<String>)>,
    /// Magnetic variation, degrees east (west negative, within ±180), for magnetic headings
    /// (`HDM`, `HDG`) when neither the sentence nor an `RMC` gives one.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true, value_parser = magnetic_variation)]
    pub magnetic_variation: Option<f64>,
    /// Take own ship (and AIS) from NMEA 0183 (RMC/GGA/GLL, VTG/VBW, HDT/THS/HDG/HDM,
    /// VHW, ZDA; AIVDM/AIVDO)
    /// through the dead-reckoning filter: `file:PATH` (a recording, replayed scan by scan),
    /// `udp:PORT`, `tcp:HOST:PORT`, `serial:DEVICE@BAUD`. Live sources may be given more
    /// than once (the GNSS and gyro on one port, the AIS transponder on another): their
    /// lines are taken together.
    #[arg(long, value_name = "SOURCE", conflicts_with = "nmea_record")]
    pub nmea_in: Vec<InSpec>,
    /// Take own ship from the plot source's own ship sent as NMEA through the
    /// dead-reckoning filter, and record the sentences to this file (`--nmea-in
    /// file:PATH` replays it with the same result).
    #[arg(long, value_name = "PATH")]
    pub nmea_record: Option<PathBuf>,
    /// Latitude and longitude of the local frame's origin, decimal degrees (for `TLL`
    /// and own-ship positions), e.g. `--origin -33.9,151.2`.
    #[arg(long, value_name = "LAT,LON", value_parser = Origin::parse, allow_hyphen_values = true)]
    pub origin: Option<Origin>,
    /// With `track --radar`: own ship stands at --origin (the antenna's position), stopped,
    /// until a position fix comes: a shore radar, or a ship moored without GNSS. True
    /// vectors may then be shown and are sent, and no "no fix" alarm stands; with
    /// --nmea-out-own-ship plotters get the position as manual input (`RMC` mode `M`,
    /// status `V`, as NMEA 0183 requires for it). A GNSS on --nmea-in takes over from its
    /// first fix (an event says how far from --origin) and is followed from then on.
    #[arg(long, requires = "origin")]
    pub fixed_position: bool,
    /// Write the scans' plots to this file (the plots file format `track` reads).
    #[arg(long, value_name = "PATH")]
    pub record_plots: Option<PathBuf>,
    /// Write every track every scan to this file
    /// (`scan,t_s,track,status,east_m,north_m,vx_mps,vy_mps,held`; `held` 1 for a track
    /// hidden in another's echo and not drawn).
    #[arg(long, value_name = "PATH")]
    pub record_tracks: Option<PathBuf>,
    /// Draw the last scan to this PNG when the run ends: a radar's echoes, the plots, the
    /// targets with numbers and vectors, AIS targets (to check extraction by eye). The name
    /// ends in `.png` (or `.jpg`, `.bmp`: the drawing's other formats).
    #[arg(long, value_name = "PATH")]
    pub snapshot: Option<PathBuf>,
    /// The snapshot's range, NM, from own ship to its edge (by default the radar's range,
    /// else the display's range scale holding every plot and target): a harbour's
    /// targets within half a mile are drawn apart, not in the middle of a 12 NM picture.
    #[arg(long, value_name = "NM", requires = "snapshot", allow_negative_numbers = true, value_parser = snapshot_range_nm)]
    pub snapshot_range_nm: Option<f64>,
    /// Write the end-of-run summary to this file as one JSON object.
    #[arg(long, value_name = "PATH")]
    pub summary_json: Option<PathBuf>,
}

/// A finite number for which `ok` holds; else "`s`: expected `what`".
pub(crate) fn number(s: &str, ok: impl Fn(f64) -> bool, what: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && ok(v) => Ok(v),
        _ => Err(format!("`{s}`: expected {what}")),
    }
}

/// `--cpa-nm`: above 0, up to 100 NM (past a radar's longest range, 96 NM; `1e308` was
/// taken, and its metres overflowed to an infinite limit).
///
/// # Errors
/// Anything else, in words.
pub fn cpa_limit_nm(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| v > 0.0 && v <= 100.0,
        "a CPA limit above 0, up to 100 NM",
    )
}

/// `--tcpa-min`: above 0, up to 1,440 min (a day).
///
/// # Errors
/// Anything else, in words.
pub fn tcpa_limit_min(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| v > 0.0 && v <= 1440.0,
        "a TCPA limit above 0, up to 1,440 min",
    )
}

/// `--snapshot-range-nm`: 0.05 to 100 NM.
///
/// # Errors
/// Anything else, in words.
pub fn snapshot_range_nm(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| (0.05..=100.0).contains(&v),
        "a range from 0.05 to 100 NM",
    )
}

/// A positive, finite number.
///
/// # Errors
/// Anything else, in words.
pub fn positive(s: &str) -> Result<f64, String> {
    number(s, |v| v > 0.0, "a positive number")
}

/// A positive number that an `f32` holds (a distance sent to the device), e.g. m.
///
/// # Errors
/// Anything else, in words.
pub fn positive_f32(s: &str) -> Result<f32, String> {
    number(
        s,
        |v| v > 0.0 && v <= f64::from(f32::MAX),
        "a positive number",
    )
    .map(|v| v as f32)
}

/// A finite number, 0 or more (e.g. seconds from a start).
///
/// # Errors
/// Anything else, in words.
pub fn non_negative(s: &str) -> Result<f64, String> {
    number(s, |v| v >= 0.0, "a number, 0 or more")
}

/// A heading or bearing, degrees true, in [0, 360): 360 is written 0, and a larger or
/// negative angle is more likely a slip than a turn meant.
///
/// # Errors
/// Anything else, in words.
pub fn heading_deg(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| (0.0..360.0).contains(&v),
        "degrees from 0 up to (not including) 360",
    )
}

/// Magnetic variation, degrees east (west negative), within ±180: the range NMEA's
/// variation fields carry (`RMC`, `HDG`: 0 to 180, E or W). Not ±90: near the magnetic
/// poles (the Northwest Passage) variation passes 90°.
///
/// # Errors
/// Anything else, in words.
pub fn magnetic_variation(s: &str) -> Result<f64, String> {
    number(
        s,
        |v| (-180.0..=180.0).contains(&v),
        "degrees east within ±180 (west negative)",
    )
}

/// `QUANTITY=TALKER,TALKER…`.
fn parse_source(s: &str) -> Result<(Quantity, Vec<String>), String> {
    let (q, talkers) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected QUANTITY=TALKER,…"))?;
    let quantity = Quantity::ALL
        .into_iter()
        .find(|x| x.name() == q)
        .ok_or_else(|| {
            format!(
                "`{q}`: expected one of {}",
                Quantity::ALL.map(Quantity::name).join(", ")
            )
        })?;
    let talkers: Vec<String> = talkers.split(',').map(str::to_string).collect();
    if talkers
        .iter()
        .any(|t| t.len() != 2 || !t.bytes().all(|b| b.is_ascii_uppercase()))
    {
        return Err(format!("`{s}`: talkers are two upper-case letters"));
    }
    Ok((quantity, talkers))
}

impl RunArgs {
    /// Own ship as these arguments choose it.
    pub fn own_ship(&self) -> OwnShipOptions {
        OwnShipOptions {
            nmea_in: self.nmea_in.first().cloned(),
            nmea_in_more: self.nmea_in.iter().skip(1).cloned().collect(),
            nmea_record: self.nmea_record.clone(),
            origin: self.origin,
            fixed_position: self.fixed_position,
            nmea: NmeaOptions {
                priority: self.nmea_source.iter().cloned().collect(),
                variation_deg: self.magnetic_variation,
                // Times before a first date are today's: a live source's, and a recording's
                // that has no date at all (one with a date takes its own first date's).
                provisional_day: crate::app::today(),
                // Set by whoever reads a recording ahead (`demo`).
                recording_window_s: None,
            },
            opened: Default::default(),
        }
    }

    /// Source seconds per real second: as given; else real time with a live NMEA source
    /// (its sentences arrive in real time), as fast as possible otherwise.
    pub fn speedup(&self) -> Option<f64> {
        match (self.speedup, self.nmea_in.first()) {
            (Some(s), _) => s.0,
            (None, Some(InSpec::File(_)) | None) => None,
            (None, Some(_)) => Some(1.0),
        }
    }

    /// The CPA/TCPA alarm limits these arguments set.
    pub fn alarms(&self) -> AlarmLimits {
        AlarmLimits {
            cpa_m: (self.cpa_nm * f64::from(METRES_PER_NM)) as f32,
            tcpa_s: (self.tcpa_min * 60.0) as f32,
        }
    }

    /// Checks every output file these arguments name (and `record_truth`, the demo's own)
    /// can be written, before anything runs: a mistyped path is told at once, not after a
    /// run of hours.
    ///
    /// # Errors
    /// The first output that cannot be written, with its option and the reason; a
    /// snapshot's name whose extension is not an image format the drawing writes; one file
    /// named by two outputs, or an output naming one of the run's input files (`inputs`,
    /// with `--nmea-in file:`), which it would overwrite.
    pub fn check_outputs(
        &self,
        record_truth: Option<&Path>,
        inputs: &[(&'static str, &Path)],
    ) -> anyhow::Result<()> {
        if let Some(p) = &self.snapshot {
            crate::record::snapshot::check_path(p).context("--snapshot")?;
        }
        let files = [
            ("--record-plots", self.record_plots.as_deref()),
            ("--record-truth", record_truth),
            ("--record-tracks", self.record_tracks.as_deref()),
            ("--nmea-record", self.nmea_record.as_deref()),
            ("--summary-json", self.summary_json.as_deref()),
            ("--snapshot", self.snapshot.as_deref()),
        ];
        // One file for two outputs: the later would overwrite the earlier at the end; an
        // output on an input would overwrite the recording being read.
        let nmea_file = match self.nmea_in.first() {
            Some(InSpec::File(p)) => Some(("--nmea-in", p.as_path())),
            _ => None,
        };
        let read: Vec<(&str, PathBuf)> = inputs
            .iter()
            .copied()
            .chain(nmea_file)
            .filter_map(|(option, p)| Some((option, file_identity(p)?)))
            .collect();
        let mut written: Vec<(&str, PathBuf)> = Vec::new();
        for (option, path) in files {
            let Some(p) = path else { continue };
            if option != "--snapshot" {
                crate::record::check_writable(p).context(option)?;
            }
            let Some(at) = file_identity(p) else { continue };
            if let Some((input, _)) = read.iter().find(|(_, q)| *q == at) {
                anyhow::bail!(
                    "{option} names {}, the file {input} reads: it would be overwritten",
                    p.display()
                );
            }
            if let Some((first, _)) = written.iter().find(|(_, q)| *q == at) {
                anyhow::bail!("{first} and {option} both name {}", p.display());
            }
            written.push((option, at));
        }
        Ok(())
    }

    /// The outputs these arguments ask for (`record_truth` is the demo's own).
    pub fn outputs(&self, record_truth: Option<PathBuf>) -> Outputs {
        Outputs {
            nmea_out: self.nmea_out.clone(),
            nmea_out_own_ship: self.nmea_out_own_ship,
            record_plots: self.record_plots.clone(),
            record_truth,
            record_tracks: self.record_tracks.clone(),
            snapshot: self.snapshot.clone(),
            snapshot_range_nm: self.snapshot_range_nm,
            associated_symbol: self.associated_symbol.into(),
            associated_data: self
                .associated_data
                .unwrap_or(self.associated_symbol)
                .into(),
        }
    }
}

/// The file `p` names, to tell two names of one file (`o.csv`, `./sub/../o.csv`, a link to
/// it) from two files: an existing regular file's canonical path, or a new file's name in
/// its directory's canonical path; `None` for what is not a regular file (`/dev/null`, a
/// FIFO), which two outputs may share.
fn file_identity(p: &Path) -> Option<PathBuf> {
    match std::fs::metadata(p) {
        Ok(m) if m.is_file() => std::fs::canonicalize(p).ok(),
        Ok(_) => None,
        Err(_) => {
            let dir = match p.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn an_association_is_named_in_summaries_as_the_option_takes_it() {
        for a in AssociationArg::value_variants() {
            let name = a
                .to_possible_value()
                .expect("a value")
                .get_name()
                .to_string();
            let association: crate::session::associate::Association = (*a).into();
            assert_eq!(association.name(), name);
        }
    }
}
