//! Where NMEA travels: out to chart plotters over UDP or a TCP server, in from a recording,
//! UDP, a TCP server (a multiplexer) or a serial port.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream, ToSocketAddrs, UdpSocket};
use std::path::PathBuf;

use anyhow::Context;

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
    ///
    /// # Errors
    /// An address that does not resolve, a port in use.
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
    ///
    /// # Errors
    /// The operating system's.
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
    ///
    /// # Errors
    /// The file does not open, the port is in use, the server refuses the connection, the serial port does not open.
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::bridge::own_ship_sentences;
    use crate::nmea::targets_sentences;
    use crate::origin::Origin;

    #[test]
    fn out_and_in_over_loopback() {
        // UDP: a datagram per sentence.
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let spec: OutSpec = format!("udp:{}", rx.local_addr().unwrap()).parse().unwrap();
        let mut out = NmeaOut::open(&spec).unwrap();
        let sentences = targets_sentences(
            &[crate::session::target::example()],
            &Origin::default(),
            1.0,
        );
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
