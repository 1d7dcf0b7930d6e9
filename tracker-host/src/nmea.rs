//! NMEA 0183 with the bridge: what the tracker tells a chart plotter about its targets
//! (`TTM` tracked target, `TLL` target latitude/longitude) and what it takes from the ship's
//! sensors for own ship (`GGA`/`RMC` position, `VTG` course and speed over ground, `HDT`
//! heading, `VHW` speed through water), fed to paper 004's dead-reckoning filter.
//!
//! Units on the wire are NMEA's: nautical miles, knots, degrees true, minutes, latitude and
//! longitude in degrees and minutes, UTC. The tracker's local frame (east, north, metres) is
//! tied to the globe by an [`Origin`]; a flat-earth mapping around it is accurate to well
//! under a metre over a radar's range.
//!
//! Incoming sentences are parsed with the `nmea` crate. A bad checksum, a malformed
//! sentence, a void fix and a sentence older than the newest one are each rejected and
//! counted ([`NavCounts`]); nothing is trusted that did not pass.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream, ToSocketAddrs, UdpSocket};
use std::path::PathBuf;

use anyhow::{bail, Context};
use tracker_core::geo::{METRES_PER_NM, MPS_PER_KNOT};
use tracker_core::icd::TrackStatus;
use tracker_core::nav::drkf::{Drkf, DrkfConfig, NavFix, SpeedlogMode};
use tracker_core::nav::GaussMarkov;

use crate::target::{OwnShip, TargetData};

const METRES_PER_DEGREE_LATITUDE: f64 = 60.0 * METRES_PER_NM as f64;

/// Where the local frame's (0, 0) is on the globe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    /// Latitude, degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
}

impl Default for Origin {
    /// The eastern approach to the Solent, 50°40′N 001°00′W: open water for the demo.
    fn default() -> Self {
        Origin {
            lat_deg: 50.0 + 40.0 / 60.0,
            lon_deg: -1.0,
        }
    }
}

impl Origin {
    /// Parses `LAT,LON` in decimal degrees.
    pub fn parse(s: &str) -> anyhow::Result<Self> {
        let (lat, lon) = s.split_once(',').context("expected LAT,LON")?;
        let o = Origin {
            lat_deg: lat.trim().parse().context("latitude")?,
            lon_deg: lon.trim().parse().context("longitude")?,
        };
        if !(o.lat_deg.abs() < 85.0 && o.lon_deg.abs() <= 180.0) {
            bail!("{s}: latitude within ±85°, longitude within ±180°");
        }
        Ok(o)
    }

    /// Latitude and longitude of a local position, degrees.
    pub fn to_lat_lon(&self, p: [f64; 2]) -> (f64, f64) {
        let lat = self.lat_deg + p[1] / METRES_PER_DEGREE_LATITUDE;
        let lon =
            self.lon_deg + p[0] / (METRES_PER_DEGREE_LATITUDE * self.lat_deg.to_radians().cos());
        (lat, lon)
    }

    /// Local position (east, north), m, of a latitude and longitude in degrees.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64) -> [f64; 2] {
        let mut dlon = lon_deg - self.lon_deg;
        if dlon > 180.0 {
            dlon -= 360.0;
        } else if dlon < -180.0 {
            dlon += 360.0;
        }
        [
            dlon * METRES_PER_DEGREE_LATITUDE * self.lat_deg.to_radians().cos(),
            (lat_deg - self.lat_deg) * METRES_PER_DEGREE_LATITUDE,
        ]
    }
}

/// XOR of the bytes between `$` and `*`.
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |acc, b| acc ^ b)
}

/// `$body*HH` with its checksum and CR LF.
pub fn sentence(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body))
}

/// UTC `hhmmss.ss` of the scenario's time (which starts at midnight).
fn utc(time_s: f64) -> String {
    let t = time_s.rem_euclid(86_400.0);
    let centis = (t * 100.0).round() as u64 % 8_640_000;
    let (h, m) = (centis / 360_000, centis / 6_000 % 60);
    format!("{h:02}{m:02}{:02}.{:02}", centis / 100 % 60, centis % 100)
}

/// `ddmm.mmmmm,N` (or `dddmm.mmmmm,E` with `degree_digits` 3).
fn angle_field(v: f64, degree_digits: usize, pos: char, neg: char) -> String {
    let a = v.abs();
    let mut deg = a.trunc();
    let mut min = ((a - deg) * 60.0 * 100_000.0).round() / 100_000.0;
    if min >= 60.0 {
        deg += 1.0;
        min -= 60.0;
    }
    let hemisphere = if v < 0.0 { neg } else { pos };
    format!(
        "{:0w$}{:08.5},{hemisphere}",
        deg as u32,
        min,
        w = degree_digits
    )
}

fn degrees(rad: f32) -> f64 {
    f64::from(rad).to_degrees().rem_euclid(360.0)
}

/// `TTM`, tracked target message, for one target: number, distance (NM) and true bearing,
/// speed (kn) and true course over ground, CPA (NM), TCPA (minutes, negative once passed),
/// units N, name, status (T tracking, L lost, Q acquiring), no reference target, UTC, A
/// (automatic acquisition).
pub fn ttm(t: &TargetData, time_s: f64) -> String {
    let status = match t.status {
        TrackStatus::Tentative => 'Q',
        TrackStatus::Lost => 'L',
        TrackStatus::Confirmed | TrackStatus::Coasting => 'T',
    };
    let number = t.track % 100;
    sentence(&format!(
        "RATTM,{number:02},{:.3},{:.1},T,{:.1},{:.1},T,{:.3},{:.2},N,TGT{number:02},{status},,{},A",
        f64::from(t.range_m) / f64::from(METRES_PER_NM),
        degrees(t.bearing_rad),
        f64::from(t.speed_mps) / f64::from(MPS_PER_KNOT),
        degrees(t.course_rad),
        f64::from(t.cpa_m) / f64::from(METRES_PER_NM),
        f64::from(t.tcpa_s) / 60.0,
        utc(time_s)
    ))
}

/// `TLL`, target latitude and longitude: number, position, name, UTC, status, no reference.
pub fn tll(t: &TargetData, origin: &Origin, time_s: f64) -> String {
    let (lat, lon) = origin.to_lat_lon([f64::from(t.position_m[0]), f64::from(t.position_m[1])]);
    let number = t.track % 100;
    let status = if t.status == TrackStatus::Lost {
        'L'
    } else {
        'T'
    };
    sentence(&format!(
        "RATLL,{number:02},{},{},TGT{number:02},{},{status},",
        angle_field(lat, 2, 'N', 'S'),
        angle_field(lon, 3, 'E', 'W'),
        utc(time_s)
    ))
}

/// What the bridge's sensors would say about own ship at `position_m`, `velocity_mps`
/// (heading taken as the course, no current): `GPGGA`, `GPRMC`, `GPVTG`, `HEHDT`, `VWVHW`.
pub fn own_ship_sentences(
    position_m: [f64; 2],
    velocity_mps: [f64; 2],
    origin: &Origin,
    time_s: f64,
) -> Vec<String> {
    let (lat, lon) = origin.to_lat_lon(position_m);
    let (lat, lon) = (angle_field(lat, 2, 'N', 'S'), angle_field(lon, 3, 'E', 'W'));
    let speed_kn = velocity_mps[0].hypot(velocity_mps[1]) / f64::from(MPS_PER_KNOT);
    let course = velocity_mps[0]
        .atan2(velocity_mps[1])
        .to_degrees()
        .rem_euclid(360.0);
    let time = utc(time_s);
    vec![
        sentence(&format!(
            "GPGGA,{time},{lat},{lon},1,10,0.9,12.0,M,47.0,M,,"
        )),
        sentence(&format!(
            "GPRMC,{time},A,{lat},{lon},{speed_kn:.2},{course:.2},010126,,,A"
        )),
        sentence(&format!(
            "GPVTG,{course:.2},T,,M,{speed_kn:.2},N,{:.2},K,A",
            speed_kn * 1.852
        )),
        sentence(&format!("HEHDT,{course:.2},T")),
        sentence(&format!(
            "VWVHW,{course:.2},T,,M,{speed_kn:.2},N,{:.2},K",
            speed_kn * 1.852
        )),
    ]
}

/// Where NMEA goes: `udp:HOST:PORT` (datagrams to one listener) or `tcp:PORT` (a server any
/// number of chart plotters connect to).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutSpec {
    /// Datagrams to this address.
    Udp(String),
    /// A TCP server on this port (all interfaces).
    Tcp(u16),
}

impl std::str::FromStr for OutSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.split_once(':') {
            Some(("udp", addr)) if addr.contains(':') => Ok(OutSpec::Udp(addr.to_string())),
            Some(("tcp", port)) => port
                .parse()
                .map(OutSpec::Tcp)
                .map_err(|_| format!("{s}: tcp:PORT with a port number")),
            _ => Err(format!("{s}: expected udp:HOST:PORT or tcp:PORT")),
        }
    }
}

/// An open NMEA output.
pub enum NmeaOut {
    /// UDP socket and destination.
    Udp(UdpSocket, std::net::SocketAddr),
    /// Listening socket and the connected clients.
    Tcp(TcpListener, Vec<TcpStream>),
}

impl NmeaOut {
    /// Opens `spec`.
    pub fn open(spec: &OutSpec) -> anyhow::Result<Self> {
        Ok(match spec {
            OutSpec::Udp(addr) => {
                let to = addr
                    .to_socket_addrs()
                    .with_context(|| format!("resolving {addr}"))?
                    .next()
                    .with_context(|| format!("{addr} resolves to nothing"))?;
                let bind = if to.is_ipv4() { "0.0.0.0:0" } else { "[::]:0" };
                NmeaOut::Udp(UdpSocket::bind(bind).context("UDP socket")?, to)
            }
            OutSpec::Tcp(port) => {
                let l = TcpListener::bind(("0.0.0.0", *port))
                    .with_context(|| format!("listening on TCP port {port}"))?;
                l.set_nonblocking(true)?;
                NmeaOut::Tcp(l, Vec::new())
            }
        })
    }

    /// The local address (for a TCP server: the port clients connect to).
    pub fn local_addr(&self) -> std::io::Result<std::net::SocketAddr> {
        match self {
            NmeaOut::Udp(s, _) => s.local_addr(),
            NmeaOut::Tcp(l, _) => l.local_addr(),
        }
    }

    /// Sends one scan's sentences (one datagram each over UDP). A chart plotter that went
    /// away is dropped; nothing here stops the tracker.
    pub fn send(&mut self, sentences: &[String]) {
        match self {
            NmeaOut::Udp(socket, to) => {
                for s in sentences {
                    let _ = socket.send_to(s.as_bytes(), *to);
                }
            }
            NmeaOut::Tcp(listener, clients) => {
                while let Ok((c, _)) = listener.accept() {
                    let _ = c.set_nodelay(true);
                    clients.push(c);
                }
                let all: String = sentences.concat();
                clients.retain_mut(|c| c.write_all(all.as_bytes()).is_ok());
            }
        }
    }
}

/// The sentences of one scan for every target a plotter should show (confirmed and
/// coasting): `TTM` and `TLL` each.
pub fn targets_sentences(targets: &[TargetData], origin: &Origin, time_s: f64) -> Vec<String> {
    targets
        .iter()
        .flat_map(|t| [ttm(t, time_s), tll(t, origin, time_s)])
        .collect()
}

/// Where own-ship NMEA comes from: `file:PATH` (a recording, replayed in step with the
/// scans by its UTC times), `udp:PORT`, `tcp:HOST:PORT` (a TCP server such as a
/// multiplexer), `serial:DEVICE@BAUD`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InSpec {
    /// A recorded file.
    File(PathBuf),
    /// Datagrams on this port.
    Udp(u16),
    /// A TCP server to connect to.
    Tcp(String),
    /// A serial port and baud rate.
    Serial(String, u32),
}

impl std::str::FromStr for InSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad =
            || format!("{s}: expected file:PATH, udp:PORT, tcp:HOST:PORT or serial:DEVICE@BAUD");
        match s.split_once(':') {
            Some(("file", p)) if !p.is_empty() => Ok(InSpec::File(p.into())),
            Some(("udp", p)) => p.parse().map(InSpec::Udp).map_err(|_| bad()),
            Some(("tcp", a)) if a.contains(':') => Ok(InSpec::Tcp(a.to_string())),
            Some(("serial", d)) => {
                let (dev, baud) = d.rsplit_once('@').ok_or_else(bad)?;
                Ok(InSpec::Serial(
                    dev.to_string(),
                    baud.parse().map_err(|_| bad())?,
                ))
            }
            _ => Err(bad()),
        }
    }
}

/// An open own-ship NMEA source.
pub enum NmeaIn {
    /// A recording: lines, and the next one read ahead.
    File(std::io::Lines<BufReader<std::fs::File>>, Option<String>),
    /// A live stream (UDP, TCP or serial) and the bytes of an unfinished line.
    Live(LiveSource, Vec<u8>),
}

/// A live byte source.
pub enum LiveSource {
    /// UDP socket.
    Udp(UdpSocket),
    /// Any non-blocking reader (TCP stream, serial port).
    Stream(Box<dyn Read + Send>),
}

impl NmeaIn {
    /// Opens `spec`.
    pub fn open(spec: &InSpec) -> anyhow::Result<Self> {
        Ok(match spec {
            InSpec::File(p) => {
                let f = std::fs::File::open(p).with_context(|| format!("{}", p.display()))?;
                NmeaIn::File(BufReader::new(f).lines(), None)
            }
            InSpec::Udp(port) => {
                let s = UdpSocket::bind(("0.0.0.0", *port))
                    .with_context(|| format!("UDP port {port}"))?;
                s.set_nonblocking(true)?;
                NmeaIn::Live(LiveSource::Udp(s), Vec::new())
            }
            InSpec::Tcp(addr) => {
                let s =
                    TcpStream::connect(addr).with_context(|| format!("connecting to {addr}"))?;
                s.set_nonblocking(true)?;
                NmeaIn::Live(LiveSource::Stream(Box::new(s)), Vec::new())
            }
            InSpec::Serial(dev, baud) => {
                let p = serialport::new(dev, *baud)
                    .timeout(std::time::Duration::from_millis(1))
                    .open()
                    .with_context(|| format!("serial port {dev}"))?;
                NmeaIn::Live(LiveSource::Stream(Box::new(p)), Vec::new())
            }
        })
    }

    /// Lines due by `time_s`: from a recording, every line up to the first timed sentence
    /// later than `time_s`; from a live source, whatever has arrived.
    pub fn lines_until(&mut self, time_s: f64) -> Vec<String> {
        let mut out = Vec::new();
        match self {
            NmeaIn::File(lines, ahead) => loop {
                let next = match ahead.take() {
                    Some(l) => l,
                    None => match lines.next() {
                        Some(Ok(l)) => l,
                        // A read error ends the recording like its end does.
                        _ => break,
                    },
                };
                if sentence_time_s(&next).is_some_and(|t| t > time_s + 1e-6) {
                    *ahead = Some(next);
                    break;
                }
                out.push(next);
            },
            NmeaIn::Live(source, partial) => {
                let mut buf = [0u8; 2048];
                loop {
                    let n = match source {
                        LiveSource::Udp(s) => s.recv(&mut buf).unwrap_or(0),
                        LiveSource::Stream(r) => r.read(&mut buf).unwrap_or(0),
                    };
                    if n == 0 {
                        break;
                    }
                    partial.extend_from_slice(&buf[..n]);
                    // A line longer than any sentence is noise: drop it.
                    if partial.len() > 4096 && !partial.contains(&b'\n') {
                        partial.clear();
                    }
                }
                while let Some(i) = partial.iter().position(|&b| b == b'\n') {
                    let line: Vec<u8> = partial.drain(..=i).collect();
                    out.push(String::from_utf8_lossy(&line).into_owned());
                }
            }
        }
        out
    }
}

/// Seconds of the day of a `GGA` or `RMC` line (time is its first field), if it has one.
fn sentence_time_s(line: &str) -> Option<f64> {
    let line = line.trim();
    let kind = line.get(3..6)?;
    if !matches!(kind, "GGA" | "RMC") {
        return None;
    }
    let field = line.split(',').nth(1)?;
    let (h, m, s) = (field.get(0..2)?, field.get(2..4)?, field.get(4..)?);
    Some(h.parse::<f64>().ok()? * 3600.0 + m.parse::<f64>().ok()? * 60.0 + s.parse::<f64>().ok()?)
}

/// What became of the own-ship sentences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NavCounts {
    /// Used by the dead-reckoning filter.
    pub accepted: u64,
    /// Checksum wrong.
    pub bad_checksum: u64,
    /// Not a sentence, or fields out of form.
    pub malformed: u64,
    /// A fix flagged invalid (RMC status V, GGA quality 0) or without its values.
    pub void: u64,
    /// Older than a sentence already used.
    pub stale: u64,
    /// Well-formed but not a sentence own ship needs (satellites, depth, …).
    pub ignored: u64,
}

impl NavCounts {
    /// Sentences rejected (errors, not the ignored ones).
    pub fn rejected(&self) -> u64 {
        self.bad_checksum + self.malformed + self.void + self.stale
    }
}

impl std::fmt::Display for NavCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} accepted, {} rejected (bad checksum {}, malformed {}, void {}, stale {}), {} ignored",
            self.accepted,
            self.rejected(),
            self.bad_checksum,
            self.malformed,
            self.void,
            self.stale,
            self.ignored
        )
    }
}

/// Own ship from NMEA: the dead-reckoning filter (paper 004's DRKF) fed GPS position and
/// velocity, the gyro's heading and the log's speed through the water.
pub struct OwnShipNav {
    origin: Origin,
    drkf: Option<Drkf<f64>>,
    /// Time of the filter's state, s of the day.
    time_s: f64,
    /// Newest sentence time seen.
    newest_s: Option<f64>,
    /// Velocity over ground from the last VTG before the first position.
    velocity: Option<[f64; 2]>,
    counts: NavCounts,
}

/// The DRKF's sensor model for bridge NMEA: GPS 5 m and 0.1 m/s, gyro 0.5°, log 0.1 m/s
/// through the water, a ship's accelerations.
fn drkf_config() -> DrkfConfig {
    let mut c = DrkfConfig::table_1(1).unwrap_or_else(|| unreachable!("test 1 exists"));
    c.acceleration = GaussMarkov::with_variance(0.05 * 0.05, 0.1);
    c.gps_position_var = 25.0;
    c.gps_velocity_var = 0.01;
    c.gyro_var = 0.5f64.to_radians().powi(2);
    c.speedlog_var = 0.01;
    c.speedlog_mode = SpeedlogMode::BottomLock;
    c
}

impl OwnShipNav {
    /// No fix yet.
    pub fn new(origin: Origin) -> Self {
        OwnShipNav {
            origin,
            drkf: None,
            time_s: 0.0,
            newest_s: None,
            velocity: None,
            counts: NavCounts::default(),
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> NavCounts {
        self.counts
    }

    /// Takes one line. Timed sentences (GGA, RMC) set the time the others apply at.
    pub fn feed(&mut self, line: &str) {
        let line = line.trim();
        if line.is_empty() {
            return;
        }
        let parsed = match nmea::parse_str(line) {
            Ok(p) => p,
            Err(nmea::Error::ChecksumMismatch { .. }) => {
                self.counts.bad_checksum += 1;
                return;
            }
            Err(nmea::Error::Unsupported(_) | nmea::Error::Unknown(_)) => {
                self.counts.ignored += 1;
                return;
            }
            Err(_) => {
                self.counts.malformed += 1;
                return;
            }
        };
        let mut fix = NavFix::default();
        let knots = f64::from(MPS_PER_KNOT);
        let velocity = |sog_kn: f64, cog_deg: f64| {
            let c = cog_deg.to_radians();
            [sog_kn * knots * c.sin(), sog_kn * knots * c.cos()]
        };
        let mut time = None;
        match parsed {
            nmea::ParseResult::GGA(g) => {
                let valid = !matches!(g.fix_type, None | Some(nmea::sentences::FixType::Invalid));
                match (valid, g.latitude, g.longitude, g.fix_time) {
                    (true, Some(lat), Some(lon), Some(t)) => {
                        fix.gps_position_m = Some(self.origin.to_local(lat, lon));
                        time = Some(seconds(t));
                    }
                    _ => {
                        self.counts.void += 1;
                        return;
                    }
                }
            }
            nmea::ParseResult::RMC(r) => {
                // Status, the second field: A valid, V void (the crate keeps its enum private).
                let valid = line.split(',').nth(2) == Some("A");
                match (valid, r.lat, r.lon, r.fix_time) {
                    (true, Some(lat), Some(lon), Some(t)) => {
                        fix.gps_position_m = Some(self.origin.to_local(lat, lon));
                        if let (Some(s), Some(c)) = (r.speed_over_ground, r.true_course) {
                            fix.gps_velocity_mps = Some(velocity(f64::from(s), f64::from(c)));
                        }
                        time = Some(seconds(t));
                    }
                    _ => {
                        self.counts.void += 1;
                        return;
                    }
                }
            }
            nmea::ParseResult::VTG(v) => match (v.speed_over_ground, v.true_course) {
                (Some(s), Some(c)) => {
                    fix.gps_velocity_mps = Some(velocity(f64::from(s), f64::from(c)))
                }
                _ => {
                    self.counts.void += 1;
                    return;
                }
            },
            nmea::ParseResult::HDT(h) => match h.heading {
                Some(h) => fix.gyro_rad = Some(f64::from(h).to_radians()),
                None => {
                    self.counts.void += 1;
                    return;
                }
            },
            nmea::ParseResult::VHW(v) => match v.relative_speed_knots {
                Some(s) => fix.speedlog_mps = Some(s * knots),
                None => {
                    self.counts.void += 1;
                    return;
                }
            },
            _ => {
                self.counts.ignored += 1;
                return;
            }
        }
        if let Some(t) = time {
            if self.newest_s.is_some_and(|n| t < n) {
                self.counts.stale += 1;
                return;
            }
            self.newest_s = Some(t);
        }
        let at = time.unwrap_or(self.time_s);
        self.apply(at, &fix);
    }

    fn apply(&mut self, at: f64, fix: &NavFix) {
        let Some(drkf) = self.drkf.as_mut() else {
            if let Some(v) = fix.gps_velocity_mps {
                self.velocity = Some(v);
            }
            // The first position starts the filter.
            if let Some(p) = fix.gps_position_m {
                let v = fix.gps_velocity_mps.or(self.velocity);
                match Drkf::new(
                    drkf_config(),
                    p,
                    v.unwrap_or([0.0, 0.0]),
                    10.0,
                    if v.is_some() { 0.5 } else { 10.0 },
                ) {
                    Ok(d) => {
                        self.drkf = Some(d);
                        self.time_s = at;
                        self.counts.accepted += 1;
                    }
                    Err(_) => self.counts.void += 1,
                }
            } else {
                self.counts.accepted += 1;
            }
            return;
        };
        let dt = at - self.time_s;
        if dt > 0.0 {
            if drkf.predict(dt).is_err() {
                self.counts.stale += 1;
                return;
            }
            self.time_s = at;
        }
        match drkf.update(fix) {
            Ok(_) => self.counts.accepted += 1,
            Err(_) => self.counts.void += 1,
        }
    }

    /// Own ship at `time_s` (s of the day), predicted from the last sentence; `None` before
    /// the first position.
    pub fn own_ship_at(&self, time_s: f64) -> Option<OwnShip> {
        let mut d = self.drkf.clone()?;
        let dt = time_s - self.time_s;
        if dt > 0.0 {
            d.predict(dt).ok()?;
        }
        let p = d.position_m();
        let v = d.velocity_over_ground_mps();
        Some(OwnShip {
            position_m: [p[0] as f32, p[1] as f32],
            velocity_mps: [v[0] as f32, v[1] as f32],
        })
    }
}

fn seconds(t: chrono::NaiveTime) -> f64 {
    use chrono::Timelike;
    f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target() -> TargetData {
        let own = OwnShip {
            position_m: [0.0, 0.0],
            velocity_mps: [0.0, 6.0],
        };
        let track = tracker_core::icd::TrackState {
            track: 7,
            status: TrackStatus::Confirmed,
            position_m: [3000.0, 4000.0],
            velocity_mps: [-5.0, 0.0],
            position_cov_m2: [100.0, 0.0, 100.0],
            age_scans: 12,
            hit_history: 0xFFF,
        };
        TargetData::new(&own, &track)
    }

    #[test]
    fn ttm_reads_back_through_an_independent_parser() {
        let t = target();
        let s = ttm(&t, 3723.5);
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
    }

    #[test]
    fn tll_has_its_fields_in_order_and_a_valid_checksum() {
        let t = target();
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let s = tll(&t, &origin, 0.0);
        // The nmea crate checks the frame and checksum (it has no TLL field parser).
        let frame = nmea::parse_nmea_sentence(s.trim()).unwrap();
        assert_eq!(frame.checksum, checksum(&s[1..s.find('*').unwrap()]));
        let f: Vec<&str> = s.trim()[1..s.find('*').unwrap()].split(',').collect();
        assert_eq!(f[0], "RATLL");
        assert_eq!(f[1], "07");
        // 4 km north of 50°N: 50°02.15968′N; 3 km east of 1°W at 50°N: 0°57.20′W.
        assert_eq!((f[2], f[3]), ("5002.15983", "N"));
        assert_eq!(f[5], "W");
        let lon_min: f64 = f[4][3..].parse().unwrap();
        assert!((lon_min - (60.0 - 3000.0 / (1852.0 * 50f64.to_radians().cos()))).abs() < 1e-3);
        assert_eq!((f[6], f[7], f[8]), ("TGT07", "000000.00", "T"));
    }

    #[test]
    fn positions_round_trip_through_latitude_and_longitude() {
        let o = Origin::default();
        for p in [[0.0, 0.0], [18_520.0, -9_000.0], [-40_000.0, 30_000.0]] {
            let (lat, lon) = o.to_lat_lon(p);
            let q = o.to_local(lat, lon);
            assert!((p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6);
        }
        assert!(Origin::parse("50.5,-1.2").is_ok());
        assert!(Origin::parse("95,0").is_err() && Origin::parse("x").is_err());
    }

    #[test]
    fn own_ship_sentences_drive_the_dead_reckoning_filter() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin);
        let v = [0.0, 6.0];
        for k in 0..60 {
            let t = 10.0 * 3600.0 + f64::from(k);
            for s in own_ship_sentences([0.0, 6.0 * f64::from(k)], v, &origin, t) {
                // Every one of ours passes the independent parser.
                assert!(nmea::parse_str(s.trim()).is_ok(), "{s}");
                nav.feed(&s);
            }
        }
        assert_eq!(nav.counts().accepted, 300);
        assert_eq!(nav.counts().rejected(), 0);
        let own = nav.own_ship_at(10.0 * 3600.0 + 60.0).unwrap();
        assert!((own.position_m[1] - 360.0).abs() < 2.0, "{own:?}");
        assert!((own.velocity_mps[1] - 6.0).abs() < 0.05 && own.velocity_mps[0].abs() < 0.05);
    }

    #[test]
    fn bad_sentences_are_rejected_and_counted() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin);
        let good = own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, 100.0);
        nav.feed(&good[0]);
        let before = nav.own_ship_at(100.0);
        // Checksum off by one.
        let mut bad = good[0].trim().to_string();
        let last = bad.pop().unwrap();
        bad.push(if last == '0' { '1' } else { '0' });
        nav.feed(&bad);
        // A void RMC and a GGA without fix.
        nav.feed(&sentence("GPRMC,000150.00,V,,,,,,,010126,,,N"));
        nav.feed(&sentence("GPGGA,000150.00,,,,,0,00,99.9,,M,,M,,"));
        // Older than what was used.
        nav.feed(&own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, 50.0)[0]);
        // Garbage with a good checksum, no sentence at all, and one own ship does not need.
        nav.feed(&sentence("GPGGA,garbage"));
        nav.feed("not nmea at all");
        nav.feed(&ttm(&target(), 100.0));
        let c = nav.counts();
        assert_eq!(c.accepted, 1);
        assert_eq!(c.bad_checksum, 1, "{c}");
        assert_eq!(c.void, 2, "{c}");
        assert_eq!(c.stale, 1, "{c}");
        assert_eq!(c.malformed, 2, "{c}");
        assert_eq!(c.ignored, 1, "{c}");
        assert_eq!(nav.own_ship_at(100.0), before);
    }

    #[test]
    fn out_and_in_over_loopback() {
        // UDP: a datagram per sentence.
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let spec: OutSpec = format!("udp:{}", rx.local_addr().unwrap()).parse().unwrap();
        let mut out = NmeaOut::open(&spec).unwrap();
        let sentences = targets_sentences(&[target()], &Origin::default(), 1.0);
        out.send(&sentences);
        let mut buf = [0u8; 256];
        let n = rx.recv(&mut buf).unwrap();
        assert_eq!(&buf[..n], sentences[0].as_bytes());
        // TCP server: a plotter connects and reads both.
        let mut out = NmeaOut::open(&OutSpec::Tcp(0)).unwrap();
        let port = out.local_addr().unwrap().port();
        let mut client = TcpStream::connect(("127.0.0.1", port)).unwrap();
        client
            .set_read_timeout(Some(std::time::Duration::from_secs(5)))
            .unwrap();
        out.send(&sentences);
        let mut got = vec![0u8; sentences.concat().len()];
        client.read_exact(&mut got).unwrap();
        assert_eq!(String::from_utf8(got).unwrap(), sentences.concat());
        // UDP in: lines arrive and are split.
        let mut input = NmeaIn::open(&InSpec::Udp(0)).unwrap();
        let NmeaIn::Live(LiveSource::Udp(sock), _) = &input else {
            unreachable!()
        };
        let to = sock.local_addr().unwrap().port();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let own = own_ship_sentences([0.0, 0.0], [0.0, 5.0], &Origin::default(), 0.0);
        tx.send_to(own[..2].concat().as_bytes(), ("127.0.0.1", to))
            .unwrap();
        let mut lines = Vec::new();
        for _ in 0..100 {
            lines.extend(input.lines_until(0.0));
            if lines.len() >= 2 {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert_eq!(lines, own[..2].to_vec());
        // TCP: we connect to a server (a multiplexer) and read what it sends, in pieces.
        let server = TcpListener::bind("127.0.0.1:0").unwrap();
        let spec = InSpec::Tcp(server.local_addr().unwrap().to_string());
        let mut input = NmeaIn::open(&spec).unwrap();
        let (mut peer, _) = server.accept().unwrap();
        let text = own.concat();
        let (a, b) = text.split_at(text.len() / 2 + 3);
        peer.write_all(a.as_bytes()).unwrap();
        let mut lines = Vec::new();
        let mut rest = Some(b);
        for _ in 0..100 {
            lines.extend(input.lines_until(0.0));
            // The rest once the first part's complete lines are through.
            if let Some(b) = rest.filter(|_| !lines.is_empty()) {
                peer.write_all(b.as_bytes()).unwrap();
                rest = None;
            }
            if lines.len() == own.len() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert_eq!(lines, own);
        assert!("udp:nowhere".parse::<OutSpec>().is_err());
        assert!("serial:/dev/ttyUSB0@4800".parse::<InSpec>().is_ok());
    }
}
