//! The host end of the link: transports (in-process, TCP, serial, QEMU) and a request/response
//! client speaking the ICD of `tracker_core::icd`.

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::str::FromStr;
use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use tracker_core::device::{Device, DeviceConfig};
use tracker_core::frame::{self, FrameDecoder, FrameError};
use tracker_core::icd::{
    DeviceToHost, Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, PROTOCOL_VERSION,
    UNPAIRED_REQUEST_ID,
};

use crate::qemu::QemuLink;

/// Where the firmware runs, as given to `--link`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LinkSpec {
    /// The device code in this process: no MCU needed.
    Inproc,
    /// The firmware under `qemu-system-arm` (mps2-an386), over a loopback socket.
    Qemu,
    /// A device (or a QEMU started by hand) behind a TCP socket.
    Tcp(String),
    /// A board on a serial port.
    Serial {
        /// Device path, e.g. `/dev/ttyACM0`.
        path: String,
        /// Baud rate.
        baud: u32,
    },
}

/// Default serial rate for boards.
pub const DEFAULT_BAUD: u32 = 115_200;

impl FromStr for LinkSpec {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "inproc" => return Ok(LinkSpec::Inproc),
            "qemu" => return Ok(LinkSpec::Qemu),
            _ => {}
        }
        if let Some(addr) = s.strip_prefix("tcp:") {
            if addr
                .rsplit_once(':')
                .is_none_or(|(_, p)| p.parse::<u16>().is_err())
            {
                return Err(format!("`{s}`: expected tcp:HOST:PORT"));
            }
            return Ok(LinkSpec::Tcp(addr.to_string()));
        }
        if let Some(rest) = s.strip_prefix("serial:") {
            let (path, baud) = match rest.rsplit_once('@') {
                Some((p, b)) => (
                    p,
                    b.parse()
                        .map_err(|_| format!("`{s}`: baud rate `{b}` is not a number"))?,
                ),
                None => (rest, DEFAULT_BAUD),
            };
            if path.is_empty() {
                return Err(format!("`{s}`: expected serial:PATH[@BAUD]"));
            }
            return Ok(LinkSpec::Serial {
                path: path.to_string(),
                baud,
            });
        }
        Err(format!(
            "`{s}`: expected inproc, qemu, tcp:HOST:PORT or serial:PATH[@BAUD]"
        ))
    }
}

impl fmt::Display for LinkSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinkSpec::Inproc => f.write_str("inproc"),
            LinkSpec::Qemu => f.write_str("qemu"),
            LinkSpec::Tcp(a) => write!(f, "tcp:{a}"),
            LinkSpec::Serial { path, baud } => write!(f, "serial:{path}@{baud}"),
        }
    }
}

/// A byte pipe to the device.
pub trait Transport: Send {
    /// Sends all of `bytes`.
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// Reads what has arrived, waiting up to `timeout`; `Ok(0)` when nothing came.
    fn read(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize>;
}

/// The device code running inside the host process.
pub struct InprocTransport {
    shared: std::sync::Arc<std::sync::Mutex<Inproc>>,
}

struct Inproc {
    device: Box<Device>,
    outbox: VecDeque<u8>,
}

fn fresh_device() -> Box<Device> {
    Box::new(Device::new(DeviceConfig {
        firmware: concat!("tracker-core ", env!("CARGO_PKG_VERSION"), " (inproc)"),
        boot_id: fastrand::u32(1..),
        max_tracks: 64,
        max_plots_per_scan: 256,
    }))
}

/// Resets the in-process device as a power cycle would (for tests of reset recovery).
#[derive(Clone)]
pub struct InprocReset(std::sync::Arc<std::sync::Mutex<Inproc>>);

impl InprocReset {
    /// A fresh device, with a new boot id; replies in flight are lost.
    pub fn reset(&self) {
        if let Ok(mut inner) = self.0.lock() {
            inner.device = fresh_device();
            inner.outbox.clear();
        }
    }
}

impl InprocTransport {
    /// A fresh in-process device.
    pub fn new() -> Self {
        InprocTransport {
            shared: std::sync::Arc::new(std::sync::Mutex::new(Inproc {
                device: fresh_device(),
                outbox: VecDeque::new(),
            })),
        }
    }

    /// A handle that resets the device.
    pub fn reset_handle(&self) -> InprocReset {
        InprocReset(self.shared.clone())
    }
}

impl Default for InprocTransport {
    fn default() -> Self {
        Self::new()
    }
}

impl Transport for InprocTransport {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        let mut guard = self
            .shared
            .lock()
            .map_err(|_| io::Error::other("in-process device poisoned"))?;
        let Inproc { device, outbox } = &mut *guard;
        for &b in bytes {
            device.receive(b, &mut |reply| outbox.extend(reply));
        }
        Ok(())
    }

    fn read(&mut self, buf: &mut [u8], _timeout: Duration) -> io::Result<usize> {
        let mut guard = self
            .shared
            .lock()
            .map_err(|_| io::Error::other("in-process device poisoned"))?;
        let n = buf.len().min(guard.outbox.len());
        for (dst, src) in buf.iter_mut().zip(guard.outbox.drain(..n)) {
            *dst = src;
        }
        Ok(n)
    }
}

/// A TCP socket (QEMU's `-serial tcp:` or a network bridge to a board).
pub struct TcpTransport {
    stream: TcpStream,
}

impl TcpTransport {
    /// Connects, with Nagle off: without it every small frame waits ~40 ms.
    pub fn connect(addr: &str) -> anyhow::Result<Self> {
        let stream = TcpStream::connect(addr).with_context(|| format!("connecting to {addr}"))?;
        Self::from_stream(stream)
    }

    /// Wraps a connected stream.
    pub fn from_stream(stream: TcpStream) -> anyhow::Result<Self> {
        stream.set_nodelay(true)?;
        Ok(TcpTransport { stream })
    }
}

impl Transport for TcpTransport {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.stream.write_all(bytes)
    }

    fn read(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.stream
            .set_read_timeout(Some(timeout.max(Duration::from_millis(1))))?;
        read_or_timeout(self.stream.read(buf), true)
    }
}

/// A board on a serial port.
pub struct SerialTransport {
    port: Box<dyn serialport::SerialPort>,
}

impl SerialTransport {
    /// Opens `path` at `baud`, 8N1.
    pub fn open(path: &str, baud: u32) -> anyhow::Result<Self> {
        let port = serialport::new(path, baud)
            .timeout(Duration::from_millis(100))
            .open()
            .with_context(|| format!("opening serial port {path}"))?;
        Ok(SerialTransport { port })
    }
}

impl Transport for SerialTransport {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all(bytes)
    }

    fn read(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.port
            .set_timeout(timeout.max(Duration::from_millis(1)))
            .map_err(io::Error::other)?;
        read_or_timeout(self.port.read(buf), false)
    }
}

/// A read's result with a time-out turned into "nothing arrived" (`Ok(0)`); with
/// `eof_is_error` a zero-byte read (the peer closed the link) becomes an error instead.
fn read_or_timeout(result: io::Result<usize>, eof_is_error: bool) -> io::Result<usize> {
    match result {
        Ok(0) if eof_is_error => Err(io::Error::new(
            io::ErrorKind::UnexpectedEof,
            "the device closed the link",
        )),
        Ok(n) => Ok(n),
        Err(e)
            if matches!(
                e.kind(),
                io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
            ) =>
        {
            Ok(0)
        }
        Err(e) => Err(e),
    }
}

/// Opens the link `spec` names. `firmware` overrides the ELF QEMU runs.
pub fn open(
    spec: &LinkSpec,
    opts: &crate::qemu::QemuOptions,
) -> anyhow::Result<Box<dyn Transport>> {
    Ok(match spec {
        LinkSpec::Inproc => Box::new(InprocTransport::new()),
        LinkSpec::Qemu => Box::new(QemuLink::start(opts)?),
        LinkSpec::Tcp(addr) => Box::new(TcpTransport::connect(addr)?),
        LinkSpec::Serial { path, baud } => Box::new(SerialTransport::open(path, *baud)?),
    })
}

/// What arrived on the link (short-lived: moved straight into the caller's hands).
#[allow(clippy::large_enum_variant)]
enum Incoming {
    Frame(Header, DeviceToHost),
    Damaged,
    Timeout,
}

/// What went wrong with a request.
#[derive(Debug)]
pub enum RequestError {
    /// No reply within the timeout.
    Timeout,
    /// The request or its reply was damaged on the way (and retries ran out).
    Lost,
    /// The transport failed.
    Io(io::Error),
    /// The request could not be encoded.
    Encode(FrameError),
}

impl fmt::Display for RequestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RequestError::Timeout => f.write_str("no reply from the device"),
            RequestError::Lost => f.write_str("the request or its reply was damaged on the link"),
            RequestError::Io(e) => write!(f, "link failed: {e}"),
            RequestError::Encode(e) => write!(f, "request not encodable: {e}"),
        }
    }
}

impl std::error::Error for RequestError {}

impl From<io::Error> for RequestError {
    fn from(e: io::Error) -> Self {
        RequestError::Io(e)
    }
}

/// Host-side counters.
#[derive(Clone, Copy, Debug, Default)]
pub struct ClientStats {
    /// Frames sent (requests and raw frames).
    pub frames_sent: u64,
    /// Reply frames that decoded.
    pub frames_received: u64,
    /// Reply frames that failed to decode (damaged on the way back).
    pub frames_damaged: u64,
    /// Replies that answered no outstanding request (late or unpaired).
    pub unmatched: u64,
    /// Requests sent again after a lost answer.
    pub retries: u64,
}

/// Request/response over a [`Transport`].
pub struct Client {
    transport: Box<dyn Transport>,
    decoder: Box<FrameDecoder>,
    inbox: VecDeque<u8>,
    next_id: u32,
    /// How long to wait for a reply.
    pub timeout: Duration,
    /// Times a request is sent again when its answer is lost.
    pub retries: u32,
    stats: ClientStats,
    scratch: Vec<u8>,
    out: Vec<u8>,
}

impl Client {
    /// A client over `transport`; nothing is sent until the first request.
    pub fn new(transport: Box<dyn Transport>) -> Self {
        Client {
            transport,
            decoder: Box::new(FrameDecoder::new()),
            inbox: VecDeque::new(),
            next_id: 1,
            timeout: Duration::from_secs(5),
            retries: 5,
            stats: ClientStats::default(),
            scratch: vec![0; MAX_FRAME_BYTES],
            out: vec![0; MAX_ENCODED_FRAME_BYTES + 1],
        }
    }

    /// Gives the transport back (a host restart keeps the link and nothing else).
    pub fn into_transport(self) -> Box<dyn Transport> {
        self.transport
    }

    /// Host-side counters.
    pub fn stats(&self) -> ClientStats {
        self.stats
    }

    /// The next request id (never [`UNPAIRED_REQUEST_ID`]).
    pub fn allocate_id(&mut self) -> u32 {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1).max(1);
        id
    }

    /// Encodes a frame: a leading delimiter (so any garbage before it ends as a frame of
    /// its own instead of spoiling this one), then the frame with its own delimiter.
    pub fn encode(&mut self, header: &Header, body: &HostToDevice) -> Result<Vec<u8>, FrameError> {
        self.out[0] = 0;
        let n = frame::encode(header, body, &mut self.scratch, &mut self.out[1..])?;
        Ok(self.out[..n + 1].to_vec())
    }

    /// Sends bytes as they are (for tests of bad input).
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), RequestError> {
        self.stats.frames_sent += 1;
        self.transport.write_all(bytes)?;
        Ok(())
    }

    /// Sends `body` and waits for the reply carrying its request id; other frames that
    /// arrive meanwhile are counted and dropped.
    pub fn request(&mut self, body: &HostToDevice) -> Result<DeviceToHost, RequestError> {
        self.request_all(body)?
            .into_iter()
            .next()
            .ok_or(RequestError::Timeout)
    }

    /// Sends `body` and collects its whole answer: one message, or every part of a gate or
    /// track report (all carrying the request's id).
    ///
    /// When the answer is lost (a damaged frame arrives, or the device reports an unreadable
    /// frame, or nothing comes within the timeout) the same frame is sent again with the same
    /// request id, up to [`Client::retries`] times: the device answers a repeated
    /// state-changing request again instead of carrying it out twice.
    pub fn request_all(&mut self, body: &HostToDevice) -> Result<Vec<DeviceToHost>, RequestError> {
        let id = self.allocate_id();
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        };
        let bytes = self.encode(&header, body).map_err(RequestError::Encode)?;
        // Parts received so far, by index: a retry is answered with the same parts, so
        // parts from an earlier attempt still count.
        let mut parts: Vec<Option<DeviceToHost>> = Vec::new();
        let mut attempt = 0;
        loop {
            self.send_raw(&bytes)?;
            match self.collect(id, &mut parts) {
                Err(RequestError::Timeout | RequestError::Lost) if attempt < self.retries => {
                    attempt += 1;
                    self.stats.retries += 1;
                }
                other => return other,
            }
        }
    }

    /// Collects the answer to request `id` into `parts` until every part is in.
    fn collect(
        &mut self,
        id: u32,
        parts: &mut Vec<Option<DeviceToHost>>,
    ) -> Result<Vec<DeviceToHost>, RequestError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            match self.next_event(deadline)? {
                Incoming::Frame(h, reply) if h.request_id == id => {
                    let (part, of) = match &reply {
                        DeviceToHost::Gated(g) => (usize::from(g.part), usize::from(g.parts)),
                        DeviceToHost::Tracks(t) => (usize::from(t.part), usize::from(t.parts)),
                        _ => (0, 1),
                    };
                    if parts.len() != of {
                        parts.clear();
                        parts.resize(of, None);
                    }
                    if let Some(slot) = parts.get_mut(part) {
                        *slot = Some(reply);
                    }
                    if parts.iter().all(Option::is_some) {
                        return Ok(parts.drain(..).flatten().collect());
                    }
                }
                // The device could not read a frame: most likely ours.
                Incoming::Frame(h, DeviceToHost::Error(_)) if is_unpaired(&h) => {
                    self.stats.unmatched += 1;
                    return Err(RequestError::Lost);
                }
                Incoming::Frame(..) => self.stats.unmatched += 1,
                Incoming::Damaged => return Err(RequestError::Lost),
                Incoming::Timeout => return Err(RequestError::Timeout),
            }
        }
    }

    /// The next reply frame, or `None` at the deadline; damaged frames are counted and
    /// skipped.
    pub fn next_frame(
        &mut self,
        deadline: Instant,
    ) -> Result<Option<(Header, DeviceToHost)>, RequestError> {
        loop {
            match self.next_event(deadline)? {
                Incoming::Frame(h, body) => return Ok(Some((h, body))),
                Incoming::Damaged => {}
                Incoming::Timeout => return Ok(None),
            }
        }
    }

    /// The next thing to arrive: a frame, a damaged frame, or nothing by the deadline.
    fn next_event(&mut self, deadline: Instant) -> Result<Incoming, RequestError> {
        loop {
            while let Some(b) = self.inbox.pop_front() {
                match self.decoder.push(b) {
                    None => {}
                    Some(Ok(payload)) => match frame::decode_payload(payload, u32::MAX) {
                        Ok((h, body)) => {
                            self.stats.frames_received += 1;
                            return Ok(Incoming::Frame(h, body));
                        }
                        Err(_) => {
                            self.stats.frames_damaged += 1;
                            return Ok(Incoming::Damaged);
                        }
                    },
                    Some(Err(_)) => {
                        self.stats.frames_damaged += 1;
                        return Ok(Incoming::Damaged);
                    }
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(Incoming::Timeout);
            }
            let mut buf = [0u8; 4096];
            let n = self.transport.read(&mut buf, deadline - now)?;
            self.inbox.extend(&buf[..n]);
        }
    }

    /// Handshake: checks the device speaks our protocol version.
    pub fn hello(&mut self) -> anyhow::Result<tracker_core::icd::DeviceInfo> {
        match self.request(&HostToDevice::Hello)? {
            DeviceToHost::HelloAck(info) if info.protocol == PROTOCOL_VERSION => Ok(info),
            DeviceToHost::HelloAck(info) => bail!(
                "device speaks protocol {}, this host {}",
                info.protocol,
                PROTOCOL_VERSION
            ),
            DeviceToHost::Error(e) => bail!("device refused the handshake: {e:?}"),
            other => bail!("unexpected handshake reply: {other:?}"),
        }
    }
}

/// Replies carrying [`UNPAIRED_REQUEST_ID`] answer frames the device could not read.
pub fn is_unpaired(h: &Header) -> bool {
    h.request_id == UNPAIRED_REQUEST_ID
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn link_specs_parse() {
        assert_eq!("inproc".parse(), Ok(LinkSpec::Inproc));
        assert_eq!("qemu".parse(), Ok(LinkSpec::Qemu));
        assert_eq!(
            "tcp:127.0.0.1:4000".parse(),
            Ok(LinkSpec::Tcp("127.0.0.1:4000".into()))
        );
        assert_eq!(
            "serial:/dev/ttyACM0@921600".parse(),
            Ok(LinkSpec::Serial {
                path: "/dev/ttyACM0".into(),
                baud: 921_600
            })
        );
        assert_eq!(
            "serial:/dev/ttyUSB1".parse(),
            Ok(LinkSpec::Serial {
                path: "/dev/ttyUSB1".into(),
                baud: DEFAULT_BAUD
            })
        );
        for bad in ["", "tcp:host", "serial:", "serial:/dev/x@fast", "usb"] {
            assert!(bad.parse::<LinkSpec>().is_err(), "{bad}");
        }
    }

    #[test]
    fn inproc_client_handshakes_and_echoes() {
        let mut c = Client::new(Box::new(InprocTransport::new()));
        let info = c.hello().unwrap();
        assert_eq!(info.protocol, PROTOCOL_VERSION);
        let body = HostToDevice::Echo((0..=255u8).collect());
        let HostToDevice::Echo(sent) = body.clone() else {
            unreachable!()
        };
        assert_eq!(c.request(&body).unwrap(), DeviceToHost::Echo(sent));
    }
}
