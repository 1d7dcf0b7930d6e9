//! Filling fixed-capacity vectors without a panic path.
//!
//! `heapless::Vec`'s `FromIterator` and `Extend` panic when the iterator yields more than the
//! capacity. The callers here are all bounded by construction, but the firmware must have no
//! reachable panic the optimiser cannot rule out, so they fill through [`take_up_to`], which
//! stops at the capacity instead.

use heapless::Vec;

/// The first `N` items of `items`; the rest are dropped.
pub(crate) fn take_up_to<T, const N: usize>(items: impl IntoIterator<Item = T>) -> Vec<T, N> {
    let mut out = Vec::new();
    for item in items {
        if out.push(item).is_err() {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stops_at_the_capacity() {
        let v: Vec<u8, 3> = take_up_to(0..10);
        assert_eq!(v.as_slice(), &[0, 1, 2]);
        let v: Vec<u8, 3> = take_up_to(0..2);
        assert_eq!(v.as_slice(), &[0, 1]);
    }
}
