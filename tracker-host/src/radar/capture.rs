//! Capture files: the UDP datagrams (and the NMEA text) of a network recording.
//!
//! A [`CaptureReader`] reads a pcap or pcapng file (told apart by their magic numbers, both
//! byte orders, µs and ns time stamps), or either compressed with gzip (by its magic, not
//! the file name), and yields every IPv4 UDP datagram with its addresses, ports and capture
//! time, IPv4 fragments reassembled in any arrival order. Link layers: Ethernet (with VLAN
//! tags), Linux cooked (SLL), raw IP, BSD loopback. Memory stays bounded: reassemblies
//! still incomplete after [`CaptureOptions::reassembly_timeout_s`] of capture time, or
//! beyond [`CaptureOptions::max_reassemblies`] at once, are dropped and counted; the file is
//! read through a fixed buffer, not loaded whole.
//!
//! NMEA 0183 text met on the way (UDP datagrams and TCP streams on
//! [`CaptureOptions::nmea_ports`]) is gathered as lines with their capture time
//! ([`super::nmea_text`]) and taken with [`CaptureReader::take_nmea_lines`].
//!
//! Anything else (IPv6, ARP, ICMP, a frame that does not parse) is counted in
//! [`CaptureStats`] and passed over; only a file that cannot be read, or that is not a
//! capture, is an error. A file cut off in the middle of a record, or a gzip stream cut
//! short, ends there ([`CaptureStats::truncated_file`]).

use std::cell::Cell;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::net::{Ipv4Addr, SocketAddrV4};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context};
use etherparse::defrag::IpDefragPool;
use etherparse::{IpNumber, NetSlice, SlicedPacket, TcpSlice, TransportSlice, UdpSlice};
use flate2::read::MultiGzDecoder;
use pcap_parser::traits::PcapReaderIterator;
use pcap_parser::{Block, Linktype, PcapBlockOwned, PcapError};

use super::nmea_text::{NmeaLine, NmeaText, NmeaTextStats, Segment};

/// The ports whose text is taken as NMEA by default: UDP 10110 (the usual NMEA-over-UDP
/// port; the HALO and 3G captures), TCP 2000 (a B&G/Navico multiplexer; the 4G capture's
/// positions and AIS) and TCP 2599 (the same capture's heading, HDG).
pub const DEFAULT_NMEA_PORTS: [u16; 3] = [10110, 2000, 2599];

/// The read buffer, bytes; it grows to [`MAX_BUFFER`] for a larger record.
const BUFFER: usize = 1 << 20;
/// The largest record accepted, bytes.
const MAX_BUFFER: usize = 64 << 20;

/// How a capture is read.
#[derive(Clone, Debug, PartialEq)]
pub struct CaptureOptions {
    /// Ports (source or destination, UDP or TCP) whose text is NMEA.
    pub nmea_ports: Vec<u16>,
    /// A reassembly with no new fragment for this long (capture time, s) is dropped. The
    /// fragments of one Navico frame come within a millisecond.
    pub reassembly_timeout_s: f64,
    /// Reassemblies under way at once; a new one beyond it drops the one that has waited
    /// longest. At most 64 KiB each.
    pub max_reassemblies: usize,
}

impl Default for CaptureOptions {
    fn default() -> Self {
        CaptureOptions {
            nmea_ports: DEFAULT_NMEA_PORTS.to_vec(),
            reassembly_timeout_s: 5.0,
            max_reassemblies: 64,
        }
    }
}

/// One UDP datagram, borrowed from the reader until the next is read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Datagram<'a> {
    /// Capture time, s since 1970 (of the last fragment, when reassembled).
    pub time_s: f64,
    /// Sender.
    pub src: SocketAddrV4,
    /// Destination (a multicast group for radar data).
    pub dst: SocketAddrV4,
    /// The UDP payload.
    pub payload: &'a [u8],
}

/// What a capture held, counted as it is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureStats {
    /// Link-layer records (packets) read.
    pub packets: u64,
    /// Records cut short by the capture's snap length.
    pub snapped: u64,
    /// Records of a link type not read (see the module's list).
    pub unsupported_link: u64,
    /// Records whose headers did not parse.
    pub undecodable: u64,
    /// Records that were not IPv4 (IPv6, ARP, …).
    pub non_ipv4: u64,
    /// pcapng packets naming an interface not described.
    pub unknown_interface: u64,
    /// IPv4 fragments.
    pub fragments: u64,
    /// Datagrams reassembled from fragments.
    pub reassembled: u64,
    /// Fragments refused by reassembly (overlapping ends, misaligned, too large).
    pub reassembly_errors: u64,
    /// Reassemblies dropped for waiting longer than the timeout.
    pub reassembly_timed_out: u64,
    /// Reassemblies dropped to stay within the cap.
    pub reassembly_evicted: u64,
    /// Reassemblies still incomplete at the end of the file.
    pub reassembly_unfinished: u64,
    /// UDP datagrams (whole or reassembled).
    pub udp_datagrams: u64,
    /// TCP segments.
    pub tcp_segments: u64,
    /// Other IPv4 packets (ICMP, IGMP, …).
    pub other_ip: u64,
    /// The file ended in the middle of a record, or its gzip stream was cut short.
    pub truncated_file: bool,
    /// The NMEA text found.
    pub nmea: NmeaTextStats,
}

/// A pcapng interface: its link type and clock.
#[derive(Clone, Copy, Debug)]
struct Interface {
    linktype: Linktype,
    ticks_per_s: u64,
    offset_s: i64,
}

/// A reassembly's last fragment: arrival number (for the oldest) and capture time (for the
/// timeout).
#[derive(Clone, Debug)]
struct FragStamp {
    seq: u64,
    time_s: f64,
}

/// Reads a capture file. See the module documentation.
pub struct CaptureReader {
    path: PathBuf,
    reader: Box<dyn PcapReaderIterator + Send>,
    /// The I/O error behind the reader's plain "read error", kept by [`Filled`].
    read_error: Arc<Mutex<Option<io::Error>>>,
    capacity: usize,
    done: bool,
    frames: Frames,
}

impl std::fmt::Debug for CaptureReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CaptureReader")
            .field("path", &self.path)
            .field("done", &self.done)
            .field("stats", &self.frames.stats)
            .finish_non_exhaustive()
    }
}

impl CaptureReader {
    /// Opens a capture: pcap or pcapng, plain or gzip.
    ///
    /// # Errors
    /// The file cannot be opened or read, or is not a capture.
    pub fn open(path: &Path, options: CaptureOptions) -> anyhow::Result<Self> {
        let file = File::open(path).with_context(|| format!("{}: cannot open", path.display()))?;
        let mut file = BufReader::new(file);
        let gzip = file
            .fill_buf()
            .with_context(|| format!("{}: cannot read", path.display()))?
            .starts_with(&[0x1f, 0x8b]);
        let read_error = Arc::new(Mutex::new(None));
        let source: Box<dyn Read + Send> = if gzip {
            Box::new(Filled::new(MultiGzDecoder::new(file), &read_error))
        } else {
            Box::new(Filled::new(file, &read_error))
        };
        let reader = pcap_parser::create_reader(BUFFER, source).map_err(|e| {
            anyhow!(
                "{}: not a pcap or pcapng capture{} ({e})",
                path.display(),
                if gzip { " inside gzip" } else { "" }
            )
        })?;
        Ok(CaptureReader {
            path: path.to_path_buf(),
            reader,
            read_error,
            capacity: BUFFER,
            done: false,
            frames: Frames::new(options),
        })
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The next UDP datagram; `Ok(None)` at the end of the file.
    ///
    /// # Errors
    /// The file cannot be read any further, or is damaged beyond a record that is cut off
    /// at its end (a block that does not parse, a record larger than 64 MiB).
    pub fn next_datagram(&mut self) -> anyhow::Result<Option<Datagram<'_>>> {
        self.frames.ready = None;
        while !self.done && self.frames.ready.is_none() {
            match self.reader.next() {
                Ok((offset, block)) => {
                    self.frames.block(block);
                    self.reader.consume(offset);
                }
                Err(PcapError::Eof) => self.finish(false),
                Err(PcapError::UnexpectedEof) => self.finish(true),
                Err(PcapError::Incomplete(_)) => self.refill()?,
                Err(PcapError::BufferTooSmall) => self.grow()?,
                Err(e) => {
                    let e = e.to_string();
                    bail!(
                        "{}: damaged capture at byte {}: {e}",
                        self.path.display(),
                        self.reader.consumed()
                    );
                }
            }
        }
        let f = &self.frames;
        Ok(f.ready.map(|(time_s, src, dst)| Datagram {
            time_s,
            src,
            dst,
            payload: &f.payload,
        }))
    }

    /// The NMEA lines met since the last call, oldest first.
    pub fn take_nmea_lines(&mut self) -> Vec<NmeaLine> {
        self.frames.nmea.take_lines()
    }

    /// What has been read so far.
    pub fn stats(&self) -> CaptureStats {
        CaptureStats {
            nmea: *self.frames.nmea.stats(),
            ..self.frames.stats
        }
    }

    /// True once the end of the file has been reached.
    pub fn is_done(&self) -> bool {
        self.done
    }

    fn finish(&mut self, truncated: bool) {
        self.done = true;
        let cut_stream = self.read_error.lock().is_ok_and(|e| {
            e.as_ref()
                .is_some_and(|e| e.kind() == io::ErrorKind::UnexpectedEof)
        });
        self.frames.stats.truncated_file |= truncated || cut_stream;
        self.frames.stats.reassembly_unfinished += self.frames.pending() as u64;
        self.frames.pool.retain(|_| false);
    }

    fn refill(&mut self) -> anyhow::Result<()> {
        let before = self.reader.data().len();
        if let Err(e) = self.reader.refill() {
            let e = e.to_string();
            let cause = self.read_error.lock().ok().and_then(|mut c| c.take());
            match cause {
                Some(cause) => bail!("{}: cannot read: {cause}", self.path.display()),
                None => bail!("{}: cannot read: {e}", self.path.display()),
            }
        }
        // A full buffer reads nothing more: make room, or the loop would not advance.
        if self.reader.data().len() == before && !self.reader.reader_exhausted() {
            self.grow()?;
        }
        Ok(())
    }

    fn grow(&mut self) -> anyhow::Result<()> {
        let wanted = self.capacity.saturating_mul(2);
        if wanted > MAX_BUFFER || !self.reader.grow(wanted) {
            bail!(
                "{}: a record larger than {} MiB at byte {}",
                self.path.display(),
                MAX_BUFFER >> 20,
                self.reader.consumed()
            );
        }
        self.capacity = wanted;
        Ok(())
    }
}

/// Everything but the file reader, so that a block borrowed from the reader can be handled
/// while this changes.
struct Frames {
    options: CaptureOptions,
    stats: CaptureStats,
    /// The legacy header's link type and whether its time stamps are in ns.
    legacy: Option<(Linktype, bool)>,
    interfaces: Vec<Interface>,
    pool: IpDefragPool<FragStamp, ()>,
    seq: u64,
    last_time_s: f64,
    last_sweep_s: f64,
    nmea: NmeaText,
    /// The datagram ready to be handed out: time, source, destination; its payload.
    ready: Option<(f64, SocketAddrV4, SocketAddrV4)>,
    payload: Vec<u8>,
}

impl Frames {
    fn new(options: CaptureOptions) -> Self {
        Frames {
            nmea: NmeaText::new(&options.nmea_ports),
            options,
            stats: CaptureStats::default(),
            legacy: None,
            interfaces: Vec::new(),
            pool: IpDefragPool::new(),
            seq: 0,
            last_time_s: 0.0,
            last_sweep_s: f64::NEG_INFINITY,
            ready: None,
            payload: Vec::new(),
        }
    }

    fn block(&mut self, block: PcapBlockOwned<'_>) {
        match block {
            PcapBlockOwned::LegacyHeader(h) => {
                self.legacy = Some((h.network, h.is_nanosecond_precision()));
            }
            PcapBlockOwned::Legacy(b) => {
                let (linktype, nanos) = self.legacy.unwrap_or((Linktype::ETHERNET, false));
                let per_s = if nanos { 1e9 } else { 1e6 };
                let time_s = f64::from(b.ts_sec) + f64::from(b.ts_usec) / per_s;
                self.stats.snapped += u64::from(b.caplen < b.origlen);
                self.frame(linktype, time_s, b.data);
            }
            PcapBlockOwned::NG(Block::SectionHeader(_)) => self.interfaces.clear(),
            PcapBlockOwned::NG(Block::InterfaceDescription(idb)) => {
                self.interfaces.push(Interface {
                    linktype: idb.linktype,
                    ticks_per_s: idb.ts_resolution().unwrap_or(1_000_000).max(1),
                    offset_s: idb.ts_offset(),
                });
            }
            PcapBlockOwned::NG(Block::EnhancedPacket(epb)) => {
                let interface = usize::try_from(epb.if_id)
                    .ok()
                    .and_then(|i| self.interfaces.get(i).copied());
                let Some(i) = interface else {
                    self.stats.packets += 1;
                    self.stats.unknown_interface += 1;
                    return;
                };
                let ticks = (u64::from(epb.ts_high) << 32) | u64::from(epb.ts_low);
                // Whole seconds apart from the fraction, so no precision is lost to f64
                // and no sum can overflow.
                let time_s = i.offset_s as f64
                    + (ticks / i.ticks_per_s) as f64
                    + (ticks % i.ticks_per_s) as f64 / i.ticks_per_s as f64;
                let caplen = usize::try_from(epb.caplen).unwrap_or(usize::MAX);
                // The block's data is padded to 4 bytes.
                let data = epb.data.get(..caplen).unwrap_or(epb.data);
                self.stats.snapped += u64::from(epb.caplen < epb.origlen);
                self.frame(i.linktype, time_s, data);
            }
            PcapBlockOwned::NG(Block::SimplePacket(spb)) => {
                // No time stamp of its own, and always interface 0.
                let Some(i) = self.interfaces.first().copied() else {
                    self.stats.packets += 1;
                    self.stats.unknown_interface += 1;
                    return;
                };
                let len = usize::try_from(spb.origlen).unwrap_or(usize::MAX);
                let data = spb.data.get(..len).unwrap_or(spb.data);
                self.frame(i.linktype, self.last_time_s, data);
            }
            PcapBlockOwned::NG(_) => {}
        }
    }

    fn frame(&mut self, linktype: Linktype, time_s: f64, data: &[u8]) {
        self.stats.packets += 1;
        self.last_time_s = time_s;
        let sliced = match linktype {
            Linktype::ETHERNET => SlicedPacket::from_ethernet(data),
            Linktype::LINUX_SLL => SlicedPacket::from_linux_sll(data),
            Linktype::RAW | Linktype::IPV4 | Linktype(12) | Linktype(14) => {
                SlicedPacket::from_ip(data)
            }
            // A 4-byte address family in the host's byte order, then the packet.
            Linktype::NULL | Linktype::LOOP => match data.get(4..) {
                Some(ip) => SlicedPacket::from_ip(ip),
                None => {
                    self.stats.undecodable += 1;
                    return;
                }
            },
            _ => {
                self.stats.unsupported_link += 1;
                return;
            }
        };
        let Ok(sliced) = sliced else {
            self.stats.undecodable += 1;
            return;
        };
        let Some(NetSlice::Ipv4(ip)) = &sliced.net else {
            self.stats.non_ipv4 += 1;
            return;
        };
        let (src, dst) = (ip.header().source_addr(), ip.header().destination_addr());
        self.sweep(time_s);
        if sliced.is_ip_payload_fragmented() {
            self.stats.fragments += 1;
            self.seq += 1;
            let stamp = FragStamp {
                seq: self.seq,
                time_s,
            };
            match self.pool.process_sliced_packet(&sliced, stamp, ()) {
                Ok(Some(done)) => {
                    self.stats.reassembled += 1;
                    self.transport(time_s, src, dst, done.ip_number, &done.payload);
                    self.pool.return_buf(done);
                }
                Ok(None) => self.bound(),
                Err(_) => self.stats.reassembly_errors += 1,
            }
            return;
        }
        match &sliced.transport {
            Some(TransportSlice::Udp(u)) => {
                self.udp(time_s, src, dst, u);
            }
            Some(TransportSlice::Tcp(t)) => self.tcp(time_s, src, dst, t),
            _ => self.stats.other_ip += 1,
        }
    }

    /// A reassembled datagram: its payload starts with the transport header.
    fn transport(&mut self, time_s: f64, src: Ipv4Addr, dst: Ipv4Addr, proto: IpNumber, b: &[u8]) {
        match proto {
            IpNumber::UDP => match UdpSlice::from_slice(b) {
                Ok(u) => self.udp(time_s, src, dst, &u),
                Err(_) => self.stats.undecodable += 1,
            },
            IpNumber::TCP => match TcpSlice::from_slice(b) {
                Ok(t) => self.tcp(time_s, src, dst, &t),
                Err(_) => self.stats.undecodable += 1,
            },
            _ => self.stats.other_ip += 1,
        }
    }

    fn udp(&mut self, time_s: f64, src: Ipv4Addr, dst: Ipv4Addr, u: &UdpSlice<'_>) {
        self.stats.udp_datagrams += 1;
        let (sp, dp) = (u.source_port(), u.destination_port());
        if let Some(port) = self.nmea.port_of(sp, dp) {
            self.nmea.datagram(time_s, port, u.payload());
        }
        self.payload.clear();
        self.payload.extend_from_slice(u.payload());
        self.ready = Some((
            time_s,
            SocketAddrV4::new(src, sp),
            SocketAddrV4::new(dst, dp),
        ));
    }

    fn tcp(&mut self, time_s: f64, src: Ipv4Addr, dst: Ipv4Addr, t: &TcpSlice<'_>) {
        self.stats.tcp_segments += 1;
        let (sp, dp) = (t.source_port(), t.destination_port());
        let Some(port) = self.nmea.port_of(sp, dp) else {
            return;
        };
        let key = (SocketAddrV4::new(src, sp), SocketAddrV4::new(dst, dp));
        let segment = Segment {
            seq: t.sequence_number(),
            syn: t.syn(),
            reset_or_fin: t.fin() || t.rst(),
            payload: t.payload(),
        };
        self.nmea.segment(time_s, port, key, segment);
    }

    /// Reassemblies under way (the pool does not say; counted by walking it, at most the cap;
    /// a predicate that keeps every entry is asked exactly once an entry).
    fn pending(&mut self) -> usize {
        let n = Cell::new(0usize);
        self.pool.retain(|_| {
            n.set(n.get() + 1);
            true
        });
        n.get()
    }

    /// Drops reassemblies that waited too long, once a second of capture time.
    fn sweep(&mut self, now_s: f64) {
        if now_s - self.last_sweep_s < 1.0 {
            return;
        }
        self.last_sweep_s = now_s;
        let timeout = self.options.reassembly_timeout_s;
        // Counted as before less after: the pool may ask the predicate twice an entry.
        let before = self.pending();
        self.pool.retain(|s| now_s - s.time_s <= timeout);
        self.stats.reassembly_timed_out += before.saturating_sub(self.pending()) as u64;
    }

    /// Keeps the reassemblies under way within the cap, dropping the longest-waiting.
    fn bound(&mut self) {
        while self.pending() > self.options.max_reassemblies.max(1) {
            let oldest = Cell::new(u64::MAX);
            self.pool.retain(|s| {
                oldest.set(oldest.get().min(s.seq));
                true
            });
            let oldest = oldest.get();
            self.pool.retain(|s| s.seq != oldest);
            self.stats.reassembly_evicted += 1;
        }
    }
}

/// A reader whose every read fills the buffer unless the end comes first: the capture
/// reader decides the format from its first read, and a gzip stream may return a few bytes
/// at a time. It keeps the I/O error it meets (the capture reader reports only that there
/// was one), and ends where a gzip stream is cut short.
struct Filled<R> {
    inner: R,
    error: Arc<Mutex<Option<io::Error>>>,
}

impl<R: Read> Filled<R> {
    fn new(inner: R, error: &Arc<Mutex<Option<io::Error>>>) -> Self {
        Filled {
            inner,
            error: Arc::clone(error),
        }
    }
}

impl<R: Read> Read for Filled<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let mut n = 0;
        while let Some(rest) = buf.get_mut(n..).filter(|r| !r.is_empty()) {
            match self.inner.read(rest) {
                Ok(0) => break,
                Ok(k) => n += k,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // A gzip stream cut short: its end, as for a plain file cut short (the
                // capture reader marks the capture truncated).
                Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
                    if let Ok(mut slot) = self.error.lock() {
                        *slot = Some(e);
                    }
                    break;
                }
                Err(e) => {
                    let kind = e.kind();
                    if let Ok(mut slot) = self.error.lock() {
                        *slot = Some(e);
                    }
                    // Hand over what was read; the error comes again on the next read.
                    if n == 0 {
                        return Err(io::Error::from(kind));
                    }
                    break;
                }
            }
        }
        Ok(n)
    }
}
