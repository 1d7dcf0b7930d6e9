//! Framing: COBS + CRC-32 around postcard, and a byte-at-a-time decoder that resynchronises.
//!
//! A UART delivers bytes with no boundaries, sometimes damaged. The 0x00 delimiter that COBS
//! guarantees never appears inside a frame, so after any damage the decoder drops what it has
//! and starts clean at the next delimiter: one bad frame never costs the good frame after it.
//! The CRC catches the damage COBS cannot see (flipped bits that leave the encoding valid).

use serde::{Deserialize, Serialize};

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
    !crc32_update(!0, bytes)
}

/// The CRC register after `bytes`, from `crc` (not inverted: start from `!0`, invert at
/// the end).
fn crc32_update(mut crc: u32, bytes: &[u8]) -> u32 {
    let t = &CRC_TABLES;
    // Every index below is a byte (masked or shifted down to 8 bits): no bounds check.
    let at = |table: &[u32; 256], v: u32| table[(v & 0xFF) as usize];
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
        crc = crc32_byte(crc, b);
    }
    crc
}

/// The CRC register after one more byte.
#[inline(always)]
fn crc32_byte(crc: u32, b: u8) -> u32 {
    CRC_TABLES[0][((crc ^ u32::from(b)) & 0xFF) as usize] ^ (crc >> 8)
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
/// The message is serialized straight into its COBS encoding (a postcard flavor): no buffer of
/// the plain frame, and the CRC is taken on the way. `out` needs
/// [`MAX_ENCODED_FRAME_BYTES`](crate::icd::MAX_ENCODED_FRAME_BYTES) for the ICD's messages.
///
/// # Errors
/// [`FrameError::BufferTooSmall`] when `out` cannot hold the frame, or the plain frame
/// would be longer than [`MAX_FRAME_BYTES`].
pub fn encode<T: Serialize>(
    header: &Header,
    body: &T,
    out: &mut [u8],
) -> Result<usize, FrameError> {
    let flavor = postcard::serialize_with_flavor(&(header, body), CobsCrc::new(out))
        .map_err(|_| FrameError::BufferTooSmall)?;
    flavor.finish()
}

/// Runs of bytes up to this long are copied, searched and CRC'd a byte at a time: below it
/// the word-at-a-time paths' set-up costs more than they save (measured on the M4F).
const SHORT_RUN: usize = 16;

/// A postcard output that COBS-encodes as it is written and takes the CRC of what it is
/// given: a byte string's bytes go into the encoding as whole runs, searched for zeros four
/// bytes at a time.
struct CobsCrc<'a> {
    out: &'a mut [u8],
    /// Where the open block's code byte goes.
    code_at: usize,
    /// Where the next byte goes.
    at: usize,
    /// The CRC register over the plain bytes.
    crc: u32,
    /// Plain bytes given.
    plain: usize,
    /// The block before the open one was full (254 bytes): an empty open block at the end
    /// is then not written (as `cobs::encode`).
    after_full: bool,
}

impl<'a> CobsCrc<'a> {
    fn new(out: &'a mut [u8]) -> Self {
        CobsCrc {
            out,
            code_at: 0,
            at: 1,
            crc: !0,
            plain: 0,
            after_full: false,
        }
    }

    /// Closes the open block (`run` data bytes) and opens the next.
    fn close(&mut self, full: bool) -> Option<()> {
        let run = self.at - self.code_at - 1;
        *self.out.get_mut(self.code_at)? = (run + 1) as u8;
        self.code_at = self.at;
        self.at += 1;
        self.after_full = full;
        Some(())
    }

    /// One byte into the encoding (no CRC): the small fields come one at a time.
    #[inline(always)]
    fn encode_byte(&mut self, b: u8) -> Option<()> {
        self.after_full = false;
        if b == 0 {
            return self.close(false);
        }
        *self.out.get_mut(self.at)? = b;
        self.at += 1;
        if self.at - self.code_at == 255 {
            self.close(true)?;
        }
        Some(())
    }

    /// Bytes into the encoding (no CRC).
    fn encode(&mut self, mut bytes: &[u8]) -> Option<()> {
        // A few bytes cost less one by one than searched and copied as a run.
        if bytes.len() <= SHORT_RUN {
            for &b in bytes {
                self.encode_byte(b)?;
            }
            return Some(());
        }
        while !bytes.is_empty() {
            let room = 254 - (self.at - self.code_at - 1);
            let window = bytes.get(..bytes.len().min(room))?;
            let (n, zero) = match find_zero(window) {
                Some(z) => (z, true),
                None => (window.len(), false),
            };
            copy_run(self.out.get_mut(self.at..self.at + n)?, window.get(..n)?);
            self.at += n;
            self.after_full = false;
            if zero {
                self.close(false)?;
                bytes = bytes.get(n + 1..)?;
            } else {
                bytes = bytes.get(n..)?;
                if n == room {
                    self.close(true)?;
                }
            }
        }
        Some(())
    }

    /// The CRC after the message, the last block closed, the delimiter: the frame's length.
    fn finish(mut self) -> Result<usize, FrameError> {
        if self.plain + CRC_BYTES > MAX_FRAME_BYTES {
            return Err(FrameError::BufferTooSmall);
        }
        let crc = (!self.crc).to_le_bytes();
        self.encode(&crc).ok_or(FrameError::BufferTooSmall)?;
        self.end().ok_or(FrameError::BufferTooSmall)
    }

    /// The last block closed and the delimiter written: the encoding's length.
    fn end(self) -> Option<usize> {
        let end = if self.after_full && self.at == self.code_at + 1 {
            // The open block is empty after a full one: not written.
            self.code_at
        } else {
            let run = self.at - self.code_at - 1;
            *self.out.get_mut(self.code_at)? = (run + 1) as u8;
            self.at
        };
        *self.out.get_mut(end)? = 0;
        Some(end + 1)
    }
}

impl postcard::ser_flavors::Flavor for CobsCrc<'_> {
    type Output = Self;

    fn try_push(&mut self, b: u8) -> postcard::Result<()> {
        self.crc = crc32_byte(self.crc, b);
        self.plain += 1;
        self.encode_byte(b)
            .ok_or(postcard::Error::SerializeBufferFull)
    }

    fn try_extend(&mut self, bytes: &[u8]) -> postcard::Result<()> {
        self.plain += bytes.len();
        // Postcard hands a varint over as a few bytes: those go one by one.
        if bytes.len() <= SHORT_RUN {
            for &b in bytes {
                self.crc = crc32_byte(self.crc, b);
                self.encode_byte(b)
                    .ok_or(postcard::Error::SerializeBufferFull)?;
            }
            return Ok(());
        }
        self.crc = crc32_update(self.crc, bytes);
        self.encode(bytes)
            .ok_or(postcard::Error::SerializeBufferFull)
    }

    fn finalize(self) -> postcard::Result<Self> {
        Ok(self)
    }
}

/// COBS-encodes `src` into `out` (no delimiter), in pieces of the given lengths as the
/// serializer hands them over; the bytes used, or `None` when `out` is too small.
#[cfg(test)]
fn cobs_encode_in_pieces(src: &[u8], pieces: &[usize], out: &mut [u8]) -> Option<usize> {
    let mut c = CobsCrc::new(out);
    let mut rest = src;
    for &n in pieces.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (piece, tail) = rest.split_at(n.clamp(1, rest.len()));
        c.encode(piece)?;
        rest = tail;
    }
    c.end().map(|n| n - 1)
}

/// Copies `src` into the start of `dst` (as much as fits): four bytes a load and a store.
/// The M4 loads and stores words at any address; the library's copy does not rely on that
/// and, for buffers of different alignment, shifts bytes into place (about three times the
/// instructions).
fn copy_run(dst: &mut [u8], src: &[u8]) {
    let n = dst.len().min(src.len());
    let (Some(dst), Some(src)) = (dst.get_mut(..n), src.get(..n)) else {
        return;
    };
    let mut d = dst.chunks_exact_mut(4);
    let mut s = src.chunks_exact(4);
    for (a, b) in (&mut d).zip(&mut s) {
        if let (Ok(a), Ok(b)) = (<&mut [u8; 4]>::try_from(a), <&[u8; 4]>::try_from(b)) {
            *a = *b;
        }
    }
    for (a, b) in d.into_remainder().iter_mut().zip(s.remainder()) {
        *a = *b;
    }
}

/// The index of the first zero in `bytes`: four bytes at a time (a word has a zero byte
/// when subtracting one from each byte borrows into a byte whose top bit was clear).
fn find_zero(bytes: &[u8]) -> Option<usize> {
    let mut chunks = bytes.chunks_exact(4);
    let mut base = 0;
    for c in &mut chunks {
        let Ok(w) = <[u8; 4]>::try_from(c) else {
            break;
        };
        let v = u32::from_le_bytes(w);
        if v.wrapping_sub(0x0101_0101) & !v & 0x8080_8080 != 0 {
            return c.iter().position(|&b| b == 0).map(|i| base + i);
        }
        base += 4;
    }
    chunks
        .remainder()
        .iter()
        .position(|&b| b == 0)
        .map(|i| base + i)
}

/// Splits a decoded, CRC-checked payload into its header and body.
///
/// The version is checked before the body is read, and a message index past the ones this
/// version knows is reported as [`FrameError::UnknownMessage`] rather than as damage.
///
/// # Errors
/// [`FrameError::Malformed`] when the header or body does not decode, [`FrameError::VersionMismatch`] for another protocol version, [`FrameError::UnknownMessage`] for a message index of `variants` or more.
pub fn decode_payload<'a, T: Deserialize<'a>>(
    payload: &'a [u8],
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
/// A whole frame handed over in one slice (a DMA buffer's) is COBS-decoded from the slice
/// straight into the frame buffer, a block at a time. Bytes that come one at a time (a
/// polled UART's) are decoded as they come: a count of the current block's bytes still
/// due, and a zero owed before the next block. Either way the CRC is checked at the
/// delimiter, and a frame whose encoding runs past the longest a frame can have is dropped
/// whole and reported once, at its delimiter.
#[derive(Clone, Debug)]
pub struct FrameDecoder {
    buf: [u8; MAX_RAW_FRAME_BYTES],
    /// Decoded bytes held.
    len: usize,
    /// Encoded bytes received since the last delimiter.
    received: usize,
    /// Data bytes still due in the current COBS block (0: the next byte is a code byte).
    block_left: u8,
    /// The block just finished was shorter than 254 bytes: a zero is due before the next.
    zero_due: bool,
}

/// Longest frame encoding, its delimiter not counted.
const MAX_RAW_FRAME_BYTES: usize = crate::icd::MAX_ENCODED_FRAME_BYTES - 1;

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        FrameDecoder {
            buf: [0; MAX_RAW_FRAME_BYTES],
            len: 0,
            received: 0,
            block_left: 0,
            zero_due: false,
        }
    }

    /// Encoded bytes received of a frame not yet delimited.
    pub fn pending(&self) -> usize {
        self.received
    }

    /// Feeds one byte. At a delimiter returns the checked payload (header and body, CRC
    /// removed) or why the frame was rejected. Empty frames (repeated delimiters, which a
    /// sender may use to flush the line) return `None`.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            self.keep(byte);
            return None;
        }
        match self.finish()? {
            Ok(n) => self.buf.get(..n).map(Ok),
            Err(e) => Some(Err(e)),
        }
    }

    /// Takes a byte that is not a delimiter (the frame's bytes but its last).
    #[inline(always)]
    pub fn keep(&mut self, byte: u8) {
        self.received += 1;
        if self.block_left != 0 {
            self.block_left -= 1;
            self.store(byte);
        } else {
            // A code byte: the zero the last block owed, then `byte - 1` data bytes.
            if self.zero_due {
                self.store(0);
            }
            self.block_left = byte.wrapping_sub(1);
            self.zero_due = byte != 0xFF;
        }
    }

    /// Appends a decoded byte (none past the buffer: such a frame is oversize by then).
    #[inline(always)]
    fn store(&mut self, b: u8) {
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = b;
            self.len += 1;
        }
    }

    /// Feeds the bytes of `bytes` up to and including the first delimiter (all of them when
    /// none is there); returns how many it took, and at a delimiter what [`Self::push`]
    /// returns there. The bytes before the delimiter are copied as one slice.
    pub fn push_slice(&mut self, bytes: &[u8]) -> (usize, Option<Result<&[u8], FrameError>>) {
        // A UART hands bytes over one at a time: no search, no copy call for those.
        if let [byte] = *bytes {
            return (1, self.push(byte));
        }
        let (run, delimited) = match find_zero(bytes) {
            Some(zero) => (bytes.get(..zero).unwrap_or(&[]), true),
            None => (bytes, false),
        };
        // A whole frame in the slice (a DMA buffer's): decoded from it straight into place.
        if delimited && self.received == 0 {
            if run.is_empty() {
                return (1, None);
            }
            // Longer than any frame's encoding: oversize, as kept byte by byte.
            if run.len() > MAX_RAW_FRAME_BYTES {
                return (run.len() + 1, Some(Err(FrameError::Oversize)));
            }
            let frame = match cobs_decode(run, &mut self.buf) {
                Ok(n) => match self.check(n) {
                    Ok(n) => self.buf.get(..n).map(Ok),
                    Err(e) => Some(Err(e)),
                },
                Err(e) => Some(Err(e)),
            };
            return (run.len() + 1, frame);
        }
        for &b in run {
            self.keep(b);
        }
        if !delimited {
            return (run.len(), None);
        }
        let used = run.len() + 1;
        let frame = match self.finish() {
            None => None,
            Some(Ok(n)) => self.buf.get(..n).map(Ok),
            Some(Err(e)) => Some(Err(e)),
        };
        (used, frame)
    }

    /// The delimiter: the frame taken so far checked; the payload's length.
    fn finish(&mut self) -> Option<Result<usize, FrameError>> {
        let received = core::mem::take(&mut self.received);
        let block_left = core::mem::take(&mut self.block_left);
        self.zero_due = false;
        let len = core::mem::take(&mut self.len);
        if received == 0 {
            return None;
        }
        if received > MAX_RAW_FRAME_BYTES {
            return Some(Err(FrameError::Oversize));
        }
        // A block cut short by the delimiter.
        if block_left != 0 {
            return Some(Err(FrameError::Cobs));
        }
        Some(self.check(len))
    }

    /// Checks the decoded frame of `decoded` bytes in `buf`: its length and CRC; the
    /// payload's length.
    fn check(&self, decoded: usize) -> Result<usize, FrameError> {
        if decoded > MAX_FRAME_BYTES {
            return Err(FrameError::Oversize);
        }
        if decoded <= CRC_BYTES {
            return Err(FrameError::Crc);
        }
        // Checked slicing throughout: the firmware must have no reachable panic.
        let (payload, crc) = self
            .buf
            .get(..decoded)
            .and_then(|d| d.split_at_checked(decoded - CRC_BYTES))
            .ok_or(FrameError::Crc)?;
        let expected: [u8; CRC_BYTES] = crc.try_into().map_err(|_| FrameError::Crc)?;
        if crc32(payload) != u32::from_le_bytes(expected) {
            return Err(FrameError::Crc);
        }
        Ok(payload.len())
    }
}

/// COBS-decodes `src` (one frame's encoding, no zero in it) into `dst`; the decoded length.
/// Each block is its length + 1, then that many data bytes; a block shorter than 254 is
/// followed by a zero unless it ends the frame.
fn cobs_decode(src: &[u8], dst: &mut [u8]) -> Result<usize, FrameError> {
    let (mut read, mut write) = (0, 0);
    let n = src.len();
    while let Some(&code) = src.get(read) {
        let data = usize::from(code).saturating_sub(1);
        let start = read + 1;
        let block = src.get(start..start + data).ok_or(FrameError::Cobs)?;
        copy_run(
            dst.get_mut(write..write + data)
                .ok_or(FrameError::Oversize)?,
            block,
        );
        read = start + data;
        write += data;
        if code != 0xFF && read < n {
            *dst.get_mut(write).ok_or(FrameError::Oversize)? = 0;
            write += 1;
        }
    }
    Ok(write)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::icd::Bytes;
    use crate::icd::{
        DeviceToHost, HostToDevice, HOST_TO_DEVICE_VARIANTS, MAX_ECHO_BYTES,
        MAX_ENCODED_FRAME_BYTES,
    };

    fn frame_of(header: Header, body: &HostToDevice) -> std::vec::Vec<u8> {
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let n = encode(&header, body, &mut out).unwrap();
        out[..n].to_vec()
    }

    fn hdr(id: u32) -> Header {
        Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        }
    }

    /// A message as it decodes: `Hello`, or an echo's bytes.
    #[derive(Debug, PartialEq, Eq, Clone)]
    enum Got {
        Hello,
        Echo(std::vec::Vec<u8>),
    }

    /// Feeds bytes (a byte at a time, and again as one slice: the same), collecting what
    /// each delimiter yields.
    fn feed(dec: &mut FrameDecoder, bytes: &[u8]) -> std::vec::Vec<Result<Got, FrameError>> {
        let read = |r: Result<&[u8], FrameError>| {
            r.and_then(|p| {
                match decode_payload::<HostToDevice>(p, HOST_TO_DEVICE_VARIANTS)
                    .map_err(|(_, e)| e)?
                    .1
                {
                    HostToDevice::Hello => Ok(Got::Hello),
                    HostToDevice::Echo(b) => Ok(Got::Echo(b.0.to_vec())),
                    other => panic!("{other:?}"),
                }
            })
        };
        let mut sliced = dec.clone();
        let mut out = std::vec::Vec::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                out.push(read(r));
            }
        }
        let mut rest = bytes;
        let mut again = std::vec::Vec::new();
        while !rest.is_empty() {
            let (used, r) = sliced.push_slice(rest);
            rest = &rest[used..];
            if let Some(r) = r {
                again.push(read(r));
            }
        }
        assert_eq!(out, again, "a byte at a time and as one slice");
        out
    }

    fn echo_bytes(n: usize) -> std::vec::Vec<u8> {
        (0..n).map(|i| (i * 7 + 1) as u8).collect()
    }

    #[test]
    fn frames_round_trip_at_every_size() {
        let mut dec = FrameDecoder::new();
        for n in (0..=MAX_ECHO_BYTES).step_by(37).chain([MAX_ECHO_BYTES]) {
            let bytes = echo_bytes(n);
            let got = feed(
                &mut dec,
                &frame_of(hdr(1), &HostToDevice::Echo(Bytes(&bytes))),
            );
            assert_eq!(got, [Ok(Got::Echo(bytes))]);
        }
    }

    #[test]
    fn a_flipped_bit_is_caught_and_the_next_frame_survives() {
        let bytes = echo_bytes(100);
        let good = frame_of(hdr(1), &HostToDevice::Echo(Bytes(&bytes)));
        let msg = Got::Echo(bytes.clone());
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
        let bytes = echo_bytes(40);
        let good = frame_of(hdr(5), &HostToDevice::Echo(Bytes(&bytes)));
        let msg = Got::Echo(bytes.clone());
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
        stream.extend_from_slice(&frame_of(hdr(9), &HostToDevice::Hello));
        assert_eq!(
            feed(&mut dec, &stream),
            [Err(FrameError::Oversize), Ok(Got::Hello)]
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
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let n = encode(&hdr(4), &200u32, &mut out).unwrap();
        let got = feed(&mut dec, &out[..n]);
        assert_eq!(got, [Err(FrameError::UnknownMessage)]);
        // Known index, body cut short.
        let n = encode(&hdr(4), &1u32, &mut out).unwrap();
        assert_eq!(feed(&mut dec, &out[..n]), [Err(FrameError::Malformed)]);
    }

    #[test]
    fn device_messages_use_the_same_framing() {
        let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
        let body = DeviceToHost::Echo(Bytes(&[0, 0, 0]));
        let n = encode(&hdr(77), &body, &mut out).unwrap();
        assert!(!out[..n - 1].contains(&0));
        let mut dec = FrameDecoder::new();
        let mut got = None;
        for &b in &out[..n] {
            if let Some(r) = dec.push(b) {
                let (h, d) = decode_payload::<DeviceToHost>(r.unwrap(), u32::MAX)
                    .map_err(|(_, e)| e)
                    .unwrap();
                assert_eq!(d, body);
                got = Some(h);
            }
        }
        assert_eq!(got, Some(hdr(77)));
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
                // Whole, and in the pieces a serializer hands over (bytes, then strings).
                for pieces in [&[usize::MAX][..], &[1], &[3, 1, 250, 7], &[254, 1]] {
                    let g = cobs_encode_in_pieces(&src, pieces, &mut got).unwrap();
                    assert_eq!(&got[..g], &want[..w], "seed {seed}, {n} bytes, {pieces:?}");
                }
                // One byte short of the encoding and its delimiter: refused.
                assert_eq!(cobs_encode_in_pieces(&src, &[5], &mut got[..w]), None);
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
