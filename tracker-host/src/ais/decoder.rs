//! Lines in, AIS reports out, everything counted: [`AisDecoder`] = fragment parsing
//! ([`super::fragment`]), reassembly ([`super::assemble`]), payload decoding (`aivdm`) and
//! reading ([`super::report`]).

use std::collections::BTreeMap;

use aivdm::error::MessageError;

use super::assemble::{Assembler, AssemblyCounts};
use super::fragment::{self, FragmentError};
use super::report::AisReport;

/// What became of the AIS lines.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct AisCounts {
    /// Lines that are (or claim to be) AIS sentences.
    pub sentences: u64,
    /// Sentences refused, by reason.
    pub rejected: BTreeMap<String, u64>,
    /// Whole messages, by type.
    pub messages: BTreeMap<u8, u64>,
    /// Messages of a type the table does not use (binary, safety text, base station, …).
    pub ignored: u64,
    /// Whole messages whose payload does not decode (too short for its type, a type not in
    /// ITU-R M.1371), by reason.
    pub undecodable: BTreeMap<String, u64>,
    /// Reports whose position is outside the globe (a latitude of 91° is "not available"
    /// and not counted here).
    pub off_the_globe: u64,
    /// Messages a few bits short of their type's length, read with the fill bits as data.
    pub short_payloads: u64,
    /// Multi-fragment messages given up.
    pub assembly: AssemblyCounts,
}

impl AisCounts {
    /// Messages decoded, all types.
    pub fn decoded(&self) -> u64 {
        self.messages.values().sum()
    }

    /// Sentences refused, all reasons.
    pub fn rejected_total(&self) -> u64 {
        self.rejected.values().sum()
    }

    /// Adds `other`'s counts (two sources' decoders, as one run's).
    pub fn add(&mut self, other: &AisCounts) {
        self.sentences += other.sentences;
        self.ignored += other.ignored;
        self.off_the_globe += other.off_the_globe;
        self.short_payloads += other.short_payloads;
        self.assembly.incomplete += other.assembly.incomplete;
        self.assembly.fragments_dropped += other.assembly.fragments_dropped;
        for (into, from) in [
            (&mut self.rejected, &other.rejected),
            (&mut self.undecodable, &other.undecodable),
        ] {
            for (k, v) in from {
                *into.entry(k.clone()).or_default() += v;
            }
        }
        for (k, v) in &other.messages {
            *self.messages.entry(*k).or_default() += v;
        }
    }
}

impl std::fmt::Display for AisCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} sentences, {} messages decoded, {} of types not used, {} sentences refused{}, {} undecodable{}, {} incomplete",
            self.sentences,
            self.decoded(),
            self.ignored,
            self.rejected_total(),
            reasons(&self.rejected),
            self.undecodable.values().sum::<u64>(),
            reasons(&self.undecodable),
            self.assembly.incomplete
        )
    }
}

/// ` (bad checksum 738, …)`, most first, for counts by reason; empty for none. Without the
/// reasons the text summary said only that sentences were refused (a new user's trial:
/// the reason was in `--summary-json` alone).
fn reasons(by_reason: &BTreeMap<String, u64>) -> String {
    let mut all: Vec<(&String, &u64)> = by_reason.iter().filter(|(_, n)| **n > 0).collect();
    if all.is_empty() {
        return String::new();
    }
    all.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
    let words: Vec<String> = all.iter().map(|(why, n)| format!("{why} {n}")).collect();
    format!(" ({})", words.join(", "))
}

/// The decoder. Bounded memory: the assembler's, and nothing else kept.
#[derive(Clone, Debug, Default)]
pub struct AisDecoder {
    assembler: Assembler,
    counts: AisCounts,
}

impl AisDecoder {
    /// A decoder with nothing pending.
    pub fn new() -> Self {
        Self::default()
    }

    /// The counts so far.
    pub fn counts(&self) -> AisCounts {
        let mut c = self.counts.clone();
        c.assembly = self.assembler.counts();
        c
    }

    /// Takes one line (an AIS sentence, else ignored and not counted); the report once a
    /// message is whole and of a type the table uses.
    pub fn feed(&mut self, line: &str) -> Option<AisReport> {
        if !fragment::is_ais(line) {
            return None;
        }
        self.counts.sentences += 1;
        let f = match fragment::parse(line) {
            Ok(f) => f,
            Err(e) => {
                self.reject(e);
                return None;
            }
        };
        let whole = self.assembler.push(f)?;
        // A payload a few bits short of its type's length (gpsd's corpus has a type 1 of 163
        // bits) is read with its fill bits as data, as pyais and gpsd read it: the bits
        // missing are the radio status at the end, which the table does not use.
        let decoded =
            aivdm::decode_payload(whole.payload.as_bytes(), whole.fill_bits).or_else(|e| match e {
                aivdm::AisError::Bit(_) | aivdm::AisError::Message(MessageError::Bit(_))
                    if whole.fill_bits > 0 =>
                {
                    let m = aivdm::decode_payload(whole.payload.as_bytes(), 0)?;
                    self.counts.short_payloads += 1;
                    Ok(m)
                }
                e => Err(e),
            });
        let m = match decoded {
            Ok(m) => m,
            Err(e) => {
                *self
                    .counts
                    .undecodable
                    .entry(undecodable_reason(&e).to_string())
                    .or_default() += 1;
                return None;
            }
        };
        let Some(r) = AisReport::of(&m, whole.own_ship) else {
            self.counts.ignored += 1;
            return None;
        };
        *self.counts.messages.entry(r.msg_type).or_default() += 1;
        if r.position_deg.is_none() && m.position().is_some() {
            self.counts.off_the_globe += 1;
        }
        Some(r)
    }

    fn reject(&mut self, e: FragmentError) {
        *self
            .counts
            .rejected
            .entry(e.reason().to_string())
            .or_default() += 1;
    }
}

fn undecodable_reason(e: &aivdm::AisError) -> &'static str {
    match e {
        aivdm::AisError::Message(MessageError::UnknownMessageType(_)) => "unknown message type",
        aivdm::AisError::Message(MessageError::InvalidEnumValue { .. }) => "fields out of range",
        aivdm::AisError::Message(MessageError::Bit(_)) | aivdm::AisError::Bit(_) => {
            "payload too short for its type"
        }
        _ => "payload not decodable",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text summary says why sentences were refused, most first, as the JSON does.
    #[test]
    fn the_counts_say_why_sentences_were_refused() {
        let mut d = AisDecoder::new();
        assert!(!d.counts().to_string().contains("refused ("));
        for _ in 0..2 {
            assert!(d
                .feed("!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*00")
                .is_none());
        }
        assert!(d
            .feed("!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D")
            .is_none());
        let text = d.counts().to_string();
        assert!(
            text.contains("3 sentences refused (bad checksum 2, "),
            "{text}"
        );
    }
}
