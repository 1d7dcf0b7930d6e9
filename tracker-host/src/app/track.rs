//! `tracker-host track`: the tracker on recorded plots (a plots file, and beside it a
//! truth file to score against) or on a radar (spokes from a capture or live, plots
//! extracted), with the same session, display, table and outputs as `demo`.

use std::path::PathBuf;

use tracker_core::filter::FilterKind;

use super::run::Run;
use super::{own_ship_source, sinks, Outputs, OwnShipOptions};
use crate::link::Client;
use crate::nmea::InSpec;
use crate::origin::Origin;
use crate::own_ship::recording::RecordedTrack;
use crate::radar::RadarSpec;
use crate::session::{Session, SessionConfig, PLOT_SIGMA_M};
use crate::source::no_radar::NoRadarSource;
use crate::source::plots_file::PlotsFileSource;
use crate::source::radar::{CaptureSurvey, RadarOptions, RadarPlotSource};
use crate::source::truth_file::TruthFile;
use crate::source::PlotSource;

/// Where `track`'s plots come from.
#[derive(Clone, Debug, PartialEq)]
pub enum TrackInput {
    /// A plots file, and a truth file for a scored summary.
    Plots {
        /// The plots file.
        plots: PathBuf,
        /// The truth file.
        truth: Option<PathBuf>,
        /// The plots' accuracy, m (one axis), in place of the file's `plot_sigma_m`.
        plot_sigma_m: Option<f32>,
    },
    /// A radar's spokes, plots extracted.
    Radar(RadarOptions),
    /// No radar: own ship and the AIS targets from `--nmea-in` alone, a scan every
    /// [`crate::source::no_radar::PERIOD_S`] ([`NoRadarSource`]).
    NoRadar,
}

/// What `track` runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackOptions {
    /// The plots.
    pub input: TrackInput,
    /// The filter every track runs.
    pub filter: FilterKind,
    /// How plots are associated and which start tracks.
    pub association: crate::session::associate::Association,
    /// The CPA/TCPA alarm limits.
    pub alarms: crate::session::target::AlarmLimits,
    /// Where own ship comes from (by default the plot source's: a plots file's own-ship
    /// columns, a capture's NMEA).
    pub own_ship: OwnShipOptions,
    /// Where results go.
    pub outputs: Outputs,
}

/// Wires `track`: the files are checked before the device is touched or anything written.
///
/// # Errors
/// A file breaks its format (the error names the line and column), a capture does not
/// open, the device does not attach, or an own-ship source or output does not open.
pub fn start(client: Client, o: &TrackOptions) -> anyhow::Result<Run> {
    // The origin is a position of own ship's (the operator's, a capture's first fix, or an
    // NMEA recording's),
    // not the default: targets' latitudes and longitudes can be sent before a fix.
    let mut origin_known = o.own_ship.origin.is_some();
    let own_ship_options;
    let o = if origin_known {
        o
    } else {
        own_ship_options = TrackOptions {
            own_ship: crate::app::with_live_origin(&o.own_ship)?,
            ..o.clone()
        };
        origin_known = own_ship_options.own_ship.origin.is_some();
        &own_ship_options
    };
    // The capture's first spoke, s since 1970: the day an NMEA recording's sentences
    // without a date fall on.
    let mut capture_s = None;
    // The NMEA recording on `--nmea-in` with a capture, read once here: its first fix may
    // be the origin, and its times before its first date fall on the capture's day.
    let mut recording = None;
    let (source, origin, sigma_m): (Box<dyn PlotSource>, Origin, f32) = match &o.input {
        TrackInput::Plots {
            plots,
            truth,
            plot_sigma_m,
        } => {
            let mut source = PlotsFileSource::open(plots)?.with_plot_sigma_m(*plot_sigma_m);
            if let Some(truth) = truth {
                source = source.with_truth(TruthFile::open(truth)?);
            }
            // A radar's recording tracked at its own accuracy (a harbour's 2 m plots taken
            // at 40 m made 1 target of the 30 tracked live, in a new user's trial).
            let sigma_m = source.first_plot_sigma_m().unwrap_or(PLOT_SIGMA_M);
            // The file's positions are metres from an origin it does not hold: without
            // `--origin` they go to plotters about the default one, wherever they were (a
            // trial's moored Dutch radar, replayed, was sent as a fix in the Solent).
            if o.own_ship.origin.is_none() && o.outputs.nmea_out.is_some() {
                let d = Origin::default();
                eprintln!(
                    "track --plots: the file's positions are metres from an origin it does not give; the positions sent to plotters are placed about the default {:.5}, {:.5} (--origin LAT,LON gives the recording's)",
                    d.lat_deg, d.lon_deg
                );
            }
            (Box::new(source), o.own_ship.origin(), sigma_m)
        }
        TrackInput::NoRadar => {
            // Plotters take the AIS from the transponder themselves: without a radar
            // there are no targets of ours to send, only own ship.
            if o.outputs.nmea_out.is_some() && !o.outputs.nmea_out_own_ship {
                eprintln!(
                    "nmea out: without a radar there are no radar targets to send (plotters take AIS from the transponder): add --nmea-out-own-ship to send own ship"
                );
            }
            // The scans follow a recording's own time, from its first fix to its last (the
            // frame about its first fix), or this computer's clock for a live source.
            let (source, origin) = match &o.own_ship.nmea_in {
                Some(InSpec::File(path)) => {
                    let track = RecordedTrack::read(path, &o.own_ship.nmea)?;
                    track.tell_set_apart(path);
                    let (start_s, end_s) = track.window_s();
                    let first_fix = track.first_position();
                    origin_known = true;
                    let origin = o.own_ship.origin.unwrap_or(first_fix);
                    let timed = track.timed;
                    recording = Some(track);
                    (
                        NoRadarSource::over_recording(start_s, end_s).with_utc(timed),
                        origin,
                    )
                }
                Some(_) => (NoRadarSource::live(), o.own_ship.origin()),
                None => anyhow::bail!(
                    "track without a radar or plots takes own ship and AIS from --nmea-in"
                ),
            };
            (Box::new(source), origin, PLOT_SIGMA_M)
        }
        TrackInput::Radar(radar) => {
            // A capture's own frame is around its first fix, wherever on earth it was made;
            // its plots are as accurate as its range scale allows.
            let survey = match &radar.spec {
                RadarSpec::Capture(path) => {
                    let survey = CaptureSurvey::of(path)?;
                    // Read to its end without a spoke: the wrong capture (a new user's trial
                    // was told "0 scans" and exit 0).
                    if survey.first_range_m.is_none() && survey.cut_short {
                        anyhow::bail!(
                            "{}: the capture ends inside a record before its first radar spoke (cut short: copied or downloaded in part?)",
                            path.display()
                        );
                    }
                    if survey.first_range_m.is_none() {
                        anyhow::bail!(
                            "{}: no radar spokes in the capture (none of a Navico BR24, 3G, 4G or HALO, nor of a Garmin xHD): capture the radar's spoke multicast on its network (README, \"A radar\")",
                            path.display()
                        );
                    }
                    survey
                }
                RadarSpec::Live { .. } => CaptureSurvey::default(),
            };
            // … else an NMEA recording's on `--nmea-in` (a capture without NMEA: own ship
            // far from the default origin had every plot refused).
            if let Some(InSpec::File(path)) = &o.own_ship.nmea_in {
                recording = match survey.first_spoke_s {
                    Some(t) => read_on_capture_day(path, &o.own_ship.nmea, t),
                    None if survey.first_fix.is_none() => {
                        RecordedTrack::read(path, &o.own_ship.nmea).ok()
                    }
                    None => None,
                };
            }
            let first_fix = survey
                .first_fix
                .or_else(|| recording.as_ref().map(RecordedTrack::first_position));
            origin_known |= first_fix.is_some();
            capture_s = survey.first_spoke_s;
            let origin = o.own_ship.origin.or(first_fix).unwrap_or_default();
            let sigma_m = radar
                .plot_sigma_on(survey.first_range_m)
                .unwrap_or(PLOT_SIGMA_M);
            (
                Box::new(RadarPlotSource::open(radar, origin)?),
                origin,
                sigma_m,
            )
        }
    };
    // A recording with no date at all (a log of GGA and GLL only) is on the capture's day,
    // not today's: today's put a log of the capture's own voyage years after its scans,
    // and own ship had no fix on any.
    // A recording that has a date is on its own: its times before that date fall on it, as
    // when it is played alone (a log of 2014 whose first sentences had no date was put on
    // a 2015 capture's day, and told as hours ahead of it instead of a year and a half).
    let mut own_ship_dated = o.own_ship.clone();
    if let (Some(t), Some(InSpec::File(path))) = (capture_s, &o.own_ship.nmea_in) {
        // Its first date as read with its fixes; read again only when it had none.
        let first_day = match &recording {
            Some(r) => r.first_day,
            None => crate::own_ship::recording::first_day_of(path),
        };
        own_ship_dated.nmea.provisional_day =
            first_day.unwrap_or_else(|| undated_day(recording.as_ref(), t));
    }
    // Without a radar, the recording is replayed on its track's own day, within its
    // track's window, as `demo` replays one (today's day put the AIS heard before its first
    // dated sentence twelve years from the scans, and none was taken).
    if let (TrackInput::NoRadar, Some(r)) = (&o.input, &recording) {
        own_ship_dated.nmea.provisional_day = crate::own_ship::clock::day_of_s(r.start_s());
        own_ship_dated.nmea.recording_window_s = Some(r.window_s());
    }
    let own_ship = own_ship_source(&own_ship_dated, origin)?;
    let config = SessionConfig {
        association: o.association,
        alarms: o.alarms,
        ..SessionConfig::tracking_plots_of(o.filter, sigma_m)
    };
    let session = Session::start(client, config)?;
    let sinks = sinks(
        &o.outputs,
        super::Simulated::default(),
        origin,
        origin_known,
        o.alarms,
    )?;
    Ok(Run::new(source, own_ship, session, sinks)
        .with_origin(origin)
        .with_associated_data(o.outputs.associated_data))
}

/// The NMEA recording at `path` with its times before its first date on the day of
/// `capture_s` (s since 1970, a capture's first spoke); `None` when it has no fix or cannot
/// be read.
fn read_on_capture_day(
    path: &std::path::Path,
    nmea: &crate::own_ship::NmeaOptions,
    capture_s: f64,
) -> Option<RecordedTrack> {
    let on_day = crate::own_ship::NmeaOptions {
        provisional_day: crate::own_ship::clock::day_of_s(capture_s),
        ..nmea.clone()
    };
    RecordedTrack::read(path, &on_day).ok()
}

/// The day (days since 1970) an NMEA recording's times before its first date fall on when
/// it is played with a capture whose first spoke is at `capture_s` (s since 1970), from
/// `track`, the recording read on the capture's day ([`read_on_capture_day`]): the
/// capture's day, or the day either side of it when that puts the recording's first fix
/// nearer the capture (a capture begun at 23:58 and a log at 00:01). A recording that has
/// a date, or no fix, is not moved by it.
fn undated_day(track: Option<&RecordedTrack>, capture_s: f64) -> i64 {
    use crate::own_ship::clock::{day_of_s, DAY_S};
    let day = day_of_s(capture_s);
    // Only across midnight: a recording days apart (another voyage, dated) is not moved.
    let across = |d: f64| (DAY_S / 2.0..1.5 * DAY_S).contains(&d);
    match track {
        Some(track) if across(track.start_s() - capture_s) => day - 1,
        Some(track) if across(capture_s - track.start_s()) => day + 1,
        _ => day,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::sentence;

    #[test]
    fn undated_times_fall_on_the_day_that_puts_them_nearest_the_capture() {
        let dir = tempfile::tempdir().unwrap();
        let log = |name: &str, hhmmss: &str| {
            let path = dir.path().join(name);
            let gga = |s: &str| {
                sentence(&format!(
                    "GPGGA,{s},5310.812,N,00525.706,E,1,08,0.9,3.5,M,45.7,M,,"
                ))
            };
            std::fs::write(&path, gga(hhmmss) + &gga(hhmmss)).unwrap();
            path
        };
        let nmea = crate::own_ship::NmeaOptions::default();
        let undated_day = |path: &std::path::Path, nmea, capture_s| {
            undated_day(
                read_on_capture_day(path, nmea, capture_s).as_ref(),
                capture_s,
            )
        };
        let day = 16_726; // 2015-10-18
        let at = |d: i64, h: f64| d as f64 * 86_400.0 + h * 3600.0;
        // A capture begun at 23:58, a log at 00:01: the next day.
        let after = log("after.log", "000100");
        assert_eq!(undated_day(&after, &nmea, at(day, 23.97)), day + 1);
        // A capture begun at 00:02, a log at 23:59: the day before.
        let before = log("before.log", "235900");
        assert_eq!(undated_day(&before, &nmea, at(day, 0.03)), day - 1);
        // Within the day: the capture's.
        assert_eq!(undated_day(&after, &nmea, at(day, 0.5)), day);
        assert_eq!(undated_day(&before, &nmea, at(day, 14.3)), day);
        // A dated log of another year, and no log at all: the capture's day.
        let dated = dir.path().join("dated.log");
        std::fs::write(
            &dated,
            sentence("GPRMC,094737,A,5251.0093,N,00518.8170,E,5.6,230.5,200818,1.4,E,A"),
        )
        .unwrap();
        assert_eq!(undated_day(&dated, &nmea, at(day, 23.97)), day);
        assert_eq!(
            undated_day(&dir.path().join("none.log"), &nmea, at(day, 1.0)),
            day
        );
    }
}
