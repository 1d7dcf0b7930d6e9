//! Plot extraction: spokes in, one plot per echo out.
//!
//! The [`Extractor`] takes spokes one at a time in angle order, runs the
//! [CFAR](super::cfar) along each, and grows blobs of detected cells across consecutive
//! spokes: a run of detections joins the blob whose run on the previous spoke overlaps it in
//! range (sharing at least one sample index); a run overlapping runs of two blobs merges
//! them; a run overlapping none starts a blob. A blob closes when a spoke passes with no run
//! overlapping it. By default it closes at the second such spoke in a row
//! ([`ExtractorConfig::max_missed_spokes`] = 1; 0 is the strict rule): a weak echo in noise
//! drops out for a spoke here and there at its beam's edges, and the pieces would be extra
//! plots beside the target. On the synthetic radar (200 rotations, `synthetic`), strict
//! closing gives extra plots beside 7.9 % of targets, P_d 0.885 and 2.2 false plots a
//! rotation; bridging one spoke 3.8 %, 0.901 and 4.2 (a noise crossing now pairs with one
//! two spokes on as well as the next, so twice the noise plots); bridging two 3.0 %, 0.908
//! and 6.0.
//!
//! A closed blob is filtered (fewer than [`ExtractorConfig::min_spokes`] spokes or
//! [`ExtractorConfig::min_cells`] cells: noise, counted and dropped); one that passes is a
//! detection of the *echo* it lies in.
//!
//! ## Echoes: what a detection is measured on
//!
//! Beside the CFAR blobs the extractor grows echoes, by the same rules, from the samples at
//! or above the [echo threshold](super::echo) (the background's level, not the
//! neighbours'): the whole return around a detection. A CFAR detects only where a return is
//! thinner than its windows, so on a short range scale a quay or a pontoon gives detections
//! only at its edges and tips, each once a plot of its own; each is now a detection of the
//! quay's echo. An echo is reported when it closes (the antenna past it), if it holds a
//! detection: measured ([`RadarPlot`]: strength-weighted centroid of the whole echo,
//! extents, strength, time) and classified by its size ([`ExtractorConfig::classify`]): a
//! point target is an [`Event::Plot`], an extended return (coast, quay, rain) an
//! [`Event::Extended`], reported apart and never to be tracked. An echo holds its blobs (a
//! detected cell is at or above the echo threshold in all but a locally quiet stretch of a
//! band), so it closes with the last of them or later: nothing waits in a buffer. A CFAR
//! blob outside any echo followed (before the first echo threshold, or where the echoes'
//! slots were full, counted as [`ExtractorStats::blobs_outside_echoes`]) is measured and
//! classified on its own, as every blob was before echoes were followed. A CFAR blob found
//! in two echoes (they touch only through it) joins them.
//!
//! On the synthetic radar (200 rotations): P_d 0.901 and 4.14 false plots a rotation (0.901
//! and 4.12 with blobs measured alone), extra plots beside 2.3 % of the targets (4.1 %), RMS
//! plot error 7.8 m (8.5 m); since its sea control (2026-12-06), 4.47 false plots a
//! rotation, the rest the same; on its noise drawn two numbers a cell (2026-12-07), P_d
//! 0.898, 4.24 false plots, 2.7 % split, 8.2 m. On the real captures: docs/radar.md.

//! ## Output: a callback per closed echo
//!
//! [`Extractor::push`] calls its callback with each echo (or lone blob) as it closes, and with
//! [`Event::Wrap`] when the angle passes 360° (before the spoke after the wrap is
//! processed). Nothing is buffered, so a rotation can hold any number of plots; a caller
//! that wants per-rotation batches collects into its own bounded list and hands it on at
//! each wrap. A blob still open at the wrap (one touching the last spoke) closes a few
//! spokes later and so arrives after the wrap, in the next batch; its time and bearing are
//! its own.
//!
//! ## The 360° wrap
//!
//! The spoke stream is one continuous sequence: the spoke after the last of a rotation is
//! the previous spoke of spoke 0, and blob positions are counted in an unwrapped spoke
//! index. So a blob across north simply grows across it and is one plot, its bearing
//! averaged on the unwrapped index. Only the very first spoke after a start (or a restart)
//! has no predecessor: blobs touching it may be missing their part before it and are
//! marked [`RadarPlot::partial`] (as are blobs cut by a restart, by a gap of more than
//! [`ExtractorConfig::max_spoke_gap`] missing spokes, or by [`Extractor::flush`]). A blob
//! that grows to a whole rotation (a ring of sea clutter) is closed there, partial, so none
//! stays open for ever.
//!
//! ## Capacity and cost
//!
//! At most `BLOBS` blobs and as many echoes are open at once and `RUNS` runs of each are
//! kept per spoke (const parameters; 64 and 128 by default, 18.8 KiB with the detector and
//! the echo threshold). A run that would start a blob when all are open is dropped and
//! counted ([`ExtractorStats::blobs_dropped`]); a run beyond `RUNS` on one spoke likewise
//! ([`ExtractorStats::runs_dropped`]); the same for echoes
//! ([`ExtractorStats::echoes_dropped`]). A spoke costs O(samples) in the CFAR and the echo
//! threshold, O(runs) to join them (the runs of two consecutive spokes are both sorted by
//! range: one merge-like pass; a merge relabels the two spokes' runs), and one pass over
//! each `BLOBS` slots to find what closed (and one over the CFAR blobs for each closing
//! echo a blob pointed at): O(samples + BLOBS · echoes closed) in all; no allocation.
//!
//! ## What is counted
//!
//! [`ExtractorStats`]: spokes, rotations, detected cells, runs, blobs (opened, dropped for
//! capacity, merged, too small, outside echoes), echoes (opened, dropped), plots, extended
//! returns, partial ones, and the stream's
//! faults: a spoke whose angle goes backwards (or repeats) mid-rotation closes every blob
//! (partial) and restarts (`out_of_order`); a change of range or sample count
//! (`range_changes`) or of spokes a rotation, north-up or largest sample (`format_changes`)
//! does the same;
//! missing angles (`missing_spokes`); head-up spokes without own heading
//! (`missing_heading`: their blobs get a bearing from the bow, flagged
//! [`RadarPlot::relative_bearing`]); malformed spokes ignored (`bad_spokes`: no samples,
//! angle out of the rotation, range not positive); spokes too short to test after blanking
//! (`short_spokes`).

use heapless::Vec;

use super::blob::{Blob, Geometry, RadarPlot, SpokeContext, NO_ECHO};
use super::cfar::{Cfar, Run};
use super::config::{ConfigError, ExtractorConfig, ReturnClass};
use super::echo::EchoThreshold;
use super::spoke::Spoke;

/// Open blobs an [`Extractor`] holds by default.
pub const DEFAULT_OPEN_BLOBS: usize = 64;
/// Runs per spoke an [`Extractor`] keeps by default.
pub const DEFAULT_RUNS: usize = 128;

/// A run's blob when it has none (dropped for capacity, or its blob closed).
const NO_BLOB: u16 = u16::MAX;

/// An echo's [`Blob::echo`] once a CFAR blob has pointed at it (unused otherwise in an
/// echo): only then can a CFAR blob still name it when it closes.
const REFERENCED: u16 = 0;

/// What the extractor reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A point target: a plot for the tracker ([`RadarPlot::to_icd`]).
    Plot(RadarPlot),
    /// An extended return (coast, jetty, rain patch): for the display, never tracked.
    Extended(RadarPlot),
    /// The antenna passed 360°: `rotation` wraps so far, at the time of the spoke after
    /// the wrap, ms.
    Wrap {
        /// Wraps since the extractor was made.
        rotation: u32,
        /// The first spoke of the new rotation's time, ms.
        time_ms: u64,
    },
}

/// The extractor's counters, from its creation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExtractorStats {
    /// Spokes pushed, every one.
    pub spokes: u64,
    /// Angle wraps through 360°.
    pub rotations: u32,
    /// Detected cells.
    pub detections: u64,
    /// Runs of detected cells.
    pub runs: u64,
    /// Runs dropped: more than `RUNS` on one spoke.
    pub runs_dropped: u64,
    /// Blobs started.
    pub blobs: u64,
    /// Runs that could not start a blob: `BLOBS` were open.
    pub blobs_dropped: u64,
    /// Blob merges (a run joining two).
    pub merges: u64,
    /// Closed blobs below the minimum size (noise), dropped.
    pub small_blobs: u64,
    /// Point-target plots reported.
    pub plots: u64,
    /// Extended returns reported.
    pub extended: u64,
    /// Reports (plots and extended) marked partial.
    pub partial: u64,
    /// Spokes whose angle went backwards or repeated: every blob closed, restarted.
    pub out_of_order: u64,
    /// Range or sample-count changes: every blob closed, restarted.
    pub range_changes: u64,
    /// Changes of spokes a rotation, of north-up or of the largest sample: every blob closed,
    /// restarted.
    pub format_changes: u64,
    /// Head-up spokes without own heading.
    pub missing_heading: u64,
    /// Angles skipped between consecutive spokes.
    pub missing_spokes: u64,
    /// Malformed spokes, ignored.
    pub bad_spokes: u64,
    /// Spokes too short to test after blanking.
    pub short_spokes: u64,
    /// Echoes started (connected samples at or above the echo threshold).
    pub echoes: u64,
    /// Runs that could not start an echo (`BLOBS` echoes open) or were beyond `RUNS` on one
    /// spoke: the CFAR blobs there are measured on their own.
    pub echoes_dropped: u64,
    /// CFAR blobs of a plot's size outside any echo followed, measured on their own (before
    /// the first echo threshold, or where echoes were dropped).
    pub blobs_outside_echoes: u64,
}

impl ExtractorStats {
    /// Nothing counted yet.
    pub const ZERO: ExtractorStats = ExtractorStats {
        spokes: 0,
        rotations: 0,
        detections: 0,
        runs: 0,
        runs_dropped: 0,
        blobs: 0,
        blobs_dropped: 0,
        merges: 0,
        small_blobs: 0,
        plots: 0,
        extended: 0,
        partial: 0,
        out_of_order: 0,
        range_changes: 0,
        format_changes: 0,
        missing_heading: 0,
        missing_spokes: 0,
        bad_spokes: 0,
        short_spokes: 0,
        echoes: 0,
        echoes_dropped: 0,
        blobs_outside_echoes: 0,
    };
}

impl Default for ExtractorStats {
    fn default() -> Self {
        Self::ZERO
    }
}

/// A run kept for the next spoke to join: its cells and its blob.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Link {
    start: u16,
    end: u16,
    blob: u16,
}

/// The spoke stream being followed.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Stream {
    geometry: Geometry,
    range_m: f32,
    samples: usize,
    /// The strongest sample (the echo threshold's bins depend on it).
    max_sample: u8,
    /// Samples blanked at the near end.
    blank: usize,
    last_angle: u16,
    /// Unwrapped position of the last spoke.
    spoke: u32,
    /// Blobs touching this spoke may miss cells before it.
    partial_from: u32,
}

/// The open blobs (CFAR blobs, or echoes) and the last two spokes' runs.
#[derive(Clone, Debug)]
struct Grower<const BLOBS: usize, const RUNS: usize> {
    slots: [Option<Blob>; BLOBS],
    free: Vec<u16, BLOBS>,
    prev: Vec<Link, RUNS>,
    cur: Vec<Link, RUNS>,
    /// Where the next spoke's `prev` is assembled.
    next: Vec<Link, RUNS>,
    /// The first previous run that can still overlap the next run.
    scan: usize,
    /// CFAR blobs merged on this run whose echoes differ (they are one echo: connected
    /// through the blob), for the extractor to join.
    conflicts: Vec<(u16, u16), 4>,
}

/// What a grower counts into, and which counters: a CFAR blob's or an echo's.
struct Counters<'a> {
    stats: &'a mut ExtractorStats,
    echoes: bool,
}

impl Counters<'_> {
    fn run(&mut self) {
        if !self.echoes {
            self.stats.runs += 1;
        }
    }

    fn run_dropped(&mut self) {
        if self.echoes {
            self.stats.echoes_dropped += 1;
        } else {
            self.stats.runs_dropped += 1;
        }
    }

    fn started(&mut self) {
        if self.echoes {
            self.stats.echoes += 1;
        } else {
            self.stats.blobs += 1;
        }
    }

    fn no_slot(&mut self) {
        if self.echoes {
            self.stats.echoes_dropped += 1;
        } else {
            self.stats.blobs_dropped += 1;
        }
    }

    fn merged(&mut self) {
        if !self.echoes {
            self.stats.merges += 1;
        }
    }
}

impl<const BLOBS: usize, const RUNS: usize> Grower<BLOBS, RUNS> {
    fn new() -> Self {
        let mut g = Self::empty();
        g.reset();
        g
    }

    /// No slot free: [`Grower::reset`] hands them out.
    const fn empty() -> Self {
        Grower {
            slots: [None; BLOBS],
            free: Vec::new(),
            prev: Vec::new(),
            cur: Vec::new(),
            next: Vec::new(),
            scan: 0,
            conflicts: Vec::new(),
        }
    }

    /// Every slot free, nothing open, in place.
    fn reset(&mut self) {
        self.slots.iter_mut().for_each(|s| *s = None);
        self.free.clear();
        // Slots handed out from 0 up (popped from the end).
        for slot in (0..BLOBS).rev() {
            let _ = self.free.push(u16::try_from(slot).unwrap_or(NO_BLOB));
        }
        self.prev.clear();
        self.cur.clear();
        self.next.clear();
        self.scan = 0;
        self.conflicts.clear();
    }

    fn open(&self) -> usize {
        BLOBS - self.free.len()
    }

    fn begin_spoke(&mut self) {
        self.cur.clear();
        self.scan = 0;
    }

    fn get_mut(&mut self, slot: u16) -> Option<&mut Blob> {
        self.slots
            .get_mut(usize::from(slot))
            .and_then(Option::as_mut)
    }

    /// Joins `run` to the blob(s) of the previous spoke's runs it overlaps (calling
    /// `on_merge(from, into)` for each merge); the blob it joined or started, `NO_BLOB` when
    /// it was dropped.
    fn add_run(
        &mut self,
        run: &Run,
        ctx: &SpokeContext,
        counters: &mut Counters<'_>,
        on_merge: &mut impl FnMut(u16, u16),
    ) -> u16 {
        counters.run();
        if self.cur.is_full() {
            counters.run_dropped();
            return NO_BLOB;
        }
        while self.prev.get(self.scan).is_some_and(|p| p.end <= run.start) {
            self.scan += 1;
        }
        let mut target = NO_BLOB;
        let mut k = self.scan;
        while let Some(p) = self.prev.get(k).copied() {
            if p.start >= run.end {
                break;
            }
            k += 1;
            if p.blob == NO_BLOB || p.blob == target {
                continue;
            }
            if target == NO_BLOB {
                target = p.blob;
            } else {
                self.merge(p.blob, target, ctx.spoke, counters);
                on_merge(p.blob, target);
            }
        }
        if target == NO_BLOB {
            match self.free.pop() {
                Some(slot) => {
                    if let Some(s) = self.slots.get_mut(usize::from(slot)) {
                        *s = Some(Blob::start(ctx, run));
                        target = slot;
                        counters.started();
                    }
                }
                None => counters.no_slot(),
            }
        } else if let Some(b) = self.get_mut(target) {
            b.add(ctx, run);
        }
        let _ = self.cur.push(Link {
            start: run.start,
            end: run.end,
            blob: target,
        });
        target
    }

    /// Moves blob `from` into `into`; runs of `from` now point at `into`.
    fn merge(&mut self, from: u16, into: u16, current: u32, counters: &mut Counters<'_>) {
        if from == into {
            return;
        }
        let Some(other) = self.slots.get_mut(usize::from(from)).and_then(Option::take) else {
            return;
        };
        if let Some(Some(b)) = self.slots.get_mut(usize::from(into)) {
            if b.echo != other.echo && b.echo != NO_ECHO && other.echo != NO_ECHO {
                let _ = self.conflicts.push((other.echo, b.echo));
            }
            b.merge(&other, current);
        }
        let _ = self.free.push(from);
        for link in self.prev.iter_mut().chain(self.cur.iter_mut()) {
            if link.blob == from {
                link.blob = into;
            }
        }
        counters.merged();
    }

    /// After a spoke's runs: closes the blobs that have now missed more than
    /// `max_missed_spokes` spokes in a row, and any that covers a whole rotation, handing
    /// each to `on_close` with its slot; the runs the next spoke may join are this spoke's
    /// and the last runs of the blobs coasting.
    fn end_spoke(
        &mut self,
        current: u32,
        geometry: &Geometry,
        config: &ExtractorConfig,
        counters: &mut Counters<'_>,
        mut on_close: impl FnMut(u16, &Blob, &mut ExtractorStats),
    ) {
        let full_circle = u32::from(geometry.spokes_per_rotation);
        for (index, slot) in self.slots.iter_mut().enumerate() {
            let Some(blob) = slot else {
                continue;
            };
            if blob.last_spoke != current {
                blob.misses = blob.misses.saturating_add(1);
            }
            let whole_rotation = blob.spokes() >= full_circle;
            if blob.misses <= config.max_missed_spokes && !whole_rotation {
                continue;
            }
            let id = u16::try_from(index).unwrap_or(NO_BLOB);
            if whole_rotation {
                blob.mark_partial();
                for link in self.cur.iter_mut().filter(|l| l.blob == id) {
                    link.blob = NO_BLOB;
                }
            }
            on_close(id, blob, counters.stats);
            *slot = None;
            let _ = self.free.push(id);
        }
        // Both lists are sorted by range and their runs disjoint (a coasting blob's run
        // overlapped nothing on this spoke, or the blob would not be coasting): merge them.
        let slots = &self.slots;
        let coasting = |l: &&Link| {
            slots
                .get(usize::from(l.blob))
                .and_then(Option::as_ref)
                .is_some_and(|b| b.last_spoke != current)
        };
        self.next.clear();
        let mut carried = self.prev.iter().filter(coasting).peekable();
        let mut fresh = self.cur.iter().peekable();
        loop {
            let take_carried = match (carried.peek(), fresh.peek()) {
                (Some(c), Some(f)) => c.start < f.start,
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => break,
            };
            let link = if take_carried {
                carried.next()
            } else {
                fresh.next()
            };
            if let Some(&link) = link {
                if self.next.push(link).is_err() {
                    counters.run_dropped();
                }
            }
        }
        core::mem::swap(&mut self.prev, &mut self.next);
        self.cur.clear();
    }

    /// Closes every open blob, partial, handing each to `on_close`, and forgets the runs.
    fn close_all(
        &mut self,
        stats: &mut ExtractorStats,
        mut on_close: impl FnMut(u16, &Blob, &mut ExtractorStats),
    ) {
        for (index, slot) in self.slots.iter_mut().enumerate() {
            if let Some(mut blob) = slot.take() {
                blob.mark_partial();
                let id = u16::try_from(index).unwrap_or(NO_BLOB);
                on_close(id, &blob, stats);
                let _ = self.free.push(id);
            }
        }
        self.prev.clear();
        self.cur.clear();
        self.next.clear();
        self.scan = 0;
        self.conflicts.clear();
    }
}

/// Measures a closed blob and reports it by its class (a point plot or an extended
/// return), or counts it as too small.
fn report<F: FnMut(Event)>(
    blob: &Blob,
    geometry: &Geometry,
    config: &ExtractorConfig,
    stats: &mut ExtractorStats,
    on_event: &mut F,
) {
    let plot = blob.measure(geometry);
    stats.partial += u64::from(plot.partial);
    match config.classify(&plot) {
        ReturnClass::Point => {
            stats.plots += 1;
            on_event(Event::Plot(plot));
        }
        ReturnClass::Extended => {
            stats.extended += 1;
            on_event(Event::Extended(plot));
        }
    }
}

/// Whether a closed CFAR blob is big enough to be a detection (not noise).
fn plot_sized(blob: &Blob, config: &ExtractorConfig) -> bool {
    blob.spokes() >= u32::from(config.min_spokes) && blob.cells() >= config.min_cells
}

/// A CFAR blob closed: a detection of the echo it lies in, or, outside any echo followed,
/// measured on its own; too small, counted as noise.
fn close_blob<F: FnMut(Event)>(
    blob: &Blob,
    echoes: &mut [Option<Blob>],
    geometry: &Geometry,
    config: &ExtractorConfig,
    stats: &mut ExtractorStats,
    on_event: &mut F,
) {
    if !plot_sized(blob, config) {
        stats.small_blobs += 1;
        return;
    }
    match echoes
        .get_mut(usize::from(blob.echo))
        .and_then(Option::as_mut)
    {
        Some(echo) => echo.detections = echo.detections.saturating_add(1),
        None => {
            stats.blobs_outside_echoes += 1;
            report(blob, geometry, config, stats, on_event);
        }
    }
}

/// An echo closed: reported when it holds a detection; the CFAR blobs still pointing at its
/// slot lose it.
fn close_echo<F: FnMut(Event)>(
    slot: u16,
    echo: &Blob,
    blobs: &mut [Option<Blob>],
    geometry: &Geometry,
    config: &ExtractorConfig,
    stats: &mut ExtractorStats,
    on_event: &mut F,
) {
    if echo.echo == REFERENCED {
        for b in blobs.iter_mut().flatten().filter(|b| b.echo == slot) {
            b.echo = NO_ECHO;
        }
    }
    if echo.detections > 0 {
        report(echo, geometry, config, stats, on_event);
    }
}

/// The plot extractor: a CFAR detector, the echo threshold, and the CFAR blobs and echoes
/// it is growing.
///
/// `BLOBS` is the most CFAR blobs (and, apart, echoes) open at once, `RUNS` the most runs
/// of each kept per spoke (both below 65,535; checked when the type is instantiated).
#[derive(Clone, Debug)]
pub struct Extractor<const BLOBS: usize = DEFAULT_OPEN_BLOBS, const RUNS: usize = DEFAULT_RUNS> {
    config: ExtractorConfig,
    cfar: Cfar,
    grower: Grower<BLOBS, RUNS>,
    echoes: Grower<BLOBS, RUNS>,
    threshold: EchoThreshold,
    stream: Option<Stream>,
    stats: ExtractorStats,
}

impl<const BLOBS: usize, const RUNS: usize> Extractor<BLOBS, RUNS> {
    /// An extractor with nothing open.
    ///
    /// # Errors
    /// The first setting out of range ([`ExtractorConfig::validate`]).
    pub fn new(config: ExtractorConfig) -> Result<Self, ConfigError> {
        const {
            assert!(BLOBS > 0 && BLOBS < NO_BLOB as usize && RUNS > 0);
        }
        config.validate()?;
        Ok(Extractor {
            config,
            cfar: Cfar::new(&config.cfar)?,
            grower: Grower::new(),
            echoes: Grower::new(),
            threshold: EchoThreshold::new(0, 15),
            stream: None,
            stats: ExtractorStats::default(),
        })
    }

    /// An extractor that extracts nothing until [`Extractor::configure`]d, built at
    /// compile time: a `static` of it is placed in RAM at reset and never passes through a
    /// board's stack (which may be smaller than the extractor's 18.8 KiB).
    pub const fn unconfigured() -> Self {
        const {
            assert!(BLOBS > 0 && BLOBS < NO_BLOB as usize && RUNS > 0);
        }
        let config = ExtractorConfig::navico_4bit();
        Extractor {
            config,
            cfar: Cfar::unconfigured(config.cfar),
            grower: Grower::empty(),
            echoes: Grower::empty(),
            threshold: EchoThreshold::new(0, 15),
            stream: None,
            stats: ExtractorStats::ZERO,
        }
    }

    /// Takes `config` in place (no extractor-sized temporary): open blobs are dropped and
    /// the stream forgotten, as at a start; the counters go on.
    ///
    /// # Errors
    /// The first setting out of range ([`ExtractorConfig::validate`]); the extractor is
    /// left as it was.
    pub fn configure(&mut self, config: ExtractorConfig) -> Result<(), ConfigError> {
        config.validate()?;
        self.cfar = Cfar::new(&config.cfar)?;
        self.config = config;
        self.grower.reset();
        self.echoes.reset();
        self.stream = None;
        Ok(())
    }

    /// The settings.
    pub fn config(&self) -> &ExtractorConfig {
        &self.config
    }

    /// The counters.
    pub fn stats(&self) -> &ExtractorStats {
        &self.stats
    }

    /// CFAR blobs open now.
    pub fn open_blobs(&self) -> usize {
        self.grower.open()
    }

    /// Echoes open now.
    pub fn open_echoes(&self) -> usize {
        self.echoes.open()
    }

    /// Takes the next spoke; calls `on_event` for each echo (or lone CFAR blob) it closes
    /// and at the 360° wrap (see the module documentation for the order).
    /// O(samples + BLOBS · closed echoes), no allocation.
    pub fn push(&mut self, spoke: &Spoke<'_>, mut on_event: impl FnMut(Event)) {
        self.stats.spokes += 1;
        let n = spoke.spokes_per_rotation;
        let range_ok = spoke.range_m > 0.0 && spoke.range_m.is_finite();
        if n == 0 || spoke.angle >= n || spoke.samples.is_empty() || !range_ok {
            self.stats.bad_spokes += 1;
            return;
        }
        if let Some(s) = self.stream {
            let range_changed = s.range_m != spoke.range_m || s.samples != spoke.samples.len();
            let format_changed = s.geometry.spokes_per_rotation != n
                || s.geometry.north_up != spoke.north_up
                || s.max_sample != spoke.max_sample;
            if range_changed {
                self.stats.range_changes += 1;
            } else if format_changed {
                self.stats.format_changes += 1;
            }
            if range_changed || format_changed {
                self.restart(&mut on_event);
            }
        }
        let stream = match self.stream {
            None => self.new_stream(spoke),
            Some(mut s) => {
                let step = (u32::from(spoke.angle) + u32::from(n) - u32::from(s.last_angle))
                    % u32::from(n);
                if step == 0 || step > u32::from(n) / 2 {
                    self.stats.out_of_order += 1;
                    self.restart(&mut on_event);
                    self.new_stream(spoke)
                } else {
                    if spoke.angle < s.last_angle {
                        self.stats.rotations = self.stats.rotations.wrapping_add(1);
                        on_event(Event::Wrap {
                            rotation: self.stats.rotations,
                            time_ms: spoke.time_ms,
                        });
                    }
                    let gap = step - 1;
                    self.stats.missing_spokes += u64::from(gap);
                    s.spoke = s.spoke.wrapping_add(step);
                    s.last_angle = spoke.angle;
                    if gap > u32::from(self.config.max_spoke_gap) {
                        self.close_all(&s.geometry, &mut on_event);
                        s.partial_from = s.spoke;
                    }
                    s
                }
            }
        };
        self.stream = Some(stream);
        let heading = spoke.heading_rad.filter(|h| h.is_finite());
        let heading_missing = !spoke.north_up && heading.is_none();
        if heading_missing {
            self.stats.missing_heading += 1;
        }
        let ctx = SpokeContext {
            spoke: stream.spoke,
            angle: spoke.angle,
            time_ms: spoke.time_ms,
            heading_rad: if spoke.north_up {
                0.0
            } else {
                heading.unwrap_or(0.0)
            },
            heading_missing,
            partial: stream.spoke == stream.partial_from,
        };
        self.grower.begin_spoke();
        self.echoes.begin_spoke();
        self.grow_echoes(spoke.samples, stream.blank, &ctx);
        let Extractor {
            config,
            cfar,
            grower,
            echoes,
            stats,
            ..
        } = self;
        // Each CFAR run lies in the echo run that overlaps it (echo runs are sorted by
        // range, as the CFAR's: one pointer walks them).
        let mut e = 0usize;
        let detected = cfar.detect(spoke.samples, stream.blank, |run| {
            while echoes.cur.get(e).is_some_and(|l| l.end <= run.start) {
                e += 1;
            }
            let echo = echoes
                .cur
                .get(e)
                .filter(|l| l.start < run.end)
                .map_or(NO_ECHO, |l| l.blob);
            let mut counters = Counters {
                stats,
                echoes: false,
            };
            let slot = grower.add_run(&run, &ctx, &mut counters, &mut |_, _| {});
            let Grower {
                slots, conflicts, ..
            } = &mut *grower;
            if let Some(Some(b)) = slots.get_mut(usize::from(slot)).filter(|_| echo != NO_ECHO) {
                if b.echo == NO_ECHO {
                    b.echo = echo;
                    if let Some(e) = echoes.get_mut(echo) {
                        e.echo = REFERENCED;
                    }
                } else if b.echo != echo {
                    let _ = conflicts.push((echo, b.echo));
                }
            }
            join_conflicts(grower, echoes, ctx.spoke, stats);
        });
        match detected {
            Some(cells) => stats.detections += u64::from(cells),
            None => stats.short_spokes += 1,
        }
        let geometry = stream.geometry;
        let mut counters = Counters {
            stats,
            echoes: false,
        };
        // CFAR blobs first: an echo holds its blobs, so it closes with the last of them or
        // later, and must have been credited with their detections by then.
        let echo_slots = &mut echoes.slots;
        grower.end_spoke(
            stream.spoke,
            &geometry,
            config,
            &mut counters,
            |_, blob, stats| close_blob(blob, echo_slots, &geometry, config, stats, &mut on_event),
        );
        let blob_slots = &mut grower.slots;
        counters.echoes = true;
        echoes.end_spoke(
            stream.spoke,
            &geometry,
            config,
            &mut counters,
            |slot, echo, stats| {
                close_echo(
                    slot,
                    echo,
                    blob_slots,
                    &geometry,
                    config,
                    stats,
                    &mut on_event,
                )
            },
        );
        self.threshold
            .end_spoke(self.config.echo_level_factor, self.config.echo_min_level);
    }

    /// The echo runs of a spoke (samples at or above their band's echo threshold, beyond
    /// the blanked ones), grown into the echoes; the samples counted for the thresholds.
    fn grow_echoes(&mut self, samples: &[u8], blank: usize, ctx: &SpokeContext) {
        let end = samples.len().min(usize::from(u16::MAX));
        let Extractor {
            grower,
            echoes,
            threshold,
            stats,
            ..
        } = self;
        let band_len = threshold.band_len();
        let mut counters = Counters {
            stats,
            echoes: true,
        };
        // Echoes merged while growing: the CFAR blobs of the one merged away now lie in
        // the other.
        let blobs = &mut grower.slots;
        let mut relabel = |from: u16, into: u16| {
            for b in blobs.iter_mut().flatten().filter(|b| b.echo == from) {
                b.echo = into;
            }
        };
        let mut run: Option<Run> = None;
        let counting = threshold.counting();
        for (band, lo) in (0..end).step_by(band_len).enumerate() {
            let hi = (lo + band_len).min(end);
            let level = threshold.level(band);
            let first = lo.max(blank);
            let band_samples = samples.get(first..hi).unwrap_or(&[]);
            if counting {
                threshold.count(band, band_samples);
            }
            // No estimate yet (or a level no sample reaches): nothing here is an echo.
            let Ok(level) = u8::try_from(level) else {
                if let Some(done) = run.take() {
                    echoes.add_run(&done, ctx, &mut counters, &mut relabel);
                }
                continue;
            };
            let mut i = 0;
            while i < band_samples.len() {
                // Most samples are below the threshold: skip them in one tight loop.
                let rest = band_samples.get(i..).unwrap_or(&[]);
                let Some(skip) = rest.iter().position(|&x| x >= level) else {
                    if let Some(done) = run.take() {
                        echoes.add_run(&done, ctx, &mut counters, &mut relabel);
                    }
                    break;
                };
                if skip > 0 {
                    if let Some(done) = run.take() {
                        echoes.add_run(&done, ctx, &mut counters, &mut relabel);
                    }
                }
                i += skip;
                while let Some(&x) = band_samples.get(i).filter(|&&x| x >= level) {
                    let index = u16::try_from(first + i).unwrap_or(u16::MAX);
                    let w = u32::from(x);
                    match run.as_mut() {
                        Some(open) => {
                            open.end = index.saturating_add(1);
                            open.sum = open.sum.saturating_add(w);
                            open.index_sum += u64::from(w) * u64::from(index);
                            open.peak = open.peak.max(x);
                        }
                        None => {
                            run = Some(Run {
                                start: index,
                                end: index.saturating_add(1),
                                sum: w,
                                index_sum: u64::from(w) * u64::from(index),
                                peak: x,
                            })
                        }
                    }
                    i += 1;
                }
            }
        }
        if let Some(done) = run {
            echoes.add_run(&done, ctx, &mut counters, &mut relabel);
        }
    }

    /// The end of the data: closes every open blob and echo (partial, they may go on in
    /// spokes not seen) and forgets the stream; the next spoke starts afresh.
    pub fn flush(&mut self, mut on_event: impl FnMut(Event)) {
        self.restart(&mut on_event);
    }

    fn restart<F: FnMut(Event)>(&mut self, on_event: &mut F) {
        if let Some(s) = self.stream.take() {
            self.close_all(&s.geometry, on_event);
        }
    }

    /// Closes every CFAR blob (crediting its echo), then every echo.
    fn close_all<F: FnMut(Event)>(&mut self, geometry: &Geometry, on_event: &mut F) {
        let Extractor {
            config,
            grower,
            echoes,
            stats,
            ..
        } = self;
        let echo_slots = &mut echoes.slots;
        grower.close_all(stats, |_, blob, stats| {
            close_blob(blob, echo_slots, geometry, config, stats, on_event)
        });
        let blob_slots = &mut grower.slots;
        echoes.close_all(stats, |slot, echo, stats| {
            close_echo(slot, echo, blob_slots, geometry, config, stats, on_event)
        });
    }

    fn new_stream(&mut self, spoke: &Spoke<'_>) -> Stream {
        let sample_m = spoke.sample_m();
        // `as` saturates, and a NaN (impossible: range and length checked) gives 0.
        let blank = libm::ceilf(self.config.min_range_m / sample_m) as usize;
        // A new geometry: the bands' backgrounds are measured afresh.
        self.threshold = EchoThreshold::new(spoke.samples.len(), spoke.max_sample);
        Stream {
            geometry: Geometry {
                spokes_per_rotation: spoke.spokes_per_rotation,
                sample_m,
                north_up: spoke.north_up,
            },
            range_m: spoke.range_m,
            samples: spoke.samples.len(),
            max_sample: spoke.max_sample,
            blank,
            last_angle: spoke.angle,
            spoke: 0,
            partial_from: 0,
        }
    }
}

/// Joins the echoes of CFAR blobs found to be one (a blob's run in another echo than the
/// blob's, or two blobs of different echoes merged): the younger echo moves into the older,
/// and the CFAR blobs of the one merged away follow.
fn join_conflicts<const BLOBS: usize, const RUNS: usize>(
    grower: &mut Grower<BLOBS, RUNS>,
    echoes: &mut Grower<BLOBS, RUNS>,
    current: u32,
    stats: &mut ExtractorStats,
) {
    while let Some((from, into)) = grower.conflicts.pop() {
        if from == into || echoes.get_mut(from).is_none() || echoes.get_mut(into).is_none() {
            continue;
        }
        let mut counters = Counters {
            stats,
            echoes: true,
        };
        echoes.merge(from, into, current, &mut counters);
        for b in grower.slots.iter_mut().flatten().filter(|b| b.echo == from) {
            b.echo = into;
        }
        // Pending pairs naming the echo merged away now name the one it went into.
        for c in grower.conflicts.iter_mut() {
            if c.0 == from {
                c.0 = into;
            }
            if c.1 == from {
                c.1 = into;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec as StdVec;

    const N: u16 = 2048;
    const SAMPLES: usize = 1024;
    const RANGE_M: f32 = 7408.0; // 4 NM: 7.23 m samples
    const BEAM_SPOKES: f32 = 10.24; // 1.8° at 2,048 spokes

    /// A point echo: amplitude halves ±5 spokes and ±2 cells from its centre.
    #[derive(Clone, Copy)]
    struct Echo {
        angle: f32,
        cell: f32,
        peak: f32,
    }

    fn echo_level(e: &Echo, angle: u16, cell: usize) -> f32 {
        let mut da = f32::from(angle) - e.angle;
        let n = f32::from(N);
        da = (da + 1.5 * n) % n - 0.5 * n;
        let dc = cell as f32 - e.cell;
        let g = (2.0 * da / BEAM_SPOKES).powi(2) + (dc / 2.0).powi(2);
        e.peak * libm::exp2f(-g)
    }

    /// Background: a fixed pattern of 0..=2 (below the floor of 4).
    fn background(angle: u16, cell: usize) -> u8 {
        let h = u32::from(angle).wrapping_mul(2_654_435_761) ^ (cell as u32).wrapping_mul(40_503);
        ((h >> 7) % 3) as u8
    }

    struct Feed {
        north_up: bool,
        heading: Option<f32>,
        range_m: f32,
        time_ms: u64,
    }

    impl Feed {
        fn new() -> Self {
            Feed {
                north_up: true,
                heading: None,
                range_m: RANGE_M,
                time_ms: 0,
            }
        }

        /// Pushes the spokes at `angles`, each painted by `paint`, collecting the events.
        fn push<const B: usize, const R: usize>(
            &mut self,
            ex: &mut Extractor<B, R>,
            angles: impl IntoIterator<Item = u16>,
            paint: &dyn Fn(u16, usize) -> u8,
            events: &mut StdVec<Event>,
        ) {
            let mut buf = [0u8; SAMPLES];
            for angle in angles {
                for (cell, s) in buf.iter_mut().enumerate() {
                    *s = paint(angle, cell).max(background(angle, cell)).min(15);
                }
                let spoke = Spoke {
                    angle,
                    spokes_per_rotation: N,
                    north_up: self.north_up,
                    heading_rad: self.heading,
                    range_m: self.range_m,
                    time_ms: self.time_ms,
                    samples: &buf,
                    max_sample: 15,
                };
                self.time_ms += 1;
                ex.push(&spoke, |e| events.push(e));
            }
        }
    }

    fn echoes(list: &[Echo]) -> impl Fn(u16, usize) -> u8 + '_ {
        move |angle, cell| {
            let v: f32 = list.iter().map(|e| echo_level(e, angle, cell)).sum();
            (v + 0.5) as u8
        }
    }

    fn plots(events: &[Event]) -> StdVec<RadarPlot> {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Plot(p) => Some(*p),
                _ => None,
            })
            .collect()
    }

    fn extended(events: &[Event]) -> StdVec<RadarPlot> {
        events
            .iter()
            .filter_map(|e| match e {
                Event::Extended(p) => Some(*p),
                _ => None,
            })
            .collect()
    }

    const SAMPLE_M: f32 = RANGE_M / SAMPLES as f32;
    const SPOKE_RAD: f32 = core::f32::consts::TAU / N as f32;

    fn rotation() -> core::ops::Range<u16> {
        0..N
    }

    /// An extractor with the Navico defaults.
    fn navico() -> Extractor {
        Extractor::new(ExtractorConfig::navico_4bit()).unwrap()
    }

    /// A point echo of peak 14 levels.
    fn echo(angle: f32, cell: f32) -> Echo {
        Echo {
            angle,
            cell,
            peak: 14.0,
        }
    }

    #[test]
    fn a_point_target_is_one_plot_within_a_cell_and_a_spoke() {
        let mut ex = navico();
        let target = echo(700.3, 400.6);
        let mut events = StdVec::new();
        Feed::new().push(&mut ex, rotation(), &echoes(&[target]), &mut events);
        let p = plots(&events);
        assert_eq!(p.len(), 1, "{events:?}");
        let p = p[0];
        let true_range = (target.cell + 0.5) * SAMPLE_M;
        assert!((p.range_m - true_range).abs() < SAMPLE_M, "{p:?}");
        let true_bearing = target.angle * SPOKE_RAD;
        assert!((p.bearing_rad - true_bearing).abs() < SPOKE_RAD, "{p:?}");
        assert!(!p.partial && !p.relative_bearing);
        assert!(p.spokes >= 5 && p.spokes <= 15, "{p:?}");
        // Its time is its centroid spoke's (one ms a spoke here).
        assert!((p.time_ms as f32 - target.angle).abs() <= 1.0, "{p:?}");
        let s = ex.stats();
        assert_eq!(
            (s.plots, s.extended, s.blobs_dropped, s.partial),
            (1, 0, 0, 0)
        );
        assert_eq!(s.spokes, u64::from(N));
    }

    #[test]
    fn built_in_place_it_extracts_as_one_built_by_new() {
        let targets = [
            echo(700.3, 400.6),
            Echo {
                angle: 2040.0,
                cell: 90.0,
                peak: 15.0,
            },
        ];
        let c = ExtractorConfig::navico_4bit();
        let mut a: Extractor = Extractor::new(c).unwrap();
        let mut b: Extractor = Extractor::unconfigured();
        // Unconfigured, it extracts nothing.
        let mut none = StdVec::new();
        Feed::new().push(&mut b, rotation(), &echoes(&targets), &mut none);
        assert!(plots(&none).is_empty() && b.stats().detections == 0);
        b.configure(c).unwrap();
        let (mut ea, mut eb) = (StdVec::new(), StdVec::new());
        for _ in 0..2 {
            Feed::new().push(&mut a, rotation(), &echoes(&targets), &mut ea);
            Feed::new().push(&mut b, rotation(), &echoes(&targets), &mut eb);
        }
        assert_eq!(plots(&ea), plots(&eb));
        assert!(plots(&ea).len() >= 3, "{ea:?}");
        // A bad setting leaves it as it was.
        let mut bad = c;
        bad.min_spokes = 0;
        assert_eq!(b.configure(bad), Err(ConfigError::MinimumSize));
        assert_eq!(b.config(), &c);
    }

    #[test]
    fn two_targets_close_in_bearing_but_apart_in_range_are_two_plots() {
        let mut ex = navico();
        // 2 spokes (0.35°) apart in bearing, 30 cells (217 m) in range: inside each
        // other's beam and CFAR window.
        let list = [
            echo(1000.0, 300.0),
            Echo {
                angle: 1002.0,
                cell: 330.0,
                peak: 12.0,
            },
        ];
        let mut events = StdVec::new();
        Feed::new().push(&mut ex, rotation(), &echoes(&list), &mut events);
        let mut p = plots(&events);
        p.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        assert_eq!(p.len(), 2, "{events:?}");
        for (plot, e) in p.iter().zip(&list) {
            assert!((plot.range_m - (e.cell + 0.5) * SAMPLE_M).abs() < SAMPLE_M);
            assert!((plot.bearing_rad - e.angle * SPOKE_RAD).abs() < SPOKE_RAD);
        }
    }

    #[test]
    fn a_target_across_north_is_one_plot() {
        let mut ex = navico();
        let target = echo(0.4, 500.0);
        let mut events = StdVec::new();
        let mut feed = Feed::new();
        for _ in 0..3 {
            feed.push(&mut ex, rotation(), &echoes(&[target]), &mut events);
        }
        ex.flush(|e| events.push(e));
        let p = plots(&events);
        // The first rotation's start and the last rotation's end are halves (partial);
        // between them the echo is whole twice, across the wrap.
        let whole: StdVec<_> = p.iter().filter(|p| !p.partial).collect();
        assert_eq!(whole.len(), 2, "{p:?}");
        for w in &whole {
            let err = crate::geo::wrap_pi(w.bearing_rad - target.angle * SPOKE_RAD);
            assert!(err.abs() < SPOKE_RAD, "{w:?}");
            assert!(w.spokes >= 5, "{w:?}");
        }
        assert_eq!(p.iter().filter(|p| p.partial).count(), 2, "{p:?}");
        assert_eq!(ex.stats().rotations, 2);
        let wraps = events
            .iter()
            .filter(|e| matches!(e, Event::Wrap { .. }))
            .count();
        assert_eq!(wraps, 2);
    }

    #[test]
    fn on_a_harbour_scale_a_quay_is_one_extended_return_and_a_boat_one_plot_at_its_centre() {
        // The 195 m range scale (0.19 m samples). The CFAR's windows (3 + 12 cells, 2.9 m)
        // lie inside anything deeper, so it detects a return only where it is thin: a
        // quay's face (a line 4 cells deep along 53°), the first spokes of a pier and of a
        // boat (their tips in the beam's edge). Each detection was a plot of its own; as
        // echoes, the face and the pier are extended returns and the boat one plot at its
        // middle.
        let face = |a: u16, c: usize| (300..600u16).contains(&a) && (400..404).contains(&c);
        let pier = |a: u16, c: usize| {
            ((700..704u16).contains(&a) && (500..504).contains(&c))
                || ((704..800u16).contains(&a) && (500..650).contains(&c))
        };
        let (boat_spokes, boat_cells) = (1400..1430u16, 600..660usize);
        let boat = |a: u16, c: usize| {
            ((1398..1400u16).contains(&a) && (628..632).contains(&c))
                || (boat_spokes.contains(&a) && boat_cells.contains(&c))
        };
        let paint = |a: u16, c: usize| {
            if face(a, c) || pier(a, c) || boat(a, c) {
                15
            } else {
                0
            }
        };
        let mut feed = Feed::new();
        feed.range_m = 195.0;
        let sample_m = 195.0 / SAMPLES as f32;
        let mut ex = navico();
        let mut events = StdVec::new();
        feed.push(&mut ex, rotation(), &paint, &mut events);
        let (p, mut e) = (plots(&events), extended(&events));
        assert_eq!((p.len(), e.len()), (1, 2), "{events:?}");
        e.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        // The face: 4 cells deep, 300 spokes wide; the pier: 150 cells deep.
        assert!(e[0].range_cells == 4 && e[0].spokes == 300, "{e:?}");
        assert!(e[1].range_cells == 150 && e[1].cells > 3_000, "{e:?}");
        let boat = p[0];
        let centre_cell = (boat_cells.start + boat_cells.end) as f32 / 2.0;
        assert!(
            (boat.range_m - centre_cell * sample_m).abs() < sample_m,
            "{boat:?}"
        );
        let centre_spoke = (f32::from(boat_spokes.start) + f32::from(boat_spokes.end - 1)) / 2.0;
        assert!((boat.bearing_rad - centre_spoke * SPOKE_RAD).abs() < SPOKE_RAD);
        assert_eq!(boat.cells, 30 * 60 + 2 * 4);
        // Every CFAR blob was a detection of one of these echoes.
        let s = ex.stats();
        assert_eq!(s.blobs_outside_echoes + s.echoes_dropped, 0, "{s:?}");
        assert_eq!((s.plots, s.extended), (1, 2));
    }

    #[test]
    fn before_the_first_echo_threshold_a_blob_is_measured_alone() {
        // The first 64 spokes after a start have no background estimate: nothing is an
        // echo, and a target there is its CFAR blob's plot, as before echoes were followed.
        let mut ex = navico();
        let mut events = StdVec::new();
        Feed::new().push(&mut ex, 0..200, &echoes(&[echo(30.0, 400.0)]), &mut events);
        let p = plots(&events);
        assert_eq!(p.len(), 1, "{events:?}");
        assert_eq!(ex.stats().blobs_outside_echoes, 1);
        assert!(
            (p[0].bearing_rad - 30.0 * SPOKE_RAD).abs() < SPOKE_RAD,
            "{p:?}"
        );
    }

    #[test]
    fn a_coastline_arc_is_extended_and_never_a_plot() {
        let mut ex = navico();
        // A cliff face 2.9 km off, 6 cells deep, along 50° of bearing; a buoy beside it.
        let buoy = [Echo {
            angle: 1500.0,
            cell: 300.0,
            peak: 12.0,
        }];
        let paint = move |angle: u16, cell: usize| {
            if (200..485).contains(&angle) && (400..406).contains(&cell) {
                13
            } else {
                echoes(&buoy)(angle, cell)
            }
        };
        let mut events = StdVec::new();
        Feed::new().push(&mut ex, rotation(), &paint, &mut events);
        let ext = extended(&events);
        assert_eq!(ext.len(), 1, "{events:?}");
        assert!(
            ext[0].cross_range_m > 2000.0 && ext[0].spokes == 285,
            "{ext:?}"
        );
        let p = plots(&events);
        assert_eq!(p.len(), 1);
        assert!((p[0].bearing_rad - 1500.0 * SPOKE_RAD).abs() < SPOKE_RAD);
        assert_eq!(ex.stats().extended, 1);
    }

    #[test]
    fn full_capacity_is_counted_not_a_panic() {
        // Room for 4 blobs and 6 runs a spoke; 10 echoes on the same spokes.
        let list: StdVec<Echo> = (0..10)
            .map(|i| Echo {
                angle: 800.0 + i as f32 * 0.2,
                cell: 100.0 + 60.0 * i as f32,
                peak: 14.0,
            })
            .collect();
        let mut ex: Extractor<4, 6> = Extractor::new(ExtractorConfig::navico_4bit()).unwrap();
        let mut events = StdVec::new();
        Feed::new().push(&mut ex, rotation(), &echoes(&list), &mut events);
        let s = *ex.stats();
        assert!(s.blobs_dropped > 0 && s.runs_dropped > 0, "{s:?}");
        // The four nearest echoes hold the blobs and are reported whole; the others are
        // lost but for fragments caught when a slot was free, never a panic.
        let whole: StdVec<_> = plots(&events)
            .into_iter()
            .filter(|p| p.spokes >= 8)
            .collect();
        assert_eq!(whole.len(), 4, "{whole:?}");
        for (p, e) in whole.iter().zip(&list) {
            assert!(
                (p.range_m - (e.cell + 0.5) * SAMPLE_M).abs() < SAMPLE_M,
                "{p:?}"
            );
        }
        assert_eq!(ex.open_blobs(), 0);
    }

    #[test]
    fn a_spoke_going_backwards_closes_everything_and_restarts() {
        let mut ex = navico();
        let target = echo(100.0, 300.0);
        let mut events = StdVec::new();
        let mut feed = Feed::new();
        feed.push(&mut ex, 0..101, &echoes(&[target]), &mut events);
        assert_eq!(ex.open_blobs(), 1);
        // Back to 90 (and a repeat of it): the open blob is reported, partial; from 90
        // on the echo is seen whole again.
        feed.push(&mut ex, [90, 90], &echoes(&[target]), &mut events);
        assert_eq!(ex.stats().out_of_order, 2);
        assert_eq!(ex.open_blobs(), 0);
        feed.push(&mut ex, 91..400, &echoes(&[target]), &mut events);
        let p = plots(&events);
        assert_eq!(p.len(), 2, "{p:?}");
        assert!(p[0].partial && !p[1].partial, "{p:?}");
        assert!((p[1].bearing_rad - 100.0 * SPOKE_RAD).abs() < SPOKE_RAD);
        assert_eq!(ex.stats().rotations, 0);
    }

    #[test]
    fn a_range_change_mid_rotation_closes_everything_and_restarts() {
        let mut ex = navico();
        let target = echo(100.0, 300.0);
        let mut events = StdVec::new();
        let mut feed = Feed::new();
        feed.push(&mut ex, 0..101, &echoes(&[target]), &mut events);
        feed.range_m = 2.0 * RANGE_M;
        feed.push(&mut ex, 101..300, &echoes(&[target]), &mut events);
        let s = *ex.stats();
        assert_eq!((s.range_changes, s.out_of_order), (1, 0));
        let p = plots(&events);
        assert_eq!(p.len(), 2, "{p:?}");
        // The first was measured at the old scale, the second at the new.
        assert!((p[0].range_m - 300.5 * SAMPLE_M).abs() < SAMPLE_M, "{p:?}");
        assert!((p[1].range_m - 300.5 * 2.0 * SAMPLE_M).abs() < 2.0 * SAMPLE_M);
        assert!(p.iter().all(|p| p.partial));
        // Head-up now: a format change.
        feed.north_up = false;
        feed.heading = Some(0.1);
        feed.push(&mut ex, 300..310, &echoes(&[]), &mut events);
        assert_eq!(ex.stats().format_changes, 1);
    }

    #[test]
    fn head_up_without_heading_gives_flagged_relative_bearings() {
        let mut ex = navico();
        let target = echo(512.0, 300.0);
        let mut events = StdVec::new();
        let mut feed = Feed::new();
        feed.north_up = false;
        feed.push(&mut ex, 0..600, &echoes(&[target]), &mut events);
        let p = plots(&events);
        assert_eq!(p.len(), 1);
        assert!(p[0].relative_bearing && p[0].to_icd().is_none());
        assert!((p[0].bearing_rad - core::f32::consts::FRAC_PI_2).abs() < SPOKE_RAD);
        assert_eq!(ex.stats().missing_heading, 600);
        // With a heading of 30° the same echo is at 120° true.
        let mut ex = navico();
        feed.heading = Some(30f32.to_radians());
        let mut events = StdVec::new();
        feed.push(&mut ex, 0..600, &echoes(&[target]), &mut events);
        let p = plots(&events);
        assert!(!p[0].relative_bearing);
        let icd = p[0].to_icd().unwrap();
        assert!(
            (icd.bearing_rad.to_degrees() - 120.0).abs() < 0.2,
            "{icd:?}"
        );
        assert_eq!(ex.stats().missing_heading, 0);
    }

    #[test]
    fn missing_spokes_are_bridged_up_to_the_gap_and_cut_beyond_it() {
        let target = echo(300.0, 300.0);
        // Every other spoke: one plot, still centred.
        let mut ex = navico();
        let mut events = StdVec::new();
        Feed::new().push(
            &mut ex,
            (0..600).step_by(2),
            &echoes(&[target]),
            &mut events,
        );
        let p = plots(&events);
        assert_eq!(p.len(), 1, "{p:?}");
        assert!((p[0].bearing_rad - 300.0 * SPOKE_RAD).abs() < SPOKE_RAD);
        assert_eq!(ex.stats().missing_spokes, 299);
        // A gap of 5 (more than 4) through the echo's middle: two partial halves.
        let mut ex = navico();
        let mut events = StdVec::new();
        let angles = (0..298).chain(303..600);
        Feed::new().push(&mut ex, angles, &echoes(&[target]), &mut events);
        let p = plots(&events);
        assert_eq!(p.len(), 2, "{p:?}");
        assert!(p.iter().all(|p| p.partial));
    }

    #[test]
    fn malformed_and_short_spokes_are_counted() {
        let mut ex = navico();
        let samples = [0u8; 40];
        let mut spoke = Spoke {
            angle: 0,
            spokes_per_rotation: N,
            north_up: true,
            heading_rad: None,
            range_m: 100.0,
            time_ms: 0,
            samples: &samples,
            max_sample: 15,
        };
        ex.push(&spoke, |_| {});
        assert_eq!(ex.stats().short_spokes, 1);
        spoke.angle = N;
        ex.push(&spoke, |_| {});
        spoke.angle = 1;
        spoke.range_m = f32::NAN;
        ex.push(&spoke, |_| {});
        spoke.range_m = 100.0;
        spoke.samples = &[];
        ex.push(&spoke, |_| {});
        assert_eq!(ex.stats().bad_spokes, 3);
        assert_eq!(ex.stats().spokes, 4);
    }
}
