//! Targets out to a chart plotter: `TTM` (tracked target message) and `TLL` (target
//! latitude and longitude), IEC 61162-1 §8; and, when the plotter has no GNSS of its own,
//! own ship (`RMC`, `HDT`, `OSD`).
//!
//! Targets go under their target numbers (01–99, unique, kept for a track's life: see
//! [`crate::session::numbers`]), the same the display and the table show: tracked ones as
//! `T`, acquiring ones (a second plot) as `Q`, and a target that ends (lost, or an
//! acquisition that failed) once as `L`, after which its number is free. A target held
//! hidden in another's echo ([`ScanReport::in_echo`]), not drawn on the display, is not
//! sent while hidden and not sent as lost either: the plotter keeps it as last sent, and
//! gets it again under its number when it is seen apart (or its `L` if it is lost). When
//! the run ends (the source's end, `q`, Ctrl-C) every target still on the plotter is sent
//! as `L`: a plotter keeps a target it was not told of as live until its own timeout
//! (OpenCPN drew the last scan's targets on, tried).
//!
//! Course and speed are true (over ground) when own ship's motion is known; otherwise they
//! are sent relative and marked `R`.

use tracker_core::geo::{METRES_PER_NM, MPS_PER_KNOT};

use super::{angle_360, angle_field, date, degrees, sentence, utc, NmeaOut, OutSpec};
use crate::origin::Origin;
use crate::own_ship::OwnShip;
use crate::session::target::TargetData;
use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::SourceScan;

/// A target as the plotter is told of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotterTarget<'a> {
    /// The plotter's number, 1–99.
    pub number: u8,
    /// The name (the AIS name of the ship paired with it), else `TGTnn` is sent.
    pub name: Option<&'a str>,
    /// Status letter: `T` tracking, `Q` acquiring, `L` lost.
    pub status: char,
    /// The target's data.
    pub data: TargetData,
}

/// `TTM` for one target: number, distance (NM) and true bearing, speed (kn) and course,
/// `T` (true) or `R` (relative: own ship's motion unknown), CPA (NM), TCPA (minutes,
/// negative once passed), units N (K for some: below), name, status, no reference target,
/// UTC, A (automatic acquisition). Bearings and courses are 0.0–359.9. A target whose motion is not known
/// ([`TargetData::trend_known`]: one acquiring, `Q`, or an acquisition that failed, `L`) has
/// its speed, course, CPA and TCPA as null fields (IEC 61162-1: a field whose value is not
/// available is sent empty), so a plotter is given no vector the radar display does not
/// show.
///
/// Distances and speed go in nautical miles and knots (units `N`), but for a target whose
/// number (2 and over) is the whole part of its distance in nautical miles (target 06 at
/// 6.040 NM), which go in kilometres and km/h (units `K`, IEC 61162-1 §8 `TTM` field 10;
/// the whole part of the kilometres is then always more than the number): OpenCPN 5.10
/// passes every `TTM`, `TLL` and `OSD` through its AIS multi-sentence reassembly, reading
/// field 1 as the number of sentences and field 2 as this sentence's, appending field 5
/// to a buffer each time; a `TTM` whose two were equal had the buffer, grown past its
/// 820-byte copy over an hour of targets, decoded as an AIS message, and OpenCPN crashed
/// (found in a new user's trial on the Solent run, 66 minutes in, and reproduced on the
/// recorded stream; the same crash was reported with radar_pi's ARPA and a BridgeMaster's
/// `TTM`s, radar_pi issue #251 and OpenCPN issue #1126; docs/nmea.md). OpenCPN converts
/// `K`; a client that ignored field 10 would draw such a target 1.852 times too far.
pub fn ttm(t: &PlotterTarget<'_>, time_s: f64) -> String {
    let d = &t.data;
    let number = t.number;
    let range_nm = f64::from(d.range_m) / f64::from(METRES_PER_NM);
    let in_nm = format!("{range_nm:.3}");
    // Per nautical mile, kilometres (and km/h per knot).
    let (unit, per_nm) = if read_as_last_part(number, &in_nm) {
        ('K', f64::from(METRES_PER_NM) / 1000.0)
    } else {
        ('N', 1.0)
    };
    // A course only where there is motion to have one: not for a target shown standing
    // still (true), nor one keeping its range (relative); the display shows `---` for
    // both, and `TTM` sent 0.0 and the noise's direction.
    let (speed, course, reference) = if d.true_motion_known {
        (d.speed_mps, d.moving().then_some(d.course_rad), 'T')
    } else {
        (
            d.rel_speed_mps,
            (!d.keeps_range()).then_some(d.rel_course_rad),
            'R',
        )
    };
    // A target shown still (no course) is 0.0 however it is measured: its knots are
    // rounded before they are turned into km/h.
    let speed_kn = f64::from(speed) / f64::from(MPS_PER_KNOT);
    let speed_kn = if course.is_none() {
        (speed_kn * 10.0).round() / 10.0
    } else {
        speed_kn
    };
    let motion = if t.status == 'Q' || !d.trend_known {
        format!(",,{reference},,")
    } else {
        format!(
            "{:.1},{},{reference},{:.3},{:.2}",
            speed_kn * per_nm,
            course.map_or_else(String::new, |c| angle_360(degrees(c), 1)),
            f64::from(d.cpa_m) / f64::from(METRES_PER_NM) * per_nm,
            // Just past the CPA (under 0.3 s) is 0.00, not -0.00.
            super::shown_signed(f64::from(d.tcpa_s) / 60.0, 2),
        )
    };
    sentence(&format!(
        "RATTM,{number:02},{:.3},{},T,{motion},{unit},{},{},,{},A",
        range_nm * per_nm,
        angle_360(degrees(d.bearing_rad), 1),
        name_field(t),
        t.status,
        utc(time_s)
    ))
}

/// The whole part of a numeric field's text, as C's `atoi` reads it (OpenCPN's
/// reassembly, [`ttm`]): its leading digits; `None` without one.
fn whole_part(field: &str) -> Option<u32> {
    let digits: String = field.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// Whether OpenCPN 5.10's reassembly ([`ttm`]) would take a sentence of target `number`
/// whose second field is `field` as the last part of a multi-sentence AIS message and
/// decode its buffer: the number 2 and over, and the field's whole part equal to it.
fn read_as_last_part(number: u8, field: &str) -> bool {
    number >= 2 && whole_part(field) == Some(u32::from(number))
}

/// The target name field: the name as IEC 61162-1 allows it in a field (printable ASCII
/// without the reserved `$ ! * , \\ ^ ~` and the delimiters, at most 20 characters), else
/// `TGTnn`.
fn name_field(t: &PlotterTarget<'_>) -> String {
    let clean: String = t
        .name
        .unwrap_or("")
        .chars()
        .filter(|c| c.is_ascii_graphic() || *c == ' ')
        .filter(|c| !"$!*,\\^~".contains(*c))
        .take(20)
        .collect();
    let clean = clean.trim();
    if clean.is_empty() {
        format!("TGT{:02}", t.number)
    } else {
        clean.to_string()
    }
}

/// A simulated target's name: `SIMnn`, or `SIM NAME` (cut to 20 characters where sent)
/// for one shown as the AIS target `NAME`.
fn simulated_name(number: u8, name: Option<&str>) -> String {
    match name.map(str::trim).filter(|n| !n.is_empty()) {
        Some(n) => format!("SIM {n}"),
        None => format!("SIM{number:02}"),
    }
}

/// `TLL` for one target: number, latitude and longitude (longitude wrapped to ±180°),
/// name, UTC, status, no reference target. The position is taken about own ship at `own_m`
/// (local, m; [`Origin::to_lat_lon_near`]), where the target's range and bearing put it,
/// however far own ship has come from the origin. `None` when that is no place on the
/// globe (own ship dead reckoned past a pole, a position not a number): no `TLL` is
/// better than a broken one. Nor within a degree of the equator where the latitude's
/// whole minutes are the target's number (2 and over): OpenCPN 5.10 reads them as its
/// sentence number ([`ttm`]), and the `TTM` carries the target.
pub fn tll(t: &PlotterTarget<'_>, origin: &Origin, own_m: [f32; 2], time_s: f64) -> Option<String> {
    let d = &t.data;
    let f = |x: [f32; 2]| [f64::from(x[0]), f64::from(x[1])];
    let (lat, lon) = origin.to_lat_lon_near(f(d.position_m), f(own_m));
    if !(lat.is_finite() && lon.is_finite()) {
        return None;
    }
    let number = t.number;
    let lat_field = angle_field(lat, 2, 'N', 'S');
    if read_as_last_part(number, &lat_field) {
        return None;
    }
    Some(sentence(&format!(
        "RATLL,{number:02},{},{},{},{},{},",
        lat_field,
        angle_field(lon, 3, 'E', 'W'),
        name_field(t),
        utc(time_s),
        t.status
    )))
}

/// Own ship for a plotter without GNSS: `RMC` (position, SOG, COG, UTC and date; status
/// `V` while own ship is dead reckoning, has no fix yet or stands at a fixed position, mode
/// `E`, `N` or `M` then, NMEA 0183 2.30 and later; speed and course empty while
/// its motion is unknown, the course also at 0.0 kn), `HDT` when a heading is
/// known, and `OSD` (own ship data: heading, course, speed, and their references).
pub fn own_ship_sentences(own: &OwnShip, origin: &Origin, time_s: f64) -> Vec<String> {
    own_ship_sentences_of(own, origin, time_s, false)
}

/// As [`own_ship_sentences`]; with `simulated` (a simulation's own ship: `demo` without
/// `--nmea-in`) the `RMC` says so, mode `S` (simulator) and status `V`, so that no plotter
/// takes a made-up position for own ship's fix.
pub fn own_ship_sentences_of(
    own: &OwnShip,
    origin: &Origin,
    time_s: f64,
    simulated: bool,
) -> Vec<String> {
    let p = [f64::from(own.position_m[0]), f64::from(own.position_m[1])];
    let (lat, lon) = origin.to_lat_lon(p);
    let q = own.quality;
    // The position's validity: a fix whose motion is not measured yet is still a fix; a
    // position entered by hand is not (NMEA 0183 2.30 and later: status V for every mode
    // but A and D).
    let status = if q.dead_reckoning_s.is_none() && !q.no_fix_yet && !q.fixed_position && !simulated
    {
        'A'
    } else {
        'V'
    };
    // Unknown motion goes as empty fields, not as a ship stopped; a ship stopped has no
    // course.
    let sog_kn = own.sog_kn().map_or(String::new(), |kn| format!("{kn:.1}"));
    let cog = own.cog_deg().map_or(String::new(), |deg| angle_360(deg, 1));
    // Before a first fix there is no position to send, only where the frame starts.
    let (lat, lon) = if q.no_fix_yet {
        (",".to_string(), ",".to_string())
    } else {
        (angle_field(lat, 2, 'N', 'S'), angle_field(lon, 3, 'E', 'W'))
    };
    let mut out = vec![sentence(&format!(
        "RARMC,{},{status},{lat},{lon},{sog_kn},{cog},{},,,{}",
        utc(time_s),
        date(time_s),
        // NMEA 0183 (2.30 and later) mode: N no fix, M manual input (a fixed position), E estimated
        // (dead reckoning), A autonomous.
        if q.no_fix_yet {
            'N'
        } else if simulated {
            'S'
        } else if q.fixed_position {
            'M'
        } else if status == 'A' {
            'A'
        } else {
            'E'
        }
    ))];
    let heading = own.heading_rad.map(|h| angle_360(degrees(h), 1));
    if let Some(h) = &heading {
        out.push(sentence(&format!("RAHDT,{h},T")));
    }
    // Course and speed referenced to the positioning system, or entered by hand (a fixed
    // position, stopped).
    let reference = if q.fixed_position { 'M' } else { 'P' };
    out.push(sentence(&format!(
        "RAOSD,{},{},{cog},{reference},{sog_kn},{reference},,,N",
        heading.as_deref().unwrap_or(""),
        if heading.is_some() { 'A' } else { 'V' }
    )));
    out
}

/// The AIS name (or MMSI) of the ship radar track `track` is paired with. Not a
/// candidate's, shown as an AIS target while their pair is confirmed: measured on the
/// Solent, naming single candidates too sent 228 changes from one ship's name to another's
/// (docs/ais.md, "The plotter's name for a target"), and a label naming another ship is
/// worse than `TGTnn`.
fn ais_name(report: &ScanReport, track: u16) -> Option<&str> {
    report
        .paired
        .iter()
        .find(|p| p.track == track)
        .map(|p| p.label.as_str())
}

/// What the plotter output sent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct TargetsOutCounts {
    /// Target reports sent (`TTM` and `TLL` pairs, tracking and acquiring).
    pub targets_sent: u64,
    /// Ends sent (`L`).
    pub lost_sent: u64,
}

/// What NMEA out sent over the run, for the summary (`--summary-json` key `nmea_out`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct NmeaOutSummary {
    /// What was sent.
    #[serde(flatten)]
    pub sent: TargetsOutCounts,
    /// UDP datagrams the system refused to send.
    pub udp_failures: u64,
    /// A TCP server's clients (`None` over UDP and serial): whether a plotter ever
    /// connected.
    pub tcp: Option<crate::nmea::out::ServerCounts>,
    /// A serial port's counts (`None` over UDP and TCP).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub serial: Option<crate::nmea::out::SerialCounts>,
}

impl std::fmt::Display for NmeaOutSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} target reports (TTM/TLL) and {} ends (L) sent",
            self.sent.targets_sent, self.sent.lost_sent
        )?;
        match (self.tcp, self.serial) {
            (Some(c), _) => write!(
                f,
                "; TCP: {} plotters connected ({} gone, {} dropped for not reading, {} refused)",
                c.accepted, c.gone, c.dropped_slow, c.refused
            ),
            (None, Some(s)) => write!(
                f,
                "; serial at {} baud: {} sentences dropped (the baud rate did not carry them in time), {} write errors",
                s.baud, s.sentences_dropped, s.write_errors
            ),
            (None, None) => write!(
                f,
                "; UDP: {} datagrams refused by the system (UDP cannot tell whether a plotter listens)",
                self.udp_failures
            ),
        }
    }
}

/// Targets (and optionally own ship) to chart plotters each scan: tracked targets as `T`,
/// acquiring ones as `Q`, ended ones once as `L`, each under its target number.
pub struct TargetsOut {
    out: NmeaOut,
    origin: Origin,
    /// The origin is own ship's position (given by the operator, or a recording's first
    /// fix), so targets can be placed on the chart before own ship's first fix.
    origin_known: bool,
    own_ship: bool,
    counts: TargetsOutCounts,
    /// Targets on the plotter now (sent `T` or `Q`, not yet `L`), by number, as last sent.
    on_plotter: std::collections::BTreeMap<u8, (Option<String>, TargetData)>,
    /// The last scan's time, own ship's position and whether `TLL` could go.
    last: Option<(f64, [f32; 2], bool)>,
    /// The targets are a simulation's (`demo`): sent named `SIMnn` (`SIM NAME` for one
    /// shown as an AIS target), so that no plotter shows them as ships.
    simulated: bool,
    /// Own ship is a simulation's too (`demo` without `--nmea-in`): its `RMC` goes with mode
    /// `S` and status `V`.
    simulated_own_ship: bool,
}

impl TargetsOut {
    /// Opens `spec`; `origin` ties the local frame to the chart; with `own_ship`, own ship is
    /// sent too.
    ///
    /// # Errors
    /// The socket does not open (an address that does not resolve, a port in use).
    pub fn open(spec: &OutSpec, origin: Origin, own_ship: bool) -> anyhow::Result<Self> {
        Ok(TargetsOut::new(NmeaOut::open(spec)?, origin, own_ship))
    }

    /// Over an open output.
    pub fn new(out: NmeaOut, origin: Origin, own_ship: bool) -> Self {
        TargetsOut {
            out,
            origin,
            origin_known: false,
            own_ship,
            counts: TargetsOutCounts::default(),
            on_plotter: std::collections::BTreeMap::new(),
            last: None,
            simulated: false,
            simulated_own_ship: false,
        }
    }

    /// With `simulated`, the targets are a simulation's: each is sent named `SIMnn`, or
    /// `SIM NAME` for one shown as an AIS target. A new user's trial ran the README's
    /// `demo --nmea-in tcp:… --nmea-out tcp:…` against a real multiplexer: OpenCPN drew
    /// the demo's 40 ships as `TGT01`–`TGT40` about the real own ship, one in CPA alarm, and
    /// nothing said they were not there. (NMEA 0183 `TTM` has no field for it; the name is
    /// what every plotter shows.)
    pub fn with_simulated(mut self, simulated: bool) -> Self {
        self.simulated = simulated;
        self
    }

    /// With `simulated`, own ship is a simulation's too: sent (`--nmea-out-own-ship`) with
    /// `RMC` mode `S` and status `V` ([`own_ship_sentences_of`]).
    pub fn with_simulated_own_ship(mut self, simulated: bool) -> Self {
        self.simulated_own_ship = simulated;
        self
    }

    /// With `known`, the origin is own ship's position (`--origin`, a recording's first
    /// fix): targets go with `TLL` before own ship's first fix too, placed from it.
    pub fn with_origin_known(mut self, known: bool) -> Self {
        self.origin_known = known;
        self
    }

    /// The socket's local address (for a TCP server: the port plotters connect to).
    ///
    /// # Errors
    /// The operating system's.
    pub fn local_addr(&self) -> std::io::Result<std::net::SocketAddr> {
        self.out.local_addr()
    }

    /// What was sent so far.
    pub fn counts(&self) -> TargetsOutCounts {
        self.counts
    }

    /// One scan's sentences: own ship's first (when sent: a plotter places a `TTM` target
    /// from own ship's position as it has it, and with `RMC` after the targets OpenCPN put
    /// them from the last scan's, 25 m behind at 20 kn, until their `TLL` came), then ends,
    /// then tracked and acquiring targets (a confirmed
    /// target whose motion's trend is not known yet is sent as acquiring, `Q`, as IEC 62388
    /// draws it); targets still waiting for a number, and targets held hidden in another's
    /// echo, are not sent. Each target goes as `TTM` and `TLL`, `TTM` alone while own ship
    /// has had no position fix and the origin is not its position
    /// ([`TargetsOut::with_origin_known`]).
    ///
    /// Times are the scan's when its clock is UTC, on the bridge's time
    /// ([`ScanReport::utc_s`]: a live NMEA source's UTC, whatever this computer's clock
    /// says, as own ship is). A source whose clock counts from an
    /// epoch of its own (a plots file from 0 s) is sent with the time it is sent at, this
    /// host's clock: 1970 would be false, and OpenCPN 5.10 draws neither targets nor own
    /// ship from sentences whose UTC and date are empty (tried).
    pub fn scan_sentences(&mut self, report: &ScanReport) -> Vec<String> {
        let time_s = report.utc_s().unwrap_or_else(crate::utc::now_s);
        // Before own ship's first fix a target's range and bearing are known (TTM), its
        // latitude and longitude are not, unless the operator said where own ship is: TLL
        // would put it where the default frame starts, in another sea. (Dead reckoning goes
        // on sending TLL, from own ship's estimate, as RMC's status `V` tells.)
        let position_unknown = report.own.quality.no_fix_yet && !self.origin_known;
        let mut out = if self.own_ship {
            own_ship_sentences_of(&report.own, &self.origin, time_s, self.simulated_own_ship)
        } else {
            Vec::new()
        };
        // A target held hidden in another's echo (`report.in_echo`) is not sent: not drawn
        // on the display, its coasting track 60–150 m from the echo would be a second
        // symbol there; nor lost, so not `L` (told so, it went off the plotter and came
        // back one or a few scans later: 410 times in 20 minutes of the Solent, a new
        // user's trial, the symbols blinking). It stays on the plotter as last sent, where
        // the two ships went into one echo, until the two are seen apart (not bounded by the
        // hold's 16 scans: 32 at most on the Solent, docs/nmea.md).
        let groups = [
            (&report.ended, 'L'),
            (&report.targets, 'T'),
            (&report.acquiring, 'Q'),
        ];
        for (targets, status) in groups {
            for d in targets {
                let Some(number) = d.number else { continue };
                // An end is sent only for a target on the plotter (a failed acquisition had
                // its `L` then).
                if status == 'L' && !self.on_plotter.contains_key(&number) {
                    continue;
                }
                // An end goes under the name last sent: a pair is parted when its track
                // ends, and the plotter would see the ship renamed `TGTnn` as it goes.
                let last_name = (status == 'L')
                    .then(|| self.on_plotter.get(&number))
                    .flatten()
                    .map(|(name, _)| name.clone());
                // A simulation's target is marked (an end goes under the name last sent,
                // marked already).
                let marked = (last_name.is_none() && self.simulated)
                    .then(|| simulated_name(number, ais_name(report, d.track)));
                let name = match (&last_name, &marked) {
                    (Some(name), _) => name.as_deref(),
                    (None, Some(m)) => Some(m.as_str()),
                    (None, None) => ais_name(report, d.track),
                };
                let data = *d;
                let t = PlotterTarget {
                    number,
                    name,
                    status: plotter_status(status, &data),
                    data,
                };
                self.push_target(
                    &mut out,
                    &t,
                    time_s,
                    report.own.position_m,
                    position_unknown,
                );
                if status == 'L' {
                    self.counts.lost_sent += 1;
                    self.on_plotter.remove(&number);
                } else {
                    self.counts.targets_sent += 1;
                    self.on_plotter
                        .insert(number, (name.map(str::to_string), data));
                }
            }
        }
        self.last = Some((time_s, report.own.position_m, position_unknown));
        out
    }

    /// The run's end: every target still on the plotter as `L`, where it was last sent,
    /// at the last scan's time; after this none is on it.
    pub fn end_sentences(&mut self) -> Vec<String> {
        let Some((time_s, own_m, position_unknown)) = self.last else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (number, (name, data)) in std::mem::take(&mut self.on_plotter) {
            let at = (time_s, own_m, position_unknown);
            self.push_lost(&mut out, number, name.as_deref(), data, at);
        }
        out
    }

    /// A target taken off the plotter (`L`), counted; `at` is the time, own ship's
    /// position and whether that is unknown, as [`TargetsOut::push_target`] takes them.
    fn push_lost(
        &mut self,
        out: &mut Vec<String>,
        number: u8,
        name: Option<&str>,
        data: TargetData,
        at: (f64, [f32; 2], bool),
    ) {
        let t = PlotterTarget {
            number,
            name,
            status: 'L',
            data,
        };
        let (time_s, own_m, position_unknown) = at;
        self.push_target(out, &t, time_s, own_m, position_unknown);
        self.counts.lost_sent += 1;
    }

    /// One target's `TTM`, and its `TLL` unless own ship's position is unknown.
    fn push_target(
        &self,
        out: &mut Vec<String>,
        t: &PlotterTarget<'_>,
        time_s: f64,
        own_m: [f32; 2],
        position_unknown: bool,
    ) {
        out.push(ttm(t, time_s));
        if !position_unknown {
            out.extend(tll(t, &self.origin, own_m, time_s));
        }
    }
}

impl ScanSink for TargetsOut {
    fn scan(&mut self, _: &SourceScan, report: &ScanReport) -> anyhow::Result<()> {
        let sentences = self.scan_sentences(report);
        self.out.send(&sentences);
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        let sentences = self.end_sentences();
        self.out.send(&sentences);
        self.out.drain(END_DRAIN);
        Ok(())
    }

    fn nmea_out(&self) -> Option<NmeaOutSummary> {
        Some(NmeaOutSummary {
            sent: self.counts,
            udp_failures: self.out.udp_failures(),
            tcp: self.out.counts(),
            serial: self.out.serial_counts(),
        })
    }
}

/// How long the run's end waits for TCP plotters to take the targets' ends.
const END_DRAIN: std::time::Duration = std::time::Duration::from_secs(1);

/// The status letter a target of `group` (`T` tracked, `Q` acquiring, `L` lost) is sent
/// with: a tracked target whose motion's trend is not known yet is still acquiring (`Q`),
/// as IEC 62388 draws it, without a vector.
fn plotter_status(group: char, d: &TargetData) -> char {
    if group == 'T' && !d.trend_known {
        'Q'
    } else {
        group
    }
}

/// The sentences for `targets` seen from own ship at `own_m` (local, m) as they stand,
/// numbered by their track numbers (for tests and one-off use: [`TargetsOut`] keeps plotter
/// numbers over a run).
pub fn targets_sentences(
    targets: &[TargetData],
    origin: &Origin,
    own_m: [f32; 2],
    time_s: f64,
) -> Vec<String> {
    targets
        .iter()
        .flat_map(|d| {
            let t = PlotterTarget {
                number: (d.track % 99 + 1) as u8,
                name: None,
                status: 'T',
                data: *d,
            };
            std::iter::once(ttm(&t, time_s)).chain(tll(&t, origin, own_m, time_s))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::checksum;

    fn plotter(data: TargetData) -> PlotterTarget<'static> {
        PlotterTarget {
            name: None,
            number: 7,
            status: 'T',
            data,
        }
    }

    #[test]
    fn own_ship_with_its_motion_unknown_goes_without_a_speed_or_course() {
        let origin = Origin::default();
        let mut own = OwnShip::at([0.0, 0.0], [0.0, 3.0]);
        let rmc = |own: &OwnShip| own_ship_sentences(own, &origin, 0.0)[0].clone();
        let known = rmc(&own);
        assert!(
            known.contains(",A,") && known.contains(",5.8,0.0,"),
            "{known}"
        );
        // Stopped: a speed, no course.
        own.velocity_mps = [0.0, 0.0];
        let stopped = rmc(&own);
        assert!(
            stopped.contains(",A,") && stopped.contains(",W,0.0,,010170,"),
            "{stopped}"
        );
        // A fix without a velocity yet: stopped it is not, and the fix is still valid.
        own.quality.motion_known = false;
        let unknown = rmc(&own);
        assert!(unknown.starts_with("$RARMC,000000.00,A,"), "{unknown}");
        assert!(unknown.contains(",W,,,010170,,,A*"), "{unknown}");
        let osd = own_ship_sentences(&own, &origin, 0.0).pop().unwrap();
        assert!(osd.starts_with("$RAOSD,,V,,P,,P,"), "{osd}");
        // Dead reckoning: the position is not a fix.
        own.quality.dead_reckoning_s = Some(12.0);
        assert!(rmc(&own).contains(",V,") && rmc(&own).contains(",,,E*"));
        // No fix yet: no position either.
        own.quality.no_fix_yet = true;
        let none = rmc(&own);
        assert!(
            none.starts_with("$RARMC,000000.00,V,,,,,,,010170,,,N*"),
            "{none}"
        );
        // A simulation's own ship: mode S, never a valid fix.
        let sim = OwnShip::at([0.0, 0.0], [0.0, 3.0]);
        let simulated = own_ship_sentences_of(&sim, &origin, 0.0, true)[0].clone();
        assert!(
            simulated.contains(",V,5040.00000,N,") && simulated.contains(",,,S*"),
            "{simulated}"
        );
        // A fixed position (`--fixed-position`): the position, stopped, entered by hand.
        let fixed = crate::own_ship::fixed::fixed_at_origin(own);
        let manual = rmc(&fixed);
        assert!(
            manual.starts_with("$RARMC,000000.00,V,5040.00000,N,00100.00000,W,0.0,,010170,,,M*"),
            "{manual}"
        );
    }

    /// A radar target paired with an AIS target goes to the plotter with the AIS name; one
    /// shown as an AIS target while their pair is confirmed with its number alone
    /// ([`ais_name`]); a paired one's end under its name.
    #[test]
    fn an_associated_target_is_sent_with_its_ais_name() {
        use crate::display::tests::{eleventh_scan, one_associated_ship};
        let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        let spec = crate::nmea::OutSpec::Udp(rx.local_addr().unwrap().to_string());
        let name_of = |view: &ScanReport| {
            let mut out = TargetsOut::open(&spec, Origin::default(), false).unwrap();
            let ttm = out.scan_sentences(view).remove(0);
            ttm.split(',').nth(11).unwrap().to_string()
        };
        assert_eq!(name_of(&one_associated_ship(eleventh_scan(), true)), "SHIP");
        let candidate = name_of(&one_associated_ship(eleventh_scan(), false));
        assert!(candidate.starts_with("TGT"), "{candidate}");
        // Its end (the pair parted with its track) goes under the name it had.
        let mut out = TargetsOut::open(&spec, Origin::default(), false).unwrap();
        let mut view = one_associated_ship(eleventh_scan(), true);
        out.scan_sentences(&view);
        view.ended = std::mem::take(&mut view.targets);
        view.paired.clear();
        let end = out.scan_sentences(&view).remove(0);
        let f: Vec<&str> = end.split(',').collect();
        assert_eq!((f[11], f[12]), ("SHIP", "L"), "{end}");
    }

    /// A simulation's targets (`demo`) are named as such on the plotter: `SIMnn`, `SIM
    /// NAME` for one paired with an AIS target, and their ends under the same name.
    #[test]
    fn a_simulations_targets_are_sent_named_as_simulated() {
        use crate::display::tests::{eleventh_scan, one_associated_ship};
        let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
        let spec = crate::nmea::OutSpec::Udp(rx.local_addr().unwrap().to_string());
        let open = || {
            TargetsOut::open(&spec, Origin::default(), false)
                .unwrap()
                .with_simulated(true)
        };
        let fields = |s: &str| s.split(',').map(str::to_string).collect::<Vec<_>>();
        let mut out = open();
        let mut view = one_associated_ship(eleventh_scan(), true);
        let sent = out.scan_sentences(&view);
        assert_eq!(fields(&sent[0])[11], "SIM SHIP", "{sent:?}");
        // The TLL's name is the TTM's.
        assert_eq!(fields(&sent[1])[6], "SIM SHIP", "{sent:?}");
        view.ended = std::mem::take(&mut view.targets);
        view.paired.clear();
        let end = fields(&out.scan_sentences(&view)[0]);
        assert_eq!((end[11].as_str(), end[12].as_str()), ("SIM SHIP", "L"));
        let unpaired = open().scan_sentences(&one_associated_ship(eleventh_scan(), false));
        let name = &fields(&unpaired[0])[11];
        assert!(
            name.starts_with("SIM") && name[3..].parse::<u8>().is_ok(),
            "{unpaired:?}"
        );
    }

    #[test]
    fn an_ais_name_goes_in_the_name_field_cleaned() {
        let mut t = plotter(crate::session::target::example());
        assert!(ttm(&t, 0.0).contains(",N,TGT07,"));
        t.name = Some("RED FALCON, *~$ISLE OF WIGHT FERRY");
        let s = ttm(&t, 0.0);
        assert!(s.contains(",N,RED FALCON ISLE OF W,"), "{s}");
        assert_eq!(
            &s[s.len() - 4..s.len() - 2],
            format!("{:02X}", checksum(&s[1..s.find('*').unwrap()]))
        );
        t.name = Some(" ,*");
        assert!(tll(&t, &Origin::default(), [0.0, 0.0], 0.0)
            .unwrap()
            .contains(",TGT07,"));
    }

    #[test]
    fn ttm_reads_back_through_an_independent_parser() {
        let t = crate::session::target::example();
        let s = ttm(&plotter(t), 3723.5);
        assert!(s.ends_with("\r\n") && s.starts_with("$RATTM,07,"));
        let parsed = match nmea::parse_str(s.trim()).unwrap() {
            nmea::ParseResult::TTM(d) => d,
            other => panic!("{other:?}"),
        };
        assert_eq!(parsed.target_number, Some(7));
        let nm = 5000.0 / 1852.0;
        assert!((parsed.target_distance.unwrap() - nm as f32).abs() < 1e-3);
        assert!((parsed.target_speed.unwrap() - 5.0 / MPS_PER_KNOT).abs() < 0.06);
        assert_eq!(
            parsed.speed_or_distance_unit,
            Some(nmea::sentences::TtmDistanceUnit::NauticalMile)
        );
        assert_eq!(
            parsed.target_status,
            Some(nmea::sentences::TtmStatus::Tracking)
        );
        assert!((parsed.distance_of_cpa.unwrap() - t.cpa_m / METRES_PER_NM).abs() < 1e-3);
        assert!((parsed.time_to_cpa.unwrap() - t.tcpa_s / 60.0).abs() < 0.01);
        assert_eq!(
            parsed.time_of_data,
            chrono::NaiveTime::from_hms_milli_opt(1, 2, 3, 500)
        );
        assert_eq!(
            parsed.type_of_acquisition,
            Some(nmea::sentences::TtmTypeOfAcquisition::Automatic)
        );
        // Bearing 036.9° true (3 km east, 4 km north); course 270° true.
        assert!(s.contains(",36.9,T,") && s.contains(",270.0,T,"), "{s}");
        // Own motion unknown: relative course and speed, marked R.
        let rel = TargetData {
            true_motion_known: false,
            ..t
        };
        let s = ttm(&plotter(rel), 0.0);
        assert!(s.contains(",R,"), "{s}");
    }

    /// OpenCPN 5.10's reassembly ([`ttm`]): a sentence is taken as the last part of a
    /// multi-sentence AIS message, and its buffer decoded, when its fields 1 and 2 read as
    /// C's `atoi` reads them are equal and over 1.
    fn opencpn_5_10_decodes_as_ais(s: &str) -> bool {
        let f: Vec<&str> = s.trim().split(',').collect();
        let (n, i) = (atoi(f[1]), atoi(f[2]));
        n > 1 && i == n
    }

    /// C's `atoi` on the fields we send (no sign, no spaces): the leading digits' value.
    fn atoi(x: &str) -> u64 {
        x.bytes()
            .take_while(u8::is_ascii_digit)
            .fold(0, |a, b| a * 10 + u64::from(b - b'0'))
    }

    #[test]
    fn atoi_reads_our_fields_as_c_does() {
        assert_eq!(atoi("06"), 6);
        assert_eq!(atoi("6.040"), 6);
        assert_eq!(atoi("0.500"), 0);
        assert_eq!(atoi("0002.16000"), 2);
        assert_eq!(atoi("A"), 0);
        assert_eq!(whole_part("06"), Some(6));
        assert_eq!(whole_part("0002.16000"), Some(2));
        assert_eq!(whole_part(".5"), None);
    }

    #[test]
    fn a_target_whose_number_is_its_distance_goes_in_kilometres() {
        let t = crate::session::target::example();
        let at = |number: u8, range_nm: f32| {
            let mut p = plotter(TargetData {
                range_m: range_nm * METRES_PER_NM,
                ..t
            });
            p.number = number;
            ttm(&p, 0.0)
        };
        // Target 06 at 6.040 NM: 11.186 km, its speed (5 m/s) 18.0 km/h, its CPA in km.
        let s = at(6, 6.04);
        let parsed = match nmea::parse_str(s.trim()).unwrap() {
            nmea::ParseResult::TTM(d) => d,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            parsed.speed_or_distance_unit,
            Some(nmea::sentences::TtmDistanceUnit::Kilometer),
            "{s}"
        );
        assert!(
            (parsed.target_distance.unwrap() - 11.186).abs() < 1e-3,
            "{s}"
        );
        assert!((parsed.target_speed.unwrap() - 18.0).abs() < 0.06, "{s}");
        assert!(
            (parsed.distance_of_cpa.unwrap() - t.cpa_m / 1000.0).abs() < 1e-3,
            "{s}"
        );
        // A target shown still (0.04 kn, no course) is 0.0 in km/h too, not 0.1.
        let mut still = plotter(TargetData {
            range_m: 6.04 * METRES_PER_NM,
            speed_mps: 0.02,
            ..t
        });
        still.number = 6;
        let s = ttm(&still, 0.0);
        let f: Vec<&str> = s.split(',').collect();
        assert_eq!((f[5], f[6], f[10]), ("0.0", "", "K"), "{s}");
        // Another number, or target 01, in nautical miles.
        assert!(at(7, 6.04).contains(",N,TGT07,"));
        assert!(at(1, 1.5).contains(",N,TGT01,"));
        // Every number at distances about its own (the field's rounding included: 5.9996
        // NM is sent as 6.000): none OpenCPN 5.10 would decode as AIS.
        for number in 1..=99u8 {
            let n = f32::from(number);
            for range_nm in [n - 0.0004, n, n + 0.5, n + 0.9994, n + 0.9996] {
                let s = at(number, range_nm);
                assert!(!opencpn_5_10_decodes_as_ais(&s), "{s}");
            }
        }
    }

    #[test]
    fn no_tll_whose_latitude_minutes_are_its_number() {
        let t = crate::session::target::example();
        let origin = Origin {
            lat_deg: 0.0,
            lon_deg: 10.0,
        };
        // The target 4 km north of the origin on the equator: 0°02.16′N, whole part 0002.
        let mut p = plotter(t);
        let s = tll(&p, &origin, [0.0, 0.0], 0.0).unwrap();
        assert!(s.starts_with("$RATLL,07,0002.1"), "{s}");
        p.number = 2;
        assert_eq!(tll(&p, &origin, [0.0, 0.0], 0.0), None);
        // Target 01 reads as a one-sentence message: no buffer is decoded.
        p.number = 1;
        assert!(tll(&p, &origin, [0.0, 0.0], 0.0).is_some());
    }

    #[test]
    fn tll_has_its_fields_in_order_and_a_valid_checksum() {
        let t = crate::session::target::example();
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let s = tll(&plotter(t), &origin, [0.0, 0.0], 0.0).unwrap();
        // The nmea crate checks the frame and checksum (it has no TLL field parser).
        let frame = nmea::parse_nmea_sentence(s.trim()).unwrap();
        assert_eq!(frame.checksum, checksum(&s[1..s.find('*').unwrap()]));
        let f: Vec<&str> = s.trim()[1..s.find('*').unwrap()].split(',').collect();
        assert_eq!(f[0], "RATLL");
        assert_eq!(f[1], "07");
        // On WGS84, 5 km from 50°N 1°W on 036.87° (4 km north, 3 km east) is 50°02.15725′N
        // 0°57.48752′W (Karney's geodesic, by geographiclib 2.0 for Python).
        assert_eq!((f[2], f[3]), ("5002.15725", "N"));
        assert_eq!(f[5], "W");
        let lon_min: f64 = f[4][3..].parse().unwrap();
        assert!((lon_min - 57.48752).abs() < 2e-5, "{s}");
        assert_eq!((f[6], f[7], f[8]), ("TGT07", "000000.00", "T"));
    }

    #[test]
    fn tll_is_where_range_and_bearing_put_the_target_far_from_the_origin() {
        // Own ship 60 NM north of the origin, a target 6 NM due east of it: TLL 6 NM of
        // longitude there east of own ship (within a metre), not the 240 m short that the
        // origin's east metres would put it, and 11.9 m south of own ship's parallel, where
        // the geodesic leaving due east is (s² tan φ / 2N).
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let own_m = origin.to_local(51.0, -1.0);
        let own = OwnShip::at([own_m[0] as f32, own_m[1] as f32], [0.0, 5.0]);
        let track = tracker_core::icd::TrackState {
            position_m: [own.position_m[0] + 11_112.0, own.position_m[1]],
            ..crate::session::target::example_track()
        };
        let d = TargetData::new(&own, &track);
        assert!((d.range_m - 11_112.0).abs() < 0.01);
        let s = tll(&plotter(d), &origin, own.position_m, 0.0).unwrap();
        let f: Vec<&str> = s.trim()[1..s.find('*').unwrap()].split(',').collect();
        let minutes = |field: &str, deg_digits: usize| -> f64 {
            let deg: f64 = field[..deg_digits].parse().unwrap();
            deg * 60.0 + field[deg_digits..].parse::<f64>().unwrap()
        };
        let south_m = (51.0 * 60.0 - minutes(f[2], 2)) * 1852.0;
        assert!((south_m - 11.9).abs() < 1.0, "{south_m} m: {s}");
        // A minute of longitude at 51° N on WGS84: 1,169.961 m.
        let east_m = (60.0 - minutes(f[4], 3)) * 1_169.961;
        assert!((east_m - 11_112.0).abs() < 1.0, "{east_m} m: {s}");
    }

    #[test]
    fn a_target_is_acquiring_until_its_trend_is_known() {
        let d = crate::session::target::example();
        assert_eq!(plotter_status('T', &d), 'T');
        let young = TargetData {
            trend_known: false,
            ..d
        };
        assert_eq!(plotter_status('T', &young), 'Q');
        assert_eq!(plotter_status('L', &young), 'L');
        // An acquisition that failed ends without the motion it never had.
        let lost = ttm(
            &PlotterTarget {
                status: 'L',
                ..plotter(young)
            },
            0.0,
        );
        assert!(lost.contains(",T,,,T,,,N,"), "{lost}");
        let s = ttm(
            &PlotterTarget {
                status: plotter_status('T', &young),
                ..plotter(young)
            },
            0.0,
        );
        let parsed = match nmea::parse_str(s.trim()).unwrap() {
            nmea::ParseResult::TTM(d) => d,
            other => panic!("{other:?}"),
        };
        assert_eq!(
            parsed.target_status,
            Some(nmea::sentences::TtmStatus::Query),
            "{s}"
        );
        // Its position is sent, its motion is not known yet.
        assert!(parsed.target_distance.is_some());
        assert_eq!(
            (
                parsed.target_speed,
                parsed.target_course.is_some(),
                parsed.distance_of_cpa,
                parsed.time_to_cpa
            ),
            (None, false, None, None),
            "{s}"
        );
        assert_eq!(
            s.split(',').count(),
            ttm(&plotter(d), 0.0).split(',').count()
        );
    }

    /// A target shown standing still has no course to send (it was 0.0), nor has one
    /// keeping its range in relative motion (the noise's direction); its speed, CPA and
    /// TCPA are sent. A parser reads the field as absent.
    #[test]
    fn a_still_target_is_sent_without_a_course() {
        let d = crate::session::target::example();
        let still = TargetData {
            speed_mps: 0.0,
            ..d
        };
        let s = ttm(&plotter(still), 0.0);
        let parsed = match nmea::parse_str(s.trim()).unwrap() {
            nmea::ParseResult::TTM(d) => d,
            other => panic!("{other:?}"),
        };
        assert_eq!(parsed.target_speed, Some(0.0), "{s}");
        assert!(parsed.target_course.is_none(), "{s}");
        assert!(parsed.distance_of_cpa.is_some(), "{s}");
        let relative = |rel_speed_mps: f32| TargetData {
            true_motion_known: false,
            rel_speed_mps,
            ..d
        };
        let keeping = ttm(&plotter(relative(0.05)), 0.0);
        assert!(keeping.contains(",0.1,,R,"), "{keeping}");
        let closing = ttm(&plotter(relative(2.0)), 0.0);
        assert!(!closing.contains(",,R,"), "{closing}");
        // The moving example keeps its course.
        let moving = ttm(&plotter(d), 0.0);
        match nmea::parse_str(moving.trim()).unwrap() {
            nmea::ParseResult::TTM(p) => assert!(p.target_course.is_some(), "{moving}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn angles_never_read_360() {
        assert_eq!(angle_360(359.96, 1), "0.0");
        assert_eq!(angle_360(-0.01, 1), "0.0");
        assert_eq!(angle_360(359.94, 1), "359.9");
        assert_eq!(angle_360(720.5, 2), "0.50");
    }
}
