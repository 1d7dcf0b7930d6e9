//! The request/response client: frames out with a request id, replies paired by it, lost
//! answers retried with the same id (the device answers a repeat without redoing it).

use std::collections::VecDeque;
use std::fmt;
use std::io;
use std::time::{Duration, Instant};

use anyhow::bail;
use tracker_core::frame::{self, FrameDecoder, FrameError};
use tracker_core::icd::{
    DeviceToHost, Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, PROTOCOL_VERSION,
    UNPAIRED_REQUEST_ID,
};

use super::reply::{DeviceInfo, Reply};
use super::transport::Transport;

/// What arrived on the link.
enum Incoming {
    Frame(Header, Reply),
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
    /// Resynchronisations of the line ([`Client::resync`]).
    pub resyncs: u64,
    /// Answers that came after their request had timed out and been sent again: the device
    /// is slower than [`Client::timeout`].
    pub late_answers: u64,
    /// Bytes written to the link.
    pub bytes_sent: u64,
    /// Bytes read from the link.
    pub bytes_received: u64,
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
    out: Vec<u8>,
    last_wait: LastWait,
}

/// How the last wait for an answer ended, when it did not end with one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LastWait {
    TimedOut,
    Damaged,
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
            out: vec![0; MAX_ENCODED_FRAME_BYTES + 1],
            last_wait: LastWait::Damaged,
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
    ///
    /// # Errors
    /// [`FrameError::BufferTooSmall`] for a message larger than a frame.
    pub fn encode(&mut self, header: &Header, body: &HostToDevice) -> Result<Vec<u8>, FrameError> {
        self.out[0] = 0;
        let n = frame::encode(header, body, &mut self.out[1..])?;
        Ok(self.out[..n + 1].to_vec())
    }

    /// Sends bytes as they are (for tests of bad input).
    ///
    /// # Errors
    /// [`RequestError::Io`] when the transport fails.
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), RequestError> {
        self.stats.frames_sent += 1;
        self.stats.bytes_sent += bytes.len() as u64;
        self.transport.write_all(bytes)?;
        Ok(())
    }

    /// Sends `body` and waits for the reply carrying its request id; other frames that
    /// arrive meanwhile are counted and dropped.
    ///
    /// # Errors
    /// As [`Client::request_all`].
    pub fn request(&mut self, body: &HostToDevice) -> Result<Reply, RequestError> {
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
    ///
    /// # Errors
    /// [`RequestError::Timeout`] or [`RequestError::Lost`] once the retries are spent, [`RequestError::Io`] when the transport fails, [`RequestError::Encode`] for a message that cannot be encoded.
    pub fn request_all(&mut self, body: &HostToDevice) -> Result<Vec<Reply>, RequestError> {
        let id = self.allocate_id();
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        };
        let bytes = self.encode(&header, body).map_err(RequestError::Encode)?;
        // Parts received so far, by index: a retry is answered with the same parts, so
        // parts from an earlier attempt still count.
        let mut parts: Vec<Option<Reply>> = Vec::new();
        let mut attempt = 0;
        let mut timed_out = false;
        loop {
            self.send_raw(&bytes)?;
            match self.collect(id, &mut parts) {
                Err(RequestError::Timeout | RequestError::Lost) if attempt < self.retries => {
                    attempt += 1;
                    self.stats.retries += 1;
                    timed_out |= matches!(self.last_wait, LastWait::TimedOut);
                }
                Ok(answer) => {
                    // An answer after a time-out: the device is slower than the time-out.
                    if timed_out {
                        self.stats.late_answers += 1;
                    }
                    return Ok(answer);
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Collects the answer to request `id` into `parts` until every part is in: the last
    /// part, and each one before it.
    fn collect(
        &mut self,
        id: u32,
        parts: &mut Vec<Option<Reply>>,
    ) -> Result<Vec<Reply>, RequestError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            match self.next_event(deadline)? {
                Incoming::Frame(h, reply) if h.request_id == id => {
                    let (part, last) = reply.part();
                    let part = usize::from(part);
                    // A part past the last one already in is no answer: ask again (a retry
                    // gets the device's report afresh).
                    let known_last = parts
                        .iter()
                        .rposition(|p| p.as_ref().is_some_and(|r| r.part().1));
                    if known_last.is_some_and(|k| part > k) || (last && part + 1 < parts.len()) {
                        self.stats.frames_damaged += 1;
                        parts.clear();
                        return Err(RequestError::Lost);
                    }
                    if parts.len() <= part {
                        parts.resize(part + 1, None);
                    }
                    if let Some(slot) = parts.get_mut(part) {
                        *slot = Some(reply);
                    }
                    let complete = parts
                        .last()
                        .is_some_and(|p| p.as_ref().is_some_and(|r| r.part().1))
                        && parts.iter().all(Option::is_some);
                    if complete {
                        return Ok(parts.drain(..).flatten().collect());
                    }
                }
                // The device could not read a frame: most likely ours.
                Incoming::Frame(h, Reply::Error(_)) if is_unpaired(&h) => {
                    self.stats.unmatched += 1;
                    return Err(RequestError::Lost);
                }
                Incoming::Frame(..) => self.stats.unmatched += 1,
                Incoming::Damaged => {
                    self.last_wait = LastWait::Damaged;
                    return Err(RequestError::Lost);
                }
                Incoming::Timeout => {
                    self.last_wait = LastWait::TimedOut;
                    // Some of a report came and the rest did not: lost on the way (the
                    // device is not silent), as a damaged part would be.
                    if parts.iter().any(Option::is_some) {
                        self.stats.frames_damaged += 1;
                        return Err(RequestError::Lost);
                    }
                    return Err(RequestError::Timeout);
                }
            }
        }
    }

    /// The next reply frame, or `None` at the deadline; damaged frames are counted and
    /// skipped.
    ///
    /// # Errors
    /// [`RequestError::Io`] when the transport fails.
    pub fn next_frame(
        &mut self,
        deadline: Instant,
    ) -> Result<Option<(Header, Reply)>, RequestError> {
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
                    Some(Ok(payload)) => {
                        match frame::decode_payload::<DeviceToHost>(payload, u32::MAX) {
                            Ok((h, body)) => {
                                self.stats.frames_received += 1;
                                return Ok(Incoming::Frame(h, Reply::from(body)));
                            }
                            Err(_) => {
                                self.stats.frames_damaged += 1;
                                return Ok(Incoming::Damaged);
                            }
                        }
                    }
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
            self.stats.bytes_received += n as u64;
            self.inbox.extend(&buf[..n]);
        }
    }

    /// Brings both ends back to a frame boundary: a lone delimiter ends whatever the device
    /// was decoding (junk on the line becomes one frame of its own, answered with an error),
    /// then everything arriving until the line has been quiet for [`RESYNC_QUIET`] (at most
    /// [`RESYNC_MAX`]) is dropped, and our decoder starts afresh.
    ///
    /// # Errors
    /// [`RequestError::Io`] when the transport fails.
    pub fn resync(&mut self) -> Result<(), RequestError> {
        self.transport.write_all(&[0])?;
        self.stats.bytes_sent += 1;
        let start = Instant::now();
        let mut quiet_since = Instant::now();
        let mut buf = [0u8; 4096];
        while quiet_since.elapsed() < RESYNC_QUIET && start.elapsed() < RESYNC_MAX {
            let n = self.transport.read(&mut buf, RESYNC_QUIET / 4)?;
            if n > 0 {
                self.stats.bytes_received += n as u64;
                quiet_since = Instant::now();
            }
        }
        self.inbox.clear();
        *self.decoder = FrameDecoder::new();
        self.stats.resyncs += 1;
        Ok(())
    }

    /// Handshake: brings the line back to a frame boundary ([`Client::resync`]), then checks
    /// the device speaks our protocol version, trying [`HELLO_ATTEMPTS`] times whatever
    /// [`Client::retries`] says (junk on the line before it must not fail the handshake).
    ///
    /// # Errors
    /// No answer, another protocol version, or a refusal.
    pub fn hello(&mut self) -> anyhow::Result<DeviceInfo> {
        let retries = self.retries;
        self.retries = self.retries.max(HELLO_ATTEMPTS - 1);
        let answer = self
            .resync()
            .and_then(|()| self.request(&HostToDevice::Hello));
        self.retries = retries;
        match answer? {
            Reply::HelloAck(info) if info.protocol == PROTOCOL_VERSION => Ok(info),
            Reply::HelloAck(info) => bail!(
                "device speaks protocol {}, this host {}",
                info.protocol,
                PROTOCOL_VERSION
            ),
            Reply::Error(e) => bail!("device refused the handshake: {e}"),
            other => bail!("unexpected handshake reply: {other}"),
        }
    }
}

/// A line quiet this long is at a frame boundary again.
pub const RESYNC_QUIET: Duration = Duration::from_millis(40);

/// Longest a resynchronisation drains a line that keeps talking.
pub const RESYNC_MAX: Duration = Duration::from_secs(1);

/// Tries of a handshake.
pub const HELLO_ATTEMPTS: u32 = 3;

/// Replies carrying [`UNPAIRED_REQUEST_ID`] answer frames the device could not read.
pub fn is_unpaired(h: &Header) -> bool {
    h.request_id == UNPAIRED_REQUEST_ID
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::InprocTransport;

    #[test]
    fn inproc_client_handshakes_and_echoes() {
        let mut c = Client::new(Box::new(InprocTransport::new()));
        let info = c.hello().unwrap();
        assert_eq!(info.protocol, PROTOCOL_VERSION);
        let sent: Vec<u8> = (0..=255u8).collect();
        let body = HostToDevice::Echo(tracker_core::icd::Bytes(&sent));
        assert_eq!(c.request(&body).unwrap(), Reply::Echo(sent));
    }

    /// The device in this process, answering `delay` late.
    struct Slow {
        inner: InprocTransport,
        delay: Duration,
        held: Vec<(Instant, u8)>,
    }

    impl Transport for Slow {
        fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
            self.inner.write_all(bytes)
        }
        fn read(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
            let mut tmp = [0u8; 4096];
            let n = self.inner.read(&mut tmp, timeout)?;
            let due = Instant::now() + self.delay;
            self.held.extend(tmp[..n].iter().map(|&b| (due, b)));
            std::thread::sleep(Duration::from_millis(1));
            let ready = self
                .held
                .iter()
                .take_while(|(t, _)| *t <= Instant::now())
                .count();
            let n = ready.min(buf.len());
            for (d, (_, b)) in buf.iter_mut().zip(self.held.drain(..n)) {
                *d = b;
            }
            Ok(n)
        }
    }

    /// Never answers.
    struct Silent;

    impl Transport for Silent {
        fn write_all(&mut self, _: &[u8]) -> std::io::Result<()> {
            Ok(())
        }
        fn read(&mut self, _: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
            std::thread::sleep(timeout.min(Duration::from_millis(5)));
            Ok(0)
        }
    }

    #[test]
    fn a_slow_device_is_noticed_and_a_silent_one_is_a_clear_error() {
        let mut c = Client::new(Box::new(Slow {
            inner: InprocTransport::new(),
            delay: Duration::from_millis(80),
            held: Vec::new(),
        }));
        c.timeout = Duration::from_millis(30);
        c.hello().unwrap();
        assert!(c.request(&HostToDevice::GetStats).is_ok());
        assert!(c.stats().late_answers >= 1, "{:?}", c.stats());
        let mut c = Client::new(Box::new(Silent));
        c.timeout = Duration::from_millis(20);
        let err = c.hello().unwrap_err();
        assert!(format!("{err:#}").contains("no reply"), "{err:#}");
    }
}
