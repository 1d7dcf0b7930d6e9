//! Byte pipes to the device: the device code in this process, a TCP socket (QEMU's UART or
//! a network bridge to a board), a serial port.

use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use anyhow::Context;
use tracker_core::device::{Device, DeviceConfig};

/// A byte pipe to the device.
pub trait Transport: Send {
    /// Sends all of `bytes`.
    ///
    /// # Errors
    /// The link failed (a closed socket, a port gone).
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()>;
    /// Reads what has arrived, waiting up to `timeout`; `Ok(0)` when nothing came.
    ///
    /// # Errors
    /// The link failed or the peer closed it.
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
        max_tracks: tracker_core::track::MAX_TRACKS as u16,
        max_plots_per_scan: tracker_core::tracker::MAX_PLOTS_PER_SCAN as u16,
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
        device.receive(bytes, &mut |reply| outbox.extend(reply));
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

/// Longest a TCP connection to the device may take to open.
pub const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// A TCP socket (QEMU's `-serial tcp:` or a network bridge to a board).
pub struct TcpTransport {
    stream: TcpStream,
}

impl TcpTransport {
    /// Connects within [`CONNECT_TIMEOUT`] (an address that never answers is an error in
    /// seconds, not minutes), with Nagle off: without it every small frame waits ~40 ms.
    ///
    /// # Errors
    /// The address does not resolve, the connection is refused, or nothing answers in time.
    pub fn connect(addr: &str) -> anyhow::Result<Self> {
        use std::net::ToSocketAddrs;
        let mut last = None;
        for a in addr
            .to_socket_addrs()
            .with_context(|| format!("resolving {addr}"))?
        {
            match TcpStream::connect_timeout(&a, CONNECT_TIMEOUT) {
                Ok(stream) => return Self::from_stream(stream),
                Err(e) => last = Some(e),
            }
        }
        Err(match last {
            Some(e) => anyhow::Error::new(e).context(format!(
                "connecting to {addr} (within {} s)",
                CONNECT_TIMEOUT.as_secs()
            )),
            None => anyhow::anyhow!("{addr} resolves to no address"),
        })
    }

    /// Wraps a connected stream.
    ///
    /// # Errors
    /// The socket option cannot be set.
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
    ///
    /// # Errors
    /// The port does not exist or cannot be opened.
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
