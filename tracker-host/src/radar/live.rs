//! Live radar data: the spoke multicast groups joined on an interface, datagrams received
//! with the time they arrived.
//!
//! One socket (and one thread) per group and port, each bound to the port on all addresses
//! with `SO_REUSEADDR` (so a chart plotter on the same machine can listen too) and a 4 MiB
//! receive buffer (a radar sends 0.4–0.6 MB/s; the kernel reassembles the fragments). The
//! threads hand datagrams to the reader through a bounded queue; a datagram that finds it
//! full is dropped and counted, so a reader that stalls costs data, never memory; what the
//! kernel drops when a socket's buffer fills is counted too ([`crate::udp`], Linux).

use std::net::{Ipv4Addr, SocketAddr, SocketAddrV4, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, SyncSender, TrySendError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::Context;
use socket2::{Domain, Protocol, Socket, Type};

use super::capture::Datagram;

/// A multicast group and the UDP port its data goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Endpoint {
    /// The group (or, for a test, any address: the socket receives all datagrams to the port).
    pub group: Ipv4Addr,
    /// The port.
    pub port: u16,
}

/// Navico spoke groups seen in the captures: 3G/4G (236.6.7.8:6678) and HALO
/// (236.6.9.51:7059). A radar announces its own in a beacon; these are the usual ones.
pub const NAVICO_SPOKE_GROUPS: [Endpoint; 2] = [
    Endpoint {
        group: Ipv4Addr::new(236, 6, 7, 8),
        port: 6678,
    },
    Endpoint {
        group: Ipv4Addr::new(236, 6, 9, 51),
        port: 7059,
    },
];

/// Navico state-report groups paired with [`NAVICO_SPOKE_GROUPS`], seen in the captures:
/// BR24/3G/4G (236.6.7.9:6679) and HALO (236.6.9.51:7061). Their reports give the model
/// (which the range of a 4G/HALO spoke depends on) and the range the user chose (which
/// checks the spokes' range).
pub const NAVICO_REPORT_GROUPS: [Endpoint; 2] = [
    Endpoint {
        group: Ipv4Addr::new(236, 6, 7, 9),
        port: 6679,
    },
    Endpoint {
        group: Ipv4Addr::new(236, 6, 9, 51),
        port: 7061,
    },
];

/// What a live Navico radar is heard on: its spoke groups, then its report groups.
pub const NAVICO_GROUPS: [Endpoint; 4] = [
    NAVICO_SPOKE_GROUPS[0],
    NAVICO_SPOKE_GROUPS[1],
    NAVICO_REPORT_GROUPS[0],
    NAVICO_REPORT_GROUPS[1],
];

/// The Garmin xHD spoke group (fixed).
pub const GARMIN_SPOKE_GROUPS: [Endpoint; 1] = [Endpoint {
    group: Ipv4Addr::new(239, 254, 2, 0),
    port: 50102,
}];

/// Datagrams waiting for the reader.
const QUEUE: usize = 4096;
/// How often a receiving thread looks whether it should stop.
const POLL: Duration = Duration::from_millis(200);

/// How often a wait for live data looks for Ctrl-C.
const INTERRUPT_POLL: Duration = Duration::from_millis(250);

/// Silence on a live radar is told this often.
pub(crate) const SILENCE_NOTE: Duration = Duration::from_secs(10);
/// Receive buffer asked of the kernel, bytes.
const RECV_BUFFER: usize = 4 << 20;

/// What the receiver has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct LiveStats {
    /// Datagrams received.
    pub received: u64,
    /// Datagrams dropped because the reader was behind.
    pub dropped: u64,
    /// Datagrams the kernel dropped before they were read (a socket's buffer full), all
    /// sockets, as told with the datagrams that came after them (drops after the last
    /// datagram received are not seen); `None` where the system does not count them.
    pub kernel_dropped: Option<u64>,
}

impl std::fmt::Display for LiveStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} datagrams received, {} dropped with the reader behind",
            self.received, self.dropped
        )?;
        match self.kernel_dropped {
            Some(n) => write!(f, ", {n} dropped by the kernel (socket buffer full)"),
            None => write!(f, ", the kernel's drops not counted on this system"),
        }
    }
}

#[derive(Debug, Default)]
struct Counters {
    received: AtomicU64,
    dropped: AtomicU64,
    kernel_dropped: AtomicU64,
    /// Sockets whose kernel drops are not counted.
    uncounted: AtomicU64,
}

/// One received datagram.
struct Received {
    time_s: f64,
    src: SocketAddrV4,
    dst: SocketAddrV4,
    payload: Vec<u8>,
}

/// Receives the datagrams of a set of multicast groups.
pub struct LiveReceiver {
    rx: Receiver<anyhow::Result<Received>>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
    counters: Arc<Counters>,
    current: Option<Received>,
}

impl std::fmt::Debug for LiveReceiver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveReceiver")
            .field("stats", &self.stats())
            .finish_non_exhaustive()
    }
}

impl LiveReceiver {
    /// Joins `endpoints` on the interface with address `interface` (`0.0.0.0`: the one the
    /// system routes multicast to).
    ///
    /// # Errors
    /// A socket cannot be made, bound (the port in use without address reuse) or joined to
    /// its group (no such interface, no multicast route).
    pub fn open(endpoints: &[Endpoint], interface: Ipv4Addr) -> anyhow::Result<Self> {
        let (tx, rx) = mpsc::sync_channel(QUEUE);
        // One clock for every group's datagrams: arrival times in one order, and no step of
        // this computer's clock taken for a radar's silence.
        let clock = crate::utc::SteadyUtc::start();
        let stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(Counters::default());
        let mut receiver = LiveReceiver {
            rx,
            stop: Arc::clone(&stop),
            threads: Vec::new(),
            counters: Arc::clone(&counters),
            current: None,
        };
        for e in endpoints {
            let socket = join(e, interface).map_err(|err| {
                let mut why = format!("joining {}:{} on {interface}", e.group, e.port);
                // ENODEV: the address is no interface's here (a typo, the radar's own
                // address, the network cable's interface not up), or, for any interface,
                // there is no route for multicast (a PC with no default gateway).
                let no_such = err
                    .downcast_ref::<std::io::Error>()
                    .is_some_and(crate::udp::is_no_such_device);
                let here = if no_such {
                    crate::udp::ipv4_interfaces()
                } else {
                    Vec::new()
                };
                if !here.is_empty() {
                    let what = if interface.is_unspecified() {
                        "no interface has a route for multicast".to_string()
                    } else {
                        format!("{interface} is not an address of this computer's")
                    };
                    why += &format!(
                        " ({what}: give the address of the interface on the radar's network, one of {})",
                        here.join(", ")
                    );
                }
                err.context(why)
            })?;
            if !crate::udp::count_kernel_drops(&socket) {
                counters.uncounted.fetch_add(1, Ordering::Relaxed);
            }
            let (tx, stop, counters) = (tx.clone(), Arc::clone(&stop), Arc::clone(&counters));
            let dst = SocketAddrV4::new(e.group, e.port);
            let thread = std::thread::Builder::new()
                .name(format!("radar {dst}"))
                .spawn(move || receive(&socket, dst, &tx, &stop, &counters, clock))
                .context("starting a receiving thread")?;
            receiver.threads.push(thread);
        }
        // Which groups, on which interface: left to the system, it is its default route's,
        // which need not be the radar's network (a new user's trial heard nothing on the
        // loopback, and nothing said where it listened).
        eprintln!("{}", listening_text(endpoints, interface));
        Ok(receiver)
    }

    /// The next datagram, waiting for it up to `wait` (`None`: as long as it takes);
    /// `Ok(None)` when none came in time.
    ///
    /// # Errors
    /// A socket failed (its error), or every receiving thread has ended.
    pub fn next_datagram(
        &mut self,
        wait: Option<Duration>,
    ) -> anyhow::Result<Option<Datagram<'_>>> {
        let got = match wait {
            Some(w) => match self.rx.recv_timeout(w) {
                Ok(r) => Some(r),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => anyhow::bail!("no radar socket is open"),
            },
            // As long as it takes, but told every SILENCE_NOTE, and not past Ctrl-C (the run
            // then ends as a capture's does).
            None => {
                let mut silent = Duration::ZERO;
                loop {
                    if crate::app::interrupt::interrupted() {
                        break None;
                    }
                    match self.rx.recv_timeout(INTERRUPT_POLL) {
                        Ok(r) => break Some(r),
                        Err(RecvTimeoutError::Timeout) => {}
                        Err(RecvTimeoutError::Disconnected) => {
                            anyhow::bail!("no radar socket is open")
                        }
                    }
                    silent += INTERRUPT_POLL;
                    if silent.as_millis().is_multiple_of(SILENCE_NOTE.as_millis()) {
                        eprintln!(
                            "no radar data for {} s: is the radar transmitting, and is the interface the one on its network (--radar navico@ADDR, garmin@ADDR)?",
                            silent.as_secs()
                        );
                    }
                }
            }
        };
        let Some(r) = got else {
            self.current = None;
            return Ok(None);
        };
        let r = self.current.insert(r?);
        Ok(Some(Datagram {
            time_s: r.time_s,
            src: r.src,
            dst: r.dst,
            payload: &r.payload,
        }))
    }

    /// What has been received.
    pub fn stats(&self) -> LiveStats {
        let c = &self.counters;
        LiveStats {
            received: c.received.load(Ordering::Relaxed),
            dropped: c.dropped.load(Ordering::Relaxed),
            kernel_dropped: (c.uncounted.load(Ordering::Relaxed) == 0)
                .then(|| c.kernel_dropped.load(Ordering::Relaxed)),
        }
    }
}

impl Drop for LiveReceiver {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            // A thread that panicked has nothing left to clean up.
            let _ = t.join();
        }
    }
}

/// The start-up line saying what a live radar source listens to: `endpoints`' groups on the
/// interface with address `interface`, or (unspecified) on the system's choice, with this
/// computer's interfaces to choose from.
pub fn listening_text(endpoints: &[Endpoint], interface: Ipv4Addr) -> String {
    let groups: Vec<String> = endpoints
        .iter()
        .map(|e| format!("{}:{}", e.group, e.port))
        .collect();
    let on = if interface.is_unspecified() {
        let here = crate::udp::ipv4_interfaces();
        format!(
            "the interface the system chooses for multicast (its default route's); if that is not the radar's network, give this computer's address on it as navico@ADDR or garmin@ADDR{}",
            if here.is_empty() {
                String::new()
            } else {
                format!(" (this computer's: {})", here.join(", "))
            }
        )
    } else {
        format!("the interface {interface}")
    };
    format!("radar: listening to {} on {on}", groups.join(", "))
}

fn join(e: &Endpoint, interface: Ipv4Addr) -> anyhow::Result<UdpSocket> {
    let socket = Socket::new(Domain::IPV4, Type::DGRAM, Some(Protocol::UDP))?;
    socket.set_reuse_address(true)?;
    // Best effort: the kernel may cap it (net.core.rmem_max).
    let _ = socket.set_recv_buffer_size(RECV_BUFFER);
    let any = SocketAddr::from((Ipv4Addr::UNSPECIFIED, e.port));
    socket.bind(&any.into())?;
    if e.group.is_multicast() {
        socket.join_multicast_v4(&e.group, &interface)?;
    }
    socket.set_read_timeout(Some(POLL))?;
    Ok(socket.into())
}

fn receive(
    socket: &UdpSocket,
    dst: SocketAddrV4,
    tx: &SyncSender<anyhow::Result<Received>>,
    stop: &AtomicBool,
    counters: &Counters,
    clock: crate::utc::SteadyUtc,
) {
    // The largest UDP payload.
    let mut buf = vec![0u8; 65536];
    // The kernel's count for this socket, as last told.
    let mut kernel_drops = 0u32;
    while !stop.load(Ordering::Relaxed) {
        let r = match crate::udp::recv_from(socket, &mut buf) {
            Ok(r) => r,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) =>
            {
                continue
            }
            Err(e) => {
                // Never blocks: a full queue would hold this thread, and the receiver's
                // drop waits for it.
                let _ = tx.try_send(Err(
                    anyhow::Error::new(e).context(format!("receiving on {dst}"))
                ));
                return;
            }
        };
        let time_s = clock.now_s();
        if let Some(k) = r.kernel_drops {
            let new = k.wrapping_sub(kernel_drops);
            kernel_drops = k;
            counters
                .kernel_dropped
                .fetch_add(u64::from(new), Ordering::Relaxed);
        }
        let Some(SocketAddr::V4(src)) = r.from else {
            continue;
        };
        counters.received.fetch_add(1, Ordering::Relaxed);
        let payload = buf.get(..r.len).unwrap_or(&buf).to_vec();
        match tx.try_send(Ok(Received {
            time_s,
            src,
            dst,
            payload,
        })) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) => {
                counters.dropped.fetch_add(1, Ordering::Relaxed);
            }
            Err(TrySendError::Disconnected(_)) => return,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An interface address that is none of this computer's (a typo, the radar's own
    /// address) is told as such, with the addresses that would do.
    #[cfg(target_os = "linux")]
    #[test]
    fn an_address_of_no_interface_here_is_told_with_those_that_are() {
        // TEST-NET-3 (RFC 5737): on no interface of a test machine.
        let nowhere = Ipv4Addr::new(203, 0, 113, 77);
        let e =
            LiveReceiver::open(&NAVICO_SPOKE_GROUPS, nowhere).expect_err("joined on no interface");
        let text = format!("{e:#}");
        assert!(
            text.contains("203.0.113.77 is not an address of this computer's")
                && text.contains(" 127.0.0.1"),
            "{text}"
        );
    }

    #[test]
    fn the_start_up_line_says_where_the_radar_is_listened_to() {
        let on = listening_text(&NAVICO_SPOKE_GROUPS, Ipv4Addr::LOCALHOST);
        assert!(
            on.starts_with("radar: listening to 236.6.7.8:6678")
                && on.ends_with("on the interface 127.0.0.1"),
            "{on}"
        );
        let chosen = listening_text(&NAVICO_SPOKE_GROUPS, Ipv4Addr::UNSPECIFIED);
        assert!(
            chosen.contains("the system chooses") && chosen.contains(" 127.0.0.1"),
            "{chosen}"
        );
    }
}
