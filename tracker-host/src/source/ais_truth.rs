//! Real traffic as the truth (`demo --ais-truth PATH --own-mmsi N`): recorded AIS position
//! reports of many ships (Stone Soup's Solent file: `Time,MMSI,Latitude_degrees,
//! Longitude_degrees,COG_degrees,SOG_knots`, 84 minutes, 91 vessels) drive the picture.
//!
//! - **Own ship** follows vessel N's real track; the own-ship source of the run takes it
//!   from there (the truth, or the sentences a bridge would send through the
//!   dead-reckoning filter with `--nmea-record`).
//! - **Targets**: every other vessel, on its real track, interpolated between its reports;
//!   across a gap longer than [`MAX_GAP_S`] it is out of the truth, and before its first and
//!   after its last report too. A vessel still at both ends of a longer gap (moored: under
//!   [`STILL_KN`] at both reports and between them) stays in across gaps up to
//!   [`AisTruthOptions::still_gap_s`] (by default the same [`MAX_GAP_S`]: out).
//! - **Radar plots** from the targets with the simulator's radar model ([`PlotModel`]: the
//!   IMO errors, P_d 0.9, clutter, resolution cells), as for the plot-level demo.
//! - **AIS**: each report of the file, at its own time, is sent as an `!AIVDM` type 1
//!   sentence (encoded by the `aivdm` crate) and read back through the product's AIS
//!   decoder; [`AIS_DROPOUT`] of them are lost on the air, as reception loses them. A
//!   report followed by a gap the truth keeps the vessel across as still is sent with the
//!   status *moored*, else *under way using engine*.
//! - **Truth ids are MMSIs**, so the scorer scores radar/AIS pairing too.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context};
use tracker_core::sim::{PlotModel, ScanOutput, SensorModel};

use super::{PlotSource, RadarScan, SourceScan};
use crate::ais::{AisDecoder, AisReport};
use crate::origin::Origin;
use crate::own_ship::OwnShip;
use crate::score::{ScanTruth, TargetTruth};

/// A vessel silent for longer than this between two reports is out of the truth in
/// between (not interpolated across), s.
pub const MAX_GAP_S: f64 = 120.0;

/// A vessel slower than this at both reports around a gap, and between them, is still
/// (moored or at anchor), kn.
pub const STILL_KN: f64 = 1.0;

/// A still vessel's longest gap kept in the truth with `--moored-gap` as the README runs
/// it, s: a moored class A ship reports every 3 minutes (ITU-R M.1371-5, Annex 1, Table 1),
/// so 400 s is its interval with one report lost.
pub const MOORED_GAP_S: f64 = 400.0;

/// The share of AIS reports lost on the air.
pub const AIS_DROPOUT: f64 = 0.05;

const KNOT_MPS: f64 = 1852.0 / 3600.0;

/// One recorded report.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Fix {
    t_s: f64,
    lat_deg: f64,
    lon_deg: f64,
    cog_deg: f64,
    sog_kn: f64,
    position_m: [f64; 2],
}

/// Every vessel's reports, time-ordered.
#[derive(Clone, Debug, PartialEq)]
pub struct AisTracks {
    vessels: BTreeMap<u32, Vec<Fix>>,
}

/// `2016-01-12 13:02:11.218` (UTC) as s since 1970.
fn parse_utc(s: &str) -> Option<f64> {
    let (date, time) = s.trim().split_once(' ')?;
    let mut d = date.split('-').map(|x| x.parse::<u32>().ok());
    let (y, m, day) = (d.next()??, d.next()??, d.next()??);
    let days = chrono::NaiveDate::from_ymd_opt(i32::try_from(y).ok()?, m, day)?
        .signed_duration_since(chrono::NaiveDate::from_ymd_opt(1970, 1, 1)?)
        .num_days();
    let mut t = time.split(':');
    let (h, min, sec) = (
        t.next()?.parse::<f64>().ok()?,
        t.next()?.parse::<f64>().ok()?,
        t.next()?.parse::<f64>().ok()?,
    );
    Some(days as f64 * 86_400.0 + h * 3600.0 + min * 60.0 + sec)
}

impl AisTracks {
    /// Reads the file, placing positions in the frame of `origin`.
    ///
    /// # Errors
    /// The file does not open, lacks a column, or a row does not parse (the error names the
    /// line).
    pub fn read(path: &Path, origin: &Origin) -> anyhow::Result<Self> {
        let mut csv =
            csv::Reader::from_path(path).with_context(|| format!("opening {}", path.display()))?;
        let headers = csv.headers()?.clone();
        let col = |name: &str| {
            headers
                .iter()
                .position(|h| h.trim() == name)
                .with_context(|| format!("{}: no column `{name}`", path.display()))
        };
        let (ct, cm, clat, clon, ccog, csog) = (
            col("Time")?,
            col("MMSI")?,
            col("Latitude_degrees")?,
            col("Longitude_degrees")?,
            col("COG_degrees")?,
            col("SOG_knots")?,
        );
        let mut vessels: BTreeMap<u32, Vec<Fix>> = BTreeMap::new();
        for (i, row) in csv.records().enumerate() {
            let row = row.with_context(|| format!("{}: line {}", path.display(), i + 2))?;
            let field = |c: usize| row.get(c).unwrap_or("").trim();
            let num = |c: usize| field(c).parse::<f64>().ok().filter(|x| x.is_finite());
            let bad = || format!("{}: line {}: a field does not parse", path.display(), i + 2);
            let t_s = parse_utc(field(ct)).with_context(bad)?;
            let mmsi: u32 = field(cm).parse().ok().with_context(bad)?;
            let (lat_deg, lon_deg) = (num(clat).with_context(bad)?, num(clon).with_context(bad)?);
            if lat_deg.abs() > 90.0 || lon_deg.abs() > 180.0 {
                bail!("{}: line {}: position off the globe", path.display(), i + 2);
            }
            vessels.entry(mmsi).or_default().push(Fix {
                t_s,
                lat_deg,
                lon_deg,
                cog_deg: num(ccog).unwrap_or(0.0),
                sog_kn: num(csog).unwrap_or(0.0),
                position_m: origin.to_local(lat_deg, lon_deg),
            });
        }
        for fixes in vessels.values_mut() {
            fixes.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        }
        if vessels.is_empty() {
            bail!("{}: no reports", path.display());
        }
        Ok(AisTracks { vessels })
    }

    /// The first and last report's times, s since 1970.
    pub fn span_s(&self) -> (f64, f64) {
        let all = self.vessels.values().flatten().map(|f| f.t_s);
        let first = all.clone().fold(f64::INFINITY, f64::min);
        (first, all.fold(f64::NEG_INFINITY, f64::max))
    }

    /// The first and last report's times of one vessel.
    pub fn vessel_span_s(&self, mmsi: u32) -> Option<(f64, f64)> {
        let f = self.vessels.get(&mmsi)?;
        Some((f.first()?.t_s, f.last()?.t_s))
    }

    /// Vessel `mmsi` at `t_s`: position (m) and velocity (m/s), on the straight line between
    /// the reports around `t_s` when they are at most `max_gap_s` apart, or `still_gap_s`
    /// when the vessel is still at both and between them (under [`STILL_KN`]); `None`
    /// outside its reports or across a longer gap.
    pub fn at(
        &self,
        mmsi: u32,
        t_s: f64,
        max_gap_s: f64,
        still_gap_s: f64,
    ) -> Option<([f64; 2], [f64; 2])> {
        let f = self.vessels.get(&mmsi)?;
        let i = f.partition_point(|x| x.t_s <= t_s);
        if i == 0 {
            return None;
        }
        let a = f[i - 1];
        let Some(&b) = f.get(i) else {
            // At the last report exactly.
            return (t_s - a.t_s < 1e-6).then(|| (a.position_m, velocity(&a)));
        };
        let dt = b.t_s - a.t_s;
        if dt <= 0.0 || (dt > max_gap_s && !still_across(&a, &b, still_gap_s)) {
            return None;
        }
        let w = (t_s - a.t_s) / dt;
        let p = [
            a.position_m[0] + w * (b.position_m[0] - a.position_m[0]),
            a.position_m[1] + w * (b.position_m[1] - a.position_m[1]),
        ];
        // The motion between the two reports: what the ship did, where SOG/COG are a
        // sensor's momentary values.
        let v = [
            (b.position_m[0] - a.position_m[0]) / dt,
            (b.position_m[1] - a.position_m[1]) / dt,
        ];
        Some((p, v))
    }
}

/// True when a vessel is still across the gap from report `a` to `b` and the gap is at most
/// `still_gap_s`: under [`STILL_KN`] at both and between them (moored or at anchor). The
/// one rule for keeping it in the truth and for sending its reports as moored.
fn still_across(a: &Fix, b: &Fix, still_gap_s: f64) -> bool {
    let dt = b.t_s - a.t_s;
    let moved_m = (b.position_m[0] - a.position_m[0]).hypot(b.position_m[1] - a.position_m[1]);
    dt > 0.0
        && dt <= still_gap_s
        && a.sog_kn < STILL_KN
        && b.sog_kn < STILL_KN
        && moved_m < STILL_KN * KNOT_MPS * dt
}

/// True when report `i` of `fixes` goes out with the status *moored*: the vessel is still
/// across the minutes to its next report, by the rule that keeps it in the truth
/// ([`still_across`]). A class A ship reports that seldom only moored or at anchor (ITU-R
/// M.1371-5, Annex 1, Table 1) and says so in its navigational status, which sets how long
/// a receiver holds it (18 min against 60 s). The last report looks back at the gap
/// before it.
fn sent_as_moored(fixes: &[Fix], i: usize, still_gap_s: f64) -> bool {
    let before = i.checked_sub(1).and_then(|j| fixes.get(j));
    let (a, b) = match (before, fixes.get(i), fixes.get(i + 1)) {
        (_, Some(f), Some(next)) => (f, next),
        (Some(previous), Some(f), None) => (previous, f),
        _ => return false,
    };
    b.t_s - a.t_s > MAX_GAP_S && still_across(a, b, still_gap_s)
}

fn velocity(f: &Fix) -> [f64; 2] {
    let (s, c) = f.cog_deg.to_radians().sin_cos();
    [f.sog_kn * KNOT_MPS * s, f.sog_kn * KNOT_MPS * c]
}

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct AisTruthOptions {
    /// The reports file.
    pub path: std::path::PathBuf,
    /// Own ship's MMSI.
    pub own_mmsi: u32,
    /// Start, s after the file's first report (default: own ship's first report).
    pub start_s: Option<f64>,
    /// Length, s (default: to own ship's last report).
    pub duration_s: Option<f64>,
    /// Seed of the radar model's and the AIS dropouts' draws.
    pub seed: u64,
    /// A still (moored) vessel's longest gap between reports across which it stays in the
    /// truth, s ([`MAX_GAP_S`]: as any vessel's; [`MOORED_GAP_S`]: moored ships stay in).
    pub still_gap_s: f64,
}

/// The source. See the module documentation.
pub struct AisTruthSource {
    tracks: AisTracks,
    /// The local frame's origin: the vessels are placed about own ship
    /// ([`Origin::about_own_ship`]), where the AIS positions heard are put.
    origin: Origin,
    own_mmsi: u32,
    still_gap_s: f64,
    model: PlotModel,
    scan_s: f64,
    time_s: f64,
    end_s: f64,
    scan: u32,
    /// Vessel ids for the radar model (u16) and back.
    ids: BTreeMap<u32, u16>,
    mmsi_of: Vec<u32>,
    /// Per vessel, the index of its next report to send as AIS.
    next_report: BTreeMap<u32, usize>,
    rng: fastrand::Rng,
    decoder: AisDecoder,
    heard: Vec<(f64, AisReport)>,
    sent: u64,
    dropped: u64,
    /// Own ship's heading, rad: its course while it makes way, held while it is stopped.
    own_heading_rad: f32,
}

/// Below this speed, kn, own ship's course over ground is no heading: a moored ship's
/// track between fixes centimetres apart points anywhere (its `HDT` swung 52–212° in the
/// Solent's first minutes, seen in OpenCPN), and its gyro would read steady.
pub const OWN_HEADING_FROM_KN: f32 = 0.5;

impl AisTruthSource {
    /// Reads the file and places own ship.
    ///
    /// # Errors
    /// The file does not read, own ship's MMSI is not in it, or the window holds none of
    /// own ship's track.
    pub fn open(o: &AisTruthOptions, origin: &Origin) -> anyhow::Result<Self> {
        let tracks = AisTracks::read(&o.path, origin)?;
        let (own_first, own_last) = tracks.vessel_span_s(o.own_mmsi).with_context(|| {
            let mmsi = crate::ais::mmsi_text(o.own_mmsi);
            format!("own ship {mmsi}: not in {}", o.path.display())
        })?;
        let (file_first, _) = tracks.span_s();
        let start = o
            .start_s
            .map_or(own_first, |s| file_first + s)
            .max(own_first);
        let end = o.duration_s.map_or(own_last, |d| start + d).min(own_last);
        if end <= start {
            bail!(
                "own ship {} has no track between {start:.0} and {end:.0} s",
                crate::ais::mmsi_text(o.own_mmsi)
            );
        }
        let own_first_course_rad = tracks
            .vessels
            .get(&o.own_mmsi)
            .and_then(|fixes| {
                fixes
                    .iter()
                    .find(|f| f.sog_kn >= f64::from(OWN_HEADING_FROM_KN))
            })
            .map_or(0.0, |f| f.cog_deg.to_radians() as f32);
        let mmsi_of: Vec<u32> = tracks.vessels.keys().copied().collect();
        let ids = mmsi_of
            .iter()
            .enumerate()
            .map(|(i, m)| (*m, u16::try_from(i + 1).unwrap_or(u16::MAX)))
            .collect();
        let next_report = tracks
            .vessels
            .iter()
            .map(|(m, f)| (*m, f.partition_point(|x| x.t_s < start)))
            .collect();
        Ok(AisTruthSource {
            tracks,
            origin: *origin,
            own_mmsi: o.own_mmsi,
            still_gap_s: o.still_gap_s,
            model: PlotModel::new(SensorModel::imo(), o.seed),
            scan_s: 2.5,
            time_s: start,
            end_s: end,
            scan: 0,
            ids,
            mmsi_of,
            next_report,
            rng: fastrand::Rng::with_seed(o.seed ^ 0xA15),
            decoder: AisDecoder::new(),
            heard: Vec::new(),
            sent: 0,
            // Until it first makes way, the course it then takes (the file has no headings).
            own_heading_rad: own_first_course_rad,
            dropped: 0,
        })
    }

    /// AIS sentences sent and lost on the air so far.
    pub fn ais_sent(&self) -> (u64, u64) {
        (self.sent, self.dropped)
    }

    /// Sends every report due by `t_s` as AIVDM through the decoder.
    fn send_ais(&mut self, t_s: f64) {
        for (mmsi, fixes) in &self.tracks.vessels {
            if *mmsi == self.own_mmsi {
                continue;
            }
            let next = self.next_report.entry(*mmsi).or_insert(0);
            while let Some(f) = fixes.get(*next).filter(|f| f.t_s <= t_s) {
                let moored = sent_as_moored(fixes, *next, self.still_gap_s);
                *next += 1;
                if self.rng.f64() < AIS_DROPOUT {
                    self.dropped += 1;
                    continue;
                }
                self.sent += 1;
                if let Some(line) = aivdm_line(*mmsi, f, moored) {
                    if let Some(r) = self.decoder.feed(&line) {
                        self.heard.push((f.t_s, r));
                    }
                }
            }
        }
    }
}

/// A class A position report (type 1) of `f` as an `!AIVDM` sentence, under way using its
/// engine or `moored`.
fn aivdm_line(mmsi: u32, f: &Fix, moored: bool) -> Option<String> {
    use aivdm::message::PositionReportClassA;
    let msg = aivdm::AisMessage::PositionReportClassA(PositionReportClassA {
        message_type: 1,
        repeat_indicator: 0,
        mmsi: aivdm::Mmsi::from_raw(mmsi),
        navigation_status: if moored {
            aivdm::NavigationStatus::Moored
        } else {
            aivdm::NavigationStatus::UnderWayUsingEngine
        },
        rate_of_turn: aivdm::RateOfTurn::from_raw(-128),
        sog: aivdm::Sog::from_raw((f.sog_kn * 10.0).round().clamp(0.0, 1022.0) as u16),
        position_accuracy: false,
        longitude: aivdm::Longitude::from_raw((f.lon_deg * 600_000.0).round() as i32),
        latitude: aivdm::Latitude::from_raw((f.lat_deg * 600_000.0).round() as i32),
        cog: aivdm::Cog::from_raw((f.cog_deg * 10.0).round().clamp(0.0, 3599.0) as u16),
        heading: aivdm::Heading::from_raw(511),
        timestamp: aivdm::Timestamp::Second((f.t_s.rem_euclid(60.0)) as u8),
        maneuver_indicator: aivdm::ManeuverIndicator::NotAvailable,
        raim: false,
        radio_status: 0,
    });
    let mut buf = [0u8; 64];
    let (payload, fill) = aivdm::encode_payload(&msg, &mut buf).ok()?;
    let body = format!("AIVDM,1,1,,A,{},{fill}", std::str::from_utf8(payload).ok()?);
    Some(format!("!{body}*{:02X}", crate::nmea::checksum(&body)))
}

impl PlotSource for AisTruthSource {
    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        let t = self.time_s;
        if t > self.end_s {
            return Ok(None);
        }
        let Some((own_p, own_v)) = self
            .tracks
            .at(self.own_mmsi, t, f64::INFINITY, f64::INFINITY)
        else {
            return Ok(None);
        };
        let f = |x: [f64; 2]| [x[0] as f32, x[1] as f32];
        let own_m = f(own_p);
        // The vessels present, nearest first, as many as the radar model holds.
        let sensor = *self.model.sensor();
        let mut present: Vec<(u32, [f64; 2], [f64; 2], f64)> = self
            .mmsi_of
            .iter()
            .filter(|m| **m != self.own_mmsi)
            .filter_map(|m| {
                let (p, v) = self.tracks.at(*m, t, MAX_GAP_S, self.still_gap_s)?;
                // About own ship, as its radar sees them.
                let (p, v) = self.origin.about_own_ship(p, v, own_p);
                let d = (p[0] - own_p[0]).hypot(p[1] - own_p[1]);
                Some((*m, p, v, d))
            })
            .filter(|x| x.3 <= f64::from(sensor.max_range_m) * 1.5)
            .collect();
        present.sort_by(|a, b| a.3.total_cmp(&b.3));
        present.truncate(tracker_core::sim::MAX_TARGETS);
        let mut out = ScanOutput::default();
        self.model.sense(
            own_m,
            present
                .iter()
                .map(|(m, p, v, _)| (self.ids.get(m).copied().unwrap_or(0), f(*p), f(*v))),
            &mut out,
        );
        let (course_rad, speed_mps) = tracker_core::geo::course_speed(f(own_v));
        if speed_mps >= OWN_HEADING_FROM_KN * tracker_core::geo::MPS_PER_KNOT {
            self.own_heading_rad = course_rad;
        }
        let own = OwnShip {
            heading_rad: Some(self.own_heading_rad),
            ..OwnShip::at(own_m, f(own_v))
        };
        let targets = out
            .truth
            .iter()
            .map(|x| TargetTruth {
                id: self
                    .mmsi_of
                    .get(usize::from(x.id).wrapping_sub(1))
                    .copied()
                    .unwrap_or(0),
                position_m: x.position_m,
                velocity_mps: x.velocity_mps,
                detected: x.detected,
                in_range: x.in_range,
            })
            .collect();
        self.send_ais(t);
        self.scan += 1;
        self.time_s += self.scan_s;
        Ok(Some(SourceScan {
            radar: RadarScan {
                scan: self.scan,
                time_s: t,
                plots: out.plots.to_vec(),
            },
            own_ship: Some(own),
            truth: Some(ScanTruth {
                own,
                targets,
                ids_are_mmsi: true,
            }),
            echoes: None,
            heading_sensor_rad: None,
            placed_heading_rad: None,
        }))
    }

    fn scan_period_s(&self) -> Option<f64> {
        Some(self.scan_s)
    }

    /// The sensor model's the plots are made with.
    fn plot_accuracy(&self) -> Option<crate::session::associate::PolarAccuracy> {
        Some(crate::session::associate::PolarAccuracy::of_sensor(
            self.model.sensor(),
        ))
    }

    fn scans_left(&self) -> Option<u64> {
        Some(((self.end_s - self.time_s) / self.scan_s).max(0.0) as u64 + 1)
    }

    fn take_ais(&mut self) -> Vec<(f64, AisReport)> {
        std::mem::take(&mut self.heard)
    }

    fn ais_counts(&self) -> Option<crate::ais::AisCounts> {
        Some(self.decoder.counts())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_parse_and_reports_round_trip_through_aivdm() {
        assert_eq!(parse_utc("1970-01-02 00:00:01.5"), Some(86_401.5));
        assert_eq!(
            parse_utc("2016-01-12 13:02:11.218"),
            Some(1_452_603_731.218)
        );
        assert_eq!(parse_utc("2016-13-12 13:02:11"), None);
        let f = Fix {
            t_s: 0.0,
            lat_deg: 50.773_013,
            lon_deg: -1.092_935,
            cog_deg: 157.8,
            sog_kn: 5.9,
            position_m: [0.0, 0.0],
        };
        let line = aivdm_line(235_070_762, &f, false).unwrap();
        let r = AisDecoder::new().feed(&line).unwrap();
        assert_eq!((r.msg_type, r.mmsi), (1, 235_070_762));
        let (lat, lon) = r.position_deg.unwrap();
        assert!((lat - f.lat_deg).abs() < 2e-6 && (lon - f.lon_deg).abs() < 2e-6);
        assert_eq!((r.sog_kn, r.cog_deg), (Some(5.9), Some(157.8)));
        let moored = AisDecoder::new()
            .feed(&aivdm_line(235_070_762, &f, true).unwrap())
            .unwrap();
        assert_eq!(moored.nav_status.as_deref(), Some("Moored"));
    }

    #[test]
    fn a_moored_vessel_stays_in_the_truth_across_its_three_minute_reports_when_asked() {
        let fix = |t_s: f64, sog_kn: f64, x: f64| Fix {
            t_s,
            lat_deg: 0.0,
            lon_deg: 0.0,
            cog_deg: 90.0,
            sog_kn,
            position_m: [x, 0.0],
        };
        let tracks = AisTracks {
            vessels: BTreeMap::from([
                // Moored: 180 s between reports, 3 m apart.
                (1, vec![fix(0.0, 0.0, 0.0), fix(180.0, 0.1, 3.0)]),
                // Under way and silent as long: out whatever the still gap.
                (2, vec![fix(0.0, 6.0, 0.0), fix(180.0, 6.0, 555.0)]),
                // Slow at both reports but 200 m on: not still between them.
                (3, vec![fix(0.0, 0.5, 0.0), fix(180.0, 0.5, 200.0)]),
            ]),
        };
        assert_eq!(tracks.at(1, 90.0, MAX_GAP_S, MAX_GAP_S), None);
        let (p, _) = tracks.at(1, 90.0, MAX_GAP_S, MOORED_GAP_S).unwrap();
        assert!((p[0] - 1.5).abs() < 1e-9);
        assert_eq!(tracks.at(1, 90.0, MAX_GAP_S, 179.0), None);
        assert_eq!(tracks.at(2, 90.0, MAX_GAP_S, MOORED_GAP_S), None);
        assert_eq!(tracks.at(3, 90.0, MAX_GAP_S, MOORED_GAP_S), None);
        // Any vessel within the ordinary gap is in.
        assert!(tracks.at(2, 90.0, 200.0, MAX_GAP_S).is_some());
        // Its reports go out as moored exactly where the truth keeps it across the gap to the
        // next one (the last looks back).
        let moored = |m: u32, still_gap_s: f64| -> Vec<bool> {
            let f = &tracks.vessels[&m];
            (0..f.len())
                .map(|i| sent_as_moored(f, i, still_gap_s))
                .collect()
        };
        assert_eq!(moored(1, MOORED_GAP_S), [true, true]);
        assert_eq!(moored(1, MAX_GAP_S), [false, false]);
        assert_eq!(moored(1, 179.0), [false, false]);
        assert_eq!(moored(2, MOORED_GAP_S), [false, false]);
        assert_eq!(moored(3, MOORED_GAP_S), [false, false]);
        // Reports 10 s apart, still: under way (held 60 s, reported again within it).
        let often = [fix(0.0, 0.0, 0.0), fix(10.0, 0.0, 0.0), fix(20.0, 0.0, 0.0)];
        assert!((0..3).all(|i| !sent_as_moored(&often, i, MOORED_GAP_S)));
        // Still across the first gap, under way after it: moored, then under way.
        let leaves = [
            fix(0.0, 0.0, 0.0),
            fix(180.0, 0.2, 2.0),
            fix(190.0, 6.0, 32.0),
        ];
        let out: Vec<bool> = (0..3)
            .map(|i| sent_as_moored(&leaves, i, MOORED_GAP_S))
            .collect();
        assert_eq!(out, [true, false, false]);
    }
}
