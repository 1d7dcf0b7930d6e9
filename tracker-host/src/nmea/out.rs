//! Where NMEA goes: datagrams to one listener (UDP), or a TCP server any number of chart
//! plotters connect to. Nothing here ever holds up a scan: clients are written without
//! blocking, each with a bounded queue, and a client that stops reading is dropped when its
//! queue is full (counted) while the others go on.

use std::collections::VecDeque;
use std::io::Write;
use std::net::{TcpListener, TcpStream, ToSocketAddrs, UdpSocket};

use anyhow::Context;

/// Bytes queued for one TCP client at most (about 20 scans of 40 targets): a client that
/// falls further behind than this has stopped reading and is dropped.
pub const MAX_CLIENT_QUEUE_BYTES: usize = 256 * 1024;

/// Clients served at once at most; more are refused (closed on accept) and counted.
pub const MAX_CLIENTS: usize = 32;

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

/// An open NMEA output.
pub enum NmeaOut {
    /// UDP socket, destination, and datagrams the system refused to send.
    Udp(UdpSocket, std::net::SocketAddr, u64),
    /// Listening socket, the connected clients, and the counts.
    Tcp(TcpListener, Vec<Client>, ServerCounts),
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
        }
    }

    /// Datagrams the system refused to send (UDP; 0 for TCP).
    pub fn udp_failures(&self) -> u64 {
        match self {
            NmeaOut::Udp(.., failed) => *failed,
            NmeaOut::Tcp(..) => 0,
        }
    }

    /// What the TCP server did with its clients (`None` for UDP).
    pub fn counts(&self) -> Option<ServerCounts> {
        match self {
            NmeaOut::Udp(..) => None,
            NmeaOut::Tcp(_, _, c) => Some(*c),
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
        }
    }

    /// The run's end: over TCP, waits up to `within` for every client to take what is
    /// queued for it (the targets' ends: nothing is sent after them that would carry the
    /// rest out). UDP has nothing queued.
    pub fn drain(&mut self, within: std::time::Duration) {
        let deadline = std::time::Instant::now() + within;
        loop {
            // Nothing new: the clients' queues written as far as they read.
            self.send(&[]);
            let NmeaOut::Tcp(_, clients, _) = self else {
                return;
            };
            if clients.iter().all(|c| c.queue.is_empty()) || std::time::Instant::now() >= deadline {
                return;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
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
