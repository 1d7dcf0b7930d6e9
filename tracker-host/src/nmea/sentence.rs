//! One line of NMEA 0183 (IEC 61162-1 §7): framed, checksum checked before any field is
//! read, its address split into talker and sentence type.
//!
//! A line is a sentence (`$` parametric, `!` encapsulated such as AIS `!AIVDM`), a
//! recording's annotation (`#` comments, gpsd's `{…}` JSON reports), or blank. A sentence
//! needs a valid `*HH` checksum: a line whose checksum does not match is a
//! [`LineError::BadChecksum`] whatever else is wrong with it, so a damaged time field never
//! reaches a parser.

use std::fmt;

/// Longest line taken, characters. The standard's limit is 82 (with `$` and CR LF); real
/// equipment sends a little more, nothing sends kilobytes.
pub const MAX_LINE_CHARS: usize = 256;

/// A framed, checksum-checked sentence.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sentence<'a> {
    /// `$` or `!`.
    pub start: char,
    /// The talker (`GP`, `GN`, `II`, `SD`, …); empty for a proprietary sentence.
    pub talker: &'a str,
    /// The sentence type (`RMC`, `VDM`, …); for a proprietary sentence the whole address
    /// after `P` (`ASHR`, `FEC`).
    pub kind: &'a str,
    /// True for proprietary sentences (`$P…`).
    pub proprietary: bool,
    /// The data fields after the address, before `*`.
    pub fields: Vec<&'a str>,
}

impl Sentence<'_> {
    /// Field `i` (from 0 after the address), `None` when absent or empty.
    pub fn field(&self, i: usize) -> Option<&str> {
        self.fields.get(i).copied().filter(|f| !f.is_empty())
    }
}

/// What a line is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Line<'a> {
    /// Nothing but white space.
    Blank,
    /// A recording's annotation (`#…`, `{…}`): not a sentence.
    Annotation,
    /// A sentence.
    Sentence(Sentence<'a>),
}

/// Why a line is not a sentence.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineError {
    /// The checksum does not match the line.
    BadChecksum,
    /// Not framed as a sentence; the reason.
    Malformed(&'static str),
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LineError::BadChecksum => f.write_str("bad checksum"),
            LineError::Malformed(why) => write!(f, "malformed: {why}"),
        }
    }
}

/// XOR of the bytes between `$`/`!` and `*`.
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |acc, b| acc ^ b)
}

/// Frames `line` (trailing CR LF and spaces allowed).
///
/// # Errors
/// [`LineError::BadChecksum`] when the checksum does not match; [`LineError::Malformed`] for
/// a line that is too long, not ASCII, without a checksum, or without a valid address.
pub fn parse(line: &str) -> Result<Line<'_>, LineError> {
    let line = line.trim();
    if line.is_empty() {
        return Ok(Line::Blank);
    }
    if line.starts_with('#') || line.starts_with('{') {
        return Ok(Line::Annotation);
    }
    if line.len() > MAX_LINE_CHARS {
        return Err(LineError::Malformed("longer than any sentence"));
    }
    if !line.is_ascii() {
        return Err(LineError::Malformed("not ASCII"));
    }
    let start = match line.as_bytes()[0] {
        b'$' => '$',
        b'!' => '!',
        _ => return Err(LineError::Malformed("does not start with $ or !")),
    };
    let Some((body, sum)) = line[1..].rsplit_once('*') else {
        return Err(LineError::Malformed("no checksum"));
    };
    let Ok(sum) = u8::from_str_radix(sum, 16) else {
        return Err(LineError::Malformed("checksum is not two hex digits"));
    };
    if sum_digits(line) != 2 {
        return Err(LineError::Malformed("checksum is not two hex digits"));
    }
    if checksum(body) != sum {
        return Err(LineError::BadChecksum);
    }
    let mut parts = body.split(',');
    let address = parts.next().unwrap_or_default();
    let fields: Vec<&str> = parts.collect();
    if !address
        .bytes()
        .all(|b| b.is_ascii_uppercase() || b.is_ascii_digit())
    {
        return Err(LineError::Malformed(
            "address is not upper-case letters and digits",
        ));
    }
    if let Some(rest) = address.strip_prefix('P') {
        if rest.is_empty() {
            return Err(LineError::Malformed("empty proprietary address"));
        }
        return Ok(Line::Sentence(Sentence {
            start,
            talker: "",
            kind: rest,
            proprietary: true,
            fields,
        }));
    }
    if address.len() != 5 {
        return Err(LineError::Malformed(
            "address is not a talker and a sentence type",
        ));
    }
    Ok(Line::Sentence(Sentence {
        start,
        talker: &address[..2],
        kind: &address[2..],
        proprietary: false,
        fields,
    }))
}

/// Characters after the last `*`.
fn sum_digits(line: &str) -> usize {
    line.rsplit_once('*').map_or(0, |(_, s)| s.len())
}

/// `$body*HH` with its checksum and CR LF.
pub fn sentence(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body))
}

/// A time of day `hhmmss[.ss]`, s after midnight.
pub fn time_of_day(field: &str) -> Option<f64> {
    if field.len() < 6 || !field.is_char_boundary(6) {
        return None;
    }
    let (hms, frac) = field.split_at(6);
    if !hms.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let n = |i: usize| {
        f64::from(hms.as_bytes()[i] - b'0') * 10.0 + f64::from(hms.as_bytes()[i + 1] - b'0')
    };
    let (h, m, s) = (n(0), n(2), n(4));
    let frac = if frac.is_empty() {
        0.0
    } else {
        let f: f64 = format!("0{frac}").parse().ok()?;
        if !frac.starts_with('.') {
            return None;
        }
        f
    };
    // 60 s admits a leap second.
    (h < 24.0 && m < 60.0 && s <= 60.0).then_some(h * 3600.0 + m * 60.0 + s + frac)
}

/// A latitude or longitude `(d)ddmm.mmmm` with its hemisphere letter, degrees (north and
/// east positive). Leading zeros of the degrees may be missing (B&G sends `516.0582,E` for
/// 005°16.0582′E): the minutes are the last two digits before the point.
pub fn angle(
    value: &str,
    hemisphere: &str,
    positive: char,
    negative: char,
    max_deg: f64,
) -> Option<f64> {
    let v: f64 = value.parse().ok()?;
    if !(v.is_finite() && v >= 0.0) {
        return None;
    }
    let degrees = (v / 100.0).trunc();
    let minutes = v - degrees * 100.0;
    if minutes >= 60.0 {
        return None;
    }
    let a = degrees + minutes / 60.0;
    if a > max_deg {
        return None;
    }
    match hemisphere.chars().next()? {
        c if c == positive => Some(a),
        c if c == negative => Some(-a),
        _ => None,
    }
}

/// A finite number.
pub fn number(field: &str) -> Option<f64> {
    field.parse::<f64>().ok().filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_framed_and_checked_before_anything_is_read() {
        let s = sentence("GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,");
        let Ok(Line::Sentence(g)) = parse(&s) else {
            panic!("{s}")
        };
        assert_eq!(
            (g.talker, g.kind, g.start, g.proprietary),
            ("GP", "GGA", '$', false)
        );
        assert_eq!(g.field(0), Some("092750.000"));
        assert_eq!(g.field(13), None);
        // A corrupt time with the old checksum: a bad checksum, not a malformed time.
        let bad = s.replace("092750", "09X750");
        assert_eq!(parse(&bad), Err(LineError::BadChecksum));
        assert_eq!(parse("  "), Ok(Line::Blank));
        assert_eq!(parse("# a comment"), Ok(Line::Annotation));
        assert_eq!(parse("{\"class\":\"TPV\"}"), Ok(Line::Annotation));
        assert!(matches!(parse("$GPGGA,1,2"), Err(LineError::Malformed(_))));
        assert!(matches!(parse("garbage"), Err(LineError::Malformed(_))));
        assert!(matches!(
            parse(&"$".repeat(300)),
            Err(LineError::Malformed(_))
        ));
        let proprietary = sentence("PASHR,1,2");
        let Ok(Line::Sentence(p)) = parse(&proprietary) else {
            panic!()
        };
        assert!(p.proprietary && p.kind == "ASHR" && p.talker.is_empty());
        let Ok(Line::Sentence(a)) = parse("!AIVDM,1,1,,A,13biI07P000HjtRNKQ89QOwL0003,0*76") else {
            panic!()
        };
        assert_eq!((a.start, a.talker, a.kind), ('!', "AI", "VDM"));
    }

    #[test]
    fn fields_parse_as_the_standard_writes_them() {
        assert_eq!(time_of_day("235959.50"), Some(86_399.5));
        assert_eq!(time_of_day("000000"), Some(0.0));
        assert_eq!(time_of_day("2460"), None);
        assert_eq!(time_of_day("250000"), None);
        assert_eq!(time_of_day("12a456"), None);
        let lat = angle("5321.6802", "N", 'N', 'S', 90.0).unwrap();
        assert!((lat - (53.0 + 21.6802 / 60.0)).abs() < 1e-12);
        let lon = angle("00630.3372", "W", 'E', 'W', 180.0).unwrap();
        assert!((lon + (6.0 + 30.3372 / 60.0)).abs() < 1e-12);
        // B&G's longitude without its leading zeros.
        let lon = angle("516.0582", "E", 'E', 'W', 180.0).unwrap();
        assert!((lon - (5.0 + 16.0582 / 60.0)).abs() < 1e-12);
        assert_eq!(angle("9100.0", "N", 'N', 'S', 90.0), None);
        assert_eq!(angle("5361.0", "N", 'N', 'S', 90.0), None);
        assert_eq!(angle("5300.0", "X", 'N', 'S', 90.0), None);
        assert_eq!(number("NaN"), None);
    }
}
