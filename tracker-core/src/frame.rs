//! Framing: COBS + CRC-32 around postcard, and a byte-at-a-time decoder that resynchronises.
//!
//! A UART delivers bytes with no boundaries, sometimes damaged. The 0x00 delimiter that COBS
//! guarantees never appears inside a frame, so after any damage the decoder drops what it has
//! and starts clean at the next delimiter: one bad frame never costs the good frame after it.
//! The CRC catches the damage COBS cannot see (flipped bits that leave the encoding valid).

use serde::{de::DeserializeOwned, Serialize};

use crate::icd::{ErrorCode, Header, MAX_FRAME_BYTES, PROTOCOL_VERSION};

/// CRC-32/ISO-HDLC (the Ethernet and zlib CRC: reflected, polynomial 0x04C11DB7, all-ones
/// in and out), eight bytes a step from eight tables (slice-by-8): 8 KiB of flash, built at
/// compile time, for about half the one-table cost a byte. Written here rather than taken
/// from `crc`'s sixteen-table form, whose index arithmetic leaves bounds checks (so panic
/// paths) in the firmware. The M4F boards here have no CRC unit for this polynomial over
/// bytes (the STM32F4's computes CRC-32/MPEG-2 over 32-bit words), so it is software.
static CRC_TABLES: [[u32; 256]; 8] = crc_tables();

const fn crc_tables() -> [[u32; 256]; 8] {
    let mut t = [[0u32; 256]; 8];
    let mut i = 0;
    while i < 256 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 8 {
            c = if c & 1 != 0 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
            k += 1;
        }
        t[0][i] = c;
        i += 1;
    }
    let mut i = 0;
    while i < 256 {
        let mut j = 1;
        while j < 8 {
            let prev = t[j - 1][i];
            t[j][i] = (prev >> 8) ^ t[0][(prev & 0xFF) as usize];
            j += 1;
        }
        i += 1;
    }
    t
}

/// CRC-32/ISO-HDLC of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let t = &CRC_TABLES;
    // Every index below is a byte (masked or shifted down to 8 bits): no bounds check.
    let at = |table: &[u32; 256], v: u32| table[(v & 0xFF) as usize];
    let mut crc = !0u32;
    let mut chunks = bytes.chunks_exact(8);
    for chunk in &mut chunks {
        let Ok(&[b0, b1, b2, b3, b4, b5, b6, b7]) = <&[u8; 8]>::try_from(chunk) else {
            break;
        };
        let lo = u32::from_le_bytes([b0, b1, b2, b3]) ^ crc;
        let hi = u32::from_le_bytes([b4, b5, b6, b7]);
        crc = at(&t[7], lo)
            ^ at(&t[6], lo >> 8)
            ^ at(&t[5], lo >> 16)
            ^ at(&t[4], lo >> 24)
            ^ at(&t[3], hi)
            ^ at(&t[2], hi >> 8)
            ^ at(&t[1], hi >> 16)
            ^ at(&t[0], hi >> 24);
    }
    for &b in chunks.remainder() {
        crc = at(&t[0], crc ^ u32::from(b)) ^ (crc >> 8);
    }
    !crc
}

/// Bytes of CRC after the payload.
pub const CRC_BYTES: usize = 4;

/// Why a frame could not be read. Each maps onto an [`ErrorCode`] for the peer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameError {
    /// Invalid COBS.
    Cobs,
    /// CRC mismatch, or too short to carry a CRC.
    Crc,
    /// Longer than [`MAX_ENCODED_FRAME_BYTES`](crate::icd::MAX_ENCODED_FRAME_BYTES) before the delimiter.
    Oversize,
    /// CRC fine, content did not decode.
    Malformed,
    /// A message index this version does not know.
    UnknownMessage,
    /// The sender's protocol version differs from ours.
    VersionMismatch {
        /// The version in the frame.
        theirs: u16,
    },
    /// The message does not fit into the output buffer (a bug on the sending side).
    BufferTooSmall,
}

impl FrameError {
    /// The code to report to the peer.
    pub fn code(self) -> ErrorCode {
        match self {
            FrameError::Cobs => ErrorCode::BadCobs,
            FrameError::Crc => ErrorCode::BadCrc,
            FrameError::Oversize => ErrorCode::Oversize,
            FrameError::Malformed | FrameError::BufferTooSmall => ErrorCode::Malformed,
            FrameError::UnknownMessage => ErrorCode::UnknownMessage,
            FrameError::VersionMismatch { .. } => ErrorCode::VersionMismatch {
                device: PROTOCOL_VERSION,
            },
        }
    }
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            FrameError::Cobs => f.write_str("invalid COBS encoding"),
            FrameError::Crc => f.write_str("CRC mismatch"),
            FrameError::Oversize => f.write_str("frame longer than the maximum"),
            FrameError::Malformed => f.write_str("frame content does not decode"),
            FrameError::UnknownMessage => f.write_str("unknown message"),
            FrameError::VersionMismatch { theirs } => write!(
                f,
                "protocol version {theirs} does not match ours ({PROTOCOL_VERSION})"
            ),
            FrameError::BufferTooSmall => f.write_str("message does not fit the frame buffer"),
        }
    }
}

#[cfg(feature = "std")]
impl std::error::Error for FrameError {}

/// Encodes `header` and `body` as one delimited frame into `out`; returns the bytes used.
///
/// `scratch` holds the unencoded frame; [`MAX_FRAME_BYTES`] is always enough for the ICD's
/// messages, and `out` needs [`MAX_ENCODED_FRAME_BYTES`](crate::icd::MAX_ENCODED_FRAME_BYTES).
///
/// # Errors
/// [`FrameError::BufferTooSmall`] when `scratch` or `out` cannot hold the frame.
pub fn encode<T: Serialize>(
    header: &Header,
    body: &T,
    scratch: &mut [u8],
    out: &mut [u8],
) -> Result<usize, FrameError> {
    let n = postcard::to_slice(&(header, body), scratch)
        .map_err(|_| FrameError::BufferTooSmall)?
        .len();
    let crc = crc32(scratch.get(..n).ok_or(FrameError::BufferTooSmall)?);
    scratch
        .get_mut(n..n + CRC_BYTES)
        .ok_or(FrameError::BufferTooSmall)?
        .copy_from_slice(&crc.to_le_bytes());
    let frame = scratch
        .get(..n + CRC_BYTES)
        .ok_or(FrameError::BufferTooSmall)?;
    let used = cobs_encode(frame, out).ok_or(FrameError::BufferTooSmall)?;
    *out.get_mut(used).ok_or(FrameError::BufferTooSmall)? = 0;
    Ok(used + 1)
}

/// COBS-encodes `src` into `out` in one pass (no delimiter); the bytes used, or `None` when
/// `out` is too small. The same bytes as `cobs::encode`: each block of up to 254 non-zero
/// bytes is preceded by its length + 1, and a zero ends a block.
fn cobs_encode(src: &[u8], out: &mut [u8]) -> Option<usize> {
    // Where the current block's code byte goes, and the next byte's place.
    let mut code_at = 0;
    let mut at = 1;
    let mut code = 1u8;
    let mut ended_full = false;
    for &b in src {
        ended_full = false;
        if b == 0 {
            *out.get_mut(code_at)? = code;
            code_at = at;
            at += 1;
            code = 1;
        } else {
            *out.get_mut(at)? = b;
            at += 1;
            code += 1;
            if code == 0xFF {
                *out.get_mut(code_at)? = code;
                code_at = at;
                at += 1;
                code = 1;
                ended_full = true;
            }
        }
    }
    // A full block ending the input is not followed by an empty one (as `cobs::encode`).
    if ended_full {
        return Some(at - 1);
    }
    *out.get_mut(code_at)? = code;
    Some(at)
}

/// Splits a decoded, CRC-checked payload into its header and body.
///
/// The version is checked before the body is read, and a message index past the ones this
/// version knows is reported as [`FrameError::UnknownMessage`] rather than as damage.
///
/// # Errors
/// [`FrameError::Malformed`] when the header or body does not decode, [`FrameError::VersionMismatch`] for another protocol version, [`FrameError::UnknownMessage`] for a message index of `variants` or more.
pub fn decode_payload<T: DeserializeOwned>(
    payload: &[u8],
    known_variants: u32,
) -> Result<(Header, T), (Option<Header>, FrameError)> {
    let (header, rest): (Header, _) =
        postcard::take_from_bytes(payload).map_err(|_| (None, FrameError::Malformed))?;
    if header.protocol != PROTOCOL_VERSION {
        return Err((
            Some(header),
            FrameError::VersionMismatch {
                theirs: header.protocol,
            },
        ));
    }
    let (variant, _): (u32, _) =
        postcard::take_from_bytes(rest).map_err(|_| (Some(header), FrameError::Malformed))?;
    if variant >= known_variants {
        return Err((Some(header), FrameError::UnknownMessage));
    }
    match postcard::from_bytes(rest) {
        Ok(body) => Ok((header, body)),
        Err(_) => Err((Some(header), FrameError::Malformed)),
    }
}

/// Reassembles frames from bytes that arrive one at a time or in pieces.
///
/// Bytes are COBS-decoded as they arrive, into a buffer of [`MAX_FRAME_BYTES`]: a count of
/// the current block's bytes still due, and a zero owed before the next block, a few
/// instructions a byte. A frame that would decode longer is dropped whole and reported once,
/// at its delimiter.
#[derive(Clone, Debug)]
pub struct FrameDecoder {
    buf: [u8; MAX_FRAME_BYTES],
    /// Decoded bytes held.
    len: usize,
    /// Encoded bytes received since the last delimiter.
    received: usize,
    /// Data bytes still due in the current COBS block (0: the next byte is a code byte).
    block_left: u8,
    /// The block just finished was shorter than 254 bytes: a zero is due before the next.
    zero_due: bool,
    /// Why the frame being received is already lost, reported at its delimiter.
    error: Option<FrameError>,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; MAX_FRAME_BYTES],
            len: 0,
            received: 0,
            block_left: 0,
            zero_due: false,
            error: None,
        }
    }

    /// Decoded bytes held of a frame not yet delimited (at most [`MAX_FRAME_BYTES`]).
    pub fn pending(&self) -> usize {
        self.len
    }

    /// Appends a decoded byte, or marks the frame oversize.
    fn store(&mut self, b: u8) {
        match self.buf.get_mut(self.len) {
            Some(slot) => {
                *slot = b;
                self.len += 1;
            }
            None => self.error = Some(FrameError::Oversize),
        }
    }

    /// Feeds one byte. At a delimiter returns the checked payload (header and body, CRC
    /// removed) or why the frame was rejected. Empty frames (repeated delimiters, which a
    /// sender may use to flush the line) return `None`.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            self.received = self.received.saturating_add(1);
            if self.error.is_some() {
                return None;
            }
            if self.block_left == 0 {
                // A code byte: the zero the last block owed, then `byte - 1` data bytes.
                if self.zero_due {
                    self.store(0);
                }
                self.block_left = byte - 1;
                self.zero_due = byte != 0xFF;
            } else {
                self.store(byte);
                self.block_left -= 1;
            }
            return None;
        }
        // The delimiter: the frame ends here whatever state it was in.
        let received = core::mem::take(&mut self.received);
        let error = self.error.take();
        let block_left = core::mem::take(&mut self.block_left);
        self.zero_due = false;
        let len = core::mem::take(&mut self.len);
        if received == 0 {
            return None;
        }
        if let Some(e) = error {
            return Some(Err(e));
        }
        // A block cut short by the delimiter.
        if block_left != 0 {
            return Some(Err(FrameError::Cobs));
        }
        if len <= CRC_BYTES {
            return Some(Err(FrameError::Crc));
        }
        // Checked slicing throughout: the firmware must have no reachable panic.
        let decoded = self.buf.get(..len)?;
        let (payload, crc) = decoded.split_at_checked(len - CRC_BYTES)?;
        let expected: [u8; CRC_BYTES] = crc.try_into().ok()?;
        if crc32(payload) != u32::from_le_bytes(expected) {
            return Some(Err(FrameError::Crc));
        }
        Some(Ok(payload))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icd::{
        DeviceToHost, HostToDevice, HOST_TO_DEVICE_VARIANTS, MAX_ECHO_BYTES,
        MAX_ENCODED_FRAME_BYTES,
    };
    use heapless::Vec;

    fn frame_of(header: Header, body: &HostToDevice) -> std::vec::Vec<u8> {
        let mut scratch = [0u8; MAX_FRAME_BYTES];
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let n = encode(&header, body, &mut scratch, &mut out).unwrap();
        out[..n].to_vec()
    }

    fn hdr(id: u32) -> Header {
        Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        }
    }

    /// Feeds bytes, collecting what each delimiter yields.
    fn feed(
        dec: &mut FrameDecoder,
        bytes: &[u8],
    ) -> std::vec::Vec<Result<HostToDevice, FrameError>> {
        let mut out = std::vec::Vec::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                out.push(r.and_then(|p| {
                    decode_payload::<HostToDevice>(p, HOST_TO_DEVICE_VARIANTS)
                        .map(|(_, m)| m)
                        .map_err(|(_, e)| e)
                }));
            }
        }
        out
    }

    fn echo(n: usize) -> HostToDevice {
        HostToDevice::Echo((0..n).map(|i| (i * 7 + 1) as u8).collect())
    }

    #[test]
    fn frames_round_trip_at_every_size() {
        let mut dec = FrameDecoder::new();
        for n in (0..=MAX_ECHO_BYTES).step_by(37).chain([MAX_ECHO_BYTES]) {
            let msg = echo(n);
            let got = feed(&mut dec, &frame_of(hdr(1), &msg));
            assert_eq!(got, [Ok(msg)]);
        }
    }

    #[test]
    fn a_flipped_bit_is_caught_and_the_next_frame_survives() {
        let msg = echo(100);
        let good = frame_of(hdr(1), &msg);
        let mut dec = FrameDecoder::new();
        for bit in 0..(good.len() - 1) * 8 {
            let mut bad = good.clone();
            bad[bit / 8] ^= 1 << (bit % 8);
            let mut stream = bad;
            stream.extend_from_slice(&good);
            let got = feed(&mut dec, &stream);
            // A flip may create a 0x00 and split the frame: every piece is rejected, and the
            // good frame after it always comes through.
            assert_eq!(got.last(), Some(&Ok(msg.clone())), "bit {bit}");
            assert!(got[..got.len() - 1].iter().all(|r| r.is_err()), "bit {bit}");
            assert!(!got[..got.len() - 1].is_empty(), "bit {bit} went unnoticed");
        }
    }

    #[test]
    fn truncated_and_garbage_frames_are_rejected() {
        let msg = echo(40);
        let good = frame_of(hdr(5), &msg);
        let mut dec = FrameDecoder::new();
        let mut stream = good[..good.len() / 2].to_vec();
        stream.push(0);
        stream.extend_from_slice(&[0x13, 0x37, 0xff, 0x42, 0]);
        stream.extend_from_slice(&good);
        let got = feed(&mut dec, &stream);
        assert_eq!(got.len(), 3);
        assert!(got[0].is_err() && got[1].is_err());
        assert_eq!(got[2], Ok(msg));
    }

    #[test]
    fn oversize_is_reported_once_then_resyncs() {
        let mut dec = FrameDecoder::new();
        let mut stream = std::vec![0x55u8; MAX_ENCODED_FRAME_BYTES * 3];
        stream.push(0);
        let msg = HostToDevice::Hello;
        stream.extend_from_slice(&frame_of(hdr(9), &msg));
        assert_eq!(
            feed(&mut dec, &stream),
            [Err(FrameError::Oversize), Ok(msg)]
        );
    }

    #[test]
    fn version_and_unknown_message_are_told_apart_from_damage() {
        let mut dec = FrameDecoder::new();
        let wrong = Header {
            protocol: PROTOCOL_VERSION + 1,
            request_id: 3,
        };
        let got = feed(&mut dec, &frame_of(wrong, &HostToDevice::Hello));
        assert_eq!(
            got,
            [Err(FrameError::VersionMismatch {
                theirs: PROTOCOL_VERSION + 1
            })]
        );
        // A hand-built frame with message index 200: valid COBS and CRC.
        let mut scratch = [0u8; MAX_FRAME_BYTES];
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let n = encode(&hdr(4), &200u32, &mut scratch, &mut out).unwrap();
        let got = feed(&mut dec, &out[..n]);
        assert_eq!(got, [Err(FrameError::UnknownMessage)]);
        // Known index, body cut short.
        let n = encode(&hdr(4), &1u32, &mut scratch, &mut out).unwrap();
        assert_eq!(feed(&mut dec, &out[..n]), [Err(FrameError::Malformed)]);
    }

    #[test]
    fn device_messages_use_the_same_framing() {
        let mut scratch = [0u8; MAX_FRAME_BYTES];
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let body = DeviceToHost::Echo(Vec::from_slice(&[0, 0, 0]).unwrap());
        let n = encode(&hdr(77), &body, &mut scratch, &mut out).unwrap();
        assert!(!out[..n - 1].contains(&0));
        let mut dec = FrameDecoder::new();
        let mut got = None;
        for &b in &out[..n] {
            if let Some(r) = dec.push(b) {
                got = Some(
                    decode_payload::<DeviceToHost>(r.unwrap(), u32::MAX)
                        .map_err(|(_, e)| e)
                        .unwrap(),
                );
            }
        }
        assert_eq!(got, Some((hdr(77), body)));
    }

    /// Pseudo-random bytes, with runs of zeros and of non-zeros around the 254-byte blocks.
    fn bytes(seed: u32, n: usize) -> std::vec::Vec<u8> {
        let mut x = seed.wrapping_mul(2_654_435_761).max(1);
        (0..n)
            .map(|i| {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                match seed % 3 {
                    0 => (x >> 24) as u8,
                    1 => u8::from(!i.is_multiple_of(300)) * ((x >> 24) as u8 | 1),
                    _ => u8::from(x.is_multiple_of(5)) * (x >> 24) as u8,
                }
            })
            .collect()
    }

    #[test]
    fn the_one_pass_cobs_matches_the_cobs_crate() {
        for seed in 0..60u32 {
            for n in [0, 1, 2, 253, 254, 255, 256, 507, 508, 509, 1000, 1028] {
                let src = bytes(seed, n);
                let mut want = [0u8; MAX_ENCODED_FRAME_BYTES + 8];
                let mut got = [0u8; MAX_ENCODED_FRAME_BYTES + 8];
                let w = cobs::encode(&src, &mut want);
                let g = cobs_encode(&src, &mut got).unwrap();
                assert_eq!(&got[..g], &want[..w], "seed {seed}, {n} bytes");
                assert_eq!(cobs_encode(&src, &mut got[..w.saturating_sub(1)]), None);
            }
        }
    }

    #[test]
    fn the_decoder_reads_what_the_cobs_crate_reads() {
        // Random byte streams cut at zeros: each piece is read as the cobs crate reads it.
        for seed in 0..200u32 {
            let stream = bytes(seed, 700);
            let mut dec = FrameDecoder::new();
            for piece in stream.split(|&b| b == 0) {
                for &b in piece {
                    assert!(dec.push(b).is_none());
                }
                let got = dec.push(0).map(|r| r.map(<[u8]>::to_vec));
                if piece.is_empty() {
                    assert_eq!(got, None);
                    continue;
                }
                let mut out = [0u8; 2048];
                let want = match cobs::decode(piece, &mut out).map(|r| r.frame_size()) {
                    Err(_) => Err(FrameError::Cobs),
                    Ok(n) if n > MAX_FRAME_BYTES => Err(FrameError::Oversize),
                    Ok(n) if n <= CRC_BYTES => Err(FrameError::Crc),
                    Ok(n) => {
                        let (p, c) = out[..n].split_at(n - CRC_BYTES);
                        if crc32(p).to_le_bytes() == c {
                            Ok(p.to_vec())
                        } else {
                            Err(FrameError::Crc)
                        }
                    }
                };
                assert_eq!(got, Some(want), "seed {seed}");
            }
        }
    }

    #[test]
    fn the_slice_by_8_crc_is_crc_32_iso_hdlc() {
        let reference = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        for seed in 0..40u32 {
            for n in [0, 1, 7, 8, 9, 15, 16, 17, 255, 1000, 1028] {
                let b = bytes(seed, n);
                assert_eq!(crc32(&b), reference.checksum(&b), "seed {seed}, {n} bytes");
            }
        }
    }
}
