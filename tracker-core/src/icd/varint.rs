//! Postcard's integer encoding, written and read by hand for the packed record lists.
//!
//! An unsigned integer is LEB128: seven bits a byte, least significant first, the top bit
//! set on every byte but the last. A signed one is first zigzag-mapped (0, −1, 1, −2, … →
//! 0, 1, 2, 3, …) so that small magnitudes of either sign take one byte. These are the very
//! bytes `postcard` writes for `u32` and `i32` (a test checks it), so a packed list is the
//! same as a postcard sequence of its elements without the count; it is packed by hand so
//! that the device can fill a frame to a byte budget and the host can read records whose
//! shape depends on a leading byte.

/// A packed list did not decode: it ended inside a number, a number ran past 32 bits, or a
/// value was out of its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Malformed;

/// Bytes `v` takes as an unsigned varint (1–5).
pub const fn u32_len(v: u32) -> usize {
    match v {
        0..=0x7F => 1,
        0x80..=0x3FFF => 2,
        0x4000..=0x1F_FFFF => 3,
        0x20_0000..=0x0FFF_FFFF => 4,
        _ => 5,
    }
}

/// The zigzag form of `v`.
pub const fn zigzag(v: i32) -> u32 {
    ((v << 1) ^ (v >> 31)) as u32
}

/// The signed value of zigzag form `z`.
pub const fn unzigzag(z: u32) -> i32 {
    ((z >> 1) as i32) ^ -((z & 1) as i32)
}

/// Bytes `v` takes as a signed (zigzag) varint (1–5).
pub const fn i32_len(v: i32) -> usize {
    u32_len(zigzag(v))
}

/// Writes varints into a byte slice; past its end it writes nothing more and says so.
#[derive(Debug)]
pub struct Writer<'a> {
    buf: &'a mut [u8],
    at: usize,
    overflow: bool,
}

impl<'a> Writer<'a> {
    /// A writer at the start of `buf`.
    pub fn new(buf: &'a mut [u8]) -> Self {
        Writer {
            buf,
            at: 0,
            overflow: false,
        }
    }

    /// Bytes written.
    pub fn len(&self) -> usize {
        self.at
    }

    /// True when nothing was written.
    pub fn is_empty(&self) -> bool {
        self.at == 0
    }

    /// Bytes still free.
    pub fn room(&self) -> usize {
        self.buf.len().saturating_sub(self.at)
    }

    /// True when a write did not fit (what was written before it stands).
    pub fn overflowed(&self) -> bool {
        self.overflow
    }

    /// The bytes written.
    pub fn written(&self) -> &[u8] {
        self.buf.get(..self.at).unwrap_or(&[])
    }

    /// One byte as it is.
    pub fn byte(&mut self, b: u8) {
        match self.buf.get_mut(self.at) {
            Some(slot) => {
                *slot = b;
                self.at += 1;
            }
            None => self.overflow = true,
        }
    }

    /// An unsigned varint.
    pub fn u32(&mut self, mut v: u32) {
        if self.room() < u32_len(v) {
            self.overflow = true;
            return;
        }
        while v >= 0x80 {
            self.byte((v as u8) | 0x80);
            v >>= 7;
        }
        self.byte(v as u8);
    }

    /// A signed (zigzag) varint.
    pub fn i32(&mut self, v: i32) {
        self.u32(zigzag(v));
    }
}

/// Reads varints from a byte slice.
#[derive(Clone, Debug)]
pub struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    /// A reader at the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Reader { bytes }
    }

    /// True when every byte was read.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// One byte as it is.
    ///
    /// # Errors
    /// [`Malformed`] at the end.
    pub fn byte(&mut self) -> Result<u8, Malformed> {
        let (&b, rest) = self.bytes.split_first().ok_or(Malformed)?;
        self.bytes = rest;
        Ok(b)
    }

    /// An unsigned varint.
    ///
    /// # Errors
    /// [`Malformed`] when the bytes end inside it or it does not fit 32 bits.
    // Inlined into the record readers' loops, where the slice stays in registers.
    #[inline(always)]
    pub fn u32(&mut self) -> Result<u32, Malformed> {
        // One arm a length, no loop: an arm is reached only when every byte before its
        // last has the continuation bit (the shorter arms did not match).
        let low = |b: u8| u32::from(b & 0x7F);
        let (v, rest) = match *self.bytes {
            [b0, ref rest @ ..] if b0 < 0x80 => (u32::from(b0), rest),
            [b0, b1, ref rest @ ..] if b1 < 0x80 => (low(b0) | u32::from(b1) << 7, rest),
            [b0, b1, b2, ref rest @ ..] if b2 < 0x80 => {
                (low(b0) | low(b1) << 7 | u32::from(b2) << 14, rest)
            }
            [b0, b1, b2, b3, ref rest @ ..] if b3 < 0x80 => (
                low(b0) | low(b1) << 7 | low(b2) << 14 | u32::from(b3) << 21,
                rest,
            ),
            // The fifth byte holds the top four bits only.
            [b0, b1, b2, b3, b4, ref rest @ ..] if b4 <= 0x0F => (
                low(b0) | low(b1) << 7 | low(b2) << 14 | low(b3) << 21 | u32::from(b4) << 28,
                rest,
            ),
            _ => return Err(Malformed),
        };
        self.bytes = rest;
        Ok(v)
    }

    /// A signed (zigzag) varint.
    ///
    /// # Errors
    /// As [`Reader::u32`].
    #[inline(always)]
    pub fn i32(&mut self) -> Result<i32, Malformed> {
        self.u32().map(unzigzag)
    }

    /// An unsigned varint that must fit 16 bits.
    ///
    /// # Errors
    /// As [`Reader::u32`], and [`Malformed`] past `u16::MAX`.
    pub fn u16(&mut self) -> Result<u16, Malformed> {
        u16::try_from(self.u32()?).map_err(|_| Malformed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bytes_are_postcards() {
        let mut pc = [0u8; 8];
        let mut ours = [0u8; 8];
        for v in [
            0u32,
            1,
            127,
            128,
            16_383,
            16_384,
            2_097_151,
            2_097_152,
            u32::MAX,
        ] {
            let want = postcard::to_slice(&v, &mut pc).unwrap().to_vec();
            let mut w = Writer::new(&mut ours);
            w.u32(v);
            assert_eq!(w.written(), want.as_slice(), "{v}");
            assert_eq!(w.len(), u32_len(v));
            assert_eq!(Reader::new(&want).u32(), Ok(v));
        }
        for v in [0i32, -1, 1, -64, 63, 64, -65, i32::MIN, i32::MAX] {
            let want = postcard::to_slice(&v, &mut pc).unwrap().to_vec();
            let mut w = Writer::new(&mut ours);
            w.i32(v);
            assert_eq!(w.written(), want.as_slice(), "{v}");
            assert_eq!(w.len(), i32_len(v));
            assert_eq!(Reader::new(&want).i32(), Ok(v));
        }
    }

    #[test]
    fn bad_bytes_are_refused_not_misread() {
        assert_eq!(Reader::new(&[]).u32(), Err(Malformed));
        assert_eq!(Reader::new(&[0x80]).u32(), Err(Malformed), "ends inside");
        assert_eq!(
            Reader::new(&[0xFF, 0xFF, 0xFF, 0xFF, 0x1F]).u32(),
            Err(Malformed),
            "past 32 bits"
        );
        assert_eq!(
            Reader::new(&[0x80, 0x80, 0x80, 0x80, 0x80, 0x00]).u32(),
            Err(Malformed)
        );
        assert_eq!(Reader::new(&[0x80, 0x80, 0x04]).u16(), Err(Malformed));
    }

    #[test]
    fn a_full_writer_writes_nothing_more() {
        let mut buf = [0u8; 2];
        let mut w = Writer::new(&mut buf);
        w.u32(300);
        assert!(!w.overflowed());
        w.u32(5);
        assert!(w.overflowed());
        assert_eq!(w.written(), &[0xAC, 0x02]);
    }
}
