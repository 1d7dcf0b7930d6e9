//! The track table: many targets, each with its own filter, through one scan at a time.
//!
//! Stone Soup's roles, on the device side of the thesis's split:
//!
//! - **predictor**: [`TrackTable::predict`] takes every track to the scan time;
//! - **gater** (rough): [`TrackTable::gate`] keeps, per track, the plots inside a circle
//!   sized from the predicted uncertainty (cheap; the host's refined gate and the
//!   associator choose among them);
//! - **updater**: [`TrackTable::apply`] updates each track with the plot the host assigned,
//!   or coasts it;
//! - **initiator**: plots the host names start tentative tracks;
//! - **deleter**: the life-cycle rules below.
//!
//! ## Life cycle
//!
//! A new track is *tentative*. It is *confirmed* on its [`CONFIRM_M`]th plot (the one that
//! started it counts), and dropped on [`TENTATIVE_LOST_AFTER_COASTS`] scans in a row
//! without a plot: hit, miss, hit, miss, hit confirms on the fifth scan, as long as the
//! track's speed is one a target can have ([`CONFIRM_SPEED_FACTOR`]). A confirmed track
//! is *coasting* on a scan without a plot, and is reported *lost* once and removed after
//! [`LOST_AFTER_COASTS`] scans in a row without one; a scan on which the host says its
//! target is *hidden* ([`crate::icd::HIDDEN_PLOT`]: no plot of its own, but one inside its
//! gate went to another firm track, as when two ships share one resolution cell) does not
//! count while it has missed at most [`HIDDEN_AFTER_MISSES`] scans of its own, up to
//! [`HIDDEN_LOST_AFTER_COASTS`] scans in a row without a plot in all. Both rules count misses in a row, as
//! Stone Soup's `MultiMeasurementInitiator(min_points=3)` with `UpdateTimeStepsDeleter(2)`
//! for its holding tracks and `UpdateTimeStepsDeleter(6)` for its tracks do
//! (docs/stonesoup.md). Until that comparison a confirmed track was lost on 5 hits of its
//! last 10 scans, which drops the track of a ship whose echo merges with a neighbour's on
//! most scans, and a tentative track needed plots on 3 of its last 4 scans (and went at 8
//! scans old): hit, miss, hit, miss, hit never confirmed, and the target waited for two
//! plots in a row.
//!
//! ## The track score
//!
//! Three plots in a row prove little where plots are dense: in a harbour of a hundred echoes
//! within 800 m, a new track's wide gate holds a dozen of them, and three echoes that happen
//! to line up make a confirmed track of tens of knots (docs/radar.md). So a tentative track
//! also keeps a score, the log-likelihood ratio of "a target" against "extraneous plots"
//! over its plots (the track score of Blackman & Popoli, *Design and Analysis of Modern
//! Tracking Systems*, 1999, ch. 6, after Sittler's sequential test, 1964). A plot adds
//!
//! ΔL = ln(P_D / (2π √|S|)) − d²/2 − ln λ,
//!
//! the target's Gaussian density at the plot (innovation covariance S, Mahalanobis d²)
//! against the density λ of extraneous plots near the track: false plots, and the plots of
//! targets no firm track holds. λ is measured each scan around the track, on the plots of its
//! rough gate that neither it nor a confirmed or coasting track took: their number over the
//! gate's area, or over the circle through the farthest when the gate's list was full (a
//! nearest-neighbour density estimate), and at least [`SCORE_MIN_EXTRANEOUS_PER_M2`]. A scan
//! without a plot adds ln(1 − P_D). The track is confirmed once it has [`CONFIRM_M`] plots
//! *and* a score of [`CONFIRM_SCORE`], and dropped if not confirmed by
//! [`TENTATIVE_MAX_AGE_SCANS`]. In open water (no extraneous plot near) the third
//! plot always confirms, as before and as in Stone Soup; in a dense harbour a one-plot
//! track's second plot is little or no evidence (its wide gate holds extraneous plots, so
//! taking one is no sign of a target), and a track confirms once the plots its tight gates
//! take say a target and not chance.

use heapless::Vec;

use crate::bounded::take_up_to;
use crate::filter::alpha_beta::AlphaBeta;
use crate::filter::gh_fixed_scan::{
    FixedScanAlphaBeta, FixedScanAlphaBetaGamma, FixedScanAlphaBetaGammaEta, FixedScanGh,
};
use crate::filter::grnn::GrnnFilter;
use crate::filter::imm::Imm;
use crate::filter::kalman::ca::KalmanCa;
use crate::filter::kalman::cv::KalmanCv;
use crate::filter::sswt::Sswt;
use crate::filter::{
    Estimate, Filter, FilterConfig, FilterError, FilterKind, Interval, Measurement,
};
use crate::float::{max, min};
use crate::geo::EastNorth;
use crate::icd::{
    Assignment, ErrorCode, GatedPlots, TrackState, TrackStatus, TrackerConfig, HIDDEN_PLOT,
    MAX_PLOTS_PER_GATE,
};
use crate::spatial::EastIndex;
use crate::tracker::MAX_PLOTS_PER_SCAN;

/// Tracks the table holds, tentative ones included.
///
/// 72: in the first scans of a 40-target picture with 10 clutter plots a scan every plot
/// starts a tentative track, and a table of 64 refused starts there (8 of 30 on the second
/// scan of the crossing scenario's seed 4), so targets first seen then were confirmed a
/// scan or two late (docs/stonesoup.md); 68 still refused some. The bound above is the
/// device's scan budget: the bench's full table (40 targets and 160 clutter plots a scan)
/// costs about 680 instructions a track a scan, and 72 keeps that scan under 80,000; the
/// 512-byte slots take 36 KiB of the 64 KiB RAM budget.
pub const MAX_TRACKS: usize = 72;

/// A tentative track is confirmed on this many plots, the one that started it included.
pub const CONFIRM_M: u32 = 3;
/// A tentative track is dropped after this many scans in a row without a plot.
pub const TENTATIVE_LOST_AFTER_COASTS: u8 = 2;
/// A tentative track not confirmed by this age (scans, its first included) is dropped: in
/// a dense picture one that keeps finding plots but never a score
/// ([the track score](self#the-track-score)) would otherwise hold its slot for ever (50 s
/// at a 2.5 s scan; without the score every tentative track was confirmed or gone by its
/// 5th scan).
pub const TENTATIVE_MAX_AGE_SCANS: u16 = 2 * KEEP_N as u16;
/// A tentative track is confirmed only while its speed is at most this many times the
/// fastest target's ([`TrackerConfig::max_speed_mps`]): three clutter plots in a new
/// track's wide gates can make a track at 50 m/s.
pub const CONFIRM_SPEED_FACTOR: f32 = 1.5;
/// A confirmed track is lost after this many scans in a row without a plot (15 s at a
/// 2.5 s scan), the scans its target was hidden in another track's plot not counted.
pub const LOST_AFTER_COASTS: u8 = 6;
/// A confirmed track whose target is hidden in another track's plot
/// ([`crate::icd::HIDDEN_PLOT`]) is lost after this many scans in a row without a plot of
/// its own, hidden or not (40 s at a 2.5 s scan; at most 16, the hit history's length):
/// the hidden track coasts on at its own velocity to where its ship comes out of the
/// neighbour's echo.
pub const HIDDEN_LOST_AFTER_COASTS: u8 = 16;
/// A scan on which a confirmed track's target is hidden does not count towards its loss
/// only while the track has missed at most this many scans of its own since its last
/// plot: one that has been losing its target for longer is dying, not hidden (with no
/// such limit, open-sea seed 4's dying tracks were kept a scan or two longer while a
/// neighbour's plot fell in their grown gates). Two allow for the misses of P_d 0.9 as a
/// merge begins.
pub const HIDDEN_AFTER_MISSES: u8 = 2;
const _: () = assert!(HIDDEN_LOST_AFTER_COASTS as u32 <= u16::BITS);
/// Scans of hit history a track reports ([`crate::icd::TrackState::hit_history`]).
pub const KEEP_N: u32 = 10;

/// The probability that a target gives a plot on a scan, as the track score takes it
/// (the simulator's P_d; [`score`](self#the-track-score)).
pub const SCORE_DETECTION_PROBABILITY: f32 = 0.9;
/// The least density of extraneous plots (false plots and the plots of targets no firm
/// track holds) the track score assumes near a track, per m² (one in 100 km²): where no
/// such plot is near, this density, not none ([`score`](self#the-track-score)).
pub const SCORE_MIN_EXTRANEOUS_PER_M2: f32 = 1e-8;
/// What a scan without a plot adds to a tentative track's score: ln(1 − P_D) = −ln 10, for
/// [`SCORE_DETECTION_PROBABILITY`] ([`score`](self#the-track-score)).
pub const SCORE_MISS: f32 = -core::f32::consts::LN_10;
/// A tentative track is confirmed only once its score is at least this: Wald's upper
/// threshold ln((1 − β)/α) with α = β = 0.1, ln 9 ([`score`](self#the-track-score)).
pub const CONFIRM_SCORE: f32 = 2.197_225;

/// The filter a track runs, in `f32` (the MCU's number): one variant per
/// [`FilterKind`], each holding that filter's state, and a second one for α-β with a gain
/// schedule.
///
/// The g-h filters with constant gains run in their fixed-scan form ([`FixedScanGh`]): a
/// scan's update also predicts the next scan, which the table then skips predicting while
/// the interval repeats. The calls follow the table's scan: [`TrackFilter::predict`] when a
/// scan's plots come, then [`TrackFilter::update`] or [`TrackFilter::coast`] when it closes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // fixed capacity: every slot holds the largest
pub enum TrackFilter {
    /// α-β with constant gains.
    AlphaBeta(FixedScanAlphaBeta<f32>),
    /// α-β with a least-squares gain schedule (thesis eq. 2-3/2-4).
    AlphaBetaScheduled(AlphaBeta<f32>),
    /// α-β-γ.
    AlphaBetaGamma(FixedScanAlphaBetaGamma<f32>),
    /// α-β-γ-η.
    AlphaBetaGammaEta(FixedScanAlphaBetaGammaEta<f32>),
    /// SSWT.
    Sswt(Sswt<f32>),
    /// CV Kalman.
    KalmanCv(KalmanCv<f32>),
    /// CA Kalman.
    KalmanCa(KalmanCa<f32>),
    /// GRNN.
    Grnn(GrnnFilter<f32>),
    /// IMM (CV, CA and settling CV).
    Imm(Imm<f32>),
}

/// `$body` on the filter of every variant that implements [`Filter`] (every one but the
/// fixed-scan g-h forms, handled by `$fixed` on the [`FixedScanGh`] itself).
macro_rules! each_filter {
    ($self:expr, $f:ident => $body:expr, fixed $g:ident => $fixed:expr) => {
        match $self {
            TrackFilter::AlphaBeta($g) => $fixed,
            TrackFilter::AlphaBetaGamma($g) => $fixed,
            TrackFilter::AlphaBetaGammaEta($g) => $fixed,
            TrackFilter::AlphaBetaScheduled($f) => $body,
            TrackFilter::Sswt($f) => $body,
            TrackFilter::KalmanCv($f) => $body,
            TrackFilter::KalmanCa($f) => $body,
            TrackFilter::Grnn($f) => $body,
            TrackFilter::Imm($f) => $body,
        }
    };
}

impl TrackFilter {
    /// A fresh filter of the configured kind (the gain design runs here, in f64).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when the configuration is out of range.
    pub fn build(config: &FilterConfig) -> Result<Self, FilterError> {
        Ok(match config {
            FilterConfig::AlphaBeta(g) => {
                let general = g.build()?;
                match FixedScanGh::from_filter(&general) {
                    Some(f) => TrackFilter::AlphaBeta(f),
                    None => TrackFilter::AlphaBetaScheduled(general),
                }
            }
            FilterConfig::AlphaBetaGamma(g) => TrackFilter::AlphaBetaGamma(fixed_scan(g.build()?)?),
            FilterConfig::AlphaBetaGammaEta(g) => {
                TrackFilter::AlphaBetaGammaEta(fixed_scan(g.build()?)?)
            }
            FilterConfig::Sswt(c) => TrackFilter::Sswt(c.build()?),
            FilterConfig::KalmanCv(c) => TrackFilter::KalmanCv(c.build_cv()?),
            FilterConfig::KalmanCa(c) => TrackFilter::KalmanCa(c.build_ca()?),
            FilterConfig::Grnn(c) => TrackFilter::Grnn(c.build()?),
            FilterConfig::Imm(c) => TrackFilter::Imm(c.build()?),
        })
    }

    /// Which filter this is.
    pub fn kind(&self) -> FilterKind {
        match self {
            TrackFilter::AlphaBeta(_) | TrackFilter::AlphaBetaScheduled(_) => FilterKind::AlphaBeta,
            TrackFilter::AlphaBetaGamma(_) => FilterKind::AlphaBetaGamma,
            TrackFilter::AlphaBetaGammaEta(_) => FilterKind::AlphaBetaGammaEta,
            TrackFilter::Sswt(_) => FilterKind::Sswt,
            TrackFilter::KalmanCv(_) => FilterKind::KalmanCv,
            TrackFilter::KalmanCa(_) => FilterKind::KalmanCa,
            TrackFilter::Grnn(_) => FilterKind::Grnn,
            TrackFilter::Imm(_) => FilterKind::Imm,
        }
    }

    /// True for the fixed-scan g-h forms, whose prediction for the next scan is made when a
    /// scan closes.
    pub fn is_fixed_scan(&self) -> bool {
        each_filter!(self, _f => false, fixed _g => true)
    }

    /// Becomes a copy of `prototype`. A slot reused for a track of the same filter (in the
    /// product always: a table runs one filter) copies that filter's state only, not the
    /// whole slot-sized enum (up to 464 B, about 350 instructions on the M4F a copy).
    pub fn reset_to(&mut self, prototype: &TrackFilter) {
        match (self, prototype) {
            (TrackFilter::AlphaBeta(f), TrackFilter::AlphaBeta(p)) => *f = *p,
            (TrackFilter::AlphaBetaScheduled(f), TrackFilter::AlphaBetaScheduled(p)) => *f = *p,
            (TrackFilter::AlphaBetaGamma(f), TrackFilter::AlphaBetaGamma(p)) => *f = *p,
            (TrackFilter::AlphaBetaGammaEta(f), TrackFilter::AlphaBetaGammaEta(p)) => *f = *p,
            (TrackFilter::Sswt(f), TrackFilter::Sswt(p)) => *f = *p,
            (TrackFilter::KalmanCv(f), TrackFilter::KalmanCv(p)) => *f = *p,
            (TrackFilter::KalmanCa(f), TrackFilter::KalmanCa(p)) => *f = *p,
            (TrackFilter::Grnn(f), TrackFilter::Grnn(p)) => *f = *p,
            (TrackFilter::Imm(f), TrackFilter::Imm(p)) => *f = *p,
            (this, p) => *this = *p,
        }
    }

    /// (Re)starts on a first plot.
    pub fn start(&mut self, z: Measurement<f32>) {
        each_filter!(self, f => f.start(z), fixed g => g.start(z))
    }

    /// Predicts `dt` past the last scan closed (or the start); returns the predicted position.
    pub fn predict(&mut self, dt: Interval<f32>) -> EastNorth {
        each_filter!(self, f => f.predict(dt), fixed g => g.predict(dt))
    }

    /// Closes a scan with the plot assigned.
    pub fn update(&mut self, z: Measurement<f32>) {
        each_filter!(self, f => { f.update(z); }, fixed g => g.update(z))
    }

    /// Updates with the plot assigned on a scan the filter was not predicted for (the
    /// table could not: see [`TrackTable::predict`]).
    pub fn update_in_place(&mut self, z: Measurement<f32>) {
        each_filter!(self, f => { f.update(z); }, fixed g => g.update_in_place(z))
    }

    /// Closes a scan without a plot. Only the fixed-scan forms act (they predict the next
    /// scan); the others' next predict goes on from this one.
    pub fn coast(&mut self) {
        each_filter!(self, _f => {}, fixed g => g.coast())
    }

    /// Position and velocity after the last scan closed.
    pub fn estimate(&self) -> Estimate<f32> {
        each_filter!(self, f => f.estimate(), fixed g => g.estimate())
    }

    /// The predicted position the next update takes as its prior.
    pub fn prediction(&self) -> EastNorth {
        each_filter!(self, f => f.prediction(), fixed g => g.prediction())
    }

    /// True while the filter has declared a manoeuvre (only filters with a detector do).
    pub fn manoeuvring(&self) -> bool {
        each_filter!(self, f => f.manoeuvring(), fixed _g => false)
    }

    /// The covariance `[s_xx, s_xy, s_yy]` (m²) of the next update's innovation, for the
    /// filters that carry one ([`Filter::innovation_covariance`]).
    pub fn innovation_covariance(&self) -> Option<[f32; 3]> {
        each_filter!(self, f => f.innovation_covariance(), fixed _g => None)
    }

    /// The innovation covariance of the current prediction, `[s_xx, s_xy, s_yy]` (m²).
    ///
    /// The Kalman filters know it ([`Filter::innovation_covariance`]). The others do not:
    /// for them it is modelled as twice the plot variance `plot_var` (prediction and plot
    /// errors of equal size), grown with the square of the scans coasted.
    pub fn innovation_cov(&self, plot_var: f32, coasts: u8) -> [f32; 3] {
        self.innovation_covariance().unwrap_or_else(|| {
            let grow = 1.0 + f32::from(coasts);
            let s = 2.0 * plot_var * grow * grow;
            [s, 0.0, s]
        })
    }
}

/// The fixed-scan form of a constant-gain design (every α-β-γ and α-β-γ-η design is one).
fn fixed_scan<const N: usize>(
    general: crate::filter::gh::GhFilter<f32, N>,
) -> Result<FixedScanGh<f32, N>, FilterError> {
    FixedScanGh::from_filter(&general).ok_or(FilterError::BadParameter)
}

/// One track.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Track number, unique while the table lives.
    pub id: u16,
    /// Life-cycle state.
    pub status: TrackStatus,
    filter: TrackFilter,
    /// Hit history, one bit a scan, newest lowest.
    hits: u16,
    /// Scans since the track started (the first included).
    age_scans: u16,
    /// Consecutive scans without a plot, those its target was hidden in another track's
    /// plot not counted (the loss rule's count; the scans since the last plot are the hit
    /// history's trailing zeros, [`Track::scans_since_plot`]: the slot stays 512 bytes).
    coasts: u8,
    /// Time of the last prediction or start, ms.
    time_ms: u64,
    /// The plots inside this scan's rough gate.
    gated: Vec<u16, MAX_PLOTS_PER_GATE>,
    /// The area the gated plots were found in, m²: the rough gate's, or the circle through
    /// the farthest of them when the list is full (for the extraneous plots' density).
    gated_area_m2: f32,
    innovation_cov: [f32; 3],
    /// The track score while tentative ([the track score](self#the-track-score)).
    score: f32,
}

impl Track {
    /// The track's state for a report.
    pub fn state(&self) -> TrackState {
        let e = self.filter.estimate();
        TrackState {
            track: self.id,
            status: self.status,
            position_m: e.position_m,
            velocity_mps: e.velocity_mps,
            age_scans: self.age_scans,
            hit_history: self.hit_history(),
        }
    }

    /// Its filter.
    pub fn filter(&self) -> &TrackFilter {
        &self.filter
    }

    /// The plots inside this scan's rough gate (after [`TrackTable::gate`]), nearest first.
    pub fn gated_plots(&self) -> &[u16] {
        &self.gated
    }

    /// The innovation covariance its gate was sized from, `[s_xx, s_xy, s_yy]` (m²).
    pub fn innovation_cov_m2(&self) -> [f32; 3] {
        self.innovation_cov
    }

    /// Hits in the last [`KEEP_N`] scans, newest lowest (as its state reports them).
    pub fn hit_history(&self) -> u16 {
        self.hits & ((1 << KEEP_N) - 1)
    }

    /// True when the last scan closed gave it a plot.
    pub fn hit_last_scan(&self) -> bool {
        self.hits & 1 == 1
    }

    /// The track score, the log-likelihood ratio of its plots being a target's (natural
    /// log, no unit; [the track score](self#the-track-score)); kept while tentative.
    pub fn score(&self) -> f32 {
        self.score
    }

    fn hits_in_last(&self, n: u32) -> u32 {
        (self.hits & ((1u16 << n) - 1)).count_ones()
    }

    /// Scans since the track's last plot (0 when it took one on the last scan), at most 16:
    /// the hit history's trailing zeros.
    fn scans_since_plot(&self) -> u8 {
        // At most 16, so the cast is exact.
        self.hits.trailing_zeros() as u8
    }
}

/// A slot no assignment named yet, in `apply` (no plot index reaches it: a scan has at
/// most 256 plots).
const NO_PLOT: u16 = u16::MAX;

/// A slot an assignment told to coast, in `apply`.
const COAST: u16 = u16::MAX - 1;

/// A slot an assignment told to coast with its target hidden ([`HIDDEN_PLOT`]), in `apply`.
const HIDDEN: u16 = u16::MAX - 2;

// No plot index reaches the markers above.
const _: () = assert!(MAX_PLOTS_PER_SCAN < HIDDEN as usize);

/// What a scan's `apply` did, for the counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ApplyReport {
    /// Tracks updated with a plot.
    pub updated: u16,
    /// Tracks coasted.
    pub coasted: u16,
    /// Tracks started.
    pub initiated: u16,
    /// Tracks that could not start: the table was full.
    pub refused_full: u16,
    /// Tracks dropped (tentative failures and lost tracks).
    pub dropped: u16,
}

/// The track table.
///
/// Tracks live in slots that never move: `order` lists the live tracks' slots in the
/// table's order (the order they started in, which is the order of the gates and states on
/// the wire), and a dropped track's slot is marked free for the next start. Dropping or
/// starting a track moves a byte of `order`, not a 512-byte slot: on the device, with a
/// table refilled from clutter every scan, moving slots was half of a scan's work.
#[derive(Clone, Debug)]
pub struct TrackTable {
    config: TrackerConfig,
    /// A fresh filter of the configured kind, built once per configuration: building one
    /// does the gain design (in f64), too slow to repeat for every new track on the MCU.
    prototype: Option<TrackFilter>,
    /// Every slot used so far, live or free.
    slots: Vec<Track, MAX_TRACKS>,
    /// The live tracks' slots, in table order.
    order: Vec<u8, MAX_TRACKS>,
    /// The free slots.
    free: SlotSet,
    next_id: u16,
    /// Track numbers have wrapped past `u16::MAX`: a new number must be checked against
    /// the live ones (before, every live number is below `next_id`).
    ids_wrapped: bool,
    /// The interval every fixed-scan g-h track's held prediction was made for, when they
    /// all share one: a scan that comes this long after the last needs no prediction from
    /// them (see [`TrackTable::predict`]).
    ahead: Option<Interval<f32>>,
    /// The time of the scan [`TrackTable::predict`] opened and [`TrackTable::apply`] has not
    /// closed yet, ms.
    open_ms: Option<u64>,
    /// Every track was predicted for the open scan (in the product always: only an interval
    /// outside [`crate::filter::MIN_INTERVAL_S`, `MAX_INTERVAL_S`] leaves one unpredicted).
    all_predicted: bool,
}

impl Default for TrackTable {
    fn default() -> Self {
        Self::new()
    }
}

impl TrackTable {
    /// An empty table with [`TrackerConfig::DEFAULT`].
    pub const fn new() -> Self {
        TrackTable {
            config: TrackerConfig::DEFAULT,
            prototype: None,
            slots: Vec::new(),
            order: Vec::new(),
            free: SlotSet::EMPTY,
            next_id: 1,
            ids_wrapped: false,
            ahead: None,
            open_ms: None,
            all_predicted: true,
        }
    }

    /// Sets the configuration for tracks started from now on; refuses values out of range.
    ///
    /// # Errors
    /// [`ErrorCode::InvalidValue`] for a gate or plot value that is not finite and positive, crossed gate radii, or a filter configuration out of range (nothing changes).
    pub fn configure(&mut self, config: TrackerConfig) -> Result<(), ErrorCode> {
        let finite_positive = |v: f32| v.is_finite() && v > 0.0;
        let ok = finite_positive(config.gate_sigmas)
            && finite_positive(config.min_gate_m)
            && finite_positive(config.max_gate_m)
            && config.min_gate_m <= config.max_gate_m
            && finite_positive(config.plot_sigma_m)
            && finite_positive(config.max_speed_mps);
        let prototype = match TrackFilter::build(&config.filter) {
            Ok(f) if ok => f,
            _ => return Err(ErrorCode::InvalidValue),
        };
        self.config = config;
        self.prototype = Some(prototype);
        Ok(())
    }

    /// The configuration.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// The tracks, in table order.
    pub fn tracks(&self) -> Tracks<'_> {
        Tracks {
            slots: &self.slots,
            order: self.order.iter(),
        }
    }

    /// The tracks in table order, each with its slot number (a slot keeps its track for
    /// the track's life; a freed slot takes a new track with another number).
    pub fn placed(&self) -> impl Iterator<Item = (usize, &Track)> + '_ {
        self.order.iter().filter_map(|&slot| {
            let slot = usize::from(slot);
            self.slots.get(slot).map(|t| (slot, t))
        })
    }

    /// The track at `index` in table order.
    pub fn track(&self, index: usize) -> Option<&Track> {
        let slot = *self.order.get(index)?;
        self.slots.get(usize::from(slot))
    }

    /// Live tracks.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// True when no track is live.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// True when one more track would fill the table: the capacity warning.
    pub fn nearly_full(&self) -> bool {
        self.order.len() + 1 >= MAX_TRACKS
    }

    /// Predicts every track to `time_ms` and opens the scan. A track already at or past that
    /// time (started on this scan) is left as it is.
    ///
    /// The interval is worked out once for all tracks at one time (every track was
    /// predicted or started at the last scan's time, in the product always). The fixed-scan
    /// g-h tracks already hold their prediction for the scan when it comes as long after the
    /// last as the one before came ([`TrackFilter::is_fixed_scan`]): this one comparison, a
    /// scan, replaces their predicts. Otherwise each predicts, and the new interval is the
    /// one they hold next time. A scan predicted before and never closed (its assignments
    /// never came) is closed first with every track coasting, as a second predict coasts
    /// the other filters.
    ///
    /// A track whose interval is out of range (a scan more than a day after its last) is
    /// not predicted, and is updated in place if it gets a plot, whatever its filter. Its
    /// gate is then centred on the last prediction it holds: for a fixed-scan g-h track,
    /// one interval past its estimate; for the others, their last scan's prediction.
    pub fn predict(&mut self, time_ms: u64) {
        if let Some(open_ms) = self.open_ms {
            let all = self.all_predicted;
            for &slot in &self.order {
                match self.slots.get_mut(usize::from(slot)) {
                    Some(t) if all || t.time_ms == open_ms => t.filter.coast(),
                    _ => {}
                }
            }
        }
        let ahead = self.ahead;
        // The interval from the last time seen, and whether the fixed-scan tracks hold it.
        let mut last: Option<(u64, Option<Interval<f32>>, bool)> = None;
        let (mut one_interval, mut all_predicted) = (true, true);
        for &slot in &self.order {
            let Some(t) = self.slots.get_mut(usize::from(slot)) else {
                continue;
            };
            let (dt, held) = match last {
                Some((from, dt, held)) if from == t.time_ms => (dt, held),
                _ => {
                    let dt_s = time_ms.saturating_sub(t.time_ms) as f32 / 1000.0;
                    let dt = Interval::new(dt_s).ok();
                    let held = dt.is_some() && dt == ahead;
                    one_interval &= last.is_none();
                    last = Some((t.time_ms, dt, held));
                    (dt, held)
                }
            };
            let Some(dt) = dt else {
                one_interval = false;
                all_predicted = false;
                continue;
            };
            if !(held && t.filter.is_fixed_scan()) {
                t.filter.predict(dt);
            }
            t.time_ms = time_ms;
        }
        self.ahead = match last {
            Some((_, Some(dt), _)) if one_interval => Some(dt),
            _ => None,
        };
        self.open_ms = Some(time_ms);
        self.all_predicted = all_predicted;
    }

    /// Rough gating: for each track, the (at most [`MAX_PLOTS_PER_GATE`]) nearest plots
    /// inside a circle of `gate_sigmas` standard deviations of the innovation, clamped to
    /// the configured radii (widened by the fastest target's travel while a track has only
    /// one plot and no velocity). Ties in distance go to the lower plot number.
    ///
    /// The plots are bucketed by east once ([`EastIndex`]), so a track looks only at the
    /// plots near its own east: the cost grows as tracks × plots in a strip of the gate's
    /// width, not tracks × plots.
    pub fn gate(&mut self, plots: &[EastNorth], scan_s: f32) {
        let cfg = self.config;
        let plot_var = cfg.plot_sigma_m * cfg.plot_sigma_m;
        let index = EastIndex::new(plots);
        for &slot in &self.order {
            let Some(t) = self.slots.get_mut(usize::from(slot)) else {
                continue;
            };
            t.innovation_cov = t.filter.innovation_cov(plot_var, t.scans_since_plot());
            let sigma = libm::sqrtf(max(t.innovation_cov[0], t.innovation_cov[2]));
            // max/min, not clamp: clamp panics on NaN or crossed bounds, and the firmware
            // must have no reachable panic.
            let mut radius = min(max(cfg.gate_sigmas * sigma, cfg.min_gate_m), cfg.max_gate_m);
            if t.age_scans <= 1 && !t.filter.kind().has_covariance() {
                radius = min(radius + cfg.max_speed_mps * scan_s, cfg.max_gate_m);
            }
            let p = t.filter.prediction();
            let r2 = radius * radius;
            let mut best = Nearest::new();
            let mut consider = |i: usize| {
                let Some(z) = plots.get(i) else { return };
                let (dx, dy) = (z[0] - p[0], z[1] - p[1]);
                let d2 = dx * dx + dy * dy;
                // `>`, not `>=`, and NaN passes: as the scan over every plot always did.
                if d2 > r2 {
                    return;
                }
                if let Ok(i) = u16::try_from(i) {
                    best.offer(d2, i);
                }
            };
            match &index {
                // The strips are wider than the gate by a margin far above f32 rounding, so
                // no plot inside the circle is missed.
                Some(index) if p[0].is_finite() && p[1].is_finite() => {
                    let w = radius * 1.001 + 1.0;
                    for &i in index.between(p[0] - w, p[0] + w) {
                        consider(usize::from(i));
                    }
                }
                _ => (0..plots.len()).for_each(&mut consider),
            }
            t.gated_area_m2 = core::f32::consts::PI
                * match best.0.last() {
                    Some(&(d2, _)) if best.0.is_full() => d2,
                    _ => r2,
                };
            t.gated = take_up_to(best.0.iter().map(|&(_, i)| i));
        }
    }

    /// The rough-gate result of one track (after [`TrackTable::gate`]).
    pub fn gated(&self, index: usize) -> Option<GatedPlots> {
        let t = self.track(index)?;
        Some(GatedPlots {
            track: t.id,
            predicted_m: t.filter.prediction(),
            innovation_cov_m2: t.innovation_cov,
            plots: t.gated.clone(),
        })
    }

    /// Closes the scan [`TrackTable::predict`] opened, at `time_ms`: updates the assigned
    /// tracks, coasts the others, applies the life-cycle rules, then starts tentative tracks
    /// on the `initiate` plots. Assignments naming unknown tracks or plots are refused whole,
    /// before any change.
    ///
    /// # Errors
    /// [`ErrorCode::OutOfSequence`] when no scan is open; [`ErrorCode::InvalidValue`] when an assignment names a track that does not exist or a plot that does not (other than [`HIDDEN_PLOT`]: the track coasts, its target hidden), or an initiation a plot that does not.
    pub fn apply(
        &mut self,
        time_ms: u64,
        plots: &[EastNorth],
        assignments: &[Assignment],
        initiate: &[u16],
    ) -> Result<ApplyReport, ErrorCode> {
        let Some(open_ms) = self.open_ms else {
            return Err(ErrorCode::OutOfSequence);
        };
        let plot = |i: u16| plots.get(usize::from(i)).copied();
        // Each track's plot, by its place in the table, in one walk over the assignments
        // (a track's first assignment counts), which also checks them all before anything
        // changes.
        let mut plot_of = [NO_PLOT; MAX_TRACKS];
        let mut from = 0;
        for a in assignments {
            let Some(at) = self.position_of(a.track, from) else {
                return Err(ErrorCode::InvalidValue);
            };
            from = at + 1;
            if a.plot
                .is_some_and(|p| p != HIDDEN_PLOT && plot(p).is_none())
            {
                return Err(ErrorCode::InvalidValue);
            }
            if let Some(p) = plot_of.get_mut(at) {
                if *p == NO_PLOT {
                    *p = match a.plot {
                        Some(HIDDEN_PLOT) => HIDDEN,
                        Some(p) => p,
                        None => COAST,
                    };
                }
            }
        }
        if initiate.iter().any(|&p| plot(p).is_none()) {
            return Err(ErrorCode::InvalidValue);
        }
        let mut report = ApplyReport::default();
        // The plots firm tracks took: not extraneous to a tentative track's score.
        let mut firm_taken = PlotSet::EMPTY;
        for (&slot, &p) in self.order.iter().zip(plot_of.iter()) {
            if p < HIDDEN
                && self
                    .slots
                    .get(usize::from(slot))
                    .is_some_and(|t| t.status.is_firm())
            {
                firm_taken.insert(usize::from(p));
            }
        }
        let mut failed = SlotSet::EMPTY;
        let all_predicted = self.all_predicted;
        let max_speed_mps = self.config.max_speed_mps;
        // Lost tracks were reported once; now they go (whatever was assigned to them).
        let mut lost = SlotSet::EMPTY;
        for (at, (&slot, &p)) in self.order.iter().zip(plot_of.iter()).enumerate() {
            let Some(t) = self.slots.get_mut(usize::from(slot)) else {
                continue;
            };
            if t.status == TrackStatus::Lost {
                lost.insert(at);
                continue;
            }
            // Not predicted for this scan (see `all_predicted`): updated in place, or left.
            let in_place = !all_predicted && t.time_ms != open_ms;
            let assigned = plot(p).and_then(|z| Measurement::new(z).ok());
            t.hits <<= 1;
            t.age_scans = t.age_scans.saturating_add(1);
            if t.status == TrackStatus::Tentative {
                t.score += match plot(p) {
                    Some(z) if assigned.is_some() => {
                        let others = t
                            .gated
                            .iter()
                            .filter(|&&i| i != p && !firm_taken.contains(usize::from(i)))
                            .count();
                        let density = max(
                            others as f32 / max(t.gated_area_m2, 1.0),
                            SCORE_MIN_EXTRANEOUS_PER_M2,
                        );
                        plot_score(t.filter.prediction(), t.innovation_cov, z, density)
                    }
                    _ => SCORE_MISS,
                };
            }
            match assigned {
                Some(z) if in_place => {
                    t.filter.update_in_place(z);
                    t.hits |= 1;
                    t.coasts = 0;
                    report.updated += 1;
                }
                Some(z) => {
                    t.filter.update(z);
                    t.hits |= 1;
                    t.coasts = 0;
                    report.updated += 1;
                }
                None => {
                    if !in_place {
                        t.filter.coast();
                    }
                    let hidden =
                        p == HIDDEN && t.status.is_firm() && t.coasts <= HIDDEN_AFTER_MISSES;
                    if !hidden {
                        t.coasts = t.coasts.saturating_add(1);
                    }
                    report.coasted += 1;
                }
            }
            match next_status(t, max_speed_mps) {
                Some(status) => t.status = status,
                None => failed.insert(at),
            }
        }
        // One drop for both: the places shift once a track goes.
        self.drop_at(&lost.union(&failed));
        report.dropped = failed.len() as u16;
        self.open_ms = None;
        for &p in initiate {
            // A full table refuses without looking (a table refilled from clutter is full on
            // most scans, and most of a scan's initiations are refused).
            if self.order.is_full() {
                report.refused_full += 1;
                continue;
            }
            if let Some(z) = plot(p).and_then(|z| Measurement::new(z).ok()) {
                match self.start_track(time_ms, z) {
                    Ok(_) => report.initiated += 1,
                    Err(_) => report.refused_full += 1,
                }
            }
        }
        Ok(report)
    }

    /// Drops the tracks at the places in the table `at` holds (0: the first track); their
    /// slots become free.
    fn drop_at(&mut self, at: &SlotSet) {
        if at.is_empty() {
            return;
        }
        let (mut place, mut free) = (0usize, self.free);
        self.order.retain(|&slot| {
            let drop = at.contains(place);
            place += 1;
            if drop {
                free.insert(usize::from(slot));
            }
            !drop
        });
        self.free = free;
    }

    /// The place in the table of track `id`, looked for from place `from` on first: the
    /// host lists its assignments in the order of the gates, which is the table's, so a
    /// walk over them finds each track in one step instead of searching the whole table.
    fn position_of(&self, id: u16, from: usize) -> Option<usize> {
        let is = |slot: &u8| {
            self.slots
                .get(usize::from(*slot))
                .is_some_and(|t| t.id == id)
        };
        let after = self
            .order
            .get(from..)
            .and_then(|rest| rest.iter().position(is))
            .map(|i| i + from);
        after.or_else(|| self.order.iter().position(is))
    }

    /// Starts a tentative track on a plot (also the operator's manual acquisition).
    ///
    /// # Errors
    /// [`ErrorCode::CapacityExceeded`] when the table is full; [`ErrorCode::InvalidValue`] when the configured filter cannot be built.
    pub fn start_track(&mut self, time_ms: u64, z: Measurement<f32>) -> Result<u16, ErrorCode> {
        if self.order.is_full() {
            return Err(ErrorCode::CapacityExceeded);
        }
        if self.prototype.is_none() {
            let f = TrackFilter::build(&self.config.filter).map_err(|_| ErrorCode::InvalidValue)?;
            self.prototype = Some(f);
        }
        let id = self.next_id;
        // Track numbers wrap past u16::MAX, skipping 0 and, once wrapped, any still in use.
        loop {
            self.next_id = self.next_id.wrapping_add(1);
            if self.next_id == 0 {
                self.next_id = 1;
                self.ids_wrapped = true;
            }
            if !self.ids_wrapped || !self.tracks().any(|t| t.id == self.next_id) {
                break;
            }
        }
        let Some(prototype) = &self.prototype else {
            return Err(ErrorCode::InvalidValue);
        };
        // A free slot is written in place; a new slot is pushed while the table has never
        // been this full.
        let slot = if let Some(slot) = self.free.first() {
            self.free.remove(slot);
            slot
        } else {
            let fresh = Track {
                id,
                status: TrackStatus::Tentative,
                filter: *prototype,
                hits: 1,
                age_scans: 1,
                coasts: 0,
                time_ms,
                gated: Vec::new(),
                gated_area_m2: 0.0,
                innovation_cov: [0.0; 3],
                score: 0.0,
            };
            self.slots
                .push(fresh)
                .map_err(|_| ErrorCode::CapacityExceeded)?;
            self.slots.len() - 1
        };
        let (Some(t), Ok(place)) = (self.slots.get_mut(slot), u8::try_from(slot)) else {
            return Err(ErrorCode::CapacityExceeded);
        };
        t.id = id;
        t.status = TrackStatus::Tentative;
        t.filter.reset_to(prototype);
        t.hits = 1;
        t.age_scans = 1;
        t.coasts = 0;
        t.time_ms = time_ms;
        t.gated.clear();
        t.gated_area_m2 = 0.0;
        t.innovation_cov = [0.0; 3];
        t.score = 0.0;
        t.filter.start(z);
        if self.open_ms.is_some() {
            // Inside an open scan, apply closes it with the others; its interval is set at
            // its first predict, so the next scan predicts every track.
            self.ahead = None;
        } else if let (Some(dt), true) = (self.ahead, t.filter.is_fixed_scan()) {
            // Predicted now at the table's interval, as every other fixed-scan track is.
            t.filter.predict(dt);
        }
        self.order
            .push(place)
            .map_err(|_| ErrorCode::CapacityExceeded)?;
        Ok(id)
    }

    /// Drops one track.
    ///
    /// # Errors
    /// [`ErrorCode::InvalidValue`] when no track has that number.
    pub fn cancel(&mut self, id: u16) -> Result<(), ErrorCode> {
        match self.position_of(id, 0) {
            Some(at) => {
                let mut place = SlotSet::EMPTY;
                place.insert(at);
                self.drop_at(&place);
                Ok(())
            }
            None => Err(ErrorCode::InvalidValue),
        }
    }

    /// Drops every track.
    pub fn cancel_all(&mut self) {
        self.order.clear();
        self.free = SlotSet::below(self.slots.len());
    }
}

/// The tracks of a [`TrackTable`] in table order ([`TrackTable::tracks`]).
#[derive(Clone, Debug)]
pub struct Tracks<'a> {
    slots: &'a [Track],
    order: core::slice::Iter<'a, u8>,
}

impl<'a> Iterator for Tracks<'a> {
    type Item = &'a Track;

    fn next(&mut self) -> Option<&'a Track> {
        // Every place in `order` names a slot that exists.
        let slot = *self.order.next()?;
        self.slots.get(usize::from(slot))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.order.size_hint()
    }
}

impl ExactSizeIterator for Tracks<'_> {}

// Slots are numbered in a u8 (`order`); the wire counts tracks in a u16.
const _: () = assert!(MAX_TRACKS <= 256);

/// The nearest plots offered, kept sorted by (distance², plot number): the result does not
/// depend on the order the plots are offered in.
struct Nearest(Vec<(f32, u16), MAX_PLOTS_PER_GATE>);

impl Nearest {
    fn new() -> Self {
        Nearest(Vec::new())
    }

    /// `a` before `b`. With NaN distances nothing is before anything, which keeps the offer
    /// order: the behaviour of the scan over every plot in plot order.
    fn before(a: (f32, u16), b: (f32, u16)) -> bool {
        a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
    }

    /// Offers plot `index` at squared distance `d2`; the farthest is dropped when full.
    fn offer(&mut self, d2: f32, index: u16) {
        let best = &mut self.0;
        if best.is_full() {
            // Not `!before(new, far)`: with a NaN distance that would drop the offer, where
            // the scan in plot order always took it.
            if best
                .last()
                .is_some_and(|&far| Self::before(far, (d2, index)))
            {
                return;
            }
            best.pop();
        }
        // Insertion into the sorted list by swaps (a library sort keeps a panic path for
        // inconsistent orderings, which the firmware must not have).
        let _ = best.push((d2, index));
        for i in (1..best.len()).rev() {
            let Some((left, right)) = best.split_at_mut_checked(i) else {
                break;
            };
            match (left.last_mut(), right.first_mut()) {
                (Some(a), Some(b)) if Self::before(*b, *a) => core::mem::swap(a, b),
                _ => break,
            }
        }
    }
}

/// A plot's addition to a tentative track's score, ln(P_D / (2π √|S|)) − d²/2 − ln λ
/// ([the track score](self#the-track-score)): `predicted` the track's predicted position,
/// `s` its innovation covariance `[s_xx, s_xy, s_yy]` (m²), `z` the plot, `extraneous_per_m2`
/// the density λ of extraneous plots near the track (per m², positive). A covariance that is
/// not positive definite, or anything not a number, adds nothing.
fn plot_score(predicted: EastNorth, s: [f32; 3], z: EastNorth, extraneous_per_m2: f32) -> f32 {
    let det = s[0] * s[2] - s[1] * s[1];
    if !(det > 0.0 && s[0] > 0.0) {
        return 0.0;
    }
    let (dx, dy) = (z[0] - predicted[0], z[1] - predicted[1]);
    let d2 = (s[2] * dx * dx - 2.0 * s[1] * dx * dy + s[0] * dy * dy) / det;
    let density_ratio = SCORE_DETECTION_PROBABILITY
        / (2.0 * core::f32::consts::PI * libm::sqrtf(det) * extraneous_per_m2);
    let score = libm::logf(density_ratio) - 0.5 * d2;
    if score.is_finite() {
        score
    } else {
        0.0
    }
}

/// A set of small numbers, one bit each: a scan's plot numbers, the table's slots or places.
/// Numbers past its capacity (32 × `W`) are never in it. Words of 32 bits: the M4F's own,
/// where a wider integer's shifts cost a dozen instructions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct BitSet<const W: usize>([u32; W]);

/// Plot numbers of a scan (those past the device's [`MAX_PLOTS_PER_SCAN`] are never in it).
type PlotSet = BitSet<{ MAX_PLOTS_PER_SCAN / 32 }>;
/// Slots, or places in the table's order.
type SlotSet = BitSet<{ MAX_TRACKS.div_ceil(32) }>;

const _: () = assert!(MAX_PLOTS_PER_SCAN.is_multiple_of(32));

impl<const W: usize> BitSet<W> {
    const EMPTY: Self = BitSet([0; W]);

    /// The set of `0..n`.
    fn below(n: usize) -> Self {
        let mut set = Self::EMPTY;
        for i in 0..n {
            set.insert(i);
        }
        set
    }

    fn insert(&mut self, i: usize) {
        if let Some(w) = self.0.get_mut(i / 32) {
            *w |= 1 << (i % 32);
        }
    }

    fn remove(&mut self, i: usize) {
        if let Some(w) = self.0.get_mut(i / 32) {
            *w &= !(1 << (i % 32));
        }
    }

    fn contains(&self, i: usize) -> bool {
        self.0.get(i / 32).is_some_and(|w| (w >> (i % 32)) & 1 == 1)
    }

    fn is_empty(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }

    fn len(&self) -> u32 {
        self.0.iter().map(|w| w.count_ones()).sum()
    }

    /// The least number in the set.
    fn first(&self) -> Option<usize> {
        self.0
            .iter()
            .enumerate()
            .find(|(_, &w)| w != 0)
            .map(|(k, w)| k * 32 + w.trailing_zeros() as usize)
    }

    fn union(mut self, other: &Self) -> Self {
        for (a, b) in self.0.iter_mut().zip(other.0.iter()) {
            *a |= b;
        }
        self
    }
}

/// The life-cycle rule: the track's next status, or `None` when a tentative track can no
/// longer be confirmed and goes. A tentative track is confirmed only at a speed a target
/// can have: at most [`CONFIRM_SPEED_FACTOR`] times `max_speed_mps`.
fn next_status(t: &Track, max_speed_mps: f32) -> Option<TrackStatus> {
    Some(match t.status {
        TrackStatus::Tentative => {
            if t.coasts >= TENTATIVE_LOST_AFTER_COASTS || t.age_scans > TENTATIVE_MAX_AGE_SCANS {
                return None;
            }
            // Every plot since it started (never two misses in a row: at least
            // CONFIRM_M in the history's KEEP_N bits once it is 2·CONFIRM_M − 1 scans old).
            let hits = t.hits_in_last(u32::from(t.age_scans).min(KEEP_N));
            let plausible = || {
                let [vx, vy] = t.filter.estimate().velocity_mps;
                let limit = CONFIRM_SPEED_FACTOR * max_speed_mps;
                // `<=` with NaN is false: no confirmation on a speed that is not a number.
                vx * vx + vy * vy <= limit * limit
            };
            if hits >= CONFIRM_M && t.score >= CONFIRM_SCORE && plausible() {
                TrackStatus::Confirmed
            } else {
                TrackStatus::Tentative
            }
        }
        TrackStatus::Confirmed | TrackStatus::Coasting => {
            if t.coasts >= LOST_AFTER_COASTS || t.scans_since_plot() >= HIDDEN_LOST_AFTER_COASTS {
                TrackStatus::Lost
            } else if t.hit_last_scan() {
                TrackStatus::Confirmed
            } else {
                TrackStatus::Coasting
            }
        }
        TrackStatus::Lost => TrackStatus::Lost,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> TrackTable {
        let mut t = TrackTable::new();
        t.configure(TrackerConfig::DEFAULT).unwrap();
        t
    }

    /// One scan, each track in table order taking the nearest gated plot no track before it
    /// took; the plots in no gate start tracks (every plot no track took, with
    /// `every_leftover`, as the host's two-stage association does).
    fn scan_with(
        t: &mut TrackTable,
        time_ms: u64,
        plots: &[EastNorth],
        every_leftover: bool,
    ) -> ApplyReport {
        t.predict(time_ms);
        t.gate(plots, 2.5);
        let mut taken = std::vec::Vec::new();
        let assignments: std::vec::Vec<Assignment> = (0..t.len())
            .map(|i| {
                let g = t.gated(i).unwrap();
                let plot = g.plots.iter().copied().find(|p| !taken.contains(p));
                taken.extend(plot);
                Assignment {
                    track: g.track,
                    plot,
                }
            })
            .collect();
        let starts: std::vec::Vec<u16> = (0..plots.len() as u16)
            .filter(|p| match every_leftover {
                true => !taken.contains(p),
                false => !(0..t.len()).any(|i| t.gated(i).unwrap().plots.contains(p)),
            })
            .collect();
        t.apply(time_ms, plots, &assignments, &starts).unwrap()
    }

    /// One scan of a single target at `z` (or none): plots in no gate start tracks.
    fn scan(t: &mut TrackTable, time_ms: u64, plots: &[EastNorth]) -> ApplyReport {
        scan_with(t, time_ms, plots, false)
    }

    #[test]
    fn a_target_is_confirmed_on_its_third_plot_and_lost_after_6_misses_in_a_row() {
        let mut t = table();
        let at = |k: u64| [1000.0 + 5.0 * 2.5 * k as f32, -300.0];
        for k in 0..3 {
            scan(&mut t, k * 2500, &[at(k)]);
        }
        assert_eq!(t.len(), 1);
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Confirmed);
        // Hits and misses alternating keep it (half its scans missed); then misses: coasting
        // until the sixth in a row.
        for k in 3..13 {
            let plots = if k % 2 == 0 { vec![at(k)] } else { vec![] };
            scan(&mut t, k * 2500, &plots);
            assert_ne!(t.track(0).unwrap().status, TrackStatus::Lost, "scan {k}");
        }
        scan(&mut t, 13 * 2500, &[at(13)]);
        for k in 14..19 {
            scan(&mut t, k * 2500, &[]);
            assert_eq!(
                t.track(0).unwrap().status,
                TrackStatus::Coasting,
                "scan {k}"
            );
        }
        scan(&mut t, 19 * 2500, &[]);
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Lost);
        scan(&mut t, 20 * 2500, &[]);
        assert!(t.is_empty());
    }

    /// One scan in which the host says `track`'s target is hidden in another's plot.
    fn hidden_scan(t: &mut TrackTable, time_ms: u64, track: u16) {
        t.predict(time_ms);
        t.gate(&[], 2.5);
        let hidden = [Assignment {
            track,
            plot: Some(HIDDEN_PLOT),
        }];
        t.apply(time_ms, &[], &hidden, &[]).unwrap();
    }

    #[test]
    fn a_hidden_target_coasts_longer_but_not_for_ever() {
        let at = |k: u64| [1000.0 + 5.0 * 2.5 * k as f32, -300.0];
        let status = |t: &TrackTable| t.track(0).unwrap().status;
        let mut t = table();
        for k in 0..3 {
            scan(&mut t, k * 2500, &[at(k)]);
        }
        let id = t.track(0).unwrap().id;
        // Hidden scans do not count towards the loss after 6 misses...
        let mut k = 3;
        for _ in 0..LOST_AFTER_COASTS + 4 {
            hidden_scan(&mut t, k * 2500, id);
            k += 1;
            assert_eq!(status(&t), TrackStatus::Coasting, "scan {k}");
        }
        // ... a plot of its own ends the coast ...
        scan(&mut t, k * 2500, &[at(k)]);
        k += 1;
        assert_eq!(status(&t), TrackStatus::Confirmed);
        // ... after misses of its own up to HIDDEN_AFTER_MISSES, hidden scans still do not
        // count ...
        let miss = |t: &mut TrackTable, k: &mut u64, hidden: bool| {
            if hidden {
                hidden_scan(t, *k * 2500, id);
            } else {
                scan(t, *k * 2500, &[]);
            }
            *k += 1;
        };
        for _ in 0..HIDDEN_AFTER_MISSES {
            miss(&mut t, &mut k, false);
        }
        for _ in 0..5 {
            miss(&mut t, &mut k, true);
        }
        assert_eq!(t.track(0).unwrap().coasts, HIDDEN_AFTER_MISSES);
        // ... but after one more miss they do: a track losing its target is dying, not
        // hidden; the sixth scan counted loses it.
        miss(&mut t, &mut k, false);
        for _ in HIDDEN_AFTER_MISSES + 1..LOST_AFTER_COASTS - 1 {
            miss(&mut t, &mut k, true);
            assert_eq!(status(&t), TrackStatus::Coasting, "scan {k}");
        }
        miss(&mut t, &mut k, true);
        assert_eq!(status(&t), TrackStatus::Lost);
        // Hidden in a row: lost after HIDDEN_LOST_AFTER_COASTS scans without a plot.
        let mut t = table();
        for k in 0..3 {
            scan(&mut t, k * 2500, &[at(k)]);
        }
        let id = t.track(0).unwrap().id;
        for k in 3..3 + u64::from(HIDDEN_LOST_AFTER_COASTS) {
            assert_ne!(status(&t), TrackStatus::Lost, "scan {k}");
            hidden_scan(&mut t, k * 2500, id);
        }
        assert_eq!(status(&t), TrackStatus::Lost);
        // A tentative track is not helped: two misses, hidden or not, drop it.
        let mut t = table();
        scan(&mut t, 0, &[at(0)]);
        let id = t.track(0).unwrap().id;
        hidden_scan(&mut t, 2500, id);
        hidden_scan(&mut t, 5000, id);
        assert!(t.is_empty());
    }

    #[test]
    fn a_g_h_tracks_gate_grows_with_the_scans_since_its_plot_hidden_or_not() {
        // A g-h filter knows no innovation covariance: its gate is twice the plot variance
        // grown with the square of the scans since its last plot (hit history), whether
        // those scans were misses or hidden.
        use crate::filter::alpha_beta::AlphaBetaGains;
        let ab = AlphaBetaGains::Fixed {
            alpha: 0.5,
            beta: 0.25 / 1.5,
        };
        let mut t = TrackTable::new();
        t.configure(TrackerConfig {
            filter: FilterConfig::AlphaBeta(ab),
            ..TrackerConfig::DEFAULT
        })
        .unwrap();
        let at = |k: u64| [1000.0 + 5.0 * 2.5 * k as f32, -300.0];
        for k in 0..3 {
            scan(&mut t, k * 2500, &[at(k)]);
        }
        let id = t.track(0).unwrap().id;
        let var = 2.0 * TrackerConfig::DEFAULT.plot_sigma_m * TrackerConfig::DEFAULT.plot_sigma_m;
        let gate_after = |t: &mut TrackTable, k: u64| {
            t.predict(k * 2500);
            t.gate(&[], 2.5);
            t.gated(0).unwrap().innovation_cov_m2[0]
        };
        assert_eq!(gate_after(&mut t, 3), var);
        t.apply(3 * 2500, &[], &[], &[]).unwrap();
        assert_eq!(gate_after(&mut t, 4), var * 4.0, "one miss");
        let hidden = [Assignment {
            track: id,
            plot: Some(HIDDEN_PLOT),
        }];
        t.apply(4 * 2500, &[], &hidden, &[]).unwrap();
        assert_eq!(gate_after(&mut t, 5), var * 9.0, "a miss, then hidden");
    }

    #[test]
    fn a_hidden_plot_for_no_track_is_refused_and_the_first_assignment_counts() {
        let at = |k: u64| [1000.0 + 5.0 * 2.5 * k as f32, -300.0];
        let mut t = table();
        for k in 0..3 {
            scan(&mut t, k * 2500, &[at(k)]);
        }
        let id = t.track(0).unwrap().id;
        t.predict(3 * 2500);
        let plots = [at(3)];
        t.gate(&plots, 2.5);
        let before = t.clone();
        let unknown = [Assignment {
            track: id + 1,
            plot: Some(HIDDEN_PLOT),
        }];
        assert_eq!(
            t.apply(3 * 2500, &plots, &unknown, &[]),
            Err(ErrorCode::InvalidValue)
        );
        assert!(
            t.tracks().eq(before.tracks()),
            "refused whole, before any change"
        );
        // Named twice, hidden first: hidden; the plot named second is not taken.
        let twice = [
            Assignment {
                track: id,
                plot: Some(HIDDEN_PLOT),
            },
            Assignment {
                track: id,
                plot: Some(0),
            },
        ];
        t.apply(3 * 2500, &plots, &twice, &[]).unwrap();
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Coasting);
        assert_eq!(t.track(0).unwrap().coasts, 0, "a hidden scan is not a miss");
    }

    #[test]
    fn assignments_in_any_order_reach_their_tracks() {
        // Three tracks; the scan's assignments listed backwards, one track named twice
        // (its first assignment counts) and one not named (it coasts).
        let starts = [[0.0, 0.0], [3000.0, 0.0], [6000.0, 0.0]];
        let mut t = table();
        scan(&mut t, 0, &starts);
        let ids: std::vec::Vec<u16> = t.tracks().map(|x| x.id).collect();
        t.predict(2500);
        let plots = [[10.0, 0.0], [3010.0, 0.0], [6010.0, 0.0]];
        t.gate(&plots, 2.5);
        let assignments = [
            Assignment {
                track: ids[2],
                plot: Some(2),
            },
            Assignment {
                track: ids[0],
                plot: None,
            },
            Assignment {
                track: ids[0],
                plot: Some(0),
            },
        ];
        let r = t.apply(2500, &plots, &assignments, &[]).unwrap();
        assert_eq!((r.updated, r.coasted), (1, 2));
        let hit = |i: usize| t.track(i).unwrap().hits & 1 == 1;
        assert_eq!([hit(0), hit(1), hit(2)], [false, false, true]);
    }

    #[test]
    fn freed_slots_are_reused_and_the_order_is_the_order_tracks_started_in() {
        // Against a packed list of ids: drops (tentative failures, cancels) and starts in
        // any mix keep the table's order the order of starting, and the slots bounded.
        let mut t = table();
        let mut model: std::vec::Vec<u16> = std::vec::Vec::new();
        let mut noise = crate::filter::testing::Noise::new(11);
        for k in 0..200u64 {
            // Clutter only: each plot starts a track that dies after two misses.
            let n = (noise.gauss(1.0).abs() * 20.0) as usize % 40;
            let plots: std::vec::Vec<EastNorth> = (0..n)
                .map(|i| {
                    [
                        (k * 977 % 50_000) as f32 + 3_000.0 * i as f32,
                        -(k as f32) * 150.0,
                    ]
                })
                .collect();
            t.predict(k * 2500);
            t.gate(&plots, 2.5);
            let before: std::vec::Vec<u16> = t.tracks().map(|x| x.id).collect();
            assert_eq!(before, model, "scan {k}");
            let fresh: std::vec::Vec<u16> = (0..plots.len() as u16).collect();
            let r = t.apply(k * 2500, &plots, &[], &fresh).unwrap();
            // Every track coasted: the tentative ones with two misses went.
            let survivors: std::vec::Vec<u16> = t.tracks().map(|x| x.id).collect();
            model.retain(|id| survivors.contains(id));
            assert!(
                survivors.starts_with(&model),
                "scan {k}: old tracks first, in order"
            );
            let started = survivors.len() - model.len();
            assert_eq!(started, usize::from(r.initiated));
            model.extend_from_slice(&survivors[model.len()..]);
            assert!(model.windows(2).all(|w| w[0] < w[1]), "numbers increase");
            if k % 17 == 5 && !model.is_empty() {
                let id = model.remove(model.len() / 2);
                t.cancel(id).unwrap();
                assert_eq!(t.cancel(id), Err(ErrorCode::InvalidValue));
            }
            assert!(t.slots.len() <= MAX_TRACKS);
            assert_eq!(t.free.len() as usize + t.len(), t.slots.len());
        }
        t.cancel_all();
        assert!(t.is_empty());
        assert_eq!(t.free.len() as usize, t.slots.len());
    }

    #[test]
    fn track_numbers_wrap_past_the_largest_skipping_live_ones() {
        let mut t = table();
        let z = |e: f32| Measurement::new([e, 0.0]).unwrap();
        let keep = t.start_track(0, z(0.0)).unwrap();
        assert_eq!(keep, 1);
        t.next_id = u16::MAX;
        assert_eq!(t.start_track(0, z(1.0)).unwrap(), u16::MAX);
        // 0 is skipped, and 1 is live: the next number is 2.
        assert_eq!(t.start_track(0, z(2.0)).unwrap(), 2);
        let ids: std::vec::Vec<u16> = t.tracks().map(|x| x.id).collect();
        assert_eq!(ids, [1, u16::MAX, 2]);
    }

    #[test]
    fn a_clutter_plot_makes_a_tentative_track_that_dies() {
        let mut t = table();
        scan(&mut t, 0, &[[5000.0, 5000.0]]);
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Tentative);
        scan(&mut t, 2500, &[]);
        assert_eq!(t.len(), 1, "one miss: kept");
        scan(&mut t, 5000, &[]);
        assert!(t.is_empty(), "two misses in a row: dropped");
    }

    #[test]
    fn a_tentative_track_is_confirmed_on_its_third_plot_unless_it_misses_twice_in_a_row() {
        let at = |k: u64| [2000.0 + 4.0 * 2.5 * k as f32, 700.0];
        // Hit, miss, hit, miss, hit: confirmed on the fifth scan, tentative before.
        let mut t = table();
        for k in 0..5u64 {
            let plots = if k % 2 == 0 { vec![at(k)] } else { vec![] };
            scan(&mut t, k * 2500, &plots);
            let want = if k == 4 {
                TrackStatus::Confirmed
            } else {
                TrackStatus::Tentative
            };
            assert_eq!(t.track(0).unwrap().status, want, "scan {k}");
        }
        // Hit, hit, miss, miss: dropped with two plots.
        let mut t = table();
        scan(&mut t, 0, &[at(0)]);
        scan(&mut t, 2500, &[at(1)]);
        scan(&mut t, 5000, &[]);
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Tentative);
        scan(&mut t, 7500, &[]);
        assert!(t.is_empty());
    }

    /// A table for a harbour radar's plots (σ 2 m).
    fn harbour_table() -> TrackTable {
        let mut t = TrackTable::new();
        t.configure(TrackerConfig {
            filter: FilterConfig::tracking(FilterKind::KalmanCv, 2.0, 20.0),
            plot_sigma_m: 2.0,
            ..TrackerConfig::DEFAULT
        })
        .unwrap();
        t
    }

    /// One scan as the host's two-stage association leaves it: every plot no track took
    /// starts a track.
    fn scan_starting_leftovers(t: &mut TrackTable, time_ms: u64, plots: &[EastNorth]) {
        scan_with(t, time_ms, plots, true);
    }

    /// Seven echoes 10 to 25 m from the origin, somewhere else on each scan `k`.
    fn echoes_around(k: u64) -> std::vec::Vec<EastNorth> {
        (0..7u64)
            .map(|i| {
                let a = i as f32 * 0.9 + k as f32 * 2.3;
                let r = 10.0 + 15.0 * ((i * 7 + k * 3) % 5) as f32 / 4.0;
                [r * libm::cosf(a), r * libm::sinf(a)]
            })
            .collect()
    }

    #[test]
    fn a_plots_score_is_the_targets_density_over_the_extraneous_one() {
        // S = 4 I (|S| = 16), d² = 2, λ = 10⁻³ m⁻²: ln(0.9 / (2π · 4 · 10⁻³)) − 1.
        let dx = 2.0 * core::f32::consts::SQRT_2;
        let score = plot_score([10.0, 20.0], [4.0, 0.0, 4.0], [10.0 + dx, 20.0], 1e-3);
        assert!((score - 2.578_3).abs() < 1e-3, "{score}");
        // Nearer is more; a denser picture is less.
        assert!(plot_score([0.0; 2], [4.0, 0.0, 4.0], [0.0; 2], 1e-3) > score);
        assert!(plot_score([10.0, 20.0], [4.0, 0.0, 4.0], [10.0 + dx, 20.0], 1e-2) < score);
        // A covariance that is not positive definite, or NaN, adds nothing.
        assert_eq!(plot_score([0.0; 2], [4.0, 4.0, 4.0], [1.0, 0.0], 1e-3), 0.0);
        assert_eq!(
            plot_score([0.0; 2], [f32::NAN, 0.0, 4.0], [1.0, 0.0], 1e-3),
            0.0
        );
    }

    #[test]
    fn a_miss_scores_the_chance_of_no_plot() {
        let ln = libm::logf(1.0 - SCORE_DETECTION_PROBABILITY);
        assert!((SCORE_MISS - ln).abs() < 1e-6, "{ln}");
        assert!((CONFIRM_SCORE - libm::logf(9.0)).abs() < 1e-6);
    }

    #[test]
    fn among_dense_plots_three_plots_do_not_confirm_a_track() {
        let mut t = harbour_table();
        scan_starting_leftovers(&mut t, 0, &[[0.0, 0.0]]);
        let mut confirmed_at = None;
        for k in 1..12u64 {
            let mut plots = vec![[0.0, 0.0]];
            plots.extend(echoes_around(k));
            scan_starting_leftovers(&mut t, k * 2500, &plots);
            let track = t.tracks().find(|t| t.id == 1).unwrap();
            if k == 2 {
                assert_eq!(track.status, TrackStatus::Tentative, "three plots");
                assert!(track.score() < CONFIRM_SCORE, "{}", track.score());
            }
            if track.status == TrackStatus::Confirmed && confirmed_at.is_none() {
                confirmed_at = Some(k);
            }
        }
        // Its plots fall where its tight gate says, scan after scan: confirmed in the end.
        let k = confirmed_at.expect("confirmed within 12 scans");
        assert!((4..12).contains(&k), "confirmed on plot {}", k + 1);
        // In open water the same target is confirmed on its third plot.
        let mut t = harbour_table();
        for k in 0..3u64 {
            scan_starting_leftovers(&mut t, k * 2500, &[[0.0, 0.0]]);
        }
        assert_eq!(t.track(0).unwrap().status, TrackStatus::Confirmed);
    }

    #[test]
    fn a_tentative_track_that_never_scores_is_dropped_in_time() {
        // A plot every scan, but 30 m one side of the last and then the other, among seven
        // echoes: never a miss, never a score.
        let mut t = harbour_table();
        scan_starting_leftovers(&mut t, 0, &[[0.0, 0.0]]);
        for k in 1..=u64::from(TENTATIVE_MAX_AGE_SCANS) {
            let mut plots = vec![[if k % 2 == 0 { 0.0 } else { 30.0 }, 0.0]];
            plots.extend(echoes_around(k).iter().map(|p| [p[0] + 15.0, p[1]]));
            t.predict(k * 2500);
            t.gate(&plots, 2.5);
            let assign = [Assignment {
                track: 1,
                plot: Some(0),
            }];
            t.apply(k * 2500, &plots, &assign, &[]).unwrap();
            let first = t.tracks().find(|t| t.id == 1);
            if k < u64::from(TENTATIVE_MAX_AGE_SCANS) {
                let first = first.expect("alive");
                assert_eq!(first.status, TrackStatus::Tentative);
                assert!(first.hit_last_scan());
            } else {
                assert!(first.is_none(), "dropped at {} scans old", k + 1);
            }
        }
    }

    #[test]
    fn plots_firm_tracks_take_are_not_extraneous() {
        // Seven moored boats, each confirmed in time however near the others...
        let boats = echoes_around(0);
        let mut t = harbour_table();
        for k in 0..12u64 {
            scan_starting_leftovers(&mut t, k * 2500, &boats);
        }
        assert_eq!(t.len(), 7);
        assert!(t.tracks().all(|t| t.status == TrackStatus::Confirmed));
        // ... and a boat that comes among them is confirmed on its third plot: their plots
        // are theirs, not extraneous to its track.
        let mut plots = boats.clone();
        plots.push([0.0, 0.0]);
        for k in 12..15u64 {
            scan_starting_leftovers(&mut t, k * 2500, &plots);
        }
        let new = t.track(7).unwrap();
        assert_eq!(new.status, TrackStatus::Confirmed, "score {}", new.score());
    }

    #[test]
    fn gates_keep_the_nearest_plots_and_bad_assignments_change_nothing() {
        let mut t = table();
        scan(&mut t, 0, &[[0.0, 0.0]]);
        t.predict(2500);
        let plots: std::vec::Vec<EastNorth> = (0..20).map(|i| [i as f32 * 10.0, 0.0]).collect();
        t.gate(&plots, 2.5);
        let g = t.gated(0).unwrap();
        assert_eq!(g.plots.as_slice(), &[0, 1, 2, 3, 4, 5, 6, 7]);
        let before: std::vec::Vec<Track> = t.tracks().cloned().collect();
        let bad = [Assignment {
            track: 999,
            plot: Some(0),
        }];
        assert_eq!(
            t.apply(2500, &plots, &bad, &[]),
            Err(ErrorCode::InvalidValue)
        );
        let bad = [Assignment {
            track: g.track,
            plot: Some(20),
        }];
        assert_eq!(
            t.apply(2500, &plots, &bad, &[]),
            Err(ErrorCode::InvalidValue)
        );
        assert_eq!(
            t.apply(2500, &plots, &[], &[99]),
            Err(ErrorCode::InvalidValue)
        );
        assert_eq!(t.tracks().cloned().collect::<std::vec::Vec<_>>(), before);
    }

    #[test]
    fn the_table_refuses_past_capacity_and_warns_before() {
        let mut t = table();
        for i in 0..MAX_TRACKS {
            assert!(!t.is_empty() || i == 0);
            t.start_track(0, Measurement::new([i as f32 * 1000.0, 0.0]).unwrap())
                .unwrap();
        }
        assert!(t.nearly_full());
        assert_eq!(
            t.start_track(0, Measurement::new([0.0, 0.0]).unwrap()),
            Err(ErrorCode::CapacityExceeded)
        );
        t.cancel_all();
        assert!(t.is_empty());
    }

    #[test]
    fn slots_past_the_first_32_are_freed_and_reused() {
        // The free slots and the places dropped are sets of 32-bit words: a track in the
        // last word goes and its slot takes the next track, as one in the first does.
        let mut t = table();
        let mut ids = std::vec::Vec::new();
        for i in 0..MAX_TRACKS {
            ids.push(
                t.start_track(0, Measurement::new([i as f32 * 1000.0, 0.0]).unwrap())
                    .unwrap(),
            );
        }
        let (first, last) = (ids[0], ids[MAX_TRACKS - 1]);
        t.cancel(last).unwrap();
        t.cancel(first).unwrap();
        assert_eq!(t.len(), MAX_TRACKS - 2);
        assert_eq!(t.free.len(), 2);
        assert!(t.free.contains(0) && t.free.contains(MAX_TRACKS - 1));
        // The lowest free slot first; the order is the order tracks started in.
        let a = t
            .start_track(0, Measurement::new([0.0, 500.0]).unwrap())
            .unwrap();
        let b = t
            .start_track(0, Measurement::new([0.0, 900.0]).unwrap())
            .unwrap();
        assert_eq!(t.order.first(), Some(&1));
        assert_eq!(
            t.order[MAX_TRACKS - 2..],
            [0, u8::try_from(MAX_TRACKS - 1).unwrap()]
        );
        let numbers: std::vec::Vec<u16> = t.tracks().map(|k| k.id).collect();
        assert_eq!(numbers[MAX_TRACKS - 2..], [a, b]);
        assert!(t.free.is_empty());
        assert_eq!(
            t.start_track(0, Measurement::new([0.0, 0.0]).unwrap()),
            Err(ErrorCode::CapacityExceeded)
        );
    }

    #[test]
    fn every_filter_tracks() {
        for filter in FilterKind::ALL.map(|k| FilterConfig::tracking(k, 30.0, 20.0)) {
            let mut t = TrackTable::new();
            t.configure(TrackerConfig {
                filter,
                ..TrackerConfig::DEFAULT
            })
            .unwrap();
            for k in 0..20u64 {
                scan(&mut t, k * 2500, &[[100.0 + 8.0 * 2.5 * k as f32, 50.0]]);
            }
            assert_eq!(t.len(), 1, "{filter:?}");
            let s = t.track(0).unwrap().state();
            assert_eq!(s.status, TrackStatus::Confirmed, "{filter:?}");
            assert!((s.velocity_mps[0] - 8.0).abs() < 0.5, "{filter:?}: {s:?}");
        }
        let mut t = TrackTable::new();
        let bad = TrackerConfig {
            filter: FilterConfig::Sswt(crate::filter::sswt::SswtConfig {
                window: 1,
                start: crate::filter::alpha_beta::AlphaBetaGains::BenedictBordner { alpha: 0.5 },
            }),
            ..TrackerConfig::DEFAULT
        };
        assert_eq!(t.configure(bad), Err(ErrorCode::InvalidValue));
        let bad = TrackerConfig {
            gate_sigmas: f32::NAN,
            ..TrackerConfig::DEFAULT
        };
        assert_eq!(t.configure(bad), Err(ErrorCode::InvalidValue));
    }

    /// The table's fixed-scan g-h tracks against the general filter driven as the table
    /// drove every filter before (predict each track when a scan's plots come, update it
    /// when its plot is assigned): same predictions and estimates, bit for bit, through
    /// repeated and changed intervals, coasts, a scan whose assignments never came, a track
    /// acquired inside a scan and one between scans at another time, and a gap of over a day
    /// (where nothing can be predicted and the tracks are updated in place).
    fn fixed_scan_tracks_match_the_general_filter<const N: usize>(
        config: FilterConfig,
        general: impl Fn() -> crate::filter::gh::GhFilter<f32, N>,
    ) {
        use std::collections::BTreeMap;
        let mut t = TrackTable::new();
        t.configure(TrackerConfig {
            filter: config,
            ..TrackerConfig::DEFAULT
        })
        .unwrap();
        let mut shadow: BTreeMap<u16, crate::filter::gh::GhFilter<f32, N>> = BTreeMap::new();
        let mut noise = crate::filter::testing::Noise::new(5);
        let bits = |v: EastNorth| v.map(f32::to_bits);
        let mut time_ms = 0u64;
        let (mut skipped, mut in_place, mut updated_in_place) = (0, 0, 0);
        for k in 0..120u64 {
            time_ms += match k {
                40 => 2_400,
                41 | 42 => 3_100,
                90 => 86_400_001 + 2_500,
                _ => 2_500,
            };
            let ts = time_ms as f32 / 1000.0;
            // Three targets; the third seen on two scans in three; clutter now and then.
            let mut plots: std::vec::Vec<EastNorth> = (0..3)
                .filter(|&i| i < 2 || k % 3 != 0)
                .map(|i| {
                    let i = i as f32;
                    let e = 1000.0 + 4_000.0 * i + (3.0 + i) * ts + noise.gauss(20.0) as f32;
                    let turn = 400.0 * (ts / 90.0).sin();
                    let n = -2_000.0 * i - 5.0 * ts + turn + noise.gauss(20.0) as f32;
                    [e, n]
                })
                .collect();
            if k % 7 == 3 {
                plots.push([20_000.0 + 37.0 * k as f32, -15_000.0]);
            }
            // The shadow first, from the tracks' own times, as the table predicted before.
            let ids: std::vec::Vec<u16> = t.tracks().map(|tr| tr.id).collect();
            for tr in t.tracks() {
                let dt_s = time_ms.saturating_sub(tr.time_ms) as f32 / 1000.0;
                if let (Ok(dt), Some(g)) = (Interval::new(dt_s), shadow.get_mut(&tr.id)) {
                    g.predict(dt);
                }
            }
            let held_before = t.ahead;
            t.predict(time_ms);
            if held_before.is_some() && t.ahead == held_before {
                skipped += 1;
            }
            if !t.all_predicted {
                in_place += 1;
            }
            // A track the table could not predict keeps a prediction of its own (see
            // `TrackTable::predict`); every predicted one has the general filter's.
            for tr in t.tracks().filter(|tr| tr.time_ms == time_ms) {
                let g = &shadow[&tr.id];
                assert_eq!(
                    bits(tr.filter.prediction()),
                    bits(g.prediction()),
                    "scan {k}"
                );
            }
            if k == 60 {
                // Assignments that never come: the next scan's predict closes this one.
                continue;
            }
            t.gate(&plots, 2.5);
            let mut used = std::vec::Vec::new();
            let assignments: std::vec::Vec<Assignment> = (0..t.len())
                .map(|i| {
                    let g = t.gated(i).unwrap();
                    let plot = match k {
                        // After the gap no gate holds a plot: the host assigns them anyway.
                        90 => (i < plots.len()).then_some(i as u16),
                        _ => g.plots.iter().copied().find(|p| !used.contains(p)),
                    };
                    used.extend(plot);
                    Assignment {
                        track: g.track,
                        plot,
                    }
                })
                .collect();
            if k == 75 {
                // An operator's acquisition inside the scan: its track coasts when it closes.
                let id = t
                    .start_track(time_ms, Measurement::new([-7_000.0, 3_000.0]).unwrap())
                    .unwrap();
                let mut g = general();
                g.start(Measurement::new([-7_000.0, 3_000.0]).unwrap());
                shadow.insert(id, g);
            }
            let fresh: std::vec::Vec<u16> = (0..plots.len() as u16)
                .filter(|p| !used.contains(p) && (*p as usize) < 3)
                .collect();
            let report = t.apply(time_ms, &plots, &assignments, &fresh).unwrap();
            if !t.all_predicted {
                updated_in_place += report.updated;
            }
            for a in &assignments {
                if let (Some(p), Some(g)) = (a.plot, shadow.get_mut(&a.track)) {
                    g.update(Measurement::new(plots[usize::from(p)]).unwrap());
                }
            }
            for tr in t.tracks() {
                let g = shadow.entry(tr.id).or_insert_with(|| {
                    let mut g = general();
                    g.start(Measurement::new(tr.filter.estimate().position_m).unwrap());
                    g
                });
                let (e, eg) = (tr.filter.estimate(), g.estimate());
                assert_eq!(
                    bits(e.position_m),
                    bits(eg.position_m),
                    "scan {k} track {}",
                    tr.id
                );
                assert_eq!(
                    bits(e.velocity_mps),
                    bits(eg.velocity_mps),
                    "scan {k} track {}",
                    tr.id
                );
            }
            shadow.retain(|id, _| t.tracks().any(|tr| tr.id == *id) || !ids.contains(id));
            if k == 100 {
                // An acquisition between scans, at a time of its own.
                let z = Measurement::new([9_000.0, 9_000.0]).unwrap();
                let id = t.start_track(time_ms - 700, z).unwrap();
                let mut g = general();
                g.start(z);
                shadow.insert(id, g);
            }
        }
        assert!(t.tracks().filter(|tr| tr.filter.is_fixed_scan()).count() >= 3);
        // The held predictions were used on most scans, and the gap took the in-place path.
        assert!(skipped > 80, "{skipped}");
        assert!(
            in_place >= 1 && updated_in_place >= 2,
            "{in_place} {updated_in_place}"
        );
    }

    #[test]
    fn fixed_scan_tracks_are_the_general_filters_bit_for_bit() {
        use crate::filter::alpha_beta::AlphaBetaGains;
        use crate::filter::alpha_beta_gamma::AbgGains;
        use crate::filter::alpha_beta_gamma_eta::AbgeGains;
        let ab = AlphaBetaGains::Fixed {
            alpha: 0.5,
            beta: 0.25 / 1.5,
        };
        fixed_scan_tracks_match_the_general_filter(FilterConfig::AlphaBeta(ab), || {
            ab.build().unwrap()
        });
        let abg = AbgGains::FadingMemory { xi: 0.6 };
        fixed_scan_tracks_match_the_general_filter(FilterConfig::AlphaBetaGamma(abg), || {
            abg.build().unwrap()
        });
        let abge = AbgeGains::FadingMemory { xi: 0.7 };
        fixed_scan_tracks_match_the_general_filter(FilterConfig::AlphaBetaGammaEta(abge), || {
            abge.build().unwrap()
        });
        // A gain schedule stays with the general filter.
        let ls = TrackFilter::build(&FilterConfig::AlphaBeta(AlphaBetaGains::LeastSquares));
        assert!(matches!(ls, Ok(TrackFilter::AlphaBetaScheduled(_))));
    }

    #[test]
    fn a_scan_is_closed_only_once_it_is_open() {
        let mut t = table();
        assert_eq!(t.apply(0, &[], &[], &[]), Err(ErrorCode::OutOfSequence));
        t.predict(0);
        assert!(t.apply(0, &[], &[], &[]).is_ok());
        assert_eq!(t.apply(0, &[], &[], &[]), Err(ErrorCode::OutOfSequence));
    }

    #[test]
    fn bucketed_gates_match_a_scan_over_every_plot() {
        let mut t = table();
        let cfg = *t.config();
        // Tracks and plots on a coarse grid: many plots at equal distances, and repeats.
        for k in 0..30u16 {
            let z = [f32::from(k % 6) * 700.0 - 2000.0, f32::from(k / 6) * 500.0];
            t.start_track(0, Measurement::new(z).unwrap()).unwrap();
        }
        t.predict(2500);
        let plots: std::vec::Vec<EastNorth> = (0..250u32)
            .map(|i| {
                let e = ((i * 37) % 41) as f32 * 100.0 - 2100.0;
                [e, ((i * 11) % 29) as f32 * 100.0]
            })
            .collect();
        t.gate(&plots, 2.5);
        for i in 0..t.len() {
            let g = t.gated(i).unwrap();
            let s = g.innovation_cov_m2;
            let radius = (cfg.gate_sigmas * libm::sqrtf(s[0].max(s[2])))
                .max(cfg.min_gate_m)
                .min(cfg.max_gate_m);
            let p = g.predicted_m;
            let mut all: std::vec::Vec<(f32, u16)> = plots
                .iter()
                .enumerate()
                .map(|(j, z)| {
                    let (dx, dy) = (z[0] - p[0], z[1] - p[1]);
                    (dx * dx + dy * dy, j as u16)
                })
                .filter(|&(d2, _)| d2 <= radius * radius)
                .collect();
            all.sort_by(|a, b| a.partial_cmp(b).unwrap());
            let want: std::vec::Vec<u16> = all
                .iter()
                .take(MAX_PLOTS_PER_GATE)
                .map(|&(_, j)| j)
                .collect();
            assert!(!want.is_empty());
            assert_eq!(g.plots.as_slice(), want.as_slice(), "track {i}");
        }
    }
}
