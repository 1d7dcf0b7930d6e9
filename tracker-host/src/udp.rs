//! UDP datagrams with the kernel's count of those it dropped.
//!
//! A socket's receive buffer that fills (a reader that stalls, a burst larger than the
//! buffer) loses datagrams in the kernel, before the program sees them, and nothing in
//! `recv` tells. On Linux the kernel counts them per socket and, once asked
//! (`SO_RXQ_OVFL`, socket(7)), hands the running count with every datagram; it is read
//! here so that a radar or an AIS feed that loses data says so. Elsewhere the count is not
//! known (`None`).

use std::io;
use std::net::{SocketAddr, UdpSocket};

/// One datagram received.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Received {
    /// Bytes written to the buffer (a longer datagram is cut to it).
    pub len: usize,
    /// The sender (`None`: not an IPv4 or IPv6 address).
    pub from: Option<SocketAddr>,
    /// Datagrams the kernel had dropped on this socket, since it was opened, when this one
    /// arrived (`None`: none yet, or not counted on this system, or not asked for: the
    /// kernel tells the count only once it is above zero).
    pub kernel_drops: Option<u32>,
}

/// Asks the kernel to hand its count of dropped datagrams with each one received; false
/// where it cannot (not Linux, or refused).
pub fn count_kernel_drops(socket: &UdpSocket) -> bool {
    #[cfg(target_os = "linux")]
    {
        nix::sys::socket::setsockopt(socket, nix::sys::socket::sockopt::RxqOvfl, &1).is_ok()
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = socket;
        false
    }
}

/// Receives one datagram into `buf`, as `recv_from` does (blocking, or not, as the socket
/// is set), with the kernel's drop count when [`count_kernel_drops`] was granted.
///
/// # Errors
/// As `recv_from`: `WouldBlock` or `TimedOut` when nothing came, else the socket's error.
pub fn recv_from(socket: &UdpSocket, buf: &mut [u8]) -> io::Result<Received> {
    #[cfg(target_os = "linux")]
    {
        use nix::sys::socket::{recvmsg, ControlMessageOwned, MsgFlags, SockaddrStorage};
        use std::os::fd::AsRawFd;
        let mut control = nix::cmsg_space!(u32);
        let mut iov = [io::IoSliceMut::new(buf)];
        let msg = recvmsg::<SockaddrStorage>(
            socket.as_raw_fd(),
            &mut iov,
            Some(&mut control),
            MsgFlags::empty(),
        )
        .map_err(io::Error::from)?;
        let from = msg.address.and_then(|a| {
            a.as_sockaddr_in()
                .map(|v4| SocketAddr::V4((*v4).into()))
                .or_else(|| a.as_sockaddr_in6().map(|v6| SocketAddr::V6((*v6).into())))
        });
        let kernel_drops = msg.cmsgs().ok().and_then(|mut c| {
            c.find_map(|m| match m {
                ControlMessageOwned::RxqOvfl(n) => Some(n),
                _ => None,
            })
        });
        Ok(Received {
            len: msg.bytes,
            from,
            kernel_drops,
        })
    }
    #[cfg(not(target_os = "linux"))]
    {
        let (len, from) = socket.recv_from(buf)?;
        Ok(Received {
            len,
            from: Some(from),
            kernel_drops: None,
        })
    }
}

/// True for "no such device" (ENODEV): joining a group on an address that is no
/// interface's, or on any interface (`0.0.0.0`) with no route for multicast. Linux only.
pub fn is_no_such_device(e: &io::Error) -> bool {
    #[cfg(target_os = "linux")]
    {
        e.raw_os_error() == Some(nix::errno::Errno::ENODEV as i32)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = e;
        false
    }
}

/// This computer's IPv4 interfaces, as `name address` (`eth0 192.168.1.3`), for an
/// operator who gave an address that is none of them; empty where they cannot be listed
/// (not Linux).
pub fn ipv4_interfaces() -> Vec<String> {
    #[cfg(target_os = "linux")]
    {
        let Ok(addrs) = nix::ifaddrs::getifaddrs() else {
            return Vec::new();
        };
        addrs
            .filter_map(|a| {
                let v4 = std::net::SocketAddrV4::from(*a.address?.as_sockaddr_in()?);
                Some(format!("{} {}", a.interface_name, v4.ip()))
            })
            .collect()
    }
    #[cfg(not(target_os = "linux"))]
    {
        Vec::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    #[test]
    fn the_loopback_interface_is_listed() {
        let here = ipv4_interfaces();
        assert!(here.iter().any(|i| i.ends_with(" 127.0.0.1")), "{here:?}");
    }

    /// A socket whose buffer is flooded while nobody reads: the kernel's drops are counted,
    /// and the datagrams kept are read with their sender.
    #[test]
    #[cfg(target_os = "linux")]
    fn a_flooded_socket_counts_what_the_kernel_dropped() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        // Small, whatever the system's default: a few dozen 1 KiB datagrams.
        socket2::SockRef::from(&rx)
            .set_recv_buffer_size(64 << 10)
            .unwrap();
        assert!(count_kernel_drops(&rx));
        rx.set_nonblocking(true).unwrap();
        let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
        let to = rx.local_addr().unwrap();
        let datagram = [7u8; 1024];
        let sent = 5_000u32;
        for _ in 0..sent {
            tx.send_to(&datagram, to).unwrap();
        }
        let mut buf = [0u8; 2048];
        let mut got = 0u32;
        while let Ok(r) = recv_from(&rx, &mut buf) {
            assert_eq!(r.len, 1024);
            assert_eq!(r.from, Some(tx.local_addr().unwrap()));
            // Those kept arrived before the buffer was full: no drops yet when they came.
            assert_eq!(r.kernel_drops, None);
            got += 1;
        }
        assert!(got < sent, "the buffer held all {sent}");
        // The next datagram comes with the count.
        tx.send_to(&datagram, to).unwrap();
        let r = recv_from(&rx, &mut buf).unwrap();
        assert_eq!(r.kernel_drops, Some(sent - got), "{got} of {sent} read");
    }

    #[test]
    fn nothing_waiting_is_would_block() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        rx.set_nonblocking(true).unwrap();
        let e = recv_from(&rx, &mut [0u8; 16]).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::WouldBlock);
    }
}
