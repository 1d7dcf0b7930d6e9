//! Where NMEA comes in from: a recording, UDP, a TCP server (a multiplexer) or a serial
//! port; lines bounded, live sources reopened after a drop.

use std::io::{BufRead, BufReader, Read};
use std::net::{TcpStream, ToSocketAddrs, UdpSocket};
use std::path::PathBuf;

use anyhow::Context;

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

impl InSpec {
    /// A live source (UDP, TCP, serial), not a recording.
    pub fn is_live(&self) -> bool {
        !matches!(self, InSpec::File(_))
    }
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

/// Longest line kept, bytes: longer ones (noise, a stream that is not NMEA) are dropped
/// and counted, and memory never grows with them.
pub const MAX_LINE_BYTES: usize = crate::nmea::sentence::MAX_LINE_CHARS;

/// Most lines taken from a live source per scan: beyond it the rest wait for the next
/// scan (a flood cannot stall a scan).
pub const MAX_LINES_PER_READ: usize = 20_000;

/// An open own-ship NMEA source.
pub enum NmeaIn {
    /// A recording, read ahead line by line.
    File(FileLines),
    /// A live stream (UDP, TCP or serial).
    Live(LiveLines),
}

/// A recording's lines, with a look-ahead.
pub struct FileLines {
    reader: BufReader<std::fs::File>,
    ahead: std::collections::VecDeque<String>,
    ended: bool,
}

impl FileLines {
    /// Line `i` ahead (0: the next), reading as far as needed; `None` past the end.
    pub fn peek(&mut self, i: usize) -> Option<&str> {
        while self.ahead.len() <= i && !self.ended {
            match read_bounded_line(&mut self.reader, MAX_LINE_BYTES) {
                Ok(Some(line)) => self.ahead.push_back(line),
                // A read error ends the recording as its end does.
                Ok(None) | Err(_) => self.ended = true,
            }
        }
        self.ahead.get(i).map(String::as_str)
    }

    /// The next line.
    pub fn next_line(&mut self) -> Option<String> {
        self.peek(0)?;
        self.ahead.pop_front()
    }
}

/// Reads one line (without its end); `Ok(None)` at the end. A line longer than `max`
/// bytes is consumed to its end but only its first `max + 1` bytes are kept: enough for
/// whoever reads it to see that it is too long, and memory stays bounded.
///
/// # Errors
/// The reader's.
pub fn read_bounded_line(reader: &mut impl BufRead, max: usize) -> std::io::Result<Option<String>> {
    let mut line = Vec::new();
    let mut any = false;
    loop {
        let buf = reader.fill_buf()?;
        if buf.is_empty() {
            break;
        }
        any = true;
        let (chunk, done) = match buf.iter().position(|&b| b == b'\n') {
            Some(i) => (&buf[..i], Some(i + 1)),
            None => (buf, None),
        };
        let room = (max + 1).saturating_sub(line.len());
        line.extend_from_slice(&chunk[..chunk.len().min(room)]);
        let used = done.unwrap_or(buf.len());
        reader.consume(used);
        if done.is_some() {
            break;
        }
    }
    if !any {
        return Ok(None);
    }
    if line.last() == Some(&b'\r') {
        line.pop();
    }
    Ok(Some(String::from_utf8_lossy(&line).into_owned()))
}

/// A live byte source, reconnected after a drop.
pub enum LiveSource {
    /// UDP socket.
    Udp(UdpSocket),
    /// A TCP server we connect to; `None` while disconnected.
    Tcp {
        /// `HOST:PORT`.
        addr: String,
        /// The connection.
        stream: Option<TcpStream>,
        /// When to try again, and the wait after that.
        retry: Retry,
    },
    /// A serial port; `None` while closed.
    Serial {
        /// Device path.
        device: String,
        /// Baud rate.
        baud: u32,
        /// The open port.
        port: Option<Box<dyn serialport::SerialPort>>,
        /// When to try again.
        retry: Retry,
    },
}

/// Reconnection with back-off: 1 s, doubling to 30 s.
#[derive(Clone, Copy, Debug)]
pub struct Retry {
    at: std::time::Instant,
    wait: std::time::Duration,
}

impl Retry {
    fn now() -> Self {
        Retry {
            at: std::time::Instant::now(),
            wait: std::time::Duration::from_secs(1),
        }
    }

    fn due(&self) -> bool {
        std::time::Instant::now() >= self.at
    }

    fn failed(&mut self) {
        self.at = std::time::Instant::now() + self.wait;
        self.wait = (self.wait * 2).min(std::time::Duration::from_secs(30));
    }

    fn succeeded(&mut self) {
        *self = Retry::now();
    }
}

/// Lines given back to a live source at most ([`LiveLines::give_back`]): a start-up's
/// wait for the first fix (30 s of a busy bridge's sentences and AIS) and no more.
pub const MAX_GIVEN_BACK_LINES: usize = 4096;

/// How long a reconnection attempt may take, so the scan loop is never held longer.
const CONNECT_TIMEOUT: std::time::Duration = std::time::Duration::from_millis(200);

/// A live source's lines.
pub struct LiveLines {
    source: LiveSource,
    partial: Vec<u8>,
    /// Lines read already and given back, to be read again first ([`LiveLines::give_back`]).
    given_back: std::collections::VecDeque<String>,
    /// Times the source went away.
    pub drops: u64,
    /// Times it came back.
    pub reconnects: u64,
    /// UDP: datagrams the kernel dropped before they were read (the socket's buffer full:
    /// a flood, or scans that took long), as last told ([`crate::udp`]).
    pub kernel_drops: u64,
}

impl LiveLines {
    /// Whether the source is connected now.
    pub fn connected(&self) -> bool {
        match &self.source {
            LiveSource::Udp(_) => true,
            LiveSource::Tcp { stream, .. } => stream.is_some(),
            LiveSource::Serial { port, .. } => port.is_some(),
        }
    }

    /// The local address of a UDP source.
    pub fn udp_addr(&self) -> Option<std::net::SocketAddr> {
        match &self.source {
            LiveSource::Udp(s) => s.local_addr().ok(),
            _ => None,
        }
    }

    /// Reads what has arrived, as complete lines (at most [`MAX_LINES_PER_READ`]; a flood
    /// leaves the rest in the socket). A UDP datagram ends its last line (IEC 61162-450 puts
    /// whole sentences in a datagram; many senders leave out the last CR LF), so one
    /// sender's half line never joins another's.
    pub fn available(&mut self) -> Vec<String> {
        let mut buf = [0u8; 65_536];
        let given_back = self.given_back.len().min(MAX_LINES_PER_READ);
        let mut out: Vec<String> = self.given_back.drain(..given_back).collect();
        if out.len() >= MAX_LINES_PER_READ {
            return out;
        }
        let datagrams = matches!(self.source, LiveSource::Udp(_));
        // Reads per call are bounded too (a 1-byte-a-read stream, a serial port).
        for _ in 0..MAX_LINES_PER_READ {
            let n = self.read(&mut buf);
            if n == 0 {
                break;
            }
            self.take(&buf[..n], &mut out);
            if datagrams && !self.partial.is_empty() {
                self.take(b"\n", &mut out);
            }
            if out.len() >= MAX_LINES_PER_READ {
                break;
            }
        }
        out
    }

    /// Gives `lines` (read from this source) back, to be read again first, oldest first;
    /// at most [`MAX_GIVEN_BACK_LINES`] are kept, the newest.
    pub fn give_back(&mut self, lines: impl IntoIterator<Item = String>) {
        self.given_back.extend(lines);
        let over = self.given_back.len().saturating_sub(MAX_GIVEN_BACK_LINES);
        self.given_back.drain(..over);
    }

    /// Splits bytes into lines, in linear time; an unfinished line waits in `partial`. A
    /// line longer than [`MAX_LINE_BYTES`] keeps only its first `MAX_LINE_BYTES + 1` bytes
    /// (the reader sees it is too long; memory stays bounded).
    fn take(&mut self, bytes: &[u8], out: &mut Vec<String>) {
        for &b in bytes {
            if b == b'\n' {
                let line = self.partial.strip_suffix(b"\r").unwrap_or(&self.partial);
                out.push(String::from_utf8_lossy(line).into_owned());
                self.partial.clear();
            } else if self.partial.len() <= MAX_LINE_BYTES {
                self.partial.push(b);
            }
        }
    }

    fn read(&mut self, buf: &mut [u8]) -> usize {
        use std::io::ErrorKind::{Interrupted, TimedOut, WouldBlock};
        let (drops, reconnects) = (&mut self.drops, &mut self.reconnects);
        match &mut self.source {
            LiveSource::Udp(s) => match crate::udp::recv_from(s, buf) {
                Ok(r) => {
                    if let Some(k) = r.kernel_drops {
                        self.kernel_drops = u64::from(k);
                    }
                    r.len
                }
                Err(_) => 0,
            },
            LiveSource::Tcp {
                addr,
                stream,
                retry,
            } => {
                if stream.is_none() && retry.due() {
                    match connect(addr) {
                        Ok(s) => {
                            *stream = Some(s);
                            retry.succeeded();
                            *reconnects += 1;
                        }
                        Err(_) => retry.failed(),
                    }
                }
                let Some(s) = stream.as_mut() else {
                    return 0;
                };
                match s.read(buf) {
                    Ok(0) => {
                        *stream = None;
                        *drops += 1;
                        retry.failed();
                        0
                    }
                    Ok(n) => n,
                    Err(e) if matches!(e.kind(), WouldBlock | TimedOut | Interrupted) => 0,
                    Err(_) => {
                        *stream = None;
                        *drops += 1;
                        retry.failed();
                        0
                    }
                }
            }
            LiveSource::Serial {
                device,
                baud,
                port,
                retry,
            } => {
                if port.is_none() && retry.due() {
                    match open_serial(device, *baud) {
                        Ok(p) => {
                            *port = Some(p);
                            retry.succeeded();
                            *reconnects += 1;
                        }
                        Err(_) => retry.failed(),
                    }
                }
                let Some(p) = port.as_mut() else {
                    return 0;
                };
                match p.read(buf) {
                    Ok(n) => n,
                    Err(e) if matches!(e.kind(), WouldBlock | TimedOut | Interrupted) => 0,
                    Err(_) => {
                        // A hung-up port (a USB adapter pulled): close it, reopen later.
                        *port = None;
                        *drops += 1;
                        retry.failed();
                        0
                    }
                }
            }
        }
    }
}

/// A UDP socket on `port` of every interface, shared with other listeners (a chart
/// plotter on the same machine listens on the same port: IEC 61162-450 senders multicast
/// or broadcast to all), non-blocking, with a receive buffer for a few seconds of a busy
/// AIS feed between two scans.
fn udp_listener(port: u16) -> std::io::Result<UdpSocket> {
    use socket2::{Domain, Protocol, Socket, Type};
    let socket = Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))?;
    socket.set_reuse_address(true)?;
    // The kernel may give less; what it gives is enough to go on with.
    let _ = socket.set_recv_buffer_size(UDP_RECV_BUFFER);
    let any = std::net::SocketAddr::from(([0, 0, 0, 0], port));
    socket.bind(&any.into())?;
    socket.set_nonblocking(true)?;
    let socket: UdpSocket = socket.into();
    // Best effort: where the kernel does not count its drops, none are told.
    let _ = crate::udp::count_kernel_drops(&socket);
    Ok(socket)
}

/// Receive buffer asked for a UDP NMEA source, bytes: 2,000 AIS sentences a second for
/// 2.5 s is about 0.4 MB.
const UDP_RECV_BUFFER: usize = 1 << 20;

fn connect(addr: &str) -> std::io::Result<TcpStream> {
    let mut last = std::io::Error::other("no address");
    for a in addr.to_socket_addrs()? {
        match TcpStream::connect_timeout(&a, CONNECT_TIMEOUT) {
            Ok(s) => {
                s.set_nonblocking(true)?;
                return Ok(s);
            }
            Err(e) => last = e,
        }
    }
    Err(last)
}

/// Opens a recorded NMEA file, refusing anything that is not a regular file: a serial device
/// or a FIFO given as `file:` would block the reader for ever, and a recording is read twice
/// (its first day, then its lines).
///
/// # Errors
/// The path does not open, or is a device, FIFO or directory (the message names the live
/// source to use instead).
pub fn open_recording(path: &std::path::Path) -> anyhow::Result<std::fs::File> {
    let meta =
        std::fs::metadata(path).map_err(|e| anyhow::anyhow!("opening {}: {e}", path.display()))?;
    if !meta.is_file() {
        anyhow::bail!(
            "{} is not a regular file: a recording is read with file:PATH; a live source is \
             serial:DEVICE@BAUD, udp:PORT or tcp:HOST:PORT (a pipe can go through \
             `socat - UDP:127.0.0.1:PORT`)",
            path.display()
        );
    }
    let mut file = std::fs::File::open(path)
        .map_err(|e| anyhow::anyhow!("opening {}: {e}", path.display()))?;
    if let Some(what) = not_text(&mut file) {
        anyhow::bail!(
            "{} is {what}, not an NMEA 0183 recording (text, one sentence a line): a radar \
             capture is given with --radar pcap:PATH, and the NMEA in it is read as own \
             ship's",
            path.display()
        );
    }
    Ok(file)
}

/// What a recording that is not text begins as (a pcap, pcapng or gzip file given to
/// `--nmea-in`: its lines counted as malformed made an error about AIS); `None` for
/// anything else. The file is left at its start.
fn not_text(file: &mut std::fs::File) -> Option<&'static str> {
    use std::io::{Read as _, Seek as _};
    let mut magic = [0u8; 4];
    let n = file.read(&mut magic).ok()?;
    file.seek(std::io::SeekFrom::Start(0)).ok()?;
    match (n, magic) {
        (4, [0xd4, 0xc3, 0xb2, 0xa1] | [0xa1, 0xb2, 0xc3, 0xd4])
        | (4, [0x4d, 0x3c, 0xb2, 0xa1] | [0xa1, 0xb2, 0x3c, 0x4d]) => Some("a pcap packet capture"),
        (4, [0x0a, 0x0d, 0x0d, 0x0a]) => Some("a pcapng packet capture"),
        (2.., [0x1f, 0x8b, ..]) => {
            Some("gzip-compressed (a packet capture, or a log to gunzip first)")
        }
        _ => None,
    }
}

fn open_serial(device: &str, baud: u32) -> serialport::Result<Box<dyn serialport::SerialPort>> {
    serialport::new(device, baud)
        .timeout(std::time::Duration::from_millis(1))
        .open()
}

impl NmeaIn {
    /// Opens `spec`.
    ///
    /// # Errors
    /// The file does not open, the port is in use, the server refuses the connection, the
    /// serial port does not open.
    pub fn open(spec: &InSpec) -> anyhow::Result<Self> {
        let live = |source| {
            NmeaIn::Live(LiveLines {
                source,
                partial: Vec::new(),
                given_back: std::collections::VecDeque::new(),
                drops: 0,
                reconnects: 0,
                kernel_drops: 0,
            })
        };
        Ok(match spec {
            InSpec::File(p) => {
                let f = open_recording(p)?;
                NmeaIn::File(FileLines {
                    reader: BufReader::new(f),
                    ahead: std::collections::VecDeque::new(),
                    ended: false,
                })
            }
            InSpec::Udp(port) => {
                let s = udp_listener(*port).with_context(|| format!("UDP port {port}"))?;
                live(LiveSource::Udp(s))
            }
            InSpec::Tcp(addr) => live(LiveSource::Tcp {
                stream: Some(connect(addr).with_context(|| format!("connecting to {addr}"))?),
                addr: addr.clone(),
                retry: Retry::now(),
            }),
            InSpec::Serial(dev, baud) => live(LiveSource::Serial {
                port: Some(open_serial(dev, *baud).with_context(|| format!("serial port {dev}"))?),
                device: dev.clone(),
                baud: *baud,
                retry: Retry::now(),
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::bridge::own_ship_sentences;
    use crate::nmea::targets_sentences;
    use crate::nmea::{NmeaOut, OutSpec};
    use crate::origin::Origin;
    use std::io::Write;
    use std::net::TcpListener;

    #[test]
    fn a_device_or_fifo_is_not_a_recording() {
        for p in ["/dev/null", "/tmp"] {
            let e = open_recording(std::path::Path::new(p)).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{p}: {e}");
        }
        let fifo = std::env::temp_dir().join(format!("nmea-fifo-{}", std::process::id()));
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = NmeaIn::open(&InSpec::File(fifo.clone())).err().unwrap();
            assert!(e.to_string().contains("serial:DEVICE@BAUD"), "{e}");
            let _ = std::fs::remove_file(&fifo);
        }
    }

    /// A packet capture or a gzip file given to `--nmea-in` is refused in words that name
    /// `--radar pcap:`; a text file whatever its lines opens, and is read from its start.
    #[test]
    fn a_packet_capture_is_not_an_nmea_recording() {
        let dir = tempfile::tempdir().unwrap();
        let pcap = Some("a pcap packet capture");
        let cases: [(&[u8], Option<&str>); 8] = [
            (&[0xd4, 0xc3, 0xb2, 0xa1, 2, 0], pcap),
            (&[0xa1, 0xb2, 0xc3, 0xd4, 0, 2], pcap),
            (&[0x4d, 0x3c, 0xb2, 0xa1], pcap),
            (&[0xa1, 0xb2, 0x3c, 0x4d], pcap),
            (
                &[0x0a, 0x0d, 0x0d, 0x0a, 0x1c],
                Some("a pcapng packet capture"),
            ),
            (&[0x1f, 0x8b, 8, 0], Some("gzip-compressed")),
            (b"$GPRMC,", None),
            (b"", None),
        ];
        for (k, (bytes, refused)) in cases.into_iter().enumerate() {
            let path = dir.path().join(format!("f{k}"));
            std::fs::write(&path, bytes).unwrap();
            match (open_recording(&path), refused) {
                (Err(e), Some(what)) => {
                    let e = e.to_string();
                    assert!(e.contains(what) && e.contains("--radar pcap:"), "{e}");
                }
                (Ok(mut f), None) => {
                    let mut back = Vec::new();
                    std::io::Read::read_to_end(&mut f, &mut back).unwrap();
                    assert_eq!(back, bytes);
                }
                (got, _) => panic!("case {k}: {:?}", got.map(|_| ())),
            }
        }
    }

    #[test]
    fn out_and_in_over_loopback() {
        // UDP: a datagram per sentence.
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let spec: OutSpec = format!("udp:{}", rx.local_addr().unwrap()).parse().unwrap();
        let mut out = NmeaOut::open(&spec).unwrap();
        let sentences = targets_sentences(
            &[crate::session::target::example()],
            &Origin::default(),
            [0.0, 0.0],
            1.0,
        );
        out.send(&sentences);
        let mut buf = [0u8; 256];
        let n = rx.recv(&mut buf).unwrap();
        assert_eq!(&buf[..n], sentences[0].as_bytes());
        // A broadcast address: sent, not refused by the system.
        let rx = UdpSocket::bind("0.0.0.0:0").unwrap();
        let port = rx.local_addr().unwrap().port();
        let spec: OutSpec = format!("udp:255.255.255.255:{port}").parse().unwrap();
        let mut out = NmeaOut::open(&spec).unwrap();
        out.send(&sentences);
        assert_eq!(out.udp_failures(), 0);
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
        let NmeaIn::Live(live) = &mut input else {
            unreachable!()
        };
        let to = live.udp_addr().unwrap().port();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let own = own_ship_sentences([0.0, 0.0], [0.0, 5.0], &Origin::default(), 0.0);
        tx.send_to(own[..2].concat().as_bytes(), ("127.0.0.1", to))
            .unwrap();
        let mut lines = Vec::new();
        for _ in 0..100 {
            lines.extend(live.available());
            if lines.len() >= 2 {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert_eq!(
            lines,
            own[..2]
                .iter()
                .map(|l| l.trim_end().to_string())
                .collect::<Vec<_>>()
        );
        // A datagram ends its line: a sentence without CR LF is read, and a half line never
        // joins the next datagram's sentence.
        tx.send_to(own[0].trim_end().as_bytes(), ("127.0.0.1", to))
            .unwrap();
        tx.send_to(b"$GPRMC,1234", ("127.0.0.1", to)).unwrap();
        tx.send_to(own[1].as_bytes(), ("127.0.0.1", to)).unwrap();
        let mut lines = Vec::new();
        for _ in 0..100 {
            lines.extend(live.available());
            if lines.len() >= 3 {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        assert_eq!(lines, [own[0].trim_end(), "$GPRMC,1234", own[1].trim_end()]);
        // TCP: we connect to a server (a multiplexer) and read what it sends, in pieces.
        let server = TcpListener::bind("127.0.0.1:0").unwrap();
        let spec = InSpec::Tcp(server.local_addr().unwrap().to_string());
        let mut input = NmeaIn::open(&spec).unwrap();
        let NmeaIn::Live(live) = &mut input else {
            unreachable!()
        };
        let (mut peer, _) = server.accept().unwrap();
        let text = own.concat();
        let (a, b) = text.split_at(text.len() / 2 + 3);
        peer.write_all(a.as_bytes()).unwrap();
        let mut lines = Vec::new();
        let mut rest = Some(b);
        for _ in 0..100 {
            lines.extend(live.available());
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
        assert_eq!(
            lines,
            own.iter()
                .map(|l| l.trim_end().to_string())
                .collect::<Vec<_>>()
        );
        assert!("udp:nowhere".parse::<OutSpec>().is_err());
        assert!("serial:/dev/ttyUSB0@4800".parse::<InSpec>().is_ok());
    }
}

#[cfg(test)]
mod reconnect_tests {
    use super::*;
    use std::io::Write;
    use std::net::TcpListener;
    use std::time::{Duration, Instant};

    /// Reads from `input` until `want` lines have come or 10 s pass.
    fn read_lines(live: &mut LiveLines, want: usize) -> Vec<String> {
        let deadline = Instant::now() + Duration::from_secs(10);
        let mut lines = Vec::new();
        while lines.len() < want && Instant::now() < deadline {
            lines.extend(live.available());
            std::thread::sleep(Duration::from_millis(20));
        }
        lines
    }

    #[test]
    fn a_dropped_tcp_source_is_reconnected_and_an_endless_line_is_bounded() {
        let server = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = server.local_addr().unwrap();
        let mut input = NmeaIn::open(&InSpec::Tcp(addr.to_string())).unwrap();
        let NmeaIn::Live(live) = &mut input else {
            unreachable!()
        };
        let (mut peer, _) = server.accept().unwrap();
        peer.write_all(b"$GPZDA,000001,01,01,2026,00,00*4F\r\n")
            .unwrap();
        assert_eq!(read_lines(live, 1).len(), 1);
        // The multiplexer drops the connection: noticed, and the source connects again (the
        // port is still listening) within the back-off.
        drop(peer);
        let deadline = Instant::now() + Duration::from_secs(10);
        while live.drops == 0 && Instant::now() < deadline {
            assert!(live.available().is_empty());
            std::thread::sleep(Duration::from_millis(20));
        }
        assert_eq!(live.drops, 1);
        // Accept while the source tries again (it connects from `available`).
        server.set_nonblocking(true).unwrap();
        let deadline = Instant::now() + Duration::from_secs(10);
        let mut peer = loop {
            assert!(live.available().is_empty());
            if let Ok((p, _)) = server.accept() {
                break p;
            }
            assert!(Instant::now() < deadline, "no reconnection");
            std::thread::sleep(Duration::from_millis(20));
        };
        peer.set_nonblocking(false).unwrap();
        peer.write_all(b"$GPZDA,000002,01,01,2026,00,00*4C\r\n")
            .unwrap();
        let lines = read_lines(live, 1);
        assert_eq!(lines, ["$GPZDA,000002,01,01,2026,00,00*4C"]);
        assert_eq!(live.reconnects, 1);
        // A megabyte without a line end: kept to its first MAX_LINE_BYTES + 1 bytes.
        let writer = std::thread::spawn(move || {
            peer.write_all(&vec![b'x'; 1 << 20]).unwrap();
            peer.write_all(b"\n$GPZDA,000003,01,01,2026,00,00*4D\r\n")
                .unwrap();
            peer
        });
        let lines = read_lines(live, 2);
        drop(writer.join());
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].len(), MAX_LINE_BYTES + 1);
        assert!(live.partial.capacity() < 64 * 1024);
    }
}
