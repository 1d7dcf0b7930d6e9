//! Where NMEA goes: datagrams to one listener (UDP), a TCP server any number of chart
//! plotters connect to, or a serial port (the bridge's RS-422 to a plotter, IEC 61162-1/-2).
//! Nothing here ever holds up a scan: clients are written without blocking, each with a
//! bounded queue, and a client that stops reading is dropped when its queue is full
//! (counted) while the others go on; a serial port's queue holds what its baud rate
//! carries in [`SERIAL_QUEUE_S`], the oldest sentences dropped (counted) past it.

use std::collections::VecDeque;
use std::io::Write;
use std::net::{TcpListener, TcpStream, ToSocketAddrs, UdpSocket};

use anyhow::Context;

/// Bytes queued for one TCP client at most (about 20 scans of 40 targets): a client that
/// falls further behind than this has stopped reading and is dropped.
pub const MAX_CLIENT_QUEUE_BYTES: usize = 256 * 1024;

/// Clients served at once at most; more are refused (closed on accept) and counted.
pub const MAX_CLIENTS: usize = 32;

/// A serial port's queue holds what its baud rate carries in this long, s: a scan's
/// sentences that do not go out by then are stale (the next scan's say it again).
pub const SERIAL_QUEUE_S: u32 = 2;

/// Where NMEA goes: `udp:HOST:PORT` (datagrams to one listener), `tcp:PORT` (a server any
/// number of chart plotters connect to) or `serial:DEVICE@BAUD` (a serial port).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutSpec {
    /// Datagrams to this address.
    Udp(String),
    /// A TCP server on this port (all interfaces).
    Tcp(u16),
    /// A serial port and its baud rate.
    Serial(String, u32),
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
            Some(("serial", d)) => {
                let bad = || format!("{s}: serial:DEVICE@BAUD, e.g. serial:/dev/ttyUSB0@38400");
                let (device, baud) = d.rsplit_once('@').ok_or_else(bad)?;
                match baud.parse::<u32>() {
                    Ok(b) if b > 0 && !device.is_empty() => {
                        Ok(OutSpec::Serial(device.to_string(), b))
                    }
                    _ => Err(bad()),
                }
            }
            _ => Err(format!(
                "{s}: expected udp:HOST:PORT, tcp:PORT or serial:DEVICE@BAUD"
            )),
        }
    }
}

/// One connected plotter and what it has yet to read.
pub struct Client {
    stream: TcpStream,
    queue: VecDeque<u8>,
}

/// What the TCP server did with its clients.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ServerCounts {
    /// Clients accepted.
    pub accepted: u64,
    /// Clients dropped because they stopped reading (queue full).
    pub dropped_slow: u64,
    /// Clients gone (closed the connection, an error).
    pub gone: u64,
    /// Clients refused: already [`MAX_CLIENTS`].
    pub refused: u64,
}

/// What a serial port did with the sentences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SerialCounts {
    /// The port's baud rate.
    pub baud: u32,
    /// Sentences dropped, oldest first, because the baud rate did not carry them in time.
    pub sentences_dropped: u64,
    /// Writes the port failed (a device unplugged: counted, tracking goes on).
    pub write_errors: u64,
}

/// A serial port and the sentences waiting for it.
pub struct SerialOut {
    port: Box<dyn serialport::SerialPort>,
    device: String,
    /// Sentences waiting, oldest first; how much of the first has gone out; their bytes.
    queue: VecDeque<String>,
    written: usize,
    queued_bytes: usize,
    /// Bytes the queue holds at most: [`SERIAL_QUEUE_S`] of the baud rate (10 bits a byte).
    max_bytes: usize,
    counts: SerialCounts,
}

/// True for a target's end (`TTM` or `TLL` with status `L`): sent once, so never dropped
/// (the plotter would keep the target as a ghost).
fn is_end(sentence: &str) -> bool {
    let fields: Vec<&str> = sentence.split(',').collect();
    let status = match fields.first().map(|f| f.get(3..).unwrap_or("")) {
        Some("TTM") => fields.get(12),
        Some("TLL") => fields.get(8),
        _ => None,
    };
    status.is_some_and(|s| *s == "L")
}

impl SerialOut {
    /// Queues `sentences` (a scan's: the targets' ends first, then the targets nearest
    /// first) and writes what the port takes now. Past the queue's bound, the sentences of
    /// earlier scans still waiting go first, then the scan's own from its tail (the
    /// farthest targets): never a target's end, which is sent once, nor the sentence going
    /// out (cut, it would reach the plotter as garbage).
    fn send(&mut self, sentences: &[String]) {
        let first_dropped = self.counts.sentences_dropped == 0;
        let incoming: usize = sentences.iter().map(String::len).sum();
        let mut at = usize::from(self.written > 0);
        while self.queued_bytes + incoming > self.max_bytes && at < self.queue.len() {
            // Ends too, past four times the bound (a port that never takes anything).
            let hard = self.queued_bytes + incoming > 4 * self.max_bytes;
            if is_end(&self.queue[at]) && !hard {
                at += 1;
                continue;
            }
            if let Some(old) = self.queue.remove(at) {
                self.queued_bytes -= old.len();
                self.counts.sentences_dropped += 1;
            }
        }
        for s in sentences {
            let room = if is_end(s) { 4 } else { 1 } * self.max_bytes;
            if self.queued_bytes + s.len() > room {
                self.counts.sentences_dropped += 1;
                continue;
            }
            self.queued_bytes += s.len();
            self.queue.push_back(s.clone());
        }
        if first_dropped && self.counts.sentences_dropped > 0 {
            eprintln!(
                "nmea out: {} at {} baud cannot carry every scan's sentences: the oldest are dropped (counted); 38400 baud (IEC 61162-2) carries about 3,800 bytes a second, 4800 about 480",
                self.device, self.counts.baud
            );
        }
        use std::io::ErrorKind::{Interrupted, TimedOut, WouldBlock};
        while let Some(front) = self.queue.front() {
            match self.port.write(&front.as_bytes()[self.written..]) {
                Ok(0) => break,
                Ok(n) => {
                    self.written += n;
                    if self.written >= front.len() {
                        self.queued_bytes -= front.len();
                        self.queue.pop_front();
                        self.written = 0;
                    }
                }
                Err(e) if matches!(e.kind(), WouldBlock | Interrupted | TimedOut) => break,
                Err(e) => {
                    if self.counts.write_errors == 0 {
                        eprintln!(
                            "nmea out: writing to {} failed: {e} (counted; tracking goes on)",
                            self.device
                        );
                    }
                    self.counts.write_errors += 1;
                    break;
                }
            }
        }
    }
}

/// An open NMEA output.
pub enum NmeaOut {
    /// UDP socket, destination, and datagrams the system refused to send.
    Udp(UdpSocket, std::net::SocketAddr, u64),
    /// Listening socket, the connected clients, and the counts.
    Tcp(TcpListener, Vec<Client>, ServerCounts),
    /// A serial port.
    Serial(SerialOut),
}

impl NmeaOut {
    /// Opens `spec`.
    ///
    /// # Errors
    /// An address that does not resolve, a port in use, a serial device that does not open.
    pub fn open(spec: &OutSpec) -> anyhow::Result<Self> {
        Ok(match spec {
            OutSpec::Udp(addr) => {
                let to = addr
                    .to_socket_addrs()
                    .with_context(|| format!("resolving {addr}"))?
                    .next()
                    .with_context(|| format!("{addr} resolves to nothing"))?;
                let bind = if to.is_ipv4() { "0.0.0.0:0" } else { "[::]:0" };
                let socket = UdpSocket::bind(bind).context("UDP socket")?;
                // A broadcast address (192.168.1.255) is how many plotters are fed; without
                // the option the system refuses every datagram.
                socket
                    .set_broadcast(true)
                    .context("allowing broadcast on the UDP socket")?;
                NmeaOut::Udp(socket, to, 0)
            }
            OutSpec::Tcp(port) => {
                let l = TcpListener::bind(("0.0.0.0", *port))
                    .with_context(|| format!("listening on TCP port {port}"))?;
                l.set_nonblocking(true)?;
                NmeaOut::Tcp(l, Vec::new(), ServerCounts::default())
            }
            OutSpec::Serial(device, baud) => {
                let port = open_serial_out(device, *baud)
                    .with_context(|| format!("opening {device} at {baud} baud"))?;
                let per_s = usize::try_from(*baud / 10).unwrap_or(usize::MAX);
                NmeaOut::Serial(SerialOut {
                    port,
                    device: device.clone(),
                    queue: VecDeque::new(),
                    written: 0,
                    queued_bytes: 0,
                    max_bytes: per_s
                        .saturating_mul(SERIAL_QUEUE_S as usize)
                        .max(crate::nmea::sentence::MAX_LINE_CHARS),
                    counts: SerialCounts {
                        baud: *baud,
                        ..SerialCounts::default()
                    },
                })
            }
        })
    }

    /// The local address (for a TCP server: the port clients connect to).
    ///
    /// # Errors
    /// The operating system's.
    pub fn local_addr(&self) -> std::io::Result<std::net::SocketAddr> {
        match self {
            NmeaOut::Udp(s, ..) => s.local_addr(),
            NmeaOut::Tcp(l, _, _) => l.local_addr(),
            NmeaOut::Serial(_) => Err(std::io::Error::new(
                std::io::ErrorKind::Unsupported,
                "a serial port has no network address",
            )),
        }
    }

    /// Datagrams the system refused to send (UDP; 0 for TCP).
    pub fn udp_failures(&self) -> u64 {
        match self {
            NmeaOut::Udp(.., failed) => *failed,
            NmeaOut::Tcp(..) | NmeaOut::Serial(_) => 0,
        }
    }

    /// What the TCP server did with its clients (`None` for UDP and serial).
    pub fn counts(&self) -> Option<ServerCounts> {
        match self {
            NmeaOut::Udp(..) | NmeaOut::Serial(_) => None,
            NmeaOut::Tcp(_, _, c) => Some(*c),
        }
    }

    /// What a serial port did (`None` for UDP and TCP).
    pub fn serial_counts(&self) -> Option<SerialCounts> {
        match self {
            NmeaOut::Serial(s) => Some(s.counts),
            _ => None,
        }
    }

    /// Sends one scan's sentences (one datagram each over UDP; over TCP queued for each
    /// client and written as far as it reads). Never blocks; a chart plotter that went away
    /// or stopped reading is dropped; nothing here stops the tracker.
    pub fn send(&mut self, sentences: &[String]) {
        match self {
            NmeaOut::Udp(socket, to, failed) => {
                for s in sentences {
                    if let Err(e) = socket.send_to(s.as_bytes(), *to) {
                        if *failed == 0 {
                            eprintln!(
                                "nmea out: sending to {to} failed: {e} (counted; tracking goes on)"
                            );
                        }
                        *failed += 1;
                    }
                }
            }
            NmeaOut::Tcp(listener, clients, counts) => {
                while let Ok((stream, peer)) = listener.accept() {
                    if clients.len() >= MAX_CLIENTS {
                        counts.refused += 1;
                        eprintln!("nmea out: {peer} refused: {MAX_CLIENTS} clients already");
                        continue;
                    }
                    if stream.set_nonblocking(true).is_err() {
                        continue;
                    }
                    let _ = stream.set_nodelay(true);
                    counts.accepted += 1;
                    clients.push(Client {
                        stream,
                        queue: VecDeque::new(),
                    });
                }
                let all: String = sentences.concat();
                clients.retain_mut(|c| {
                    if c.queue.len() + all.len() > MAX_CLIENT_QUEUE_BYTES {
                        counts.dropped_slow += 1;
                        let peer = c
                            .stream
                            .peer_addr()
                            .map(|a| a.to_string())
                            .unwrap_or_default();
                        eprintln!("nmea out: {peer} stopped reading; dropped");
                        return false;
                    }
                    c.queue.extend(all.as_bytes());
                    let alive = flush(c);
                    if !alive {
                        counts.gone += 1;
                    }
                    alive
                });
            }
            NmeaOut::Serial(port) => port.send(sentences),
        }
    }

    /// The run's end: over TCP and serial, waits up to `within` for every client (the
    /// port) to take what is queued for it (the targets' ends: nothing is sent after them
    /// that would carry the rest out). UDP has nothing queued.
    pub fn drain(&mut self, within: std::time::Duration) {
        let deadline = std::time::Instant::now() + within;
        loop {
            // Nothing new: the clients' queues written as far as they read.
            self.send(&[]);
            let empty = match self {
                NmeaOut::Tcp(_, clients, _) => clients.iter().all(|c| c.queue.is_empty()),
                NmeaOut::Serial(s) => s.queue.is_empty(),
                NmeaOut::Udp(..) => true,
            };
            if empty || std::time::Instant::now() >= deadline {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }
}

/// Opens a serial port whose writes never wait: non-blocking on Unix (the `serialport`
/// crate's own write polls with the timeout, then writes blocking, and a line discipline
/// with a little room waits for a whole sentence to fit), a zero timeout elsewhere.
fn open_serial_out(device: &str, baud: u32) -> anyhow::Result<Box<dyn serialport::SerialPort>> {
    let builder = serialport::new(device, baud).timeout(std::time::Duration::ZERO);
    #[cfg(unix)]
    {
        use nix::fcntl::{fcntl, FcntlArg, OFlag};
        use std::os::fd::{AsRawFd, BorrowedFd};
        let port = builder.open_native()?;
        // SAFETY: the descriptor is the port's own, open while `port` lives, and only
        // borrowed for these two calls.
        let fd = unsafe { BorrowedFd::borrow_raw(port.as_raw_fd()) };
        let flags = OFlag::from_bits_truncate(fcntl(fd, FcntlArg::F_GETFL)?);
        fcntl(fd, FcntlArg::F_SETFL(flags | OFlag::O_NONBLOCK))?;
        Ok(Box::new(port))
    }
    #[cfg(not(unix))]
    {
        Ok(builder.open()?)
    }
}

/// Writes what the client will take now; `false` when it is gone.
fn flush(c: &mut Client) -> bool {
    use std::io::ErrorKind::{Interrupted, WouldBlock};
    while !c.queue.is_empty() {
        let (front, _) = c.queue.as_slices();
        match c.stream.write(front) {
            Ok(0) => return false,
            Ok(n) => {
                c.queue.drain(..n);
            }
            Err(e) if matches!(e.kind(), WouldBlock | Interrupted) => return true,
            Err(_) => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    /// A pseudo-terminal pair: the master (the plotter's end) and the slave's path (the
    /// port the tracker opens).
    fn serial_line() -> (std::fs::File, String) {
        let pty = nix::pty::openpty(None, None).unwrap();
        let path = nix::unistd::ttyname(&pty.slave).unwrap();
        // Raw: the line discipline would otherwise turn "\r\n" into "\n\n" and echo.
        let mut t = nix::sys::termios::tcgetattr(&pty.slave).unwrap();
        nix::sys::termios::cfmakeraw(&mut t);
        nix::sys::termios::tcsetattr(&pty.slave, nix::sys::termios::SetArg::TCSANOW, &t).unwrap();
        (
            std::fs::File::from(pty.master),
            path.to_string_lossy().into_owned(),
        )
    }

    /// A scan of `n` targets' `TTM`s.
    fn ttm_scan(n: usize) -> Vec<String> {
        (0..n)
            .map(|i| {
                let body = format!(
                    "RATTM,{:02},1.000,90.0,T,10.0,180.0,T,0.500,3.00,N,TGT,T,,000000.00,A",
                    i % 99 + 1
                );
                let sum = crate::nmea::sentence::checksum(&body);
                format!("${body}*{sum:02X}\r\n")
            })
            .collect()
    }

    #[test]
    fn a_serial_plotter_gets_every_sentence_whole() {
        assert_eq!(
            "serial:/dev/ttyUSB0@38400".parse::<OutSpec>(),
            Ok(OutSpec::Serial("/dev/ttyUSB0".into(), 38_400))
        );
        for bad in [
            "serial:/dev/ttyUSB0",
            "serial:/dev/ttyUSB0@0",
            "serial:@4800",
        ] {
            assert!(bad.parse::<OutSpec>().is_err(), "{bad}");
        }
        let (mut plotter, path) = serial_line();
        let mut out = NmeaOut::open(&OutSpec::Serial(path, 38_400)).unwrap();
        let scan = ttm_scan(40);
        let total = scan.concat().len() * 10;
        let reading = std::thread::spawn(move || {
            let mut got = Vec::new();
            let mut buf = [0u8; 4096];
            while got.len() < total {
                match plotter.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => got.extend_from_slice(&buf[..n]),
                }
            }
            got
        });
        for _ in 0..10 {
            out.send(&scan);
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        out.drain(std::time::Duration::from_secs(5));
        let got = String::from_utf8(reading.join().unwrap()).unwrap();
        assert_eq!(got, scan.concat().repeat(10));
        let c = out.serial_counts().unwrap();
        assert_eq!((c.sentences_dropped, c.write_errors), (0, 0), "{c:?}");
    }

    #[test]
    fn a_serial_port_that_cannot_keep_up_drops_the_oldest_sentences_whole() {
        // Nobody reads the line: the port's buffer fills, and the scans still go at once,
        // the oldest sentences dropped (counted), never one cut in the middle, never a
        // target's end (sent once), and the scan's nearest targets kept before its farthest.
        let (mut plotter, path) = serial_line();
        let mut out = NmeaOut::open(&OutSpec::Serial(path, 38_400)).unwrap();
        let end = "$RATTM,99,1.000,90.0,T,10.0,180.0,T,0.500,3.00,N,TGT,L,,000000.00,A*00\r\n";
        assert!(is_end(end) && !is_end(&ttm_scan(1)[0]));
        let scan: Vec<String> = std::iter::once(end.to_string())
            .chain(ttm_scan(200))
            .collect();
        let started = std::time::Instant::now();
        for _ in 0..50 {
            out.send(&scan);
        }
        assert!(
            started.elapsed() < std::time::Duration::from_secs(20),
            "it blocked"
        );
        let c = out.serial_counts().unwrap();
        assert!(c.sentences_dropped > 0, "{c:?}");
        // What the plotter then reads is whole sentences.
        let reading = std::thread::spawn(move || {
            let mut got = Vec::new();
            let mut buf = [0u8; 4096];
            let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
            while std::time::Instant::now() < deadline {
                match plotter.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => got.extend_from_slice(&buf[..n]),
                }
                if got.ends_with(b"\r\n") && got.len() > 100_000 {
                    break;
                }
            }
            got
        });
        out.drain(std::time::Duration::from_secs(3));
        drop(out);
        let got = String::from_utf8(reading.join().unwrap()).unwrap();
        let lines: Vec<&str> = got.split_terminator("\r\n").collect();
        assert!(!lines.is_empty());
        for l in &lines {
            assert!(
                scan.iter().any(|s| s.trim_end() == *l),
                "a cut sentence: {l:?}"
            );
        }
        assert_eq!(
            lines.iter().filter(|l| is_end(l)).count(),
            50,
            "every scan's end reached the plotter"
        );
        // The last scan's nearest target went out; its farthest did not.
        let last = lines.iter().rposition(|l| is_end(l)).unwrap();
        assert_eq!(lines.get(last + 1), Some(&scan[1].trim_end()));
        assert_ne!(lines.last(), Some(&scan[200].trim_end()));
    }

    #[test]
    fn a_plotter_that_stops_reading_is_dropped_and_holds_up_nothing() {
        let mut out = NmeaOut::open(&OutSpec::Tcp(0)).unwrap();
        let port = out.local_addr().unwrap().port();
        let _stuck = TcpStream::connect(("127.0.0.1", port)).unwrap(); // never reads
        let mut reader = TcpStream::connect(("127.0.0.1", port)).unwrap();
        let scans = 400;
        let scan: Vec<String> = (0..200)
            .map(|i| {
                format!(
                    "$RATTM,{:02},1.000,90.0,T,10.0,180.0,T,0.500,3.00,N,TGT,T,,000000.00,A*00\r\n",
                    i % 99 + 1
                )
            })
            .collect();
        let per_scan = scan.concat().len();
        let total = per_scan * scans;
        let reading = std::thread::spawn(move || {
            let mut got = 0;
            let mut buf = vec![0u8; 1 << 16];
            while got < total {
                match reader.read(&mut buf) {
                    Ok(0) | Err(_) => break,
                    Ok(n) => got += n,
                }
            }
            got
        });
        // The scans go out in a thread of their own: were a write to block, the test would
        // report it instead of hanging.
        let (done_tx, done_rx) = std::sync::mpsc::channel();
        let sending = std::thread::spawn(move || {
            for _ in 0..scans {
                out.send(&scan);
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            // The reader takes the rest as it reads.
            for _ in 0..2000 {
                out.send(&[]);
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            let _ = done_tx.send(());
            out
        });
        done_rx
            .recv_timeout(std::time::Duration::from_secs(120))
            .expect("sending never blocks");
        let out = sending.join().unwrap();
        let counts = out.counts().unwrap();
        assert_eq!(counts.accepted, 2);
        assert_eq!(counts.dropped_slow, 1, "{counts:?}");
        assert_eq!(
            reading.join().unwrap(),
            total,
            "the reading plotter got everything"
        );
    }
}
