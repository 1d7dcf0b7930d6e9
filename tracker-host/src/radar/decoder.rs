//! What every radar's spoke decoder does: take a packet, then step through its spokes.

use tracker_core::radar::Spoke;

use super::Fault;

/// A decoder of one radar make's spoke packets. Each spoke borrows the decoder's sample
/// buffer, so spokes are stepped through (`advance`, then `spoke`) rather than iterated.
pub trait SpokeDecoder {
    /// Takes a packet received at `time_ms` (ms, the capture's or the host's clock), dropping
    /// what is left of the previous one; returns the spoke slots in it.
    ///
    /// # Errors
    /// The packet is refused and counted, with the [`Fault`] that says why.
    fn feed(&mut self, payload: &[u8], time_ms: u64) -> Result<usize, Fault>;

    /// Moves to the packet's next usable spoke, skipping (and counting) unusable ones; false
    /// when the packet has no more.
    fn advance(&mut self) -> bool;

    /// The spoke [`advance`](Self::advance) moved to.
    fn spoke(&self) -> Option<Spoke<'_>>;

    /// Feeds a packet and hands each usable spoke to `f`; returns how many.
    ///
    /// # Errors
    /// As [`feed`](Self::feed).
    fn decode(
        &mut self,
        payload: &[u8],
        time_ms: u64,
        mut f: impl FnMut(Spoke<'_>),
    ) -> Result<usize, Fault>
    where
        Self: Sized,
    {
        self.feed(payload, time_ms)?;
        let mut n = 0;
        while self.advance() {
            if let Some(s) = self.spoke() {
                f(s);
                n += 1;
            }
        }
        Ok(n)
    }
}
