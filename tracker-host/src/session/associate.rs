//! Refined gating, data association and the choice of plots that start tracks: the host's
//! half of the thesis's split (Stone Soup's hypothesiser, associator and the initiator's
//! choice).
//!
//! The device returns, per track, the few plots inside its rough gate. Here each pair is
//! tested against the **refined gate**: the Mahalanobis distance d² = νᵀS⁻¹ν of the
//! innovation ν with the track's innovation covariance S, kept when d² is below the
//! chi-square threshold (2 degrees of freedom). **Global nearest neighbour** then picks
//! the one-to-one assignment of plots to tracks that minimises the summed pair costs
//! d² + ln|S| (the Gaussian likelihood's; S with the plot's own range and bearing accuracy
//! when the source knows it, [`PlotCovariances`]), with "no plot" allowed for every track
//! at a cost above any pair in a refined gate, solved exactly by the Kuhn–Munkres
//! (Hungarian) algorithm from `pathfinding`.
//!
//! [`Association::TwoStage`] does this twice: the **firm** tracks (confirmed
//! and coasting) take their plots first, the tentative tracks then share what is left, so a
//! new track on a clutter plot never takes a plot from an established one; only a plot a
//! tentative track as settled as the firm one explains far better is left to it
//! ([`CEDE_MARGIN`], [`CEDE_WIDTH`]): two ships in company each keep their own. Every plot no
//! track took starts a new tentative track, as Stone Soup's initiator does: a ship that
//! comes out of a neighbour's echo (two ships in one resolution cell give one plot) is
//! acquired on its first plot of its own, however near the neighbour's track it still is.
//! A tentative track started on a firm track's own second echo cannot take that track's
//! plots (it associates second) and goes after two scans without one. Until the Stone Soup
//! comparison (docs/stonesoup.md) a plot inside a firm track's refined gate started
//! nothing, which kept such a ship untracked until it was clear of the neighbour's gate.
//! [`Association::Joint`] is the rule before that, kept for comparison: one stage over all
//! tracks, and only plots in no rough gate start tracks. [`Association::TwoStageUnresolved`]
//! (the default) is two-stage with one more rule, for two ships in one resolution cell:
//! the track left without a plot is held as hidden in its neighbour's, not dropped.
//!
//! A track whose target is found standing still is tested from where it stands (the mean of
//! its last minute's plots, [`super::stationary`]) for the plots in the refined gate about
//! that place, from the device's prediction for the others ([`StandingAt`]).

use std::collections::BTreeSet;

use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;
use tracker_core::geo::EastNorth;
use tracker_core::icd::{Assignment, GatedPlots, Plot, HIDDEN_PLOT};

/// Chi-square, 2 degrees of freedom, 99 %: a true plot falls outside 1 % of the time.
pub const CHI2_2DOF_99: f64 = 9.21;

/// Costs are integers for the assignment solver: d² in units of 1e-6.
const SCALE: f64 = 1e6;
/// A pairing that is not allowed.
const FORBIDDEN: i64 = i64::MAX / 1024;
/// Largest d² on a plot's own accuracy a pair cost takes: far beyond any gate, and far
/// below [`FORBIDDEN`] once scaled.
const MAX_OWN_D2: f64 = 1e6;

/// How plots are associated and tracks started.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Association {
    /// Firm tracks first (but for a plot a tentative track as settled holds far better:
    /// [`CEDE_MARGIN`]), tentative tracks from what is left; every plot no track took
    /// starts a track.
    TwoStage,
    /// One assignment over all tracks; only plots in no rough gate start tracks.
    Joint,
    /// As [`Association::TwoStage`], and a firm track left without a plot whose refined
    /// gate held a plot another firm track took is taken as **unresolved** from that track
    /// (two targets in one resolution cell give one plot): it coasts, and the scans so
    /// coasted do not count towards its loss ([`HIDDEN_PLOT`], up to
    /// [`tracker_core::track::HIDDEN_LOST_AFTER_COASTS`] scans). The default: it keeps
    /// both ships of a merge tracked (docs/tracking.md); the tracks so kept are not drawn
    /// while hidden ([`crate::session::ScanReport::in_echo`]), so that a ship is not shown
    /// beside its own AIS target (docs/ais.md).
    #[default]
    TwoStageUnresolved,
}

impl Association {
    /// The name `--association` takes (`two-stage`, `joint`, `two-stage-unresolved`).
    pub fn name(self) -> &'static str {
        match self {
            Self::TwoStage => "two-stage",
            Self::Joint => "joint",
            Self::TwoStageUnresolved => "two-stage-unresolved",
        }
    }
}

/// The host's decision for one scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Associated {
    /// Per gated track: the chosen plot, or `None` to coast.
    pub assignments: Vec<Assignment>,
    /// Plots that start new tentative tracks.
    pub initiate: Vec<u16>,
    /// Pairs that passed the rough gate but not the refined one.
    pub refined_out: usize,
    /// Plots no track took and not started either: inside a rough gate
    /// ([`Association::Joint`]; none with [`Association::TwoStage`]).
    pub withheld: usize,
    /// Firm tracks coasted with their target hidden in a plot another firm track took
    /// ([`HIDDEN_PLOT`]; [`Association::TwoStageUnresolved`] only).
    pub hidden: usize,
    /// Each such track, with the firm track that took the plot it is hidden in.
    pub hidden_in: Vec<(u16, u16)>,
}

/// A radar's plot accuracy in its own coordinates: how far a plot lies from its target
/// along the line of sight and across it. The simulator's sensor model knows it
/// ([`tracker_core::sim::SensorModel`]); a real radar's extracted plots are taken as
/// isotropic ([`crate::source::PlotSource::plot_accuracy`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolarAccuracy {
    /// Standard deviation of a plot's range, m.
    pub range_sigma_m: f32,
    /// Standard deviation of a plot's bearing, rad.
    pub bearing_sigma_rad: f32,
}

impl PolarAccuracy {
    /// The accuracy of the plots `sensor` makes (the simulator's IMO sensor model).
    pub fn of_sensor(sensor: &tracker_core::sim::SensorModel) -> Self {
        PolarAccuracy {
            range_sigma_m: sensor.range_sigma_m(),
            bearing_sigma_rad: sensor.bearing_sigma_rad(),
        }
    }
}

/// One scan's plots' covariances in the local frame, for the pair cost
/// ([`PolarAccuracy`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotCovariances {
    /// Per plot, in the scan's order, its covariance `[sxx, sxy, syy]`, m² (east, north).
    pub plot_cov_m2: Vec<[f32; 3]>,
    /// The variance the device's filters take every plot to have on each axis, m²
    /// ([`tracker_core::icd::TrackerConfig::plot_sigma_m`] squared, as
    /// [`tracker_core::filter::FilterConfig::tracking`] makes the filters): the part of a
    /// track's innovation covariance that is replaced by the plot's own. (Tracks started
    /// before a change of plot σ keep their filters' old one; a radar, whose σ changes with
    /// its range scale, gives no [`PolarAccuracy`].)
    pub filter_var_m2: f32,
}

impl PlotCovariances {
    /// The covariance of each of `plots` (range, bearing from own ship) measured to
    /// `accuracy`: σ_r² along the line of sight, (r σ_b)² across it.
    pub fn polar(plots: &[Plot], accuracy: PolarAccuracy, filter_var_m2: f32) -> Self {
        let plot_cov_m2 = plots
            .iter()
            .map(|p| {
                // Along the line of sight u = (sin b, cos b), across it w = (cos b, −sin b).
                let (u_e, u_n) = (p.bearing_rad.sin(), p.bearing_rad.cos());
                let along = accuracy.range_sigma_m * accuracy.range_sigma_m;
                let across = (p.range_m.max(0.0) * accuracy.bearing_sigma_rad).powi(2);
                [
                    along * u_e * u_e + across * u_n * u_n,
                    (along - across) * u_e * u_n,
                    along * u_n * u_n + across * u_e * u_e,
                ]
            })
            .collect();
        PlotCovariances {
            plot_cov_m2,
            filter_var_m2,
        }
    }

    /// A track's innovation covariance `s` with plot `p`'s own covariance in place of the
    /// filter's: `None` when the plot is unknown or the result not positive definite.
    fn innovation_cov_m2(&self, s: [f32; 3], p: u16) -> Option<[f32; 3]> {
        let c = self.plot_cov_m2.get(usize::from(p))?;
        let t = [
            s[0] - self.filter_var_m2 + c[0],
            s[1] + c[1],
            s[2] - self.filter_var_m2 + c[2],
        ];
        (t[0] > 0.0 && t[0] * t[2] - t[1] * t[1] > 0.0).then_some(t)
    }
}

/// Mahalanobis distance² of `z` from `predicted` under `s = [sxx, sxy, syy]`; `None` when S
/// is not positive definite.
pub fn mahalanobis2(z: EastNorth, predicted: EastNorth, s: [f32; 3]) -> Option<f64> {
    let (sxx, sxy, syy) = (f64::from(s[0]), f64::from(s[1]), f64::from(s[2]));
    let det = sxx * syy - sxy * sxy;
    if !(det > 0.0 && sxx > 0.0) {
        return None;
    }
    let dx = f64::from(z[0]) - f64::from(predicted[0]);
    let dy = f64::from(z[1]) - f64::from(predicted[1]);
    Some((syy * dx * dx - 2.0 * sxy * dx * dy + sxx * dy * dy) / det)
}

/// Where targets found standing still stand, by track number, m (east, north, local
/// frame): a plot within the refined gate about that place is tested from there, others
/// from the device's prediction ([`super::stationary`]).
pub type StandingAt = std::collections::BTreeMap<u16, EastNorth>;

/// Associates one scan. `plots` are the scan's plots in the local frame, in the order the
/// device received them; `threshold` is the refined gate (d²); `firm` tells whether a
/// track number is confirmed or coasting (as the device reported it at the scan before);
/// `standing` where the targets found standing still stand.
pub fn associate(
    mode: Association,
    gates: &[GatedPlots],
    plots: &[EastNorth],
    threshold: f64,
    firm: impl Fn(u16) -> bool,
    accuracy: Option<&PlotCovariances>,
    standing: &StandingAt,
) -> Associated {
    let mut out = Associated::default();
    let mut taken = BTreeSet::new();
    let mut assigned = Vec::with_capacity(gates.len());
    // Joint: one stage over every track; two-stage: firm tracks first, then the others,
    // the firm ones leaving to a tentative one the plots it holds far better ([`ceded`]).
    // Each gate's pair costs, worked out once for both.
    let costed: Vec<Costed> = gates
        .iter()
        .map(|gate| Costed {
            gate,
            costs: pair_costs(gate, plots, threshold, (accuracy, standing)),
        })
        .collect();
    let (stages, ceded): (Vec<Vec<&Costed>>, _) = match mode {
        Association::Joint => (vec![costed.iter().collect()], BTreeSet::new()),
        Association::TwoStage | Association::TwoStageUnresolved => {
            let (strong, weak): (Vec<_>, Vec<_>) = costed.iter().partition(|c| firm(c.gate.track));
            let ceded = ceded(&strong, &weak);
            (vec![strong, weak], ceded)
        }
    };
    for stage in &stages {
        gnn(
            stage,
            threshold,
            &ceded,
            &mut taken,
            &mut assigned,
            &mut out,
        );
    }
    // A plot a firm track left that no tentative track took after all (the assignment
    // gave that track another) goes back to the firm track rather than start a new one
    // (of several firm tracks that left it, the first by number).
    for (track, plot) in &ceded {
        let Some(slot) = assigned.iter_mut().find(|(t, p)| t == track && p.is_none()) else {
            continue;
        };
        if taken.insert(*plot) {
            slot.1 = Some(*plot);
        }
    }
    // Unresolved: a firm track left without a plot whose refined gate held a plot another
    // firm track took has its target taken as hidden in that plot (two ships in one
    // resolution cell give one plot), and the miss does not count towards its loss
    // ([`HIDDEN_PLOT`]): it coasts on at its own velocity to where its ship comes out,
    // instead of being dropped after six scans and the ship acquired anew.
    let firm_took: std::collections::BTreeMap<u16, u16> = assigned
        .iter()
        .filter(|(t, _)| firm(*t))
        .filter_map(|(t, p)| Some(((*p)?, *t)))
        .collect();
    let unresolved = mode == Association::TwoStageUnresolved;
    for (track, plot) in assigned.iter_mut().filter(|_| unresolved) {
        if plot.is_some() || !firm(*track) {
            continue;
        }
        let Some(g) = gates.iter().find(|g| g.track == *track) else {
            continue;
        };
        let in_gate = |p: u16| {
            plots
                .get(usize::from(p))
                .and_then(|z| {
                    // A still target is hidden only in an echo where it stands.
                    let c = standing.get(&g.track).copied().unwrap_or(g.predicted_m);
                    mahalanobis2(*z, c, g.innovation_cov_m2)
                })
                .is_some_and(|d2| d2 <= threshold)
        };
        if let Some(taker) = g
            .plots
            .iter()
            .filter(|&&p| in_gate(p))
            .find_map(|p| firm_took.get(p))
        {
            *plot = Some(HIDDEN_PLOT);
            out.hidden += 1;
            out.hidden_in.push((*track, *taker));
        }
    }
    // Assignments in the order of the gates, as the device listed them.
    out.assignments = gates
        .iter()
        .map(|g| Assignment {
            track: g.track,
            plot: assigned
                .iter()
                .find(|(t, _)| *t == g.track)
                .and_then(|(_, p)| *p),
        })
        .collect();
    let withheld =
        |i: u16| mode == Association::Joint && gates.iter().any(|g| g.plots.contains(&i));
    for i in (0..plots.len()).filter_map(|i| u16::try_from(i).ok()) {
        if taken.contains(&i) {
            continue;
        }
        if withheld(i) {
            out.withheld += 1;
        } else {
            out.initiate.push(i);
        }
    }
    out
}

/// How much cheaper (in the pair cost d² + ln|S|) a tentative track's pair with a plot must
/// be than every firm track's for the firm tracks to leave it to the tentative one in a
/// two-stage association ([`Association::TwoStage`]): a likelihood e³, 20 times, greater.
/// Chosen on `demo --scenario merging`, open sea and crossing, seeds 1–8, among 3, 6 and 10
/// (docs/tracking.md).
pub const CEDE_MARGIN: f64 = 6.0;

/// Firm tracks leave a plot to a tentative one ([`CEDE_MARGIN`]) only when their innovation
/// covariances are about as wide: the areas of their ellipses (√|S|) within this factor
/// of each other.
pub const CEDE_WIDTH: f64 = 1.25;

/// The pairs (firm track, plot) a firm track leaves to a tentative one in a two-stage
/// association: a plot that is the cheapest in its gate for the tentative track whose pair
/// with it is cheapest, where that pair is [`CEDE_MARGIN`] cheaper than every firm track's
/// pair with the plot and every such firm track's innovation covariance about as wide as
/// the tentative track's ([`CEDE_WIDTH`]); else no firm track leaves it (one that kept it
/// would take it, and the others would be held hidden in it). Costs are
/// [`pair_costs`]'s without the still target's penalty: a firm track casting off does not
/// leave its plot for the penalty alone. Firm tracks take their plots first so that a track
/// started on a clutter plot never takes an established one's; but a just-confirmed track
/// whose own plot was missed took, 196 m off its prediction (d² 8.4 in its young gate), the
/// plot a tentative track as old on the ship beside it held 26 m off, and the two tracks
/// swapped ships (`demo --scenario merging`, seed 2). A tentative track of a few plots, its
/// velocity barely known, has a far wider S and takes nothing (without the width rule such
/// tracks beside settled ones took their plots and became duplicates: open sea, seeds 1–3,
/// 5 more confirmed tracks; seeds 1–8, OSPA 0.8 m higher). Nor does a firm track widened by
/// its misses leave its plot (without the rule, a coasting track started with a wrong
/// velocity left its ship's plot to a new track and coasted on to its loss: crossing, seed
/// 6). Only the cheapest tentative pair is weighed: a runner-up as wide that also clears
/// the margin is not, which errs towards the firm track keeping its plot.
fn ceded(firm: &[&Costed], tentative: &[&Costed]) -> BTreeSet<(u16, u16)> {
    use std::collections::BTreeMap;
    let raw = |cost: Option<(f64, bool)>| cost.map(|(c, _)| c);
    // Per plot: the cheapest tentative pair's cost and that track's ln|S|, when the plot is
    // that track's cheapest too.
    let mut best: BTreeMap<u16, (f64, f64, bool)> = BTreeMap::new();
    for t in tentative {
        let width = ln_det(t.gate.innovation_cov_m2);
        let costs: Vec<(u16, f64)> = t
            .costs
            .iter()
            .filter_map(|&(p, c)| Some((p, raw(c)?)))
            .collect();
        let Some(&(own, _)) = costs.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
            continue;
        };
        for (p, c) in costs {
            let b = best.entry(p).or_insert((f64::INFINITY, width, false));
            if c < b.0 {
                *b = (c, width, p == own);
            }
        }
    }
    // Per plot: every firm track with it in its refined gate, its cost and ln|S|.
    let mut holders: BTreeMap<u16, Vec<(u16, f64, f64)>> = BTreeMap::new();
    for f in firm {
        let width = ln_det(f.gate.innovation_cov_m2);
        for &(p, c) in &f.costs {
            if let Some(c) = raw(c) {
                holders.entry(p).or_default().push((f.gate.track, c, width));
            }
        }
    }
    // |ln|S_t| − ln|S_f|| within 2 ln CEDE_WIDTH: the areas within the factor.
    let alike = 2.0 * CEDE_WIDTH.ln();
    let mut out = BTreeSet::new();
    for (p, firms) in holders {
        let Some(&(t, t_width, own)) = best.get(&p) else {
            continue;
        };
        let leaves = |&(_, c, width): &(u16, f64, f64)| {
            t + CEDE_MARGIN < c && (t_width - width).abs() <= alike
        };
        if own && firms.iter().all(leaves) {
            out.extend(firms.iter().map(|(track, _, _)| (*track, p)));
        }
    }
    out
}

/// Where a plot `z` is tested from for `g`'s track, and whether that is away from where
/// its target stands: where it stands, when it is found standing still and `z` lies in the
/// refined gate (`threshold`, d²) about that place; else the device's prediction (`true`
/// for a target found still: a ship casting off, whose plots leave that gate before the
/// stationary test finds it moving). A neighbour's echo tens of metres off is weighed from
/// where the target stands, not from where its filter's noisy velocity has carried the
/// prediction.
fn gate_centre(
    z: EastNorth,
    g: &GatedPlots,
    standing: &StandingAt,
    threshold: f64,
) -> (EastNorth, bool) {
    match standing.get(&g.track) {
        Some(&at) if mahalanobis2(z, at, g.innovation_cov_m2).is_some_and(|d2| d2 <= threshold) => {
            (at, false)
        }
        Some(_) => (g.predicted_m, true),
        None => (g.predicted_m, false),
    }
}

/// ln|S| of `s = [sxx, sxy, syy]` (m²), 0 when S is not positive definite (such a track
/// takes no plot anyway: [`mahalanobis2`] refuses it).
fn ln_det(s: [f32; 3]) -> f64 {
    let det = f64::from(s[0]) * f64::from(s[2]) - f64::from(s[1]) * f64::from(s[1]);
    if det > 0.0 {
        det.ln()
    } else {
        0.0
    }
}

/// A gate with its pair costs ([`pair_costs`]).
struct Costed<'a> {
    gate: &'a GatedPlots,
    costs: Vec<(u16, Option<(f64, bool)>)>,
}

/// Each plot of `g`'s rough gate known to this scan with its pair cost when it lies in the
/// refined gate (`threshold`, d²; `None` when not), and whether it lies away from where the
/// track's target stands still ([`gate_centre`]; the cost then wants the gate's
/// `threshold` added, which [`gnn`] does): the
/// generalised statistical distance d² + ln|S| (Blackman & Popoli, Design and Analysis of
/// Modern Tracking Systems, 1999, §6.3.2), the negative log-likelihood up to a constant.
/// With d² alone a coasting track's wide S makes a plot 100 m off look as near as a
/// settled track's plot 30 m off, and the coasting track takes the settled one's target.
/// When the plots' own accuracy is known ([`PlotCovariances`]), the likelihood is taken
/// with it in S in place of the filter's round 40 m: a radar measures bearing to 11–20 m
/// across the line of sight at 4–7 NM, and two ships passing 50–150 m abeam in one
/// resolution cell are then told apart by which side of the line of sight the plot lies
/// (docs/tracking.md). The refined gate stays on the filter's S, so a track that lags a
/// turn keeps its plots.
fn pair_costs(
    g: &GatedPlots,
    plots: &[EastNorth],
    threshold: f64,
    (accuracy, standing): (Option<&PlotCovariances>, &StandingAt),
) -> Vec<(u16, Option<(f64, bool)>)> {
    // d² and ln|S| on the plot's own accuracy, when known.
    let own_accuracy = |p: u16, c: EastNorth| -> Option<(f64, f64)> {
        let a = accuracy?;
        let z = plots.get(usize::from(p))?;
        let s = a.innovation_cov_m2(g.innovation_cov_m2, p)?;
        Some((mahalanobis2(*z, c, s)?, ln_det(s)))
    };
    let ln_det_g = ln_det(g.innovation_cov_m2);
    g.plots
        .iter()
        .filter_map(|&p| {
            let z = plots.get(usize::from(p))?;
            let (c, away) = gate_centre(*z, g, standing, threshold);
            let cost = mahalanobis2(*z, c, g.innovation_cov_m2)
                .filter(|d2| *d2 <= threshold)
                .map(|d2| {
                    let cost = match own_accuracy(p, c) {
                        // Bounded, so that a miss stays below a forbidden pair's cost.
                        Some((d2_own, ln_det_own)) => d2_own.min(MAX_OWN_D2) + ln_det_own,
                        None => d2 + ln_det_g,
                    };
                    (cost, away)
                });
            Some((p, cost))
        })
        .collect()
}

/// One GNN stage: assigns `gates`' tracks plots not yet `taken` (and marks those taken),
/// pushing (track, plot) for every gate; never a pair (track, plot) in `ceded`.
fn gnn(
    gates: &[&Costed],
    threshold: f64,
    ceded: &BTreeSet<(u16, u16)>,
    taken: &mut BTreeSet<u16>,
    assigned: &mut Vec<(u16, Option<u16>)>,
    out: &mut Associated,
) {
    if gates.is_empty() {
        return;
    }
    // Columns: every plot some track may take, then one "miss" column per track.
    let candidates: Vec<u16> = gates
        .iter()
        .flat_map(|c| c.gate.plots.iter().copied())
        .filter(|p| !taken.contains(p))
        .collect::<BTreeSet<u16>>()
        .into_iter()
        .collect();
    let n = gates.len();
    let m = candidates.len();
    // Pair costs as [`pair_costs`] gives them. A miss costs the same for every track, more
    // than any pair inside a refined gate, so a track with a plot in its gate and no rival
    // takes it.
    let widest = gates
        .iter()
        .map(|c| ln_det(c.gate.innovation_cov_m2))
        .fold(0.0, f64::max);
    let mut costs: Vec<Vec<(usize, f64)>> = Vec::with_capacity(n);
    for c in gates {
        let mut row = Vec::new();
        for &(p, cost) in &c.costs {
            let Ok(col) = candidates.binary_search(&p) else {
                continue;
            };
            match cost {
                Some(_) if ceded.contains(&(c.gate.track, p)) => {}
                // Away from where a still target stands, a plot costs as if it were at the
                // edge of the gate there at least: one inside is taken first, and the cost
                // does not fall at the gate's edge.
                Some((c, true)) => row.push((col, c + threshold)),
                Some((c, false)) => row.push((col, c)),
                None => out.refined_out += 1,
            }
        }
        costs.push(row);
    }
    let most = costs
        .iter()
        .flatten()
        .map(|(_, c)| *c)
        .fold(threshold + widest, f64::max);
    let miss_cost = if most > threshold + widest {
        (most * SCALE) as i64 + 1
    } else {
        ((threshold + widest) * SCALE) as i64
    };
    let mut rows = Vec::with_capacity(n);
    for (i, row_costs) in costs.iter().enumerate() {
        let mut row = vec![FORBIDDEN; m + n];
        for &(col, c) in row_costs {
            row[col] = (c * SCALE) as i64;
        }
        row[m + i] = miss_cost;
        rows.push(row);
    }
    let Ok(matrix) = Matrix::from_rows(rows) else {
        assigned.extend(gates.iter().map(|c| (c.gate.track, None)));
        return;
    };
    let (_, columns) = kuhn_munkres_min(&matrix);
    for (i, (c, col)) in gates.iter().zip(columns).enumerate() {
        // Never a pair the gate refused, whatever the costs came to.
        let plot = (col < m && matrix[(i, col)] < FORBIDDEN).then(|| candidates[col]);
        if let Some(p) = plot {
            taken.insert(p);
        }
        assigned.push((c.gate.track, plot));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The association with plots taken as the filters take them.
    fn associate_on_filter(
        mode: Association,
        gates: &[GatedPlots],
        plots: &[EastNorth],
        firm: impl Fn(u16) -> bool,
    ) -> Associated {
        associate(
            mode,
            gates,
            plots,
            CHI2_2DOF_99,
            firm,
            None,
            &StandingAt::new(),
        )
    }

    fn gate(track: u16, predicted: EastNorth, sigma: f32, plots: &[u16]) -> GatedPlots {
        GatedPlots {
            track,
            predicted_m: predicted,
            innovation_cov_m2: [sigma * sigma, 0.0, sigma * sigma],
            plots: plots.iter().copied().collect(),
        }
    }

    #[test]
    fn mahalanobis_uses_the_covariance() {
        let d = mahalanobis2([30.0, 0.0], [0.0, 0.0], [100.0, 0.0, 100.0]).unwrap();
        assert!((d - 9.0).abs() < 1e-12);
        // Correlated: along the long axis is closer.
        let s = [200.0, 190.0, 200.0];
        let along = mahalanobis2([10.0, 10.0], [0.0, 0.0], s).unwrap();
        let across = mahalanobis2([10.0, -10.0], [0.0, 0.0], s).unwrap();
        assert!(along < across);
        assert_eq!(mahalanobis2([0.0, 0.0], [0.0, 0.0], [0.0, 0.0, 1.0]), None);
    }

    #[test]
    fn global_beats_greedy_nearest_neighbour() {
        // Plot 0 is nearest to both tracks; greedy would give it to track 1 and leave track
        // 2 to coast. GNN gives plot 1 to track 1 and plot 0 to track 2: lower total cost.
        let plots = [[0.0, 0.0], [-25.0, 0.0], [5000.0, 5000.0]];
        let gates = [
            gate(1, [-10.0, 0.0], 10.0, &[0, 1]),
            gate(2, [12.0, 0.0], 10.0, &[0]),
        ];
        let a = associate_on_filter(Association::Joint, &gates, &plots, |_| true);
        assert_eq!(
            a.assignments,
            [
                Assignment {
                    track: 1,
                    plot: Some(1)
                },
                Assignment {
                    track: 2,
                    plot: Some(0)
                }
            ]
        );
        assert_eq!(a.initiate, [2]);
    }

    #[test]
    fn plots_outside_the_refined_gate_are_not_taken() {
        let plots = [[40.0, 0.0]];
        let gates = [gate(7, [0.0, 0.0], 10.0, &[0])];
        let a = associate_on_filter(Association::Joint, &gates, &plots, |_| true);
        assert_eq!(
            a.assignments,
            [Assignment {
                track: 7,
                plot: None
            }]
        );
        assert_eq!(a.refined_out, 1);
        assert!(a.initiate.is_empty(), "it was in a rough gate");
        // Two-stage: no track took it, so it starts one.
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, |_| true);
        assert_eq!(a.initiate, [0]);
        assert_eq!(a.withheld, 0);
    }

    #[test]
    fn every_plot_no_track_took_starts_a_track() {
        // Three plots in a confirmed track's rough gate: it takes the nearest; the second,
        // inside its refined gate, and the third, outside it, both start tracks (a ship
        // coming out of its neighbour's echo). Jointly, neither would: both are in a gate.
        let plots = [[5.0, 0.0], [-20.0, 0.0], [130.0, 0.0]];
        let gates = [gate(1, [0.0, 0.0], 20.0, &[0, 1, 2])];
        for firm in [true, false] {
            let a = associate_on_filter(Association::TwoStage, &gates, &plots, |_| firm);
            assert_eq!(a.assignments[0].plot, Some(0));
            assert_eq!(a.initiate, [1, 2]);
            assert_eq!(a.withheld, 0);
        }
        let a = associate_on_filter(Association::Joint, &gates, &plots, |_| true);
        assert!(a.initiate.is_empty());
        assert_eq!(a.withheld, 2);
    }

    #[test]
    fn firm_tracks_take_their_plots_before_tentative_ones() {
        // The tentative track 2 is nearer to plot 0 than the confirmed track 1 (d² 0.25
        // against 4, the same S), so jointly it takes the plot. Two-stage: the confirmed
        // track takes it first.
        let plots = [[20.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 10.0, &[0]),
            gate(2, [25.0, 0.0], 10.0, &[0]),
        ];
        let firm = |t: u16| t == 1;
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, firm);
        assert_eq!(a.assignments[0].plot, Some(0));
        assert_eq!(a.assignments[1].plot, None);
        let a = associate_on_filter(Association::Joint, &gates, &plots, firm);
        assert_eq!(
            a.assignments[0].plot, None,
            "jointly the tentative track wins"
        );
        assert_eq!(a.assignments[1].plot, Some(0));
    }

    #[test]
    fn a_firm_track_leaves_a_plot_a_tentative_track_as_settled_holds_far_better() {
        // Confirmed track 1 missed its own plot; the plot of the ship beside it lies at the
        // edge of its gate (d² 9.0), 10 m from tentative track 2's prediction (d² 0.04),
        // the two as wide (σ 50 m): the firm track leaves it and coasts, and the tentative
        // track keeps its ship (merging scenario, seed 2, where they swapped ships).
        let plots = [[150.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 50.0, &[0]),
            gate(2, [160.0, 0.0], 50.0, &[0]),
        ];
        let firm = |t: u16| t == 1;
        for mode in [Association::TwoStage, Association::TwoStageUnresolved] {
            let a = associate_on_filter(mode, &gates, &plots, firm);
            assert_eq!(a.assignments[0].plot, None, "{mode:?}");
            assert_eq!(a.assignments[1].plot, Some(0), "{mode:?}");
            assert_eq!(a.hidden, 0, "a tentative track's plot hides no firm track");
        }
        // A firm track 1.4 times as wide (coasting), the plot still far better for the
        // tentative track (d² 8.2 + ln|S| 1.3 more against 0.04): it keeps its plot.
        let plots = [[200.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 70.0, &[0]),
            gate(2, [210.0, 0.0], 50.0, &[0]),
        ];
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, firm);
        assert_eq!(a.assignments[0].plot, Some(0));
        assert_eq!(a.assignments[1].plot, None);
        // A tentative track of a few plots, its velocity barely known (σ 60 m, 1.44 times
        // the area), right on the plot (its cost lower by 8.3): wider, it takes nothing
        // from the firm track.
        let plots = [[150.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 50.0, &[0]),
            gate(2, [150.0, 0.0], 60.0, &[0]),
        ];
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, firm);
        assert_eq!(a.assignments[0].plot, Some(0));
        // The tentative track holds another plot better still: the firm track keeps this
        // one (left, it would start a new track).
        let plots = [[150.0, 0.0], [160.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 50.0, &[0]),
            gate(2, [160.0, 0.0], 50.0, &[0, 1]),
        ];
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, firm);
        assert_eq!(a.assignments[0].plot, Some(0));
        assert_eq!(a.assignments[1].plot, Some(1));
        // A second firm track, coasting (σ 70 m, the plot at d² 9.0), holds the plot too
        // and does not leave it: neither does the first, which takes it as before (left,
        // the coasting track would take it in the first stage).
        let plots = [[150.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 50.0, &[0]),
            gate(3, [360.0, 0.0], 70.0, &[0]),
            gate(2, [160.0, 0.0], 50.0, &[0]),
        ];
        let firm = |t: u16| t != 2;
        let a = associate_on_filter(Association::TwoStageUnresolved, &gates, &plots, firm);
        assert_eq!(a.assignments[0].plot, Some(0));
        assert_eq!(
            a.assignments[2].plot, None,
            "the tentative track takes nothing"
        );
    }

    #[test]
    fn a_firm_track_whose_plot_a_neighbour_took_is_unresolved_from_it() {
        // Two firm tracks 60 m apart (σ 40 m) and one plot between them, nearer track 1:
        // track 1 takes it; track 2, with the plot in its gate, is unresolved from track 1
        // (hidden) with `TwoStageUnresolved`, and only coasts with `TwoStage`. Track 3,
        // whose gate holds no plot taken by a firm track, track 5, whose rough gate holds
        // track 1's plot but not its refined gate (d² 49), and the tentative track 4 only
        // coast.
        let plots = [[20.0, 0.0], [900.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 40.0, &[0]),
            gate(2, [60.0, 0.0], 40.0, &[0]),
            gate(3, [2000.0, 0.0], 40.0, &[1]),
            gate(4, [50.0, 10.0], 40.0, &[0]),
            gate(5, [300.0, 0.0], 40.0, &[0]),
        ];
        let firm = |t: u16| t != 4;
        let plot_of = |a: &Associated| a.assignments.iter().map(|x| x.plot).collect::<Vec<_>>();
        let a = associate_on_filter(Association::TwoStageUnresolved, &gates, &plots, firm);
        assert_eq!(plot_of(&a), [Some(0), Some(HIDDEN_PLOT), None, None, None]);
        assert_eq!(a.hidden, 1);
        assert_eq!(a.hidden_in, [(2, 1)]);
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, firm);
        assert_eq!(plot_of(&a), [Some(0), None, None, None, None]);
        assert_eq!(a.hidden, 0);
    }

    #[test]
    fn a_wide_track_does_not_take_a_settled_tracks_plot() {
        // Both firm; one plot 30 m from the settled track (σ 20 m: d² 2.25) and 60 m from a
        // coasting one (σ 60 m: d² 1.0). By d² alone the coasting track would take it; by
        // d² + ln|S| (2.25 + 12.0 against 1.0 + 16.4) the settled one does.
        let plots = [[30.0, 0.0]];
        let gates = [
            gate(1, [0.0, 0.0], 20.0, &[0]),
            gate(2, [90.0, 0.0], 60.0, &[0]),
        ];
        let a = associate_on_filter(Association::TwoStage, &gates, &plots, |_| true);
        assert_eq!(a.assignments[0].plot, Some(0));
        assert_eq!(a.assignments[1].plot, None);
    }

    /// Two ships 9 km north, the plot (one, merged) 70 m beyond the first along the line of
    /// sight and 45 m across from the second: nearer the second on the round 40 m of the
    /// filter, the first's by a radar that measures bearing to 0.087° (14 m across there)
    /// and range to 37.6 m.
    #[test]
    fn the_plots_own_accuracy_tells_which_side_of_the_line_of_sight_it_lies() {
        let z = [10.0f32, 9070.0];
        let plots = [z];
        let polar = [Plot {
            range_m: z[0].hypot(z[1]),
            bearing_rad: z[0].atan2(z[1]),
        }];
        // S = H P Hᵀ (20 m a side) + the filter's 40 m.
        let gates = [
            gate(1, [0.0, 9000.0], 2000f32.sqrt(), &[0]),
            gate(2, [55.0, 9065.0], 2000f32.sqrt(), &[0]),
        ];
        let accuracy = PolarAccuracy {
            range_sigma_m: 37.6,
            bearing_sigma_rad: 0.087f32.to_radians(),
        };
        let covariances = PlotCovariances::polar(&polar, accuracy, 1600.0);
        // Along the line of sight (north) the range's variance, across it the bearing's.
        let c = covariances.plot_cov_m2[0];
        assert!(
            (c[2] - 37.6 * 37.6).abs() < 2.0 && (c[0] - 13.8 * 13.8).abs() < 3.0,
            "{c:?}"
        );
        // On a bearing of 45° the two mix, the range's along north-east.
        let diagonal = Plot {
            range_m: 9070.0,
            bearing_rad: std::f32::consts::FRAC_PI_4,
        };
        let d = PlotCovariances::polar(&[diagonal], accuracy, 1600.0);
        let (along, across) = (37.6f32 * 37.6, (9070.0 * 0.087f32.to_radians()).powi(2));
        let c = d.plot_cov_m2[0];
        for (got, want) in c.iter().zip([
            (along + across) / 2.0,
            (along - across) / 2.0,
            (along + across) / 2.0,
        ]) {
            assert!((got - want).abs() < 1e-2 * want.abs(), "{c:?}");
        }
        // S' = S − the filter's 1600 + the plot's: the track's own H P Hᵀ (400) kept.
        let s = d.innovation_cov_m2([2000.0, 0.0, 2000.0], 0).unwrap();
        assert!((s[0] - (400.0 + c[0])).abs() < 1e-2 && (s[1] - c[1]).abs() < 1e-2);
        let took = |a: &Associated| {
            a.assignments
                .iter()
                .find(|x| x.plot == Some(0))
                .map(|x| x.track)
        };
        for mode in [Association::TwoStage, Association::TwoStageUnresolved] {
            let round = associate_on_filter(mode, &gates, &plots, |_| true);
            assert_eq!(took(&round), Some(2), "{mode:?}");
            let own = associate(
                mode,
                &gates,
                &plots,
                CHI2_2DOF_99,
                |_| true,
                Some(&covariances),
                &StandingAt::new(),
            );
            assert_eq!(took(&own), Some(1), "{mode:?}");
        }
        // The refined gate stays on the filter's S: a plot in it (d² 7.2) is taken however
        // far out on the plot's own accuracy (d² 24: a track lagging a turn keeps its
        // plots, and they start no second track).
        let wide = [[120.0f32, 9000.0]];
        let wide_polar = [Plot {
            range_m: wide[0][0].hypot(wide[0][1]),
            bearing_rad: wide[0][0].atan2(wide[0][1]),
        }];
        let covariances = PlotCovariances::polar(&wide_polar, accuracy, 1600.0);
        let one = [gate(1, [0.0, 9000.0], 2000f32.sqrt(), &[0])];
        let a = associate(
            Association::TwoStage,
            &one,
            &wide,
            CHI2_2DOF_99,
            |_| true,
            Some(&covariances),
            &StandingAt::new(),
        );
        assert_eq!(a.assignments[0].plot, Some(0));
        assert!(a.initiate.is_empty());
    }

    #[test]
    fn a_still_target_is_associated_where_it_stands_and_where_it_is_predicted() {
        // Two boats moored 40 m apart, A at (0, 0) and B at (40, 0). A's track, firm and
        // found still, stands at (1, 0), but its filter's velocity noise has carried its
        // prediction to (30, 0); B's track, tentative, is predicted at (40, 0). σ 20 m.
        let plots = [[1.0f32, 0.0], [41.0, 0.0]];
        let gates = [
            gate(1, [30.0, 0.0], 20.0, &[0, 1]),
            gate(2, [40.0, 0.0], 20.0, &[0, 1]),
        ];
        let run = |standing: &StandingAt| {
            let a = associate(
                Association::TwoStage,
                &gates,
                &plots,
                CHI2_2DOF_99,
                |t| t == 1,
                None,
                standing,
            );
            a.assignments.iter().map(|x| x.plot).collect::<Vec<_>>()
        };
        // From the predictions alone, A's track, choosing first, takes B's plot (d² 0.3
        // against 2.1 for its own), and B's track its neighbour's.
        assert_eq!(run(&StandingAt::new()), [Some(1), Some(0)]);
        // Where A stands, each its own.
        let standing = StandingAt::from([(1, [1.0, 0.0])]);
        assert_eq!(run(&standing), [Some(0), Some(1)]);
        // A's prediction drifted to (50, 0); its own plot at (25, 0) is in the gate about
        // where it stands (d² 1.6), B's echo at (70, 0) is not (d² 12.25) and is nearer the
        // prediction (d² 1.0): it costs the gate's 9.21 more, and A takes its own.
        let gates = [
            gate(1, [50.0, 0.0], 20.0, &[0, 1]),
            gate(2, [70.0, 0.0], 20.0, &[0, 1]),
        ];
        let a = associate(
            Association::TwoStage,
            &gates,
            &[[25.0, 0.0], [70.0, 0.0]],
            CHI2_2DOF_99,
            |t| t == 1,
            None,
            &StandingAt::from([(1, [0.0, 0.0])]),
        );
        let took: Vec<_> = a.assignments.iter().map(|x| x.plot).collect();
        assert_eq!(took, [Some(0), Some(1)]);
        // A casts off: its plot 229 m from where it stood, out of that gate (d² 131), but
        // on its prediction, which followed it (d² 0.06). Still taken.
        let off = [[230.0f32, 0.0]];
        let gates = [gate(1, [225.0, 0.0], 20.0, &[0])];
        let a = associate(
            Association::TwoStage,
            &gates,
            &off,
            CHI2_2DOF_99,
            |_| true,
            None,
            &standing,
        );
        assert_eq!(a.assignments[0].plot, Some(0));
        assert!(a.initiate.is_empty());
    }
}
