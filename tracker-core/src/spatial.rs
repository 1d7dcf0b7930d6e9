//! Plots bucketed by east coordinate, so a rough gate looks only at its neighbourhood.
//!
//! One counting sort per scan (linear in the plots, no comparison sort and so no panic path)
//! puts the plot indices into [`EAST_BUCKETS`] strips of equal width between the westmost
//! and eastmost plot. A gate of radius `r` around `p` then visits only the strips that
//! overlap `[p_e - r, p_e + r]`: about `plots × 2r / span` candidates instead of every plot.
//! The strips are a superset of the gate (the exact distance test is the caller's), so the
//! gate's content is the same as a scan over every plot.

use crate::geo::EastNorth;

/// Strips across the plots' east extent. 64: at 24 km of extent a strip is 375 m, so a gate
/// of the default 100–2000 m radius spans 2–12 strips.
pub const EAST_BUCKETS: usize = 64;

/// Plots an index can hold; the device's [`MAX_PLOTS_PER_SCAN`](crate::tracker::MAX_PLOTS_PER_SCAN).
pub const MAX_INDEXED_PLOTS: usize = crate::tracker::MAX_PLOTS_PER_SCAN;

// A strip number is kept in a byte while the index is built.
const _: () = assert!(EAST_BUCKETS <= 256);

/// The plots of one scan in east strips.
#[derive(Clone, Debug)]
pub struct EastIndex {
    /// Plot numbers, strip by strip, in plot order within a strip.
    order: [u16; MAX_INDEXED_PLOTS],
    /// `order[start[b]..start[b + 1]]` are strip `b`'s plots.
    start: [u16; EAST_BUCKETS + 1],
    /// East of the westmost plot (m).
    west_m: f32,
    /// Strips per metre of east (0 when every plot has the same east).
    per_m: f32,
}

impl EastIndex {
    /// Indexes `plots` (east, north in m). `None` when there are more than
    /// [`MAX_INDEXED_PLOTS`] or a coordinate is not finite: the caller then looks at every
    /// plot.
    pub fn new(plots: &[EastNorth]) -> Option<Self> {
        if plots.len() > MAX_INDEXED_PLOTS {
            return None;
        }
        let (mut west, mut east) = (f32::INFINITY, f32::NEG_INFINITY);
        for z in plots {
            if !(z[0].is_finite() && z[1].is_finite()) {
                return None;
            }
            // Finite (checked above): plain comparisons.
            if z[0] < west {
                west = z[0];
            }
            if z[0] > east {
                east = z[0];
            }
        }
        let span = east - west;
        let per_m = if span > 0.0 && span.is_finite() {
            EAST_BUCKETS as f32 / span
        } else {
            0.0
        };
        let mut index = EastIndex {
            order: [0; MAX_INDEXED_PLOTS],
            start: [0; EAST_BUCKETS + 1],
            west_m: west,
            per_m,
        };
        // Counting sort: counts, then each strip's end, then placement from the back so a
        // strip keeps plot order. Each plot's strip is worked out once.
        let mut strip = [0u8; MAX_INDEXED_PLOTS];
        for (z, s) in plots.iter().zip(strip.iter_mut()) {
            let b = index.bucket(z[0]);
            *s = b as u8;
            if let Some(c) = index.start.get_mut(b + 1) {
                *c += 1;
            }
        }
        for b in 1..=EAST_BUCKETS {
            let before = index.start.get(b - 1).copied().unwrap_or(0);
            if let Some(c) = index.start.get_mut(b) {
                *c += before;
            }
        }
        // `start[b + 1]` is now strip b's end; placing from the back leaves it at its start.
        for (i, &b) in strip.iter().enumerate().take(plots.len()).rev() {
            if let Some(end) = index.start.get_mut(usize::from(b) + 1) {
                *end -= 1;
                if let Some(slot) = index.order.get_mut(usize::from(*end)) {
                    *slot = i as u16;
                }
            }
        }
        // Shift: strip b starts where strip b - 1's placement ended.
        index.start.copy_within(1..=EAST_BUCKETS, 0);
        if let Some(last) = index.start.last_mut() {
            *last = plots.len() as u16;
        }
        Some(index)
    }

    /// The strip of east `e` (m), clamped to the strips: monotonic in `e`.
    fn bucket(&self, e: f32) -> usize {
        // `as` saturates (negative and NaN to 0), so no check is needed below.
        (((e - self.west_m) * self.per_m) as usize).min(EAST_BUCKETS - 1)
    }

    /// The plot numbers in the strips that overlap east `[west_m, east_m]`: every plot with
    /// its east in that range, and others near it.
    pub fn between(&self, west_m: f32, east_m: f32) -> &[u16] {
        let first = usize::from(self.start.get(self.bucket(west_m)).copied().unwrap_or(0));
        let end = usize::from(
            self.start
                .get(self.bucket(east_m) + 1)
                .copied()
                .unwrap_or(0),
        );
        self.order.get(first..end).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_holds_every_plot_in_its_range() {
        let plots: std::vec::Vec<EastNorth> = (0..200)
            .map(|i| {
                let e = ((i * 7919) % 1000) as f32 * 13.7 - 6000.0;
                [e, i as f32]
            })
            .collect();
        let index = EastIndex::new(&plots).unwrap();
        let mut all: std::vec::Vec<u16> = index.between(-1e9, 1e9).to_vec();
        all.sort();
        assert_eq!(
            all,
            (0..200).map(|i| i as u16).collect::<std::vec::Vec<_>>()
        );
        for (w, e) in [
            (-6000.0, -5000.0),
            (0.0, 0.0),
            (3000.0, 9000.0),
            (-1.0, 1.0),
        ] {
            let got = index.between(w, e);
            for (i, z) in plots.iter().enumerate() {
                if (w..=e).contains(&z[0]) {
                    assert!(got.contains(&(i as u16)), "{i} in [{w}, {e}]");
                }
            }
            assert!(got.len() < 200 || (w, e) == (3000.0, 9000.0));
        }
    }

    #[test]
    fn degenerate_plots() {
        assert!(EastIndex::new(&[[f32::NAN, 0.0]]).is_none());
        assert!(EastIndex::new(&[[0.0, 0.0]; MAX_INDEXED_PLOTS + 1]).is_none());
        let same = EastIndex::new(&[[5.0, 0.0], [5.0, 1.0]]).unwrap();
        assert_eq!(same.between(5.0, 5.0), &[0, 1]);
        assert!(EastIndex::new(&[]).unwrap().between(0.0, 1.0).is_empty());
    }
}
