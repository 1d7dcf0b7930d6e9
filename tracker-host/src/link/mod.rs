//! The link to the device: where the tracker core runs (in this process, the firmware in
//! QEMU, a board on a serial port, anything behind TCP), the byte transports, and the
//! request/response client speaking the ICD of `tracker_core::icd` over them.
//!
//! | module | what |
//! |---|---|
//! | [`transport`] | byte pipes: in-process device, TCP, serial |
//! | [`qemu`] | the firmware under `qemu-system-arm` |
//! | [`faults`] | a transport that damages bytes on purpose (tests, `--byte-errors`) |
//! | [`client`] | requests, replies, retries with the request id |
//! | [`reply`] | the device's replies, owned |
//! | [`check`] | `link-check`: handshake, echoes of every size, bad input rejected |

pub mod check;
pub mod client;
pub mod faults;
pub mod qemu;
pub mod reply;
pub mod transport;

use std::fmt;
use std::str::FromStr;

pub use client::{Client, ClientStats, RequestError};
pub use reply::{DeviceInfo, Reply, ReportPart};
pub use transport::{InprocReset, InprocTransport, SerialTransport, TcpTransport, Transport};

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

/// Opens the link `spec` names. `firmware` overrides the ELF QEMU runs.
///
/// # Errors
/// The transport's own: QEMU missing or failing to start, a refused connection, a serial
/// port that does not open.
pub fn open(spec: &LinkSpec, opts: &qemu::QemuOptions) -> anyhow::Result<Box<dyn Transport>> {
    Ok(match spec {
        LinkSpec::Inproc => Box::new(InprocTransport::new()),
        LinkSpec::Qemu => Box::new(qemu::QemuLink::start(opts)?),
        LinkSpec::Tcp(addr) => Box::new(TcpTransport::connect(addr)?),
        LinkSpec::Serial { path, baud } => Box::new(SerialTransport::open(path, *baud)?),
    })
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
}
