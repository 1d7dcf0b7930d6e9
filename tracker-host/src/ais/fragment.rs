//! One `!xxVDM`/`!xxVDO` sentence as a fragment of an AIS message (IEC 61162-1 §8.3.92–93):
//! framing and checksum by [`crate::nmea::sentence`](mod@crate::nmea::sentence), the fields read here.
//!
//! Fields after the address: fragment count (1–9), fragment number, sequential message id
//! (0–9, empty for a one-fragment message), channel (`A`/`B`, `1`/`2`, or empty), the
//! six-bit armoured payload, the fill bits (0–5). B&G/Navico GoFree units send one more
//! field after the fill bits (measured on `signalk-gofree-merrimac.log`: always `0`); it is
//! accepted and ignored. Anything before the `!` (a receiver's time stamp, a tag block) is
//! skipped.

use crate::nmea::sentence::{self, Line};

/// One fragment, owned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fragment {
    /// `VDO`: own ship's transponder; `VDM`: another station.
    pub own_ship: bool,
    /// Fragments in the message, 1–9.
    pub count: u8,
    /// This one's number, 1..=count.
    pub number: u8,
    /// Sequential message id, 0–9, tying a multi-fragment message's pieces together.
    pub sequence: Option<u8>,
    /// Radio channel, as sent (`A`, `B`, `1`, `2`; 0 when empty).
    pub channel: u8,
    /// The armoured payload (six bits a character).
    pub payload: String,
    /// Bits to drop from the end of the last fragment's payload, 0–5.
    pub fill_bits: u8,
}

/// Why a line is not an AIS fragment (each counted apart).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub enum FragmentError {
    /// The checksum does not match.
    Checksum,
    /// Not a sentence, or not a VDM/VDO one.
    NotAis,
    /// Too few fields, or a count, number, sequence or fill bits out of range.
    Fields,
    /// A payload character outside the six-bit armour (`0`–`W`, `` ` ``–`w`), or empty.
    Armour,
}

impl FragmentError {
    /// The reason, as the operator reads it.
    pub fn reason(self) -> &'static str {
        match self {
            FragmentError::Checksum => "bad checksum",
            FragmentError::NotAis => "not a VDM/VDO sentence",
            FragmentError::Fields => "fragment fields out of range",
            FragmentError::Armour => "payload not six-bit armour",
        }
    }
}

/// True for a line that is, or claims to be, an AIS sentence (`!xxVDM`, `!xxVDO`).
pub fn is_ais(line: &str) -> bool {
    line.find('!')
        .and_then(|i| line.get(i + 3..i + 6))
        .is_some_and(|f| f == "VDM" || f == "VDO")
}

/// Reads one line as a fragment.
///
/// # Errors
/// A [`FragmentError`] saying why it is not one.
pub fn parse(line: &str) -> Result<Fragment, FragmentError> {
    let start = line.find('!').ok_or(FragmentError::NotAis)?;
    let s = match sentence::parse(&line[start..]) {
        Ok(Line::Sentence(s)) => s,
        Err(sentence::LineError::BadChecksum) => return Err(FragmentError::Checksum),
        _ => return Err(FragmentError::NotAis),
    };
    let own_ship = match s.kind {
        "VDO" => true,
        "VDM" => false,
        _ => return Err(FragmentError::NotAis),
    };
    if s.start != '!' || !(6..=7).contains(&s.fields.len()) {
        return Err(FragmentError::Fields);
    }
    let digit = |f: &str| -> Option<u8> {
        (f.len() == 1)
            .then(|| f.as_bytes()[0])
            .filter(u8::is_ascii_digit)
            .map(|b| b - b'0')
    };
    let count = digit(s.fields[0])
        .filter(|c| *c >= 1)
        .ok_or(FragmentError::Fields)?;
    let number = digit(s.fields[1])
        .filter(|n| (1..=count).contains(n))
        .ok_or(FragmentError::Fields)?;
    let sequence = match s.fields[2] {
        "" => None,
        f => Some(digit(f).ok_or(FragmentError::Fields)?),
    };
    let channel = match s.fields[3].as_bytes() {
        [] => 0,
        [c] => *c,
        _ => return Err(FragmentError::Fields),
    };
    let payload = s.fields[4];
    if payload.is_empty() || !payload.bytes().all(is_armour) {
        return Err(FragmentError::Armour);
    }
    let fill_bits = digit(s.fields[5])
        .filter(|f| *f <= 5)
        .ok_or(FragmentError::Fields)?;
    Ok(Fragment {
        own_ship,
        count,
        number,
        sequence,
        channel,
        payload: payload.to_string(),
        fill_bits,
    })
}

/// ITU-R M.1371 six-bit armour: `0`..=`W` and `` ` ``..=`w`.
fn is_armour(b: u8) -> bool {
    (b'0'..=b'W').contains(&b) || (b'`'..=b'w').contains(&b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_read_and_bad_ones_named() {
        let f =
            parse("!AIVDM,2,1,9,B,55R3Vn82=ILTQ3KKS>1<D60Dq@E918U<F222221J1`?164vc03S1CCAD,0*2A")
                .unwrap();
        assert_eq!(
            (
                f.own_ship,
                f.count,
                f.number,
                f.sequence,
                f.channel,
                f.fill_bits
            ),
            (false, 2, 1, Some(9), b'B', 0)
        );
        // GoFree's extra field after the fill bits.
        let g = parse("!AIVDM,1,1,1,,13aI8e?P00PGpU:NR6s00?vT2000,0,0*1C").unwrap();
        assert_eq!((g.sequence, g.channel), (Some(1), 0));
        // A prefix before the sentence is skipped.
        assert!(parse("12:00:01 !AIVDM,1,1,,B,13aDp<PP000IwSlN?Wm@0?wN2<1T,0*29").is_ok());
        assert_eq!(
            parse("!AIVDM,1,1,,B,13aDp<PP000IwSlN?Wm@0?wN2<1T,0*28"),
            Err(FragmentError::Checksum)
        );
        let body = |b: &str| format!("!{b}*{:02X}", sentence::checksum(b));
        assert_eq!(
            parse(&body("AIVDM,1,1,,B,13aDp,7")),
            Err(FragmentError::Fields)
        );
        assert_eq!(
            parse(&body("AIVDM,2,3,,B,13aDp,0")),
            Err(FragmentError::Fields)
        );
        assert_eq!(
            parse(&body("AIVDM,0,0,,B,13aDp,0")),
            Err(FragmentError::Fields)
        );
        assert_eq!(
            parse(&body("AIVDM,1,1,,B,13a~p,0")),
            Err(FragmentError::Armour)
        );
        assert_eq!(parse(&body("AIVDM,1,1,,B,,0")), Err(FragmentError::Armour));
        assert_eq!(parse(&body("AIVDM,1,1,,B")), Err(FragmentError::Fields));
        assert_eq!(
            parse(&body("GPGGA,1,1,,B,13aDp,0")),
            Err(FragmentError::NotAis)
        );
        assert!(is_ais("!AIVDO,1,1,,,x,0*00") && !is_ais("$GPRMC,") && !is_ais("!"));
    }
}
