//! NMEA 0183 text inside a capture: the lines of UDP datagrams and of TCP streams on the
//! ports a bridge network uses for it, with the capture time of each, so that own ship can
//! come from the same recording as the spokes.
//!
//! UDP: each datagram is split into lines (a last line without an end of line counts too).
//! TCP: a stream's payload is joined in sequence-number order **as it arrives**: a segment
//! that repeats bytes already taken (a retransmission) gives only its new bytes; a segment
//! that starts past the next expected byte (one was lost, or came out of order) is a gap:
//! the partial line before it is dropped and the stream resumes at the next end of line; a
//! segment that arrives late after such a gap is dropped as a retransmission. There is no
//! reordering buffer, so out-of-order segments cost their lines (counted in
//! [`NmeaTextStats::tcp_gaps`]); lines split across segments are joined. A stream first met
//! mid-way (no SYN seen), or resumed after a gap, starts at its first byte when that starts
//! a line (`$`, `!`, `\`), else after its first end of line.
//!
//! Kept: lines that start with `$`, `!` or `\` (a TAG block) and are printable ASCII, with
//! the end of line and surrounding blanks removed. Checksums are not checked here: the
//! own-ship parser does that and counts the bad ones.

use std::collections::{HashMap, VecDeque};
use std::net::SocketAddrV4;

/// Longest line kept, bytes (NMEA allows 82; AIS and proprietary lines run longer).
pub const MAX_LINE: usize = 1024;
/// TCP streams followed at once; beyond it the stream heard from longest ago is dropped.
pub const MAX_FLOWS: usize = 64;
/// Lines held until they are taken; beyond it the oldest are dropped.
pub const MAX_PENDING_LINES: usize = 100_000;

/// One line of NMEA text found in a capture.
#[derive(Clone, Debug, PartialEq)]
pub struct NmeaLine {
    /// Capture time of the datagram or segment that completed the line, s since 1970.
    pub time_s: f64,
    /// The port that matched (source or destination).
    pub port: u16,
    /// True when it came over TCP.
    pub tcp: bool,
    /// The line, without its end of line.
    pub text: String,
}

/// What the NMEA extraction has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NmeaTextStats {
    /// Lines kept.
    pub lines: u64,
    /// Non-blank lines that were not NMEA text (binary, not starting with `$`, `!` or `\`).
    pub not_nmea: u64,
    /// Lines longer than [`MAX_LINE`], dropped.
    pub overlong: u64,
    /// TCP gaps (a segment past the next expected byte): the partial line dropped.
    pub tcp_gaps: u64,
    /// TCP segments whose bytes had all been taken already.
    pub tcp_retransmissions: u64,
    /// TCP streams dropped to stay within [`MAX_FLOWS`].
    pub flows_dropped: u64,
    /// Lines dropped because nobody took them (beyond [`MAX_PENDING_LINES`]).
    pub lines_dropped: u64,
}

/// A TCP stream's direction: source and destination.
type FlowKey = (SocketAddrV4, SocketAddrV4);

#[derive(Debug, Default)]
struct Flow {
    /// The next sequence number expected, once known.
    next_seq: Option<u32>,
    /// Bytes of the line in progress.
    partial: Vec<u8>,
    /// Skip to the next end of line before keeping text (joined mid-stream, after a gap,
    /// or after an overlong line).
    resync: bool,
    /// The last time a segment came, s (to drop the stalest flow).
    last_s: f64,
}

/// Turns datagrams and segments into lines.
#[derive(Debug, Default)]
pub struct NmeaText {
    ports: Vec<u16>,
    flows: HashMap<FlowKey, Flow>,
    lines: VecDeque<NmeaLine>,
    stats: NmeaTextStats,
}

impl NmeaText {
    /// Extraction for these ports (matched as source or destination).
    pub fn new(ports: &[u16]) -> Self {
        NmeaText {
            ports: ports.to_vec(),
            ..Self::default()
        }
    }

    /// The port of `a` or `b` that is an NMEA port, if either is.
    pub fn port_of(&self, a: u16, b: u16) -> Option<u16> {
        [b, a].into_iter().find(|p| self.ports.contains(p))
    }

    /// What it has seen.
    pub fn stats(&self) -> &NmeaTextStats {
        &self.stats
    }

    /// The lines found since the last call, oldest first.
    pub fn take_lines(&mut self) -> Vec<NmeaLine> {
        self.lines.drain(..).collect()
    }

    /// A UDP datagram's payload on an NMEA port.
    pub fn datagram(&mut self, time_s: f64, port: u16, payload: &[u8]) {
        for line in payload.split(|&b| b == b'\n') {
            self.line(time_s, port, false, line);
        }
    }

    /// A TCP segment on an NMEA port: its flow, sequence number, flags and payload.
    pub fn segment(&mut self, time_s: f64, port: u16, key: FlowKey, seg: Segment<'_>) {
        if !self.flows.contains_key(&key) && self.flows.len() >= MAX_FLOWS {
            let stalest = self
                .flows
                .iter()
                .min_by(|a, b| a.1.last_s.total_cmp(&b.1.last_s))
                .map(|(k, _)| *k);
            if let Some(k) = stalest {
                self.flows.remove(&k);
                self.stats.flows_dropped += 1;
            }
        }
        let flow = self.flows.entry(key).or_insert_with(|| Flow {
            resync: !seg.syn && !starts_line(seg.payload),
            ..Flow::default()
        });
        flow.last_s = time_s;
        if seg.syn {
            // The SYN takes one sequence number; data starts after it.
            flow.next_seq = Some(seg.seq.wrapping_add(1));
            flow.partial.clear();
            flow.resync = false;
            return;
        }
        let mut payload = seg.payload;
        if let Some(next) = flow.next_seq {
            let ahead = seg.seq.wrapping_sub(next) as i32;
            if ahead > 0 {
                self.stats.tcp_gaps += 1;
                flow.partial.clear();
                flow.resync = !starts_line(payload);
            } else if ahead < 0 {
                let seen = ahead.unsigned_abs() as usize;
                match payload.get(seen..) {
                    Some(rest) if !rest.is_empty() => payload = rest,
                    _ => {
                        self.stats.tcp_retransmissions += 1;
                        return;
                    }
                }
            }
        }
        flow.next_seq = Some(seg.seq.wrapping_add(seg.payload.len() as u32));
        // Lines end at '\n'; the text after the last one waits for the next segment.
        let mut rest = payload;
        let mut complete = Vec::new();
        while let Some(i) = rest.iter().position(|&b| b == b'\n') {
            let (line, after) = rest.split_at(i);
            rest = after.get(1..).unwrap_or(&[]);
            if flow.resync {
                flow.resync = false;
                flow.partial.clear();
                continue;
            }
            let mut whole = std::mem::take(&mut flow.partial);
            whole.extend_from_slice(line);
            complete.push(whole);
        }
        if !flow.resync {
            flow.partial.extend_from_slice(rest);
            if flow.partial.len() > MAX_LINE {
                self.stats.overlong += 1;
                flow.partial.clear();
                flow.resync = true;
            }
        }
        if seg.reset_or_fin {
            // The stream ends: its unfinished line goes with it.
            self.flows.remove(&key);
        }
        for line in complete {
            self.line(time_s, port, true, &line);
        }
    }

    fn line(&mut self, time_s: f64, port: u16, tcp: bool, raw: &[u8]) {
        let text = raw.trim_ascii();
        if text.is_empty() {
            return;
        }
        if text.len() > MAX_LINE {
            self.stats.overlong += 1;
            return;
        }
        let printable = text.iter().all(|b| (0x20..0x7F).contains(b));
        if !printable || !matches!(text.first(), Some(b'$' | b'!' | b'\\')) {
            self.stats.not_nmea += 1;
            return;
        }
        if self.lines.len() >= MAX_PENDING_LINES {
            self.lines.pop_front();
            self.stats.lines_dropped += 1;
        }
        self.stats.lines += 1;
        self.lines.push_back(NmeaLine {
            time_s,
            port,
            tcp,
            // Printable ASCII, so this is the text as it was.
            text: String::from_utf8_lossy(text).into_owned(),
        });
    }
}

/// True when `bytes` starts as an NMEA line does: where a stream met mid-way, or resumed
/// after a gap, can start without losing a line.
fn starts_line(bytes: &[u8]) -> bool {
    matches!(bytes.first(), Some(b'$' | b'!' | b'\\'))
}

/// The parts of a TCP segment the line joining needs.
#[derive(Clone, Copy, Debug)]
pub struct Segment<'a> {
    /// Its sequence number.
    pub seq: u32,
    /// SYN set.
    pub syn: bool,
    /// FIN or RST set: the stream ends (its partial line is dropped).
    pub reset_or_fin: bool,
    /// Its payload.
    pub payload: &'a [u8],
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key() -> FlowKey {
        (
            "10.0.0.1:2000".parse().unwrap(),
            "10.0.0.2:5000".parse().unwrap(),
        )
    }

    fn seg(seq: u32, payload: &[u8]) -> Segment<'_> {
        Segment {
            seq,
            syn: false,
            reset_or_fin: false,
            payload,
        }
    }

    fn texts(n: &mut NmeaText) -> Vec<String> {
        n.take_lines().into_iter().map(|l| l.text).collect()
    }

    #[test]
    fn udp_lines() {
        let mut n = NmeaText::new(&[10110]);
        n.datagram(
            1.0,
            10110,
            b"$GPRMC,1*00\r\n!AIVDM,2*00\r\n\r\n\x01\x02binary\n$HDT",
        );
        assert_eq!(texts(&mut n), ["$GPRMC,1*00", "!AIVDM,2*00", "$HDT"]);
        assert_eq!(n.stats().not_nmea, 1);
        assert_eq!(n.port_of(5000, 10110), Some(10110));
        assert_eq!(n.port_of(5000, 5001), None);
    }

    #[test]
    fn tcp_joins_segments_and_handles_repeats_and_gaps() {
        let mut n = NmeaText::new(&[2000]);
        let syn = Segment {
            seq: 99,
            syn: true,
            reset_or_fin: false,
            payload: &[],
        };
        n.segment(0.0, 2000, key(), syn);
        n.segment(1.0, 2000, key(), seg(100, b"$GPRMC,"));
        n.segment(2.0, 2000, key(), seg(107, b"1*00\r\n$GPG"));
        let lines = n.take_lines();
        assert_eq!(lines.len(), 1);
        assert_eq!(
            (lines[0].time_s, lines[0].text.as_str()),
            (2.0, "$GPRMC,1*00")
        );
        // A retransmission of bytes already taken, then one overlapping new bytes.
        n.segment(3.0, 2000, key(), seg(107, b"1*00\r\n"));
        assert_eq!(n.stats().tcp_retransmissions, 1);
        n.segment(3.0, 2000, key(), seg(113, b"$GPGGA,2*00\r\n"));
        assert_eq!(texts(&mut n), ["$GPGGA,2*00"]);
        // A gap: the partial line is lost, the stream resumes after the next end of line.
        n.segment(4.0, 2000, key(), seg(126, b"$GPG"));
        n.segment(5.0, 2000, key(), seg(140, b"LL,3*00\r\n$GPVTG,4*00\r\n"));
        assert_eq!(texts(&mut n), ["$GPVTG,4*00"]);
        assert_eq!(n.stats().tcp_gaps, 1);
    }

    #[test]
    fn tcp_met_mid_stream_starts_at_a_line() {
        let mut n = NmeaText::new(&[2000]);
        n.segment(0.0, 2000, key(), seg(5000, b"MC,1*00\r\n$GPGGA,2*00\r\n"));
        assert_eq!(texts(&mut n), ["$GPGGA,2*00"]);
        n.segment(0.0, 2000, key(), seg(0, b"x"));
        assert_eq!(n.stats().tcp_retransmissions, 1);
    }

    #[test]
    fn overlong_lines_and_many_flows_stay_bounded() {
        let mut n = NmeaText::new(&[2000]);
        n.segment(0.0, 2000, key(), seg(0, b"\n"));
        let long = vec![b'$'; MAX_LINE + 10];
        n.segment(0.0, 2000, key(), seg(1, &long));
        n.segment(
            0.0,
            2000,
            key(),
            seg(1 + long.len() as u32, b"tail\n$OK*00\n"),
        );
        assert_eq!(texts(&mut n), ["$OK*00"]);
        assert_eq!(n.stats().overlong, 1);
        for i in 0..(MAX_FLOWS as u16 + 5) {
            let k = (SocketAddrV4::new([10, 0, 0, 1].into(), i), key().1);
            n.segment(f64::from(i), 2000, k, seg(0, b"$A*00\n"));
        }
        assert_eq!(n.flows.len(), MAX_FLOWS);
        assert_eq!(n.stats().flows_dropped, 6);
    }
}
