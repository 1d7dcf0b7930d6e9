//! `tracker-host link-check`: proves the link end to end.
//!
//! Handshake; then many echo frames of varied sizes up to the maximum, each compared byte
//! for byte; then deliberately bad input, each case followed by a good frame that must come
//! back intact; finally the device's own counters must agree with what was sent.

use std::time::{Duration, Instant};

use anyhow::{bail, Context};
use tracker_core::frame;
use tracker_core::icd::{
    Bytes, ErrorCode, Header, HostToDevice, MAX_ECHO_BYTES, MAX_ENCODED_FRAME_BYTES,
    PROTOCOL_VERSION,
};

use crate::link::{Client, Reply};

/// Options of the check.
#[derive(Clone, Debug)]
pub struct LinkCheckOptions {
    /// Good echo frames to send.
    pub frames: usize,
    /// Seed for sizes and contents.
    pub seed: u64,
}

/// What the check saw.
#[derive(Clone, Debug, Default)]
pub struct LinkCheckReport {
    /// Good frames sent.
    pub good_sent: usize,
    /// Good frames returned intact.
    pub good_returned: usize,
    /// Bad inputs sent (each a case below).
    pub bad_sent: usize,
    /// Bad inputs the device rejected with an error reply.
    pub bad_rejected: usize,
    /// Round-trip times of the good frames.
    pub rtts: Vec<Duration>,
    /// Failures, in words.
    pub failures: Vec<String>,
}

impl LinkCheckReport {
    /// Every good frame back, every bad one rejected, nothing else wrong.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
            && self.good_returned == self.good_sent
            && self.bad_rejected == self.bad_sent
    }

    fn percentile(&self, p: f64) -> Duration {
        let mut v = self.rtts.clone();
        v.sort();
        v.get(((v.len() as f64 - 1.0) * p).round() as usize)
            .copied()
            .unwrap_or_default()
    }

    /// A human-readable summary.
    pub fn summary(&self) -> String {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        format!(
            "good frames: {} sent, {} returned intact (one after each bad input among them)\n\
             bad inputs:  {} sent, {} rejected with an error\n\
             round trip:  min {:.3} ms, median {:.3} ms, p99 {:.3} ms, max {:.3} ms\n\
             result:      {}",
            self.good_sent,
            self.good_returned,
            self.bad_sent,
            self.bad_rejected,
            ms(self.percentile(0.0)),
            ms(self.percentile(0.5)),
            ms(self.percentile(0.99)),
            ms(self.percentile(1.0)),
            if self.passed() { "PASS" } else { "FAIL" },
        )
    }
}

fn echo_payload(rng: &mut fastrand::Rng, len: usize) -> Vec<u8> {
    // Zeros are common so COBS has work to do.
    (0..len)
        .map(|_| if rng.u8(..4) == 0 { 0 } else { rng.u8(..) })
        .collect()
}

/// Sends one good echo and checks it comes back unchanged.
fn good_echo(
    client: &mut Client,
    rng: &mut fastrand::Rng,
    len: usize,
    report: &mut LinkCheckReport,
) -> bool {
    let payload = echo_payload(rng, len);
    report.good_sent += 1;
    let start = Instant::now();
    match client.request(&HostToDevice::Echo(Bytes(&payload))) {
        Ok(Reply::Echo(back)) if back == payload => {
            report.rtts.push(start.elapsed());
            report.good_returned += 1;
            true
        }
        Ok(other) => {
            report
                .failures
                .push(format!("echo of {len} B came back as {other}"));
            false
        }
        Err(e) => {
            report.failures.push(format!("echo of {len} B: {e}"));
            false
        }
    }
}

/// One kind of bad input: its name, its bytes, and the error code(s) it must draw.
struct BadCase {
    name: &'static str,
    bytes: Vec<u8>,
    expect: fn(ErrorCode) -> bool,
}

fn bad_cases(client: &mut Client, rng: &mut fastrand::Rng) -> anyhow::Result<Vec<BadCase>> {
    let header = |c: &mut Client| Header {
        protocol: PROTOCOL_VERSION,
        request_id: c.allocate_id(),
    };
    let h = header(client);
    let good = client.encode(&h, &HostToDevice::Echo(Bytes(&echo_payload(rng, 300))))?;
    let mut cases = Vec::new();

    // A flipped bit in the middle of a frame: CRC (or COBS, if it hits a length byte).
    for bit in [0usize, 5, 2000] {
        let mut bytes = good.clone();
        let i = 1 + (bit / 8) % (bytes.len() - 2);
        bytes[i] ^= 1 << (bit % 8);
        if bytes[i] == 0 {
            bytes[i] = 0x5a; // a flip that makes a delimiter would split the case in two
        }
        cases.push(BadCase {
            name: "bit flip",
            bytes,
            expect: |e| matches!(e, ErrorCode::BadCrc | ErrorCode::BadCobs),
        });
    }
    let mut truncated = good[..good.len() / 2].to_vec();
    truncated.push(0);
    cases.push(BadCase {
        name: "truncated frame",
        bytes: truncated,
        expect: |e| matches!(e, ErrorCode::BadCrc | ErrorCode::BadCobs),
    });
    let mut garbage: Vec<u8> = (0..57).map(|_| rng.u8(1..)).collect();
    garbage.push(0);
    cases.push(BadCase {
        name: "garbage between frames",
        bytes: garbage,
        expect: |e| matches!(e, ErrorCode::BadCrc | ErrorCode::BadCobs),
    });
    let mut oversize = vec![0x41u8; 3 * MAX_ENCODED_FRAME_BYTES];
    oversize.push(0);
    cases.push(BadCase {
        name: "oversize frame",
        bytes: oversize,
        expect: |e| e == ErrorCode::Oversize,
    });
    let wrong = Header {
        protocol: PROTOCOL_VERSION.wrapping_add(1),
        request_id: client.allocate_id(),
    };
    cases.push(BadCase {
        name: "wrong protocol version",
        bytes: client.encode(&wrong, &HostToDevice::Hello)?,
        expect: |e| {
            e == ErrorCode::VersionMismatch {
                device: PROTOCOL_VERSION,
            }
        },
    });
    // A message index no version of ours has used, in an otherwise perfect frame.
    let mut out = vec![0u8; MAX_ENCODED_FRAME_BYTES];
    let h = header(client);
    let n = frame::encode(&h, &250u32, &mut out)?;
    let mut unknown = vec![0];
    unknown.extend_from_slice(&out[..n]);
    cases.push(BadCase {
        name: "unknown message",
        bytes: unknown,
        expect: |e| e == ErrorCode::UnknownMessage,
    });
    Ok(cases)
}

/// Runs the check over `client`.
///
/// # Errors
/// The link failing outright (a transport error); failed checks are reported in the result, not as errors.
pub fn run(client: &mut Client, opts: &LinkCheckOptions) -> anyhow::Result<LinkCheckReport> {
    let mut rng = fastrand::Rng::with_seed(opts.seed);
    let mut report = LinkCheckReport::default();
    // Every frame must make it on the first try: no retries hide a fault here.
    client.retries = 0;

    let info = client.hello().context("handshake")?;
    crate::cli::say(&format!(
        "device: {} (protocol {}, max frame {} B, boot id {:#010x})\n",
        info.firmware, info.protocol, info.max_frame_bytes, info.boot_id
    ));

    // Sizes: the edges, then a spread over the whole range.
    let mut sizes = vec![0, 1, 253, 254, 255, MAX_ECHO_BYTES - 1, MAX_ECHO_BYTES];
    while sizes.len() < opts.frames {
        sizes.push(rng.usize(..=MAX_ECHO_BYTES));
    }
    sizes.truncate(opts.frames);
    for &len in &sizes {
        good_echo(client, &mut rng, len, &mut report);
    }

    let stats_before = match client.request(&HostToDevice::GetStats)? {
        Reply::Stats(s) => s,
        other => bail!("GetStats answered {other}"),
    };
    for case in bad_cases(client, &mut rng)? {
        report.bad_sent += 1;
        client.send_raw(&case.bytes)?;
        // The error reply arrives before the reply to the good frame that follows.
        let deadline = Instant::now() + client.timeout;
        match client.next_frame(deadline)? {
            Some((_, Reply::Error(code))) if (case.expect)(code) => {
                report.bad_rejected += 1;
            }
            other => report.failures.push(format!(
                "{}: expected an error reply, got {}",
                case.name,
                other.map_or("nothing".to_string(), |(_, reply)| reply.to_string())
            )),
        }
        let len = rng.usize(..=MAX_ECHO_BYTES);
        if !good_echo(client, &mut rng, len, &mut report) {
            report
                .failures
                .push(format!("the link did not recover after: {}", case.name));
        }
    }
    let stats = match client.request(&HostToDevice::GetStats)? {
        Reply::Stats(s) => s,
        other => bail!("GetStats answered {other}"),
    };
    let rejected = stats.rejected().wrapping_sub(stats_before.rejected()) as usize;
    if rejected != report.bad_sent {
        report.failures.push(format!(
            "device counted {rejected} rejected frames, {} bad inputs were sent",
            report.bad_sent
        ));
    }
    crate::cli::say(&format!(
        "device counters: {} frames ok, {} rejected (cobs {}, crc {}, oversize {}, malformed {}, unknown {}, version {}), {} frames out\n",
        stats.frames_ok,
        stats.rejected(),
        stats.bad_cobs,
        stats.bad_crc,
        stats.oversize,
        stats.malformed,
        stats.unknown_message,
        stats.version_mismatch,
        stats.frames_out
    ));
    let cs = client.stats();
    if cs.frames_damaged != 0 || cs.unmatched != 0 {
        report.failures.push(format!(
            "host saw {} damaged and {} unmatched replies",
            cs.frames_damaged, cs.unmatched
        ));
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::InprocTransport;

    #[test]
    fn inproc_link_passes() {
        let mut client = Client::new(Box::new(InprocTransport::new()));
        let report = run(
            &mut client,
            &LinkCheckOptions {
                frames: 200,
                seed: 1,
            },
        )
        .unwrap();
        assert!(
            report.passed(),
            "{}\n{:?}",
            report.summary(),
            report.failures
        );
        assert_eq!(report.good_sent, 200 + report.bad_sent);
        assert_eq!(report.bad_sent, 8);
    }

    /// A line with junk on it before anything: garbage into the device's UART and
    /// garbage (half a frame, noise) ahead of its first reply.
    struct JunkFirst {
        inner: InprocTransport,
        to_device: Option<Vec<u8>>,
        to_host: Option<Vec<u8>>,
    }

    impl crate::link::Transport for JunkFirst {
        fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
            if let Some(junk) = self.to_device.take() {
                self.inner.write_all(&junk)?;
            }
            self.inner.write_all(bytes)
        }

        fn read(&mut self, buf: &mut [u8], timeout: Duration) -> std::io::Result<usize> {
            if let Some(junk) = self.to_host.take() {
                let n = junk.len().min(buf.len());
                buf[..n].copy_from_slice(&junk[..n]);
                return Ok(n);
            }
            self.inner.read(buf, timeout)
        }
    }

    #[test]
    fn junk_on_the_line_before_the_handshake_is_survived_at_once() {
        let junk: Vec<u8> = (0..700u32).map(|i| (i * 37 % 251) as u8 | 1).collect();
        let mut client = Client::new(Box::new(JunkFirst {
            inner: InprocTransport::new(),
            to_device: Some(junk.clone()),
            to_host: Some(junk),
        }));
        let report = run(
            &mut client,
            &LinkCheckOptions {
                frames: 50,
                seed: 2,
            },
        )
        .unwrap();
        assert!(
            report.passed(),
            "{}\n{:?}",
            report.summary(),
            report.failures
        );
        assert!(client.stats().resyncs >= 1);
    }
}
