//! The echo threshold: the level from which a sample is part of an echo, for measuring an
//! echo's whole extent around its CFAR detections.
//!
//! ## Why a second threshold
//!
//! A CFAR compares each cell with its neighbours along the spoke, so inside a return larger
//! than its windows (a quay, a pontoon, a coast: on a 195 m range scale 12 reference cells
//! are 2.3 m) it detects nothing, only the edges; the edges break into point-sized blobs. To
//! tell such a return from a ship the extractor measures the *echo*: the connected cells at
//! or above a level set by the background, not by the neighbours. The CFAR still decides
//! whether there is a target (an echo without a CFAR detection is no plot); the echo gives
//! the plot's position (its strength-weighted centroid) and its size, by which it is a point
//! or an extended return ([`super::config::ExtractorConfig::classify`]).
//!
//! ## The level
//!
//! The background is estimated per range band (the spoke cut into [`BANDS`]) from a
//! histogram of the samples of every [`COUNTED_EVERY`]th spoke (16 bins), its counts halved
//! every [`UPDATE_SPOKES`] spokes (a memory of about 2 × 64 spokes): the band's 25th
//! percentile q, interpolated inside its bin. In Rayleigh noise q = 0.759 σ and a sample exceeds f·q with probability
//! exp(−(0.759 f)²/2): 1.0 % for f = 4 ([`super::config::ExtractorConfig::echo_level_factor`]).
//! The echo threshold is the larger of f·q and a least level
//! ([`super::config::ExtractorConfig::echo_min_level`], half of full scale). The percentile, not the median: in a harbour
//! echoes fill a third of some bands (measured on the 4G capture), and a quartile stays on
//! the background while echoes cover less than three quarters of the band.
//!
//! On the five real captures the radars' own processing leaves the background at zero (the
//! 25th, 50th and 75th percentiles are 0 in every band measured), so the threshold is the
//! least level; on the synthetic radar's Rayleigh noise of σ 2 levels f·q is 6, under it
//! too, and its sea clutter near own ship raises it above. Until a band's first estimate (the first [`UPDATE_SPOKES`] spokes after a start
//! or a range change) nothing is an echo and every CFAR blob is measured on its own, as
//! before echoes were followed.
//!
//! Cost: one histogram increment a sample of every fourth spoke, and 16 × [`BANDS`] steps
//! every [`UPDATE_SPOKES`] spokes; 2 KiB of counts.

/// Range bands the spoke is cut into.
pub const BANDS: usize = 32;
/// Histogram bins a band keeps (sample levels, shifted down to 4 bits).
pub const BINS: usize = 16;
/// Spokes between updates of the levels (and halvings of the counts).
pub const UPDATE_SPOKES: u16 = 64;
/// Only every this many spokes' samples are counted: the background changes slowly round
/// a rotation, and counting is most of the echo threshold's cost.
pub const COUNTED_EVERY: u16 = 4;

/// The per-band echo thresholds and the histograms they come from.
#[derive(Clone, Debug)]
pub struct EchoThreshold {
    /// Counts, at most 2 × 64 spokes × 2,048 samples a band (spokes of up to 65,535
    /// samples): they fit a `u32` with room, so they are added without a check.
    hist: [[u32; BINS]; BANDS],
    /// The threshold per band, sample levels; `u16::MAX` before the first estimate.
    levels: [u16; BANDS],
    /// Samples a band spans (the last may be shorter).
    band_len: usize,
    /// Right shift from a sample to its bin.
    shift: u8,
    spokes: u16,
}

impl EchoThreshold {
    /// No estimate yet; bands for spokes of `samples` samples up to `max_sample`.
    pub const fn new(samples: usize, max_sample: u8) -> Self {
        let mut shift = 0u8;
        while (max_sample >> shift) as usize >= BINS {
            shift += 1;
        }
        let band_len = samples.div_ceil(BANDS);
        EchoThreshold {
            hist: [[0; BINS]; BANDS],
            levels: [u16::MAX; BANDS],
            band_len: if band_len == 0 { 1 } else { band_len },
            shift,
            spokes: 0,
        }
    }

    /// Samples each band spans.
    pub fn band_len(&self) -> usize {
        self.band_len
    }

    /// The threshold of band `band`, sample levels (`u16::MAX`: nothing is an echo yet).
    pub fn level(&self, band: usize) -> u16 {
        self.levels.get(band).copied().unwrap_or(u16::MAX)
    }

    /// Whether this spoke's samples are counted ([`COUNTED_EVERY`]).
    pub fn counting(&self) -> bool {
        self.spokes.is_multiple_of(COUNTED_EVERY)
    }

    /// Counts `samples` into band `band`.
    #[inline]
    pub fn count(&mut self, band: usize, samples: &[u8]) {
        if let Some(h) = self.hist.get_mut(band) {
            let shift = self.shift;
            for &x in samples {
                // The mask keeps the index in the array (a no-op: the shift already does).
                let c = &mut h[usize::from(x >> shift) & (BINS - 1)];
                *c = c.wrapping_add(1);
            }
        }
    }

    /// After a spoke: every [`UPDATE_SPOKES`] spokes, the levels from the counts
    /// (`factor` × the 25th percentile, at least `floor`), then the counts halved.
    pub fn end_spoke(&mut self, factor: f32, floor: u8) {
        self.spokes = self.spokes.saturating_add(1);
        if self.spokes < UPDATE_SPOKES {
            return;
        }
        self.spokes = 0;
        let width = (1u32 << self.shift) as f32;
        for (h, level) in self.hist.iter_mut().zip(self.levels.iter_mut()) {
            let total: u32 = h.iter().sum();
            if total > 0 {
                let q = quartile(h, total) * width;
                // `as` saturates: a huge factor gives a level no sample reaches.
                let l = libm::ceilf(factor * q) as u16;
                *level = l.max(u16::from(floor));
            }
            h.iter_mut().for_each(|c| *c >>= 1);
        }
    }
}

/// The 25th percentile of a histogram of `total` counts, in bins (bin b covering [b, b + 1)),
/// interpolated inside the bin it falls in.
fn quartile(h: &[u32; BINS], total: u32) -> f32 {
    let target = total as f32 / 4.0;
    let mut below = 0u32;
    for (bin, &c) in h.iter().enumerate() {
        if (below + c) as f32 >= target && c > 0 {
            return bin as f32 + (target - below as f32) / c as f32;
        }
        below += c;
    }
    BINS as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeros_give_the_floor_and_noise_its_quartile_times_the_factor() {
        let mut e = EchoThreshold::new(1024, 15);
        assert_eq!(e.band_len(), 32);
        assert_eq!(e.level(0), u16::MAX);
        // Band 0 all zeros; band 1 a quarter of 1s, the rest 3s: the quartile is at the top
        // of bin 1, q = 2 levels.
        let quarter_ones: std::vec::Vec<u8> =
            (0..32).map(|i| if i % 4 == 0 { 1 } else { 3 }).collect();
        for _ in 0..UPDATE_SPOKES {
            if e.counting() {
                e.count(0, &[0; 32]);
                e.count(1, &quarter_ones);
            }
            e.end_spoke(4.0, 4);
        }
        assert_eq!(e.level(0), 4);
        assert_eq!(e.level(1), 8);
        // A band never counted keeps no estimate; a band out of range reads as none.
        assert_eq!(e.level(2), u16::MAX);
        assert_eq!(e.level(BANDS), u16::MAX);
        // 8-bit samples go into 16-level bins.
        let mut g = EchoThreshold::new(723, 255);
        for _ in 0..UPDATE_SPOKES {
            g.count(0, &[200]);
            g.end_spoke(1.0, 48);
        }
        assert_eq!(g.level(0), (12.25 * 16.0) as u16);
        assert_eq!(g.band_len(), 23);
    }
}
