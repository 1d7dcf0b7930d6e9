//! A transport that damages the link on purpose: bit flips and dropped and duplicated bytes,
//! in both directions, at configurable rates, from a seed. For testing that the framing
//! catches every damaged frame, the link resynchronises, and retries neither lose nor
//! repeat a request.

use std::io;
use std::time::Duration;

use super::transport::Transport;

/// Fault rates, each a probability per byte.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultRates {
    /// A byte has one random bit flipped.
    pub flip: f64,
    /// A byte is lost.
    pub drop: f64,
    /// A byte arrives twice.
    pub duplicate: f64,
}

impl FaultRates {
    /// `rate` split as the line noise of a serial link: mostly flips, some losses and
    /// repeats.
    pub fn byte_errors(rate: f64) -> Self {
        FaultRates {
            flip: rate * 0.8,
            drop: rate * 0.1,
            duplicate: rate * 0.1,
        }
    }
}

/// What the injector did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultStats {
    /// Bytes passed through.
    pub bytes: u64,
    /// Bytes damaged (flipped, dropped or duplicated).
    pub faults: u64,
}

/// Wraps a transport and damages what crosses it.
pub struct FaultyTransport {
    inner: Box<dyn Transport>,
    rates: FaultRates,
    rng: fastrand::Rng,
    stats: FaultStats,
}

impl FaultyTransport {
    /// Damages `inner`'s traffic at `rates`, reproducibly from `seed`.
    pub fn new(inner: Box<dyn Transport>, rates: FaultRates, seed: u64) -> Self {
        FaultyTransport {
            inner,
            rates,
            rng: fastrand::Rng::with_seed(seed),
            stats: FaultStats::default(),
        }
    }

    /// The counts so far.
    pub fn stats(&self) -> FaultStats {
        self.stats
    }

    fn damage(&mut self, bytes: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(bytes.len() + 4);
        for &b in bytes {
            self.stats.bytes += 1;
            let r = self.rng.f64();
            let FaultRates {
                flip,
                drop,
                duplicate,
            } = self.rates;
            if r < flip {
                out.push(b ^ (1 << self.rng.u8(..8)));
            } else if r < flip + drop {
                // lost
            } else if r < flip + drop + duplicate {
                out.extend([b, b]);
            } else {
                out.push(b);
                continue;
            }
            self.stats.faults += 1;
        }
        out
    }
}

impl Transport for FaultyTransport {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        let damaged = self.damage(bytes);
        self.inner.write_all(&damaged)
    }

    fn read(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        // Read at most half the buffer so a duplicated byte still fits.
        let half = (buf.len() / 2).max(1);
        let mut tmp = vec![0u8; half];
        let n = self.inner.read(&mut tmp, timeout)?;
        let damaged = self.damage(&tmp[..n]);
        let n = damaged.len().min(buf.len());
        buf[..n].copy_from_slice(&damaged[..n]);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::Reply;
    use crate::link::{Client, InprocTransport};
    use tracker_core::icd::{Bytes, HostToDevice};

    #[test]
    fn echoes_survive_a_noisy_link_through_retries() {
        let faulty = FaultyTransport::new(
            Box::new(InprocTransport::new()),
            FaultRates::byte_errors(2e-3),
            11,
        );
        let mut client = Client::new(Box::new(faulty));
        client.timeout = Duration::from_millis(20);
        client.retries = 20;
        client.hello().unwrap();
        for i in 0..500u32 {
            let payload: Vec<u8> = (0..(i % 300) as u8).collect();
            let back = client
                .request(&HostToDevice::Echo(Bytes(&payload)))
                .unwrap();
            assert_eq!(back, Reply::Echo(payload), "echo {i}");
        }
        let s = client.stats();
        assert!(s.retries > 0 && s.frames_damaged > 0, "{s:?}");
    }
}
