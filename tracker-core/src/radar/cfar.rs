//! Constant-false-alarm-rate detection along one spoke: greatest-of two trimmed means
//! (GO-CMLD): each side of the cell under test estimates the noise by the mean of its k
//! smallest reference samples, and the larger estimate sets the threshold.
//!
//! ## Why
//!
//! A cell is a detection when its sample exceeds a threshold scaled from the noise around
//! it. Three things go wrong with the simple estimates on a marine radar:
//!
//! - **Other echoes in the window.** Cell averaging (CA-CFAR, the mean of the reference
//!   cells) is raised several-fold by one strong echo: a second ship a few hundred metres
//!   away in range masks the first (harbours, convoys, buoy lines), and the tail of a
//!   target's own pulse beyond the guard cells masks itself. Ordered statistics fix this:
//!   rank each side's samples and ignore the largest (n − k = 3 a side here).
//! - **Clutter edges.** Where rain, land or the sea-clutter slope begins, half the window
//!   is quiet and half is not; any estimate over both halves sits between them, and the
//!   cells just inside the clutter cross it (a rain patch's near edge, measured with a
//!   single 24-cell trimmed mean: 3–4 false plots a rotation per rain cell). Taking the
//!   greater of the two sides' estimates (GO) puts the threshold at the clutter's level.
//! - **Coarse samples.** The textbook OS-CFAR (Rohling) takes the k-th value alone; on a
//!   Navico's 4 bits the k-th value of the noise is one of two or three levels, so its
//!   threshold jumps by a third at a time and its false-alarm rate missed the design by a
//!   factor of 3.4 (measured: 3.4 × 10⁻³ for 10⁻³, noise σ 2 levels). The mean of the k
//!   smallest (Ritcey's censored mean level detector) moves in fine steps and holds the
//!   design (measured below).
//!
//! The price against CA-CFAR is a little detection loss in uniform noise (the estimate
//! uses 9 of 12 samples a side, and GO picks the larger of two noisy estimates) and the
//! sorting, which is kept O(1) a cell: samples are small integers, so each side's window is
//! a histogram of levels (256 bins) with an occupancy bitmap, its k-th level and the power
//! summed below it. Moving the windows changes two samples in each; the k-th moves past at
//! most two of them, each move skipping empty levels by bit scans over eight words. A spoke
//! of n samples costs O(n), allocation-free.
//!
//! ## The numbers
//!
//! - Guard cells, 3 a side: a point echo's range spread (±3 samples at the Navico's 7 m
//!   samples and a 25 m pulse) stays out of its own noise estimate.
//! - Reference cells, n = 12 a side; the k = 9 smallest of each (¾ n) are summed.
//! - Power: a level v stands for amplitudes [v, v + 1) (the receiver floors), so its power
//!   is taken at the interval's middle, (v + ½)², computed as (2v + 1)² in integers.
//! - Threshold: a cell x is detected when (2x + 1)² > T · max(Z_near, Z_far), each Z the
//!   sum of a side's k smallest powers. In Rayleigh amplitude (exponential power) noise the
//!   order statistics of one side are sums of independent exponentials (Rényi):
//!   Z = Σⱼ cⱼ Eⱼ, cⱼ = (k − j + 1)/(n − j + 1). So each Z is the absorption time of a
//!   chain of k exponential phases (rates 1/cⱼ), max(Z_near, Z_far) that of the two chains
//!   run together, and P_fa = E[e^(−T·max)] is found exactly, free of the noise level, by a
//!   recursion over the (k + 1)² joint phases whose terms are all positive (a closed form by
//!   partial fractions exists but cancels catastrophically in f64 for k = 9):
//!
//!   φ(i, j) = (rᵢ·φ(i+1, j) + rⱼ·φ(i, j+1)) / (rᵢ + rⱼ + T), φ(k, k) = 1, P_fa = φ(0, 0)
//!
//!   [`CfarConfig::thresholds`] solves it for T by bisection: P_fa = 10⁻³ with n = 12,
//!   k = 9 gives T = 1.4303.
//! - The spoke's ends: where the far side has fewer than n cells (the last g + n samples),
//!   and where the near side has none (the first g + 1 samples when fewer than n are
//!   blanked before them), only the other side is used, with its own factor for the same
//!   P_fa (one chain: P_fa = ∏ⱼ 1/(1 + T·cⱼ), T = 2.0475); a near side of fewer than n
//!   cells is handled as past the blanking, below. A spoke shorter than 2(n + g) + 1
//!   samples (after blanking) is not tested at all.
//! - The formulas hold for continuous amplitudes; on 8-bit samples with the noise spread
//!   over tens of levels they hold within a few per cent (measured 1.016 × 10⁻³ at σ 30),
//!   and on the synthetic Navico's 4 bits nearly so: 1.033, 1.019 and 0.978 × 10⁻³ at noise
//!   σ 3, 2 and 1.5 levels (the coarser the noise in levels, the lower; tested in
//!   `synthetic`, feature `sim`).
//! - Sea clutter and near range: the CFAR adapts to the clutter's local level, and GO keeps
//!   it on the high side of the clutter's steep fall with range; the first samples are
//!   blanked ([`super::config::ExtractorConfig::min_range_m`]: the main bang and own ship
//!   saturate them) and are never tested. The first g + 1 cells tested have no tested cell
//!   on their near side: the n blanked samples nearest them serve as it. Without them those
//!   cells would have the far side only, which on clutter falling with range sits below the
//!   cell under test and calls it a target: on the synthetic radar at 12 NM (21.7 m
//!   samples, blanking to 0.2 NM) that edge gave 10 of the 12 false plots a rotation. From
//!   the next cell on, the near side holds only tested cells, a ≥ 1 of them until there are
//!   n: the sum of their ⌈a·k/n⌉ smallest ([`partial_rank`]), scaled to a full side's
//!   mean, against the far side's, greater-of, with a factor T(a) solved for the design
//!   P_fa by the same recursion over two unequal chains ([`greatest_of_unequal_pfa`]; on
//!   noise each a holds the design, 0.90–1.08 × 10⁻³ measured). On clutter falling steeply
//!   the cells with 1–3 tested cells false-alarm above it (11.9, 5.2, 2.7 × 10⁻³ on a
//!   steep test slope: a near side of few cells is often low, and greater-of falls to the
//!   far side), the price of seeing there at all ([`MIN_TESTED_NEAR`] gives the trade).
//!   Until 2026-12-05 the blanked samples served the first n + g cells: on the synthetic
//!   radar at 12 NM they hold the main bang and clutter saturating the 4 bits, and a target
//!   at 400–600 m was found on 3 % of its scans (23 % after: there the clutter's own σ of 4–5
//!   levels left an echo saturated at 15 little above its threshold; 600–800 m 53 → 58 %;
//!   since 2026-12-06 the synthetic radar's sea control holds that clutter at the noise's
//!   level, as a real radar's does).
//!   An absolute floor
//!   ([`CfarConfig::min_level`]) keeps quiet stretches (a radar's own noise rejection leaves
//!   zeros) from detecting every ripple. Real sea clutter is spikier than Rayleigh
//!   (K-distributed) and would raise P_fa near own ship; a range-dependent floor for it is
//!   not modelled.

use super::config::ConfigError;

/// Sample levels a `u8` can take.
const LEVELS: usize = 256;
/// Words of the histogram's occupancy bitmap.
const WORDS: usize = LEVELS / 32;
/// Most reference cells a side.
pub const MAX_REFERENCE_CELLS: u16 = 64;
/// Tested cells the near side needs before it holds only tested cells (with fewer, the
/// blanked samples nearest make up its n). On clutter falling steeply with range a near
/// side of 1–3 cells is often low, greater-of then falls to the far side, and those cells
/// false-alarm above the design; waiting for more cells blinds them instead. Measured on
/// `demo --video` (seed 1) before the synthetic radar had a sea control, its clutter
/// saturating the 4 bits near own ship, 1 / 2 / 3–4 / 6 cells: OSPA 29.1 / 30.9 / 31.8 /
/// 34.6 m, false plots 4.34 / 4.20 / 4.17 / 4.15 a scan, no false track at any (module docs,
/// "Sea clutter and near range"). With the sea control on auto (2026-12-06) the choice
/// hardly matters there: 1 / 2 / 3 / 6 cells, OSPA 24.9 m and 7 untracked target-scans
/// each, false plots 4.29 / 4.30 / 4.30 / 4.31 a scan. Kept at 1 for a radar whose sea
/// control is set low or off, where the first figures apply.
pub const MIN_TESTED_NEAR: usize = 1;

/// The detector's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CfarConfig {
    /// Guard cells each side of the cell under test, left out of the noise estimate so a
    /// target's own range spread does not raise its threshold, cells (0..=64).
    pub guard_cells: u16,
    /// Reference cells each side, n, cells (1..=[`MAX_REFERENCE_CELLS`]).
    pub reference_cells: u16,
    /// k: each side's k smallest reference samples are summed for its noise estimate, its
    /// n − k largest ignored, 1..=n.
    pub rank: u16,
    /// Design probability of false alarm per cell, for Rayleigh-amplitude noise.
    pub pfa: f32,
    /// Smallest sample that may be detected whatever the estimate, sample levels.
    pub min_level: u8,
}

/// The threshold factors, on a side's k smallest powers' sum, that give the design P_fa.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// T on the greater of the two sides' sums (both sides full).
    pub both_sides: f64,
    /// T on one side's sum (near the spoke's ends).
    pub one_side: f64,
}

impl CfarConfig {
    /// Checks the settings.
    ///
    /// # Errors
    /// [`ConfigError::ReferenceCells`], [`ConfigError::GuardCells`], [`ConfigError::Rank`]
    /// or [`ConfigError::FalseAlarmProbability`] for the first one out of range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(1..=MAX_REFERENCE_CELLS).contains(&self.reference_cells) {
            return Err(ConfigError::ReferenceCells);
        }
        if self.guard_cells > 64 {
            return Err(ConfigError::GuardCells);
        }
        if !(1..=self.reference_cells).contains(&self.rank) {
            return Err(ConfigError::Rank);
        }
        if !(self.pfa > 1e-12 && self.pfa < 0.5) {
            return Err(ConfigError::FalseAlarmProbability);
        }
        Ok(())
    }

    /// The factors T that give [`CfarConfig::pfa`] in Rayleigh-amplitude noise, with both
    /// sides and with one (the module's formulas; bisection in f64, once).
    ///
    /// # Errors
    /// As [`CfarConfig::validate`].
    pub fn thresholds(&self) -> Result<Thresholds, ConfigError> {
        self.validate()?;
        let (n, k) = (u32::from(self.reference_cells), u32::from(self.rank));
        let target = f64::from(self.pfa);
        Ok(Thresholds {
            both_sides: solve(|t| greatest_of_pfa(n, k, t), target)?,
            one_side: solve(|t| trimmed_pfa(n, k, t), target)?,
        })
    }
}

/// The T at which the falling `pfa(T)` is `target`: bracket, then halve.
fn solve(pfa: impl Fn(f64) -> f64, target: f64) -> Result<f64, ConfigError> {
    let mut hi = 1.0f64;
    while pfa(hi) > target {
        hi *= 2.0;
        if hi > 1e12 {
            return Err(ConfigError::FalseAlarmProbability);
        }
    }
    let mut lo = 0.0f64;
    // 50 halvings leave the bracket 2⁻⁵⁰ of its width: far below the f32 the factors are
    // kept in, and each step is a recursion in software f64 on an M4F.
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if pfa(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// The rate of phase `j` (1-based) of a side's trimmed sum, 1/cⱼ = (n − j + 1)/(k − j + 1).
fn phase_rate(n: u32, k: u32, j: u32) -> f64 {
    f64::from(n - j + 1) / f64::from(k - j + 1)
}

/// One side's false-alarm probability in Rayleigh-amplitude (exponential power) noise: the
/// chance that a noise sample's power exceeds `factor` times the sum of the `rank`
/// smallest of `reference` others' powers, ∏ⱼ 1/(1 + T·cⱼ).
pub fn trimmed_pfa(reference: u32, rank: u32, factor: f64) -> f64 {
    let k = rank.min(reference);
    let mut p = 1.0f64;
    for j in 1..=k {
        let r = phase_rate(reference, k, j);
        p *= r / (r + factor);
    }
    p
}

/// The greatest-of false-alarm probability: `factor` times the larger of two independent
/// sides' trimmed sums (the module's recursion, O(k²)).
pub fn greatest_of_pfa(reference: u32, rank: u32, factor: f64) -> f64 {
    let side = (reference, rank, 1.0);
    greatest_of_unequal_pfa(side, side, factor)
}

/// The rank used on a near side cut to `cells` of the `reference` cells by the blanking
/// (or the spoke's start): the same fraction k/n of them, rounded up, at least one.
pub fn partial_rank(cells: u16, reference: u16, rank: u16) -> u16 {
    let scaled = (u32::from(cells) * u32::from(rank)).div_ceil(u32::from(reference.max(1)));
    (scaled as u16).clamp(1, cells.max(1))
}

/// A side's trimmed sum's mean over the noise's mean power, Σⱼ cⱼ (`reference` cells,
/// `rank` smallest summed).
pub fn trimmed_mean(reference: u32, rank: u32) -> f64 {
    let k = rank.min(reference);
    (1..=k).map(|j| 1.0 / phase_rate(reference, k, j)).sum()
}

/// The greatest-of false-alarm probability for two sides of unequal windows,
/// `(n, k, scale)` each (the side's trimmed sum times `scale` is compared): the module's
/// recursion over the two chains' joint phases, φ(i, j) with i of the first chain's k₁
/// phases run and j of the second's, O(k₁·k₂). With equal sides and scales of 1 it is
/// [`greatest_of_pfa`].
pub fn greatest_of_unequal_pfa(
    first: (u32, u32, f64),
    second: (u32, u32, f64),
    factor: f64,
) -> f64 {
    let cap = u32::from(MAX_REFERENCE_CELLS);
    let (n1, k1, s1) = (first.0.min(cap), first.1.min(first.0).min(cap), first.2);
    let (n2, k2, s2) = (second.0.min(cap), second.1.min(second.0).min(cap), second.2);
    // A phase of rate r scaled by s runs at r / s; each chain's rates once, not per step.
    let mut rates1 = [0.0f64; MAX_REFERENCE_CELLS as usize + 1];
    let mut rates2 = [0.0f64; MAX_REFERENCE_CELLS as usize + 1];
    for (rates, n, k, s) in [(&mut rates1, n1, k1, s1), (&mut rates2, n2, k2, s2)] {
        for j in 1..=k {
            if let Some(r) = rates.get_mut(j as usize) {
                *r = phase_rate(n, k, j) / s;
            }
        }
    }
    let phase_rate = |rates: &[f64; MAX_REFERENCE_CELLS as usize + 1], j: u32| {
        rates.get(j as usize).copied().unwrap_or(1.0)
    };
    // row[j] = φ(i, j) for the current i, from i = k₁ (the first chain absorbed) down to 0.
    let mut row = [0.0f64; MAX_REFERENCE_CELLS as usize + 1];
    let k2u = k2 as usize;
    if let Some(last) = row.get_mut(k2u) {
        *last = 1.0;
    }
    for j in (0..k2).rev() {
        let r = phase_rate(&rates2, j + 1);
        let next = row.get(j as usize + 1).copied().unwrap_or(0.0);
        if let Some(cell) = row.get_mut(j as usize) {
            *cell = r * next / (r + factor);
        }
    }
    for i in (0..k1).rev() {
        let ri = phase_rate(&rates1, i + 1);
        // φ(i, k₂): the second chain absorbed, the first runs alone.
        if let Some(cell) = row.get_mut(k2u) {
            *cell *= ri / (ri + factor);
        }
        // Leftwards: row[j] still holds φ(i + 1, j), row[j + 1] already φ(i, j + 1).
        for j in (0..k2).rev() {
            let rj = phase_rate(&rates2, j + 1);
            let right = row.get(j as usize + 1).copied().unwrap_or(0.0);
            if let Some(cell) = row.get_mut(j as usize) {
                *cell = (ri * *cell + rj * right) / (ri + rj + factor);
            }
        }
    }
    row.first().copied().unwrap_or(0.0)
}

/// A level's power, at the middle of the amplitudes it stands for: (2v + 1)² = 4(v + ½)².
fn power(v: u8) -> u32 {
    let a = 2 * u32::from(v) + 1;
    a * a
}

/// A run of adjacent detected cells on one spoke.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Run {
    /// The first cell, a sample index from the antenna.
    pub start: u16,
    /// One past the last cell.
    pub end: u16,
    /// Sum of the cells' samples, sample levels.
    pub sum: u32,
    /// Sum of sample × sample index, for the strength-weighted centroid.
    pub index_sum: u64,
    /// The strongest sample, sample levels.
    pub peak: u8,
}

impl Run {
    /// Cells in the run.
    pub fn cells(&self) -> u16 {
        self.end.saturating_sub(self.start)
    }
}

/// The k-th smallest of a multiset of `u8` and the power summed below it, kept as a
/// histogram while samples come and go.
#[derive(Clone, Debug)]
struct RankWindow {
    hist: [u16; LEVELS],
    /// Bit `v % 32` of word `v / 32` is set while `hist[v] > 0`.
    occupied: [u32; WORDS],
    /// The current k-th value …
    kth: u8,
    /// … how many samples lie below it …
    below: u16,
    /// … and their summed [`power`] (at most 64 × 511² < 2²⁴: exact in f32).
    below_power: u32,
}

impl RankWindow {
    const fn new() -> Self {
        RankWindow {
            hist: [0; LEVELS],
            occupied: [0; WORDS],
            kth: 0,
            below: 0,
            below_power: 0,
        }
    }

    fn clear(&mut self) {
        *self = RankWindow::new();
    }

    fn add(&mut self, v: u8) {
        // Indexing a 256-array by a u8 cannot go out of bounds.
        let h = &mut self.hist[usize::from(v)];
        *h = h.saturating_add(1);
        if let Some(w) = self.occupied.get_mut(usize::from(v >> 5)) {
            *w |= 1 << (v & 31);
        }
        if v < self.kth {
            self.below = self.below.saturating_add(1);
            self.below_power = self.below_power.saturating_add(power(v));
        }
    }

    fn remove(&mut self, v: u8) {
        let h = &mut self.hist[usize::from(v)];
        *h = h.saturating_sub(1);
        if *h == 0 {
            if let Some(w) = self.occupied.get_mut(usize::from(v >> 5)) {
                *w &= !(1 << (v & 31));
            }
        }
        if v < self.kth {
            self.below = self.below.saturating_sub(1);
            self.below_power = self.below_power.saturating_sub(power(v));
        }
    }

    /// The largest occupied level below `v`.
    fn prev_occupied(&self, v: u8) -> Option<u8> {
        let mut word = usize::from(v >> 5);
        // Bits strictly below v's in its own word, then whole lower words.
        let mut mask = (1u32 << (v & 31)) - 1;
        loop {
            let bits = self.occupied.get(word).copied().unwrap_or(0) & mask;
            if bits != 0 {
                let bit = 31 - bits.leading_zeros() as usize;
                return u8::try_from(word * 32 + bit).ok();
            }
            word = word.checked_sub(1)?;
            mask = u32::MAX;
        }
    }

    /// The smallest occupied level above `v`.
    fn next_occupied(&self, v: u8) -> Option<u8> {
        let mut word = usize::from(v >> 5);
        let mut mask = u32::MAX.checked_shl(u32::from(v & 31) + 1).unwrap_or(0);
        while word < WORDS {
            let bits = self.occupied.get(word).copied().unwrap_or(0) & mask;
            if bits != 0 {
                let bit = bits.trailing_zeros() as usize;
                return u8::try_from(word * 32 + bit).ok();
            }
            word += 1;
            mask = u32::MAX;
        }
        None
    }

    /// Moves to the `k`-th smallest (1-based) sample after adds and removes (the level
    /// with fewer than `k` samples below it and at least `k` at or below it) and returns
    /// the summed power of the `k` smallest. Each step passes one occupied level; after a
    /// window move of four samples that is at most a few steps, and after any number of
    /// moves (a settle skipped for cells below the floor) at most the occupied levels.
    fn settle(&mut self, k: u16) -> u32 {
        while self.below >= k {
            let Some(v) = self.prev_occupied(self.kth) else {
                self.below = 0;
                self.below_power = 0;
                break;
            };
            self.kth = v;
            let h = self.hist[usize::from(v)];
            self.below = self.below.saturating_sub(h);
            self.below_power = self.below_power.saturating_sub(u32::from(h) * power(v));
        }
        while self.below.saturating_add(self.hist[usize::from(self.kth)]) < k {
            let Some(v) = self.next_occupied(self.kth) else {
                break;
            };
            let h = self.hist[usize::from(self.kth)];
            self.below = self.below.saturating_add(h);
            self.below_power = self
                .below_power
                .saturating_add(u32::from(h) * power(self.kth));
            self.kth = v;
        }
        let at_kth = u32::from(k.saturating_sub(self.below));
        self.below_power.saturating_add(at_kth * power(self.kth))
    }
}

/// The CFAR detector: its settings, its threshold factors, and the two sliding windows it
/// reuses spoke after spoke, and the factors for a near side cut short (about 1.6 KiB in
/// all).
#[derive(Clone, Debug)]
pub struct Cfar {
    config: CfarConfig,
    both_sides: f32,
    one_side: f32,
    /// `partial[a]`: for a near side of `a` cells (1 ≤ a < n, with its own rank,
    /// [`partial_rank`]) against a full far side, T and the scale that puts the near sum on
    /// the far sum's mean; 0 unused.
    partial: [(f32, f32); MAX_REFERENCE_CELLS as usize],
    near: RankWindow,
    far: RankWindow,
}

impl Cfar {
    /// A detector for `config`.
    ///
    /// # Errors
    /// As [`CfarConfig::validate`].
    pub fn new(config: &CfarConfig) -> Result<Self, ConfigError> {
        let t = config.thresholds()?;
        let (n, k) = (config.reference_cells, config.rank);
        let target = f64::from(config.pfa);
        let mut partial = [(f32::INFINITY, 1.0); MAX_REFERENCE_CELLS as usize];
        let far = (u32::from(n), u32::from(k), 1.0);
        for (a, entry) in partial.iter_mut().enumerate().take(usize::from(n)).skip(1) {
            let a = a as u16;
            let (a, rank) = (u32::from(a), u32::from(partial_rank(a, n, k)));
            let scale = trimmed_mean(far.0, far.1) / trimmed_mean(a, rank);
            let near = (a, rank, scale);
            let factor = solve(|t| greatest_of_unequal_pfa(near, far, t), target)?;
            *entry = (factor as f32, scale as f32);
        }
        Ok(Cfar {
            config: *config,
            both_sides: t.both_sides as f32,
            one_side: t.one_side as f32,
            partial,
            near: RankWindow::new(),
            far: RankWindow::new(),
        })
    }

    /// A detector that detects nothing (infinite thresholds) until replaced by one from
    /// [`Cfar::new`]: for a `static` built at compile time.
    pub const fn unconfigured(config: CfarConfig) -> Self {
        Cfar {
            config,
            both_sides: f32::INFINITY,
            one_side: f32::INFINITY,
            partial: [(f32::INFINITY, 1.0); MAX_REFERENCE_CELLS as usize],
            near: RankWindow::new(),
            far: RankWindow::new(),
        }
    }

    /// The settings.
    pub fn config(&self) -> &CfarConfig {
        &self.config
    }

    /// Whether a sample `x` is a detection, given each full side's sum of its k smallest
    /// powers (in the module's (2v + 1)² units; `None` for a side with fewer than n cells).
    pub fn detects(&self, x: u8, near: Option<u32>, far: Option<u32>) -> bool {
        let noise = match (near, far) {
            (Some(a), Some(b)) => self.both_sides * a.max(b) as f32,
            (Some(a), None) | (None, Some(a)) => self.one_side * a as f32,
            (None, None) => return false,
        };
        // The sums are exact in f32 (below 2²⁴ for n ≤ 64).
        x >= self.config.min_level && power(x) as f32 > noise
    }

    /// Whether a sample `x` is a detection with a near side of only `cells` (1 ≤ cells < n)
    /// tested cells, the sum of their [`partial_rank`] smallest powers `near`, and a far
    /// side `far` as in [`Cfar::detects`] (`None`: not tested).
    pub fn detects_beside_blanking(&self, x: u8, cells: u16, near: u32, far: Option<u32>) -> bool {
        let (Some((factor, scale)), Some(far)) =
            (self.partial.get(usize::from(cells)).copied(), far)
        else {
            return false;
        };
        let noise = factor * (near as f32 * scale).max(far as f32);
        x >= self.config.min_level && power(x) as f32 > noise
    }

    /// Detects along `samples[first..]` (the first samples blanked: not tested, but the
    /// nearest n of them are the near reference of the cells with no tested cell before
    /// their guard; the next cells' near side is the tested cells before the guard, fewer
    /// than n at first, see the module's "Sea clutter and near range"), calling
    /// `on_run` for each run of adjacent detections, nearest first; returns the cells
    /// detected, or `None` when fewer than 2(n + guard) + 1 samples remain to test. Samples
    /// beyond index 65,535 are ignored. O(samples), no allocation.
    pub fn detect(
        &mut self,
        samples: &[u8],
        first: usize,
        mut on_run: impl FnMut(Run),
    ) -> Option<u32> {
        let end = samples.len().min(usize::from(u16::MAX));
        let g = usize::from(self.config.guard_cells);
        let n = usize::from(self.config.reference_cells);
        let k = self.config.rank;
        if end.saturating_sub(first) < 2 * (n + g) + 1 {
            return None;
        }
        // Windows run over the blanked samples nearest the first tested cell too.
        let base = first.saturating_sub(n + g);
        let xs = samples.get(base..end)?;
        let len = xs.len();
        let tested = first - base;
        self.near.clear();
        self.far.clear();
        // The sides are [near_a, near_b) and [far_a, far_b), clipped to the spoke; every
        // bound only moves outwards as the cell under test does, so each sample enters and
        // leaves each window once.
        let (mut near_a, mut near_b, mut far_a, mut far_b) = (0usize, 0usize, 0usize, 0usize);
        let mut run: Option<Run> = None;
        let mut detected = 0u32;
        for (i, &x) in xs.iter().enumerate().skip(tested) {
            let to_near_b = i.saturating_sub(g);
            // Once the near side has MIN_TESTED_NEAR tested cells, it holds only those
            // (fewer than n at first, each count with its own factor); until then the
            // blanked samples nearest make up its n. They hold the main bang and the
            // strongest clutter, and a side of them would blind the first n cells tested
            // (the module's "near range").
            let to_near_a = if to_near_b >= tested + MIN_TESTED_NEAR.min(n) {
                to_near_b.saturating_sub(n).max(tested)
            } else {
                to_near_b.saturating_sub(n)
            };
            let to_far_a = (i + g + 1).min(len);
            let to_far_b = (i + g + 1 + n).min(len);
            move_upper(&mut self.near, xs, &mut near_b, to_near_b);
            move_lower(&mut self.near, xs, &mut near_a, to_near_a);
            move_upper(&mut self.far, xs, &mut far_b, to_far_b);
            move_lower(&mut self.far, xs, &mut far_a, to_far_a);
            // A cell below the floor is never detected: its windows need not settle (they
            // settle later, over as many steps as it takes; on noise most cells are below it).
            let testable = x >= self.config.min_level;
            let near_cells = near_b.saturating_sub(near_a);
            let far = (testable && far_b.saturating_sub(far_a) == n).then(|| self.far.settle(k));
            let hit = if !testable {
                false
            } else if near_cells == n {
                let near = self.near.settle(k);
                self.detects(x, Some(near), far)
            } else if near_a == tested && near_cells >= MIN_TESTED_NEAR {
                let cells = near_cells as u16;
                let rank = partial_rank(cells, self.config.reference_cells, k);
                let sum = self.near.settle(rank);
                self.detects_beside_blanking(x, cells, sum, far)
            } else {
                self.detects(x, None, far)
            };
            if !hit {
                if let Some(done) = run.take() {
                    on_run(done);
                }
                continue;
            }
            detected += 1;
            let index = u16::try_from(base + i).unwrap_or(u16::MAX);
            let weight = u32::from(x);
            match run.as_mut() {
                Some(open) => {
                    open.end = index.saturating_add(1);
                    open.sum = open.sum.saturating_add(weight);
                    open.index_sum += u64::from(weight) * u64::from(index);
                    open.peak = open.peak.max(x);
                }
                None => {
                    run = Some(Run {
                        start: index,
                        end: index.saturating_add(1),
                        sum: weight,
                        index_sum: u64::from(weight) * u64::from(index),
                        peak: x,
                    });
                }
            }
        }
        if let Some(done) = run {
            on_run(done);
        }
        Some(detected)
    }
}

/// Moves an interval's upper (exclusive) bound to `to`: samples passed going up enter.
fn move_upper(w: &mut RankWindow, xs: &[u8], cur: &mut usize, to: usize) {
    while *cur < to {
        if let Some(&v) = xs.get(*cur) {
            w.add(v);
        }
        *cur += 1;
    }
    while *cur > to {
        *cur -= 1;
        if let Some(&v) = xs.get(*cur) {
            w.remove(v);
        }
    }
}

/// Moves an interval's lower bound to `to`: samples passed going up leave.
fn move_lower(w: &mut RankWindow, xs: &[u8], cur: &mut usize, to: usize) {
    while *cur < to {
        if let Some(&v) = xs.get(*cur) {
            w.remove(v);
        }
        *cur += 1;
    }
    while *cur > to {
        *cur -= 1;
        if let Some(&v) = xs.get(*cur) {
            w.add(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;
    use rand_core::SeedableRng;
    use rand_pcg::Pcg32;

    fn config(pfa: f32, min_level: u8) -> CfarConfig {
        CfarConfig {
            guard_cells: 3,
            reference_cells: 12,
            rank: 9,
            pfa,
            min_level,
        }
    }

    /// Rayleigh amplitude of scale `sigma`, floored to an integer level like an ADC.
    fn rayleigh(rng: &mut Pcg32, sigma: f32, max: u8) -> u8 {
        let u = 1.0 - rng.random::<f32>();
        let a = sigma * libm::sqrtf(-2.0 * libm::logf(u));
        (a as u32).min(u32::from(max)) as u8
    }

    #[test]
    fn the_threshold_factors_give_the_design_pfa() {
        let t = config(1e-3, 0).thresholds().unwrap();
        assert!((t.both_sides - 1.4303).abs() < 1e-4, "{t:?}");
        assert!((t.one_side - 2.0475).abs() < 1e-4, "{t:?}");
        assert!((greatest_of_pfa(12, 9, t.both_sides) - 1e-3).abs() < 1e-9);
        assert!((trimmed_pfa(12, 9, t.one_side) - 1e-3).abs() < 1e-9);
        // The recursion against exact rational arithmetic (partial fractions).
        assert!((greatest_of_pfa(12, 9, 1.5) - 7.639_554_430_943_9e-4).abs() < 1e-15);
        assert!((greatest_of_pfa(8, 6, 1.5) - 6.420_201_567_671_9e-3).abs() < 1e-15);
        // k = n is cell averaging on one side's sum: (1 + T)^−n; its greatest-of has the
        // textbook closed form 2(1+T)^−n − 2 Σ_{i<n} C(n−1+i, i) (2+T)^−(n+i).
        assert!((trimmed_pfa(12, 12, 0.25) - 1.25f64.powi(-12)).abs() < 1e-15);
        let (n, t) = (4, 0.7f64);
        let mut go = 2.0 * (1.0 + t).powi(-n);
        for (i, binomial) in [1.0, 4.0, 10.0, 20.0].iter().enumerate() {
            go -= 2.0 * binomial * (2.0 + t).powi(-(n + i as i32));
        }
        assert!((greatest_of_pfa(4, 4, t) - go).abs() < 1e-14, "{go}");
        // The unequal recursion: with equal sides it is the equal one; it is symmetric in
        // its sides; and one cell scaled by s (an exponential A) against cell averaging over
        // m (k = m: a Gamma(m) sum G) has the closed form
        // E[e^(−T·max(sA, G))] = 1/(1 + Ts) − Σ_{i<m} sⁱ/(1 + Ts + s)^(i+1)
        //                      + (1 + T)^(−m) − (1 + T + 1/s)^(−m)
        // (split on which is larger; checked by Monte Carlo when written).
        for (n, k) in [(12, 9), (8, 6), (5, 4)] {
            for t in [0.3, 1.4303, 4.0] {
                let a = greatest_of_unequal_pfa((n, k, 1.0), (n, k, 1.0), t);
                assert!((a - greatest_of_pfa(n, k, t)).abs() < 1e-15, "{n} {k} {t}");
            }
        }
        for (near, far, t) in [
            ((3, 2, 1.7), (12, 9, 1.0), 1.2),
            ((7, 5, 0.6), (12, 9, 1.0), 2.0),
        ] {
            let (a, b) = (
                greatest_of_unequal_pfa(near, far, t),
                greatest_of_unequal_pfa(far, near, t),
            );
            assert!((a - b).abs() < 1e-15, "{a} {b}");
        }
        for (m, s, t) in [
            (1u32, 2.5f64, 0.8f64),
            (2, 2.5, 0.8),
            (5, 0.7, 0.3),
            (9, 1.3, 1.1),
        ] {
            let mut exact = 1.0 / (1.0 + t * s) + (1.0 + t).powi(-(m as i32))
                - (1.0 + t + 1.0 / s).powi(-(m as i32));
            for i in 0..m as i32 {
                exact -= s.powi(i) / (1.0 + t * s + s).powi(i + 1);
            }
            let got = greatest_of_unequal_pfa((1, 1, s), (m, m, 1.0), t);
            assert!((got - exact).abs() < 1e-13, "m {m}: {got} {exact}");
        }
        // Partial ranks keep the fraction k/n, rounded up.
        let ranks: std::vec::Vec<u16> = (1..=12).map(|a| partial_rank(a, 12, 9)).collect();
        assert_eq!(ranks, [1, 2, 3, 3, 4, 5, 6, 6, 7, 8, 9, 9]);
    }

    #[test]
    fn the_windows_rank_like_a_sort_at_every_cell_and_both_ends() {
        // Recompute every cell's noise estimates the slow way and compare the detections.
        let mut rng = Pcg32::seed_from_u64(7);
        // Rank 3 of 5: the near side cut to a = 1–4 cells takes 1, 2, 2, 3 of them, so the
        // partial ranks are exercised; blanking up to 12 samples puts the near side in the
        // blanked samples, then in the tested ones, then in full windows.
        let c = CfarConfig {
            guard_cells: 2,
            reference_cells: 5,
            rank: 3,
            pfa: 1e-2,
            min_level: 0,
        };
        let mut cfar = Cfar::new(&c).unwrap();
        let mut partial_hits = 0;
        for trial in 0..600 {
            let len = 15 + trial % 40;
            let first = trial % 13;
            let levels = if trial % 2 == 0 { 16 } else { 256 };
            let xs: std::vec::Vec<u8> = (0..len)
                .map(|_| rng.random_range(0..levels) as u8)
                .collect();
            let mut fast = std::vec::Vec::new();
            cfar.detect(&xs, first, |r| fast.push(r));
            let body = &xs[first..];
            let m = body.len();
            let (g, n, k) = (2usize, 5usize, 3usize);
            let trimmed = |cells: &[u8]| -> Option<u32> {
                (cells.len() == n).then(|| {
                    let mut v = cells.to_vec();
                    v.sort_unstable();
                    v[..k].iter().map(|&x| power(x)).sum()
                })
            };
            let mut slow = std::vec::Vec::new();
            if m < 2 * (n + g) + 1 {
                assert_eq!(fast, [], "trial {trial}: too short to test");
                continue;
            }
            // Tested from `first` on; the near side holds the tested cells before the
            // guard once there are any (fewer than n: their own rank and factor), else
            // reaches into the blanked samples.
            for j in first..xs.len() {
                let far = if j + g + n < xs.len() {
                    trimmed(&xs[j + g + 1..j + g + 1 + n])
                } else {
                    None
                };
                let near_b = j.saturating_sub(g);
                let hit = if j >= g && near_b >= first + MIN_TESTED_NEAR && near_b - first < n {
                    let cells = &xs[first..near_b];
                    let rank = partial_rank(cells.len() as u16, n as u16, k as u16);
                    let mut v = cells.to_vec();
                    v.sort_unstable();
                    let sum = v[..usize::from(rank)].iter().map(|&x| power(x)).sum();
                    let hit = cfar.detects_beside_blanking(xs[j], cells.len() as u16, sum, far);
                    partial_hits += usize::from(hit);
                    hit
                } else {
                    let near = if j >= g + n {
                        trimmed(&xs[j - g - n..j - g])
                    } else {
                        None
                    };
                    cfar.detects(xs[j], near, far)
                };
                if hit {
                    slow.push(j);
                }
            }
            let fast_cells: std::vec::Vec<usize> = fast
                .iter()
                .flat_map(|r| usize::from(r.start)..usize::from(r.end))
                .collect();
            assert_eq!(fast_cells, slow, "trial {trial}");
        }
        assert!(
            partial_hits > 20,
            "{partial_hits} detections with a cut near side"
        );
    }

    #[test]
    fn false_alarms_on_rayleigh_noise_are_within_ten_per_cent_of_the_design() {
        // 8-bit samples with the noise spread over tens of levels (σ 30): the continuous
        // formulas' regime. 2,000 spokes × 1,000 cells (the first 4 and last 15 of each
        // on one side, the 11 after those first 4 with a near side cut short): about 2,000
        // false alarms expected, a standard error of 2.2 %.
        let c = config(1e-3, 0);
        let mut cfar = Cfar::new(&c).unwrap();
        let mut rng = Pcg32::seed_from_u64(11);
        let mut spoke = [0u8; 1000];
        let (mut alarms, mut cells) = (0u64, 0u64);
        for _ in 0..2000 {
            for s in spoke.iter_mut() {
                *s = rayleigh(&mut rng, 30.0, 255);
            }
            alarms += u64::from(cfar.detect(&spoke, 0, |_| {}).unwrap());
            cells += spoke.len() as u64;
        }
        let pfa = alarms as f64 / cells as f64;
        eprintln!("8-bit Rayleigh noise σ 30: P_fa {pfa:.3e} over {cells} cells");
        assert!((pfa - 1e-3).abs() < 1e-4, "P_fa {pfa:.3e}");
    }

    /// False alarms of each cell past the blanking at `first`, by the tested cells on its
    /// near side (index a = 1..n; 0 the cells with none), over `spokes` spokes drawn by
    /// `draw`, each with `target` painted in if given: (alarms a cell, target found).
    fn past_the_blanking(
        spokes: u32,
        first: usize,
        seed: u64,
        draw: impl Fn(&mut Pcg32, usize) -> u8,
        target: Option<(usize, u8)>,
    ) -> ([f64; 12], f64) {
        let c = config(1e-3, 0);
        let mut cfar = Cfar::new(&c).unwrap();
        let mut rng = Pcg32::seed_from_u64(seed);
        let g = 3;
        let mut alarms = [0u32; 12];
        let mut found = 0u32;
        let mut spoke = [0u8; 120];
        for _ in 0..spokes {
            for (i, s) in spoke.iter_mut().enumerate() {
                *s = draw(&mut rng, i);
            }
            cfar.detect(&spoke, first, |r| {
                for i in usize::from(r.start)..usize::from(r.end) {
                    if let Some(a) = (i + 1).checked_sub(first + g + 1) {
                        if let Some(n) = alarms.get_mut(a) {
                            *n += 1;
                        }
                    }
                }
            });
            if let Some((at, level)) = target {
                spoke[at] = level;
                cfar.detect(&spoke, first, |r| {
                    found += u32::from((r.start..r.end).contains(&(at as u16)));
                });
            }
        }
        (
            alarms.map(|n| f64::from(n) / f64::from(spokes)),
            f64::from(found) / f64::from(spokes),
        )
    }

    #[test]
    fn the_first_cells_past_the_blanking_hold_the_design_false_alarm_rate() {
        // Homogeneous noise (σ 30, 8 bits) blanked to cell 40: each cell whose near side
        // holds a = 1–11 tested cells (its own rank and factor) false-alarms at the design
        // rate. 200,000 spokes: about 200 alarms a cell, a standard error of 7 %.
        let (pfa, _) = past_the_blanking(200_000, 40, 5, |r, _| rayleigh(r, 30.0, 255), None);
        let milli = pfa.map(|p| p * 1e3);
        eprintln!("near side of a tested cells on noise, P_fa × 10³ by a: {milli:.2?}");
        for (a, p) in pfa.iter().enumerate().skip(1) {
            assert!((p - 1e-3).abs() < 2.5e-4, "a = {a}: P_fa {p:.3e}");
        }
    }

    #[test]
    fn a_target_just_past_the_blanking_is_found_in_the_clutter_falling_with_range() {
        // Sea clutter falling as r^−1.5 (σ 60 levels at cell 10, 8 bits, saturating nearer),
        // blanked to cell 20; a target 6 cells past the blanking (3 tested cells on its near
        // side) of 6 times the clutter's σ there. With the blanked samples as its near side
        // (before 2026-12-05) it was found on 12 % of spokes, 68 % now. The price: on this
        // steep clutter the cells with a near side of 1–3 tested cells false-alarm above the
        // design (greater-of falls to the far side when their few cells are low; measured
        // 11.9, 5.2, 2.7 × 10⁻³, and 2.2 at 4), those with 5 or more below it; with the
        // blanked samples the 30 cells past the blanking false-alarmed 7.7 × 10⁻⁵ a cell
        // (MIN_TESTED_NEAR).
        let sigma = |i: usize| 60.0 * libm::powf(10.0 / (i as f32 + 0.5), 1.5);
        let level = (6.0 * sigma(26)) as u8;
        let (pfa, pd) = past_the_blanking(
            20_000,
            20,
            9,
            |r, i| rayleigh(r, sigma(i), 255),
            Some((26, level)),
        );
        let milli = pfa.map(|p| p * 1e3);
        eprintln!("target past the blanking: P_d {pd:.3}; clutter P_fa × 10³ by a: {milli:.2?}");
        assert!(pd > 0.6, "P_d {pd:.3}");
        assert!(
            pfa[1] < 15e-3 && pfa[2] < 7e-3 && pfa[3] < 3.5e-3,
            "{pfa:?}"
        );
        assert!(pfa[6..].iter().all(|&p| p < 1e-3), "{pfa:?}");
    }

    #[test]
    fn a_target_is_found_at_its_cell_despite_a_neighbour_in_the_window() {
        let c = config(1e-3, 0);
        let mut cfar = Cfar::new(&c).unwrap();
        let mut rng = Pcg32::seed_from_u64(3);
        let mut spoke = [0u8; 400];
        for s in spoke.iter_mut() {
            *s = rayleigh(&mut rng, 10.0, 255);
        }
        // Two echoes 8 cells apart, each 3 cells long: each is in the other's reference
        // window, which a cell-averaging CFAR would let mask it.
        for (c0, peak) in [(200usize, 200u8), (208, 150)] {
            spoke[c0 - 1] = peak / 2;
            spoke[c0] = peak;
            spoke[c0 + 1] = peak / 2;
        }
        let mut runs = std::vec::Vec::new();
        cfar.detect(&spoke, 0, |r| runs.push(r));
        let peaks: std::vec::Vec<u16> = runs
            .iter()
            .filter(|r| r.peak > 100)
            .map(|r| r.start + r.cells() / 2)
            .collect();
        assert_eq!(peaks, [200, 208], "{runs:?}");
    }

    #[test]
    fn blanked_short_and_silent_spokes() {
        let c = config(1e-3, 4);
        let mut cfar = Cfar::new(&c).unwrap();
        // A saturated main bang in the first 10 samples, zeros beyond: nothing.
        let mut spoke = [0u8; 100];
        spoke[..10].fill(15);
        let mut runs = 0;
        assert_eq!(cfar.detect(&spoke, 10, |_| runs += 1), Some(0));
        // Unblanked, the bang is one detection: its cell 3, whose only side (the far)
        // holds 3 more of it, which the trimming ignores. Cells 0–2 hold more in their far
        // side, and from cell 4 on the near side is the bang's own first cells.
        let mut at = std::vec::Vec::new();
        assert_eq!(cfar.detect(&spoke, 0, |r| at.push(r.start)), Some(1));
        assert_eq!(at, [3]);
        runs += at.len();
        assert_eq!(runs, 1);
        // Below the floor nothing is detected whatever the estimate.
        spoke.fill(0);
        spoke[50] = 3;
        assert_eq!(cfar.detect(&spoke, 0, |_| {}), Some(0));
        spoke[50] = 4;
        assert_eq!(cfar.detect(&spoke, 0, |_| {}), Some(1));
        // Too short to hold a window: not tested; past the end: not tested.
        assert_eq!(cfar.detect(&spoke[..30], 0, |_| {}), None);
        assert_eq!(cfar.detect(&spoke, 200, |_| {}), None);
    }
}
