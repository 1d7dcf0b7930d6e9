//! Why a packet or a spoke was skipped, and how often: every decoder counts what it refuses
//! by kind instead of failing, so one bad packet costs only itself.

use std::fmt;

/// What was wrong with a packet (or with one spoke inside a Navico frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Fault {
    /// Shorter than its fixed header, or than the length its own fields announce.
    Truncated,
    /// Its length does not fit the format (a Navico frame not 8 + k · 536 bytes; a Garmin
    /// length field that disagrees with the datagram).
    BadLength,
    /// Not a packet type the decoder knows (a Garmin type other than 0x0998).
    UnknownType,
    /// A Navico spoke whose header length byte is not 24.
    BadSpokeHeader,
    /// A Navico spoke whose status byte is not one that carries a picture (0x82 at transmit
    /// start and before a range change, or anything unknown).
    Status,
    /// An angle outside the rotation (Navico raw > 4095, Garmin ≥ 360°).
    BadAngle,
    /// No usable range: the samples could not be placed in metres.
    NoRange,
    /// A spoke with no samples.
    NoSamples,
}

impl Fault {
    /// Every kind, in the order counts are kept and printed.
    pub const ALL: [Fault; 8] = [
        Fault::Truncated,
        Fault::BadLength,
        Fault::UnknownType,
        Fault::BadSpokeHeader,
        Fault::Status,
        Fault::BadAngle,
        Fault::NoRange,
        Fault::NoSamples,
    ];

    /// A short snake_case name, for tables and logs.
    pub fn name(self) -> &'static str {
        match self {
            Fault::Truncated => "truncated",
            Fault::BadLength => "bad_length",
            Fault::UnknownType => "unknown_type",
            Fault::BadSpokeHeader => "bad_spoke_header",
            Fault::Status => "status",
            Fault::BadAngle => "bad_angle",
            Fault::NoRange => "no_range",
            Fault::NoSamples => "no_samples",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Counts of faults by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FaultCounts {
    counts: [u64; Fault::ALL.len()],
}

impl FaultCounts {
    /// Counts one more `fault`.
    pub fn add(&mut self, fault: Fault) {
        if let Some(c) = self.counts.get_mut(fault.index()) {
            *c += 1;
        }
    }

    /// How many of `fault`.
    pub fn get(&self, fault: Fault) -> u64 {
        self.counts.get(fault.index()).copied().unwrap_or(0)
    }

    /// All faults together.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// The kinds seen at least once, with their counts.
    pub fn nonzero(&self) -> Vec<(Fault, u64)> {
        Fault::ALL
            .iter()
            .map(|&f| (f, self.get(f)))
            .filter(|&(_, n)| n > 0)
            .collect()
    }
}

impl fmt::Display for FaultCounts {
    /// `none`, or `truncated 3, status 2`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let seen = self.nonzero();
        if seen.is_empty() {
            return f.write_str("none");
        }
        for (i, (fault, n)) in seen.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{fault} {n}")?;
        }
        Ok(())
    }
}

/// Little-endian reads that return `None` past the end, so a short packet is a fault and
/// never a panic.
pub(crate) fn le_u16(bytes: &[u8], offset: usize) -> Option<u16> {
    let b = bytes.get(offset..offset.checked_add(2)?)?;
    Some(u16::from_le_bytes(b.try_into().ok()?))
}

/// See [`le_u16`].
pub(crate) fn le_u32(bytes: &[u8], offset: usize) -> Option<u32> {
    let b = bytes.get(offset..offset.checked_add(4)?)?;
    Some(u32::from_le_bytes(b.try_into().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_by_kind_and_prints_them() {
        let mut c = FaultCounts::default();
        assert_eq!(c.to_string(), "none");
        c.add(Fault::Status);
        c.add(Fault::Truncated);
        c.add(Fault::Status);
        assert_eq!(c.get(Fault::Status), 2);
        assert_eq!(c.total(), 3);
        assert_eq!(c.to_string(), "truncated 1, status 2");
    }

    #[test]
    fn reads_past_the_end_are_none() {
        let b = [1u8, 2, 3];
        assert_eq!(le_u16(&b, 1), Some(0x0302));
        assert_eq!(le_u16(&b, 2), None);
        assert_eq!(le_u32(&b, 0), None);
        assert_eq!(le_u16(&b, usize::MAX), None);
    }
}
