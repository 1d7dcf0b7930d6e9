//! Multi-fragment AIS messages put back together (IEC 61162-1 §8.3.92: fragments of one
//! message share the sequential message id and the channel, and come in order).
//!
//! Fragments are held per (VDM/VDO, sequential id, channel, count) until all have come, in
//! any order. Bounded: at most [`MAX_PENDING`] messages wait at once, and one waits for at
//! most [`MAX_WAIT_LINES`] further fragments of any message; past either, the oldest is given
//! up as incomplete (counted). A fragment number already held replaces nothing: the
//! message is restarted (a sequential id reused before its message completed).

use super::fragment::Fragment;

/// Messages waiting for fragments at once.
pub const MAX_PENDING: usize = 32;

/// Fragments (of any message) a message waits through before it is given up. Real
/// receivers send a message's fragments back to back; a few other sentences between is
/// usual, dozens mean a fragment was lost.
pub const MAX_WAIT_LINES: u64 = 40;

/// A whole message: the payload of its fragments joined, and the last one's fill bits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Assembled {
    /// From own ship's transponder (`VDO`).
    pub own_ship: bool,
    /// The armoured payload.
    pub payload: String,
    /// Fill bits of the last fragment.
    pub fill_bits: u8,
    /// Fragments it came in.
    pub fragments: u8,
}

/// What the assembler gave up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct AssemblyCounts {
    /// Messages given up with fragments missing (timed out, crowded out, or restarted).
    pub incomplete: u64,
    /// Fragments in those messages.
    pub fragments_dropped: u64,
}

#[derive(Clone, Debug)]
struct Pending {
    own_ship: bool,
    sequence: Option<u8>,
    channel: u8,
    count: u8,
    parts: Vec<Option<(String, u8)>>,
    since: u64,
}

/// The assembler. See the module documentation.
#[derive(Clone, Debug, Default)]
pub struct Assembler {
    pending: Vec<Pending>,
    fragments: u64,
    counts: AssemblyCounts,
}

impl Assembler {
    /// An empty assembler.
    pub fn new() -> Self {
        Self::default()
    }

    /// What has been given up.
    pub fn counts(&self) -> AssemblyCounts {
        self.counts
    }

    /// Messages waiting now.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Takes a fragment; the whole message once its last fragment is in.
    pub fn push(&mut self, f: Fragment) -> Option<Assembled> {
        self.fragments += 1;
        if f.count == 1 {
            self.expire();
            return Some(Assembled {
                own_ship: f.own_ship,
                payload: f.payload,
                fill_bits: f.fill_bits,
                fragments: 1,
            });
        }
        let key = |p: &Pending| {
            p.own_ship == f.own_ship
                && p.sequence == f.sequence
                && p.channel == f.channel
                && p.count == f.count
        };
        let index = match self.pending.iter().position(key) {
            Some(i) if self.pending[i].parts[usize::from(f.number - 1)].is_some() => {
                // The id came round again before the message completed.
                self.give_up(i);
                None
            }
            i => i,
        };
        let index = index.unwrap_or_else(|| {
            if self.pending.len() >= MAX_PENDING {
                self.give_up(0);
            }
            self.pending.push(Pending {
                own_ship: f.own_ship,
                sequence: f.sequence,
                channel: f.channel,
                count: f.count,
                parts: vec![None; usize::from(f.count)],
                since: self.fragments,
            });
            self.pending.len() - 1
        });
        self.pending[index].parts[usize::from(f.number - 1)] = Some((f.payload, f.fill_bits));
        let whole = self.pending[index]
            .parts
            .iter()
            .all(Option::is_some)
            .then(|| {
                let p = self.pending.remove(index);
                let mut payload = String::new();
                let mut fill_bits = 0;
                for (text, fill) in p.parts.into_iter().flatten() {
                    payload += &text;
                    fill_bits = fill;
                }
                Assembled {
                    own_ship: p.own_ship,
                    payload,
                    fill_bits,
                    fragments: p.count,
                }
            });
        self.expire();
        whole
    }

    fn expire(&mut self) {
        while self
            .pending
            .first()
            .is_some_and(|p| self.fragments - p.since > MAX_WAIT_LINES)
        {
            self.give_up(0);
        }
    }

    fn give_up(&mut self, i: usize) {
        let p = self.pending.remove(i);
        self.counts.incomplete += 1;
        self.counts.fragments_dropped += p.parts.iter().flatten().count() as u64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frag(count: u8, number: u8, seq: u8, text: &str) -> Fragment {
        Fragment {
            own_ship: false,
            count,
            number,
            sequence: Some(seq),
            channel: b'A',
            payload: text.to_string(),
            fill_bits: number,
        }
    }

    #[test]
    fn fragments_join_in_any_order_and_lost_ones_are_bounded() {
        let mut a = Assembler::new();
        assert_eq!(a.push(frag(2, 2, 1, "cd")), None);
        let m = a.push(frag(2, 1, 1, "ab")).unwrap();
        assert_eq!(
            (m.payload.as_str(), m.fill_bits, m.fragments),
            ("abcd", 2, 2)
        );
        // A first fragment whose second never comes: given up after MAX_WAIT_LINES.
        assert_eq!(a.push(frag(2, 1, 3, "xx")), None);
        for _ in 0..=MAX_WAIT_LINES {
            a.push(frag(1, 1, 0, "z"));
        }
        assert_eq!(a.pending(), 0);
        assert_eq!(a.counts().incomplete, 1);
        // A flood of first fragments: never more than MAX_PENDING held.
        for i in 0..1000u32 {
            let mut f = frag(3, 1, (i % 10) as u8, "q");
            f.channel = (i / 10 % 200) as u8;
            a.push(f);
            assert!(a.pending() <= MAX_PENDING);
        }
        // An id reused before completion restarts the message.
        let mut b = Assembler::new();
        b.push(frag(2, 1, 5, "a"));
        b.push(frag(2, 1, 5, "b"));
        assert_eq!(b.push(frag(2, 2, 5, "c")).unwrap().payload, "bc");
        assert_eq!(b.counts().incomplete, 1);
    }
}
