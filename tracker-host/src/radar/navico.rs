//! Navico BR24, 3G, 4G and HALO spoke frames: one UDP datagram (17,160 bytes, sent as 12
//! IPv4 fragments) carries 32 spokes.
//!
//! Layout (little-endian; offsets from the start of the UDP payload):
//!
//! | bytes | what |
//! |---|---|
//! | 0..8 | frame header, `01 00 00 00 00 20 00 02` in every frame seen; ignored |
//! | 8 + 536·k .. +24 | header of spoke k |
//! | 8 + 536·k + 24 .. +512 | its 1,024 samples, 4 bits each, **low nibble first** |
//!
//! Spoke header (24 bytes): `u8@0` header length (24), `u8@1` status (0x02 and 0x12 normal,
//! 0xC2 on HALO 20+; 0x82 at transmit start and before a range change, dropped), `u16@8`
//! angle in 1/4096 of a turn from the bow, clockwise (+2 a spoke, so 2,048 spokes a
//! rotation), `u16@10` heading (bit 14 set: a heading the radar calls true, bits 0–11 in
//! 1/4096 of a turn; 0x8000: none). Then two forms, told apart by bytes 4–7:
//!
//! - `00 44 0d 0e`: the BR24 form (BR24, 3G): `u32@12 & 0xFFFFFF` × 10/√2 is the range in m;
//! - otherwise the 4G/HALO form: `u16@6` "large", `u16@12` "small"; large = 0x80 gives
//!   small/4 m (0xFFFF: none); otherwise HALO large·small/512 m, 4G large·64 m.
//!
//! The range is what the 1,024 samples span, about 1.6–2 times the range the user chose
//! (that one is only in the radar's state report, [`range_setting_report_m`]). A 3G sends its *magnetic* heading with the
//! true flag set; nothing in the spoke tells, so its heading is passed on as true (see
//! [`NavicoDecoder`]).
//!
//! HALO with VelocityTrack (Doppler) on re-uses sample values 14 (receding) and 15
//! (approaching); samples are passed on unchanged, `max_sample` 15.

use std::f64::consts::SQRT_2;

use tracker_core::radar::Spoke;

use super::decoder::SpokeDecoder;
use super::fault::{le_u16, le_u32, Fault, FaultCounts};

/// Bytes before the first spoke.
pub const FRAME_HEADER_LEN: usize = 8;
/// Bytes of a spoke's header.
pub const SPOKE_HEADER_LEN: usize = 24;
/// Bytes of a spoke's packed samples.
pub const SPOKE_DATA_LEN: usize = 512;
/// Bytes a spoke takes in a frame.
pub const SPOKE_LEN: usize = SPOKE_HEADER_LEN + SPOKE_DATA_LEN;
/// Samples a spoke holds (two a byte).
pub const SAMPLES_PER_SPOKE: usize = 2 * SPOKE_DATA_LEN;
/// Spokes a frame holds in every capture seen.
pub const SPOKES_PER_FRAME: usize = 32;
/// Spokes in a rotation (the 4096 raw angles halved).
pub const SPOKES_PER_ROTATION: u16 = 2048;
/// The strongest sample (4 bits).
pub const MAX_SAMPLE: u8 = 15;
/// Bytes 4–7 of a spoke header in the BR24 form.
pub const BR24_MARK: [u8; 4] = [0x00, 0x44, 0x0d, 0x0e];

/// Which Navico radar sent the spokes; only needed to read a 4G/HALO-form range whose
/// "large" field is not 0x80, where 4G and HALO differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NavicoModel {
    /// Not known (no scanner-type report seen): such a range is read as HALO's and counted
    /// in [`NavicoCounts::range_guessed`].
    #[default]
    Unknown,
    /// BR24 (scanner type 10).
    Br24,
    /// 3G (12).
    G3,
    /// 4G (13).
    G4,
    /// Any HALO (14, 16–23).
    Halo,
}

impl NavicoModel {
    /// The model for a scanner type as the radar reports it (`u32@30` of report 0xC403).
    pub fn from_scanner_type(scanner_type: u32) -> Self {
        match scanner_type {
            10 => NavicoModel::Br24,
            12 => NavicoModel::G3,
            13 => NavicoModel::G4,
            14 | 16..=23 => NavicoModel::Halo,
            _ => NavicoModel::Unknown,
        }
    }
}

/// The scanner type in a Navico 0xC403 state report (`03 C4`, 129 bytes, `u32@30`), `None`
/// for any other datagram.
pub fn scanner_type_report(payload: &[u8]) -> Option<u32> {
    if payload.len() != 129 || payload.get(..2)? != [0x03, 0xC4] {
        return None;
    }
    le_u32(payload, 30)
}

/// The range the user chose on the radar, m, from a Navico state report `02 C4` (99
/// bytes): `u32@2` in decimetres, as radar_pi reads it; `None` for any other datagram or a
/// range of 0.
///
/// The spokes span more than this (the corners of the picture): 1.62–1.95 times it in every
/// reading checked (3G ½ and 1 NM, 1,633 and 3,274 m; HALO ¼ and 8 NM, 796 and 25,465 m; 4G
/// 100 m, 195 m; a 4G at 500 m, 808 m, radar_pi issue #299), so it checks the spokes' own
/// range ([`SPOKE_REACH_PER_RANGE_SETTING`]).
pub fn range_setting_report_m(payload: &[u8]) -> Option<f64> {
    if payload.len() != 99 || payload.get(..2)? != [0x02, 0xC4] {
        return None;
    }
    let dm = le_u32(payload, 2)?;
    (dm > 0).then(|| f64::from(dm) / 10.0)
}

/// How far the spokes may reach, as multiples of the range the radar reports as chosen
/// ([`range_setting_report_m`]), before their range is taken for misread: 1.62–1.95 in every
/// reading checked; a range read 4 times too long or too short (`small` taken as metres,
/// or the 4G's `large · 64` against HALO's `large · small / 512`) falls outside.
pub const SPOKE_REACH_PER_RANGE_SETTING: std::ops::RangeInclusive<f64> = 1.25..=2.5;

/// A spoke header's heading field, read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NavicoHeading {
    /// Flagged true (bit 14): the heading in 1/4096 of a turn, 0..4096.
    True(u16),
    /// A heading without the true flag (magnetic or unknown reference): not used.
    NotTrue(u16),
    /// 0x8000: the radar has no heading.
    None,
    /// Any other pattern (bits outside 0x4FFF set, not 0x8000): not a heading.
    Invalid(u16),
}

impl NavicoHeading {
    /// Reads the raw field.
    pub fn from_raw(raw: u16) -> Self {
        if raw & !(0x4000 | 0x0FFF) != 0 {
            if raw == 0x8000 {
                NavicoHeading::None
            } else {
                NavicoHeading::Invalid(raw)
            }
        } else if raw & 0x4000 != 0 {
            NavicoHeading::True(raw & 0x0FFF)
        } else {
            NavicoHeading::NotTrue(raw & 0x0FFF)
        }
    }

    /// The true heading, rad in [0, 2π), when flagged true.
    pub fn true_rad(self) -> Option<f32> {
        match self {
            NavicoHeading::True(h) => Some((f64::from(h) * std::f64::consts::TAU / 4096.0) as f32),
            _ => None,
        }
    }
}

/// Range of the BR24 form, m: `(raw & 0xFFFFFF) · 10 / √2` (the top byte is 0x01 on a 3G
/// and is not part of it).
pub fn br24_range_m(raw: u32) -> f64 {
    f64::from(raw & 0x00FF_FFFF) * 10.0 / SQRT_2
}

/// Range of the 4G/HALO form, m, and whether the model had to be guessed; `None` when the
/// radar says it has none (large 0x80, small 0xFFFF).
///
/// large = 0x80: small/4 (4G 780 → 195 m, HALO 3184 → 796 m). Otherwise HALO
/// large·small/512 (25465·512/512 = 25,465 m); 4G large·64, as radar_pi reads it (mayara
/// reads it as HALO's; no capture settles it). An unknown model is read as HALO.
pub fn g4_halo_range_m(large: u16, small: u16, model: NavicoModel) -> (Option<f64>, bool) {
    if large == 0x80 {
        if small == 0xFFFF {
            return (None, false);
        }
        return (Some(f64::from(small) / 4.0), false);
    }
    match model {
        NavicoModel::G4 => (Some(f64::from(large) * 64.0), false),
        NavicoModel::Unknown => (Some(f64::from(large) * f64::from(small) / 512.0), true),
        NavicoModel::Halo | NavicoModel::Br24 | NavicoModel::G3 => {
            (Some(f64::from(large) * f64::from(small) / 512.0), false)
        }
    }
}

/// One spoke header, read and checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpokeHeader {
    /// The status byte (0x02, 0x12 or 0xC2).
    pub status: u8,
    /// The raw angle, 0..4096 from the bow, clockwise.
    pub angle_raw: u16,
    /// The heading field.
    pub heading: NavicoHeading,
    /// True for the BR24 form.
    pub br24_form: bool,
    /// The range the samples span, m (> 0).
    pub range_m: f64,
    /// The range formula depended on a model that was not known.
    pub range_guessed: bool,
}

impl SpokeHeader {
    /// The spoke's index in the rotation, `0..2048`.
    pub fn angle(&self) -> u16 {
        self.angle_raw >> 1
    }
}

/// Reads a 24-byte spoke header.
///
/// # Errors
/// The [`Fault`] that makes the spoke unusable: short header, header length not 24, a status
/// that carries no picture, an angle past 4095, no range.
pub fn parse_spoke_header(h: &[u8], model: NavicoModel) -> Result<SpokeHeader, Fault> {
    let header_len = *h.first().ok_or(Fault::Truncated)?;
    if h.len() < SPOKE_HEADER_LEN {
        return Err(Fault::Truncated);
    }
    if usize::from(header_len) != SPOKE_HEADER_LEN {
        return Err(Fault::BadSpokeHeader);
    }
    let status = *h.get(1).ok_or(Fault::Truncated)?;
    if !matches!(status, 0x02 | 0x12 | 0xC2) {
        return Err(Fault::Status);
    }
    let angle_raw = le_u16(h, 8).ok_or(Fault::Truncated)?;
    if angle_raw >= 4096 {
        return Err(Fault::BadAngle);
    }
    let heading = NavicoHeading::from_raw(le_u16(h, 10).ok_or(Fault::Truncated)?);
    let br24_form = h.get(4..8) == Some(&BR24_MARK[..]);
    let (range_m, range_guessed) = if br24_form {
        (
            Some(br24_range_m(le_u32(h, 12).ok_or(Fault::Truncated)?)),
            false,
        )
    } else {
        let large = le_u16(h, 6).ok_or(Fault::Truncated)?;
        let small = le_u16(h, 12).ok_or(Fault::Truncated)?;
        g4_halo_range_m(large, small, model)
    };
    let range_m = range_m.filter(|r| *r > 0.0).ok_or(Fault::NoRange)?;
    Ok(SpokeHeader {
        status,
        angle_raw,
        heading,
        br24_form,
        range_m,
        range_guessed,
    })
}

/// Unpacks 4-bit samples, low nibble first: byte `b` gives `b & 0x0F`, then `b >> 4`.
/// `out` is cleared and ends with two samples a byte, each 0..=15.
pub fn expand_nibbles(packed: &[u8], out: &mut Vec<u8>) {
    out.clear();
    out.extend(packed.iter().flat_map(|&b| [b & 0x0F, b >> 4]));
}

/// True when `payload` has the shape of a spoke frame: 8 + k · 536 bytes (k ≥ 1) with the
/// first spoke header's length byte 24. How a capture's streams are recognised, by
/// structure rather than port.
pub fn looks_like_frame(payload: &[u8]) -> bool {
    payload.len() >= FRAME_HEADER_LEN + SPOKE_LEN
        && (payload.len() - FRAME_HEADER_LEN).is_multiple_of(SPOKE_LEN)
        && payload.get(FRAME_HEADER_LEN) == Some(&(SPOKE_HEADER_LEN as u8))
}

/// What a Navico decoder has seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NavicoCounts {
    /// Frames accepted.
    pub frames: u64,
    /// Frames accepted with other than 32 spokes (decoded all the same).
    pub unusual_frames: u64,
    /// Datagrams refused whole, by kind.
    pub frame_faults: FaultCounts,
    /// Spokes handed out.
    pub spokes: u64,
    /// Spokes skipped inside accepted frames, by kind.
    pub spoke_faults: FaultCounts,
    /// Spokes handed out with a heading flagged true.
    pub heading_true: u64,
    /// … with a heading not flagged true (not used).
    pub heading_not_true: u64,
    /// … with 0x8000, no heading.
    pub heading_none: u64,
    /// … with a heading field that is no heading.
    pub heading_invalid: u64,
    /// Spokes whose range depended on a model not known (read as HALO's).
    pub range_guessed: u64,
    /// Spokes in the BR24 header form.
    pub br24_form: u64,
}

/// The spoke being handed out.
#[derive(Clone, Copy, Debug)]
struct Current {
    angle: u16,
    heading_rad: Option<f32>,
    range_m: f32,
}

/// Decodes Navico spoke frames into [`Spoke`]s that borrow the decoder's sample buffer.
///
/// [`feed`](Self::feed) a frame, then [`advance`](Self::advance) and read
/// [`spoke`](Self::spoke) until `advance` is false (or use [`decode`](Self::decode)). Every
/// spoke of a frame has the frame's time: the format has no per-spoke time (HALO's `u16@14`
/// millisecond clock is not used; a frame spans about 30–40 ms).
///
/// Angles are from the bow (`north_up` false); `heading_rad` is the heading when the radar
/// flags it true. A 3G flags its magnetic heading true (measured: 1.5–1.9° against HDT 6.2°
/// in the same capture): for such a radar the session should prefer a true heading from
/// NMEA.
#[derive(Clone, Debug)]
pub struct NavicoDecoder {
    frame: Vec<u8>,
    spokes_in_frame: usize,
    next_index: usize,
    time_ms: u64,
    samples: Vec<u8>,
    current: Option<Current>,
    model: NavicoModel,
    counts: NavicoCounts,
}

impl Default for NavicoDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl NavicoDecoder {
    /// A decoder for a radar of unknown model.
    pub fn new() -> Self {
        NavicoDecoder {
            frame: Vec::new(),
            spokes_in_frame: 0,
            next_index: 0,
            time_ms: 0,
            samples: Vec::with_capacity(SAMPLES_PER_SPOKE),
            current: None,
            model: NavicoModel::Unknown,
            counts: NavicoCounts::default(),
        }
    }

    /// The model used for ranges.
    pub fn model(&self) -> NavicoModel {
        self.model
    }

    /// Sets the model (from the user, or a scanner-type report).
    pub fn set_model(&mut self, model: NavicoModel) {
        self.model = model;
    }

    /// Takes the model from a state report when `payload` is a scanner-type report of a
    /// known model; true if it was.
    pub fn note_report(&mut self, payload: &[u8]) -> bool {
        match scanner_type_report(payload).map(NavicoModel::from_scanner_type) {
            Some(m) if m != NavicoModel::Unknown => {
                self.model = m;
                true
            }
            _ => false,
        }
    }

    /// What the decoder has seen.
    pub fn counts(&self) -> &NavicoCounts {
        &self.counts
    }

    /// Takes a frame taken at `time_ms`, dropping what is left of the previous one. Returns
    /// the spoke slots in it (some may still be skipped by [`advance`](Self::advance)).
    ///
    /// # Errors
    /// The frame is refused (and counted): shorter than one spoke ([`Fault::Truncated`]),
    /// or not 8 + k · 536 bytes ([`Fault::BadLength`]).
    pub fn feed(&mut self, payload: &[u8], time_ms: u64) -> Result<usize, Fault> {
        self.spokes_in_frame = 0;
        self.next_index = 0;
        self.current = None;
        let fault = if payload.len() < FRAME_HEADER_LEN + SPOKE_LEN {
            Some(Fault::Truncated)
        } else if !(payload.len() - FRAME_HEADER_LEN).is_multiple_of(SPOKE_LEN) {
            Some(Fault::BadLength)
        } else {
            None
        };
        if let Some(f) = fault {
            self.counts.frame_faults.add(f);
            return Err(f);
        }
        let n = (payload.len() - FRAME_HEADER_LEN) / SPOKE_LEN;
        self.counts.frames += 1;
        if n != SPOKES_PER_FRAME {
            self.counts.unusual_frames += 1;
        }
        self.frame.clear();
        self.frame.extend_from_slice(payload);
        self.spokes_in_frame = n;
        self.time_ms = time_ms;
        Ok(n)
    }

    /// Moves to the frame's next usable spoke, skipping (and counting) unusable ones; false
    /// when the frame has no more.
    pub fn advance(&mut self) -> bool {
        self.current = None;
        while self.next_index < self.spokes_in_frame {
            let start = FRAME_HEADER_LEN + self.next_index * SPOKE_LEN;
            self.next_index += 1;
            let Some(slot) = self.frame.get(start..start + SPOKE_LEN) else {
                self.counts.spoke_faults.add(Fault::Truncated);
                continue;
            };
            let (head, data) = slot.split_at(SPOKE_HEADER_LEN);
            let h = match parse_spoke_header(head, self.model) {
                Ok(h) => h,
                Err(f) => {
                    self.counts.spoke_faults.add(f);
                    continue;
                }
            };
            expand_nibbles(data, &mut self.samples);
            let c = &mut self.counts;
            c.spokes += 1;
            c.range_guessed += u64::from(h.range_guessed);
            c.br24_form += u64::from(h.br24_form);
            match h.heading {
                NavicoHeading::True(_) => c.heading_true += 1,
                NavicoHeading::NotTrue(_) => c.heading_not_true += 1,
                NavicoHeading::None => c.heading_none += 1,
                NavicoHeading::Invalid(_) => c.heading_invalid += 1,
            }
            self.current = Some(Current {
                angle: h.angle(),
                heading_rad: h.heading.true_rad(),
                range_m: h.range_m as f32,
            });
            return true;
        }
        false
    }

    /// The spoke [`advance`](Self::advance) moved to; `None` before it or once it was false.
    pub fn spoke(&self) -> Option<Spoke<'_>> {
        let c = self.current?;
        Some(Spoke {
            angle: c.angle,
            spokes_per_rotation: SPOKES_PER_ROTATION,
            north_up: false,
            heading_rad: c.heading_rad,
            range_m: c.range_m,
            time_ms: self.time_ms,
            samples: &self.samples,
            max_sample: MAX_SAMPLE,
        })
    }
}

impl SpokeDecoder for NavicoDecoder {
    fn feed(&mut self, payload: &[u8], time_ms: u64) -> Result<usize, Fault> {
        NavicoDecoder::feed(self, payload, time_ms)
    }

    fn advance(&mut self) -> bool {
        NavicoDecoder::advance(self)
    }

    fn spoke(&self) -> Option<Spoke<'_>> {
        NavicoDecoder::spoke(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 24-byte header: BR24 form when `br24`, else 4G/HALO with `large`/`small`.
    fn header(
        status: u8,
        angle: u16,
        heading: u16,
        br24: Option<u32>,
        large: u16,
        small: u16,
    ) -> [u8; 24] {
        let mut h = [0u8; 24];
        h[0] = 24;
        h[1] = status;
        h[4] = 0x00;
        h[5] = 0x44;
        h[8..10].copy_from_slice(&angle.to_le_bytes());
        h[10..12].copy_from_slice(&heading.to_le_bytes());
        match br24 {
            Some(raw) => {
                h[4..8].copy_from_slice(&BR24_MARK);
                h[12..16].copy_from_slice(&raw.to_le_bytes());
            }
            None => {
                h[6..8].copy_from_slice(&large.to_le_bytes());
                h[12..14].copy_from_slice(&small.to_le_bytes());
            }
        }
        h
    }

    #[test]
    fn nibbles_low_first() {
        let mut out = Vec::new();
        expand_nibbles(&[0x21, 0xF0, 0x0E], &mut out);
        assert_eq!(out, [1, 2, 0, 15, 14, 0]);
        expand_nibbles(&[], &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn br24_range_masks_the_top_byte() {
        // The 3G capture: 0x010000E7 and 0x010001CF.
        assert_eq!(br24_range_m(0x0100_00E7) as u32, 1633);
        assert_eq!(br24_range_m(0x0100_01CF) as u32, 3273);
        assert!((br24_range_m(231) - 2310.0 / SQRT_2).abs() < 1e-9);
    }

    #[test]
    fn g4_halo_ranges() {
        // 4G merrimac and HALO velocitytrack: large 0x80, small/4.
        assert_eq!(
            g4_halo_range_m(0x80, 780, NavicoModel::G4),
            (Some(195.0), false)
        );
        assert_eq!(
            g4_halo_range_m(0x80, 3184, NavicoModel::Halo),
            (Some(796.0), false)
        );
        assert_eq!(
            g4_halo_range_m(0x80, 0xFFFF, NavicoModel::Halo),
            (None, false)
        );
        // HALO mayara: large·small/512.
        assert_eq!(
            g4_halo_range_m(25465, 512, NavicoModel::Halo),
            (Some(25465.0), false)
        );
        assert_eq!(
            g4_halo_range_m(25465, 512, NavicoModel::Unknown),
            (Some(25465.0), true)
        );
        // 4G, large not 0x80: radar_pi's large·64.
        assert_eq!(
            g4_halo_range_m(100, 512, NavicoModel::G4),
            (Some(6400.0), false)
        );
    }

    #[test]
    fn headings() {
        assert_eq!(NavicoHeading::from_raw(0x4D28), NavicoHeading::True(0xD28));
        let deg = NavicoHeading::from_raw(0x4D28)
            .true_rad()
            .unwrap()
            .to_degrees();
        assert!((deg - 296.02).abs() < 0.01, "{deg}");
        assert_eq!(NavicoHeading::from_raw(0x8000), NavicoHeading::None);
        assert_eq!(
            NavicoHeading::from_raw(0x9234),
            NavicoHeading::Invalid(0x9234)
        );
        assert_eq!(
            NavicoHeading::from_raw(0x0123),
            NavicoHeading::NotTrue(0x123)
        );
        assert_eq!(NavicoHeading::from_raw(0x0123).true_rad(), None);
    }

    #[test]
    fn spoke_headers_checked() {
        let m = NavicoModel::Unknown;
        let h = parse_spoke_header(&header(0x02, 605, 0x4D28, None, 25465, 512), m).unwrap();
        assert_eq!((h.angle(), h.range_m, h.br24_form), (302, 25465.0, false));
        let h =
            parse_spoke_header(&header(0x12, 2169, 0x4013, Some(0x0100_00E7), 0, 0), m).unwrap();
        assert_eq!(
            (h.angle(), h.range_m as u32, h.br24_form),
            (1084, 1633, true)
        );
        assert_eq!(
            parse_spoke_header(&header(0x82, 0, 0, None, 0x80, 780), m),
            Err(Fault::Status)
        );
        assert_eq!(
            parse_spoke_header(&header(0x02, 4096, 0, None, 0x80, 780), m),
            Err(Fault::BadAngle)
        );
        assert_eq!(
            parse_spoke_header(&header(0x02, 0, 0, None, 0x80, 0xFFFF), m),
            Err(Fault::NoRange)
        );
        assert_eq!(
            parse_spoke_header(&header(0x02, 0, 0, None, 0x80, 0), m),
            Err(Fault::NoRange)
        );
        let mut bad = header(0x02, 0, 0, None, 0x80, 780);
        bad[0] = 20;
        assert_eq!(parse_spoke_header(&bad, m), Err(Fault::BadSpokeHeader));
        assert_eq!(parse_spoke_header(&bad[..10], m), Err(Fault::Truncated));
        assert_eq!(parse_spoke_header(&[], m), Err(Fault::Truncated));
    }

    #[test]
    fn a_frame_gives_its_spokes_and_skips_bad_ones() {
        let mut frame = vec![1, 0, 0, 0, 0, 0x20, 0, 2];
        for k in 0..3u16 {
            let status = if k == 1 { 0x82 } else { 0x02 };
            frame.extend_from_slice(&header(status, 2 * k, 0x8000, None, 0x80, 780));
            frame.extend(std::iter::repeat_n(0x21u8, SPOKE_DATA_LEN));
        }
        assert!(looks_like_frame(&frame));
        let mut d = NavicoDecoder::new();
        let mut seen = Vec::new();
        let n = d
            .decode(&frame, 7, |s| {
                assert_eq!(s.samples.len(), SAMPLES_PER_SPOKE);
                assert_eq!(&s.samples[..2], &[1, 2]);
                seen.push((s.angle, s.range_m, s.time_ms, s.heading_rad));
            })
            .unwrap();
        assert_eq!(n, 2);
        assert_eq!(seen, [(0, 195.0, 7, None), (2, 195.0, 7, None)]);
        let c = d.counts();
        assert_eq!(
            (c.frames, c.unusual_frames, c.spokes, c.heading_none),
            (1, 1, 2, 2)
        );
        assert_eq!(c.spoke_faults.get(Fault::Status), 1);
        assert_eq!(d.feed(&frame[..100], 0), Err(Fault::Truncated));
        assert_eq!(d.feed(&frame[..frame.len() - 1], 0), Err(Fault::BadLength));
        assert!(!d.advance());
        assert!(d.spoke().is_none());
    }

    #[test]
    fn the_range_report_gives_the_range_chosen() {
        let mut r = vec![0u8; 99];
        r[..2].copy_from_slice(&[0x02, 0xC4]);
        // The 4G capture's: 1,000 dm, the 4G's 100 m range.
        r[2..6].copy_from_slice(&1000u32.to_le_bytes());
        assert_eq!(range_setting_report_m(&r), Some(100.0));
        // The 3G capture's ½ NM.
        r[2..6].copy_from_slice(&9260u32.to_le_bytes());
        assert_eq!(range_setting_report_m(&r), Some(926.0));
        assert_eq!(range_setting_report_m(&r[..98]), None);
        r[0] = 0x03;
        assert_eq!(range_setting_report_m(&r), None);
        r[0] = 0x02;
        r[2..6].copy_from_slice(&0u32.to_le_bytes());
        assert_eq!(range_setting_report_m(&r), None);
    }

    #[test]
    fn the_scanner_type_report_sets_the_model() {
        let mut r = vec![0u8; 129];
        r[0] = 0x03;
        r[1] = 0xC4;
        r[30] = 13;
        let mut d = NavicoDecoder::new();
        assert!(d.note_report(&r));
        assert_eq!(d.model(), NavicoModel::G4);
        assert!(!d.note_report(&r[..128]));
    }
}
