//! Garmin xHD spokes (GMR xHD, xHD2, Fantom; UDP 239.254.2.0:50102): one spoke a datagram,
//! a 36-byte header and then one byte a sample.
//!
//! | offset | type | field |
//! |---|---|---|
//! | 0 | u32 | packet type, 0x0998 |
//! | 4 | u32 | bytes after these 8 (the datagram's length − 8) |
//! | 12 | u16 | angle in 1/32° from the bow, clockwise (+8 a spoke: 1,440 spokes a rotation) |
//! | 16 | u32 | the range the user chose, m |
//! | 20 | u32 | the range the samples span, m ("display meters", 1.125 × the chosen range) |
//! | 26 | u16 | sample count N |
//! | 36 | N × u8 | samples, 0 (nothing) to 255 |
//!
//! The spoke's range is the span (`u32@20`), as radar_pi scales its picture: 4,167 m over
//! 695 samples on the capture, 6.0 m a sample (mayara's decoder uses the chosen range; no
//! capture with AIS settles it). `u16@10`, often read as a sample count, is not one (723
//! against 695 samples). There is no heading: spokes are head-up. The legacy Garmin HD
//! format (0x02A3, 1-bit samples) is not decoded and counts as [`Fault::UnknownType`].

use tracker_core::radar::Spoke;

use super::decoder::SpokeDecoder;
use super::fault::{le_u16, le_u32, Fault, FaultCounts};

/// The xHD spoke packet type.
pub const SPOKE_TYPE: u32 = 0x0998;
/// Bytes before the samples.
pub const HEADER_LEN: usize = 36;
/// Spokes in a rotation.
pub const SPOKES_PER_ROTATION: u16 = 1440;
/// Angle units (1/32°) in a rotation.
pub const ANGLE_UNITS: u32 = 360 * 32;
/// The strongest sample.
pub const MAX_SAMPLE: u8 = 255;

/// True when `payload` starts with the xHD spoke type: how a capture's Garmin stream is
/// recognised, by structure rather than port.
pub fn looks_like_spoke(payload: &[u8]) -> bool {
    payload.len() >= 8 && le_u32(payload, 0) == Some(SPOKE_TYPE)
}

/// One spoke header, read and checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpokeHeader {
    /// Angle in 1/32°, `0..11520`.
    pub angle_raw: u16,
    /// The range the user chose, m.
    pub selected_range_m: u32,
    /// The range the samples span, m (> 0).
    pub span_m: u32,
    /// Samples (> 0).
    pub samples: usize,
}

impl SpokeHeader {
    /// The spoke's index in the rotation, `0..1440`.
    pub fn angle(&self) -> u16 {
        self.angle_raw / 8
    }
}

/// Reads and checks a spoke datagram's header.
///
/// # Errors
/// The [`Fault`]: another packet type, shorter than the header or than its samples, a
/// length field that disagrees with the datagram, an angle of 360° or more, no span, no
/// samples.
pub fn parse_header(payload: &[u8]) -> Result<SpokeHeader, Fault> {
    let kind = le_u32(payload, 0).ok_or(Fault::Truncated)?;
    if kind != SPOKE_TYPE {
        return Err(Fault::UnknownType);
    }
    if payload.len() < HEADER_LEN {
        return Err(Fault::Truncated);
    }
    let announced = le_u32(payload, 4).ok_or(Fault::Truncated)?;
    let samples = usize::from(le_u16(payload, 26).ok_or(Fault::Truncated)?);
    if HEADER_LEN + samples > payload.len() {
        return Err(Fault::Truncated);
    }
    if usize::try_from(announced).ok() != Some(payload.len() - 8) {
        return Err(Fault::BadLength);
    }
    if samples == 0 {
        return Err(Fault::NoSamples);
    }
    let angle_raw = le_u16(payload, 12).ok_or(Fault::Truncated)?;
    if u32::from(angle_raw) >= ANGLE_UNITS {
        return Err(Fault::BadAngle);
    }
    let span_m = le_u32(payload, 20).ok_or(Fault::Truncated)?;
    if span_m == 0 {
        return Err(Fault::NoRange);
    }
    Ok(SpokeHeader {
        angle_raw,
        selected_range_m: le_u32(payload, 16).ok_or(Fault::Truncated)?,
        span_m,
        samples,
    })
}

/// What a Garmin decoder has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GarminCounts {
    /// Spokes handed out (one a datagram).
    pub spokes: u64,
    /// Datagrams refused, by kind.
    pub faults: FaultCounts,
    /// The range the user chose on the last spoke, m.
    pub selected_range_m: Option<u32>,
}

/// Decodes Garmin xHD spoke datagrams into [`Spoke`]s that borrow the decoder's sample
/// buffer: [`feed`](Self::feed), then [`advance`](Self::advance) (true once) and
/// [`spoke`](Self::spoke); or [`decode`](Self::decode).
#[derive(Clone, Debug, Default)]
pub struct GarminDecoder {
    samples: Vec<u8>,
    current: Option<SpokeHeader>,
    pending: bool,
    time_ms: u64,
    counts: GarminCounts,
}

impl GarminDecoder {
    /// A decoder.
    pub fn new() -> Self {
        Self::default()
    }

    /// What the decoder has seen.
    pub fn counts(&self) -> &GarminCounts {
        &self.counts
    }

    /// Takes a datagram taken at `time_ms`; returns the spokes in it (1).
    ///
    /// # Errors
    /// The datagram is refused and counted, with the [`Fault`] of [`parse_header`].
    pub fn feed(&mut self, payload: &[u8], time_ms: u64) -> Result<usize, Fault> {
        self.current = None;
        self.pending = false;
        let h = match parse_header(payload) {
            Ok(h) => h,
            Err(f) => {
                self.counts.faults.add(f);
                return Err(f);
            }
        };
        let Some(data) = payload.get(HEADER_LEN..HEADER_LEN + h.samples) else {
            // parse_header checked the length; kept so a slip can never panic.
            self.counts.faults.add(Fault::Truncated);
            return Err(Fault::Truncated);
        };
        self.samples.clear();
        self.samples.extend_from_slice(data);
        self.time_ms = time_ms;
        self.current = Some(h);
        self.pending = true;
        Ok(1)
    }

    /// Moves to the spoke of the datagram fed last: true once a datagram.
    pub fn advance(&mut self) -> bool {
        if !self.pending {
            self.current = None;
            return false;
        }
        self.pending = false;
        self.counts.spokes += 1;
        self.counts.selected_range_m = self.current.map(|h| h.selected_range_m);
        true
    }

    /// The spoke [`advance`](Self::advance) moved to.
    pub fn spoke(&self) -> Option<Spoke<'_>> {
        let h = self.current.filter(|_| !self.pending)?;
        Some(Spoke {
            angle: h.angle(),
            spokes_per_rotation: SPOKES_PER_ROTATION,
            north_up: false,
            heading_rad: None,
            range_m: h.span_m as f32,
            time_ms: self.time_ms,
            samples: &self.samples,
            max_sample: MAX_SAMPLE,
        })
    }
}

impl SpokeDecoder for GarminDecoder {
    fn feed(&mut self, payload: &[u8], time_ms: u64) -> Result<usize, Fault> {
        GarminDecoder::feed(self, payload, time_ms)
    }

    fn advance(&mut self) -> bool {
        GarminDecoder::advance(self)
    }

    fn spoke(&self) -> Option<Spoke<'_>> {
        GarminDecoder::spoke(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spoke datagram as the capture has them (3,704 m chosen, 4,167 m span).
    fn spoke(angle: u16, samples: &[u8]) -> Vec<u8> {
        let mut p = vec![0u8; HEADER_LEN];
        p[0..4].copy_from_slice(&SPOKE_TYPE.to_le_bytes());
        p[4..8].copy_from_slice(&((HEADER_LEN + samples.len() - 8) as u32).to_le_bytes());
        p[8..10].copy_from_slice(&1u16.to_le_bytes());
        p[10..12].copy_from_slice(&723u16.to_le_bytes());
        p[12..14].copy_from_slice(&angle.to_le_bytes());
        p[16..20].copy_from_slice(&3704u32.to_le_bytes());
        p[20..24].copy_from_slice(&4167u32.to_le_bytes());
        p[26..28].copy_from_slice(&(samples.len() as u16).to_le_bytes());
        p[28..30].copy_from_slice(&0x0108u16.to_le_bytes());
        p[30..34].copy_from_slice(&(samples.len() as u32).to_le_bytes());
        p.extend_from_slice(samples);
        p
    }

    #[test]
    fn decodes_a_spoke() {
        let p = spoke(11512, &[0, 39, 255]);
        assert!(looks_like_spoke(&p));
        let mut d = GarminDecoder::new();
        let mut seen = None;
        assert_eq!(
            d.decode(&p, 5, |s| seen =
                Some((s.angle, s.range_m, s.samples.to_vec(), s.max_sample))),
            Ok(1)
        );
        assert_eq!(seen, Some((1439, 4167.0, vec![0, 39, 255], 255)));
        assert_eq!(d.counts().selected_range_m, Some(3704));
        assert!(!d.advance());
        assert!(d.spoke().is_none());
    }

    #[test]
    fn refuses_and_counts_bad_datagrams() {
        let good = spoke(8, &[1, 2, 3]);
        let mut d = GarminDecoder::new();
        assert_eq!(d.feed(&good[..20], 0), Err(Fault::Truncated));
        assert_eq!(d.feed(&good[..good.len() - 1], 0), Err(Fault::Truncated));
        let mut longer = good.clone();
        longer.push(0);
        assert_eq!(d.feed(&longer, 0), Err(Fault::BadLength));
        let mut other = good.clone();
        other[0] = 0xA3;
        other[1] = 0x02;
        assert_eq!(d.feed(&other, 0), Err(Fault::UnknownType));
        assert_eq!(d.feed(&spoke(11520, &[1]), 0), Err(Fault::BadAngle));
        assert_eq!(d.feed(&spoke(0, &[]), 0), Err(Fault::NoSamples));
        let mut no_span = good.clone();
        no_span[20..24].fill(0);
        assert_eq!(d.feed(&no_span, 0), Err(Fault::NoRange));
        assert_eq!(d.feed(&[], 0), Err(Fault::Truncated));
        assert_eq!(d.counts().faults.total(), 8);
        assert_eq!(d.counts().spokes, 0);
    }
}
