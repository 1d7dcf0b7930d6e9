//! Refined gating and data association: the host's half of the thesis's split.
//!
//! The device returns, per track, the few plots inside its rough gate. Here each pair is
//! tested against the **refined gate**: the Mahalanobis distance d² = νᵀS⁻¹ν of the
//! innovation ν with the track's innovation covariance S, kept when d² is below the
//! chi-square threshold (2 degrees of freedom). **Global nearest neighbour** then picks
//! the one-to-one assignment of plots to tracks that minimises the summed d², with "no
//! plot" allowed for every track at the cost of the threshold, solved exactly by the
//! Kuhn–Munkres (Hungarian) algorithm from `pathfinding`. Plots in no rough gate start new
//! tentative tracks (a plot inside a gate but not chosen is more likely a second echo of
//! that track's target, or a manoeuvre the gate lags, than a new target).

use std::collections::BTreeSet;

use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;
use tracker_core::geo::EastNorth;
use tracker_core::icd::{Assignment, GatedPlots};

/// Chi-square, 2 degrees of freedom, 99 %: a true plot falls outside 1 % of the time.
pub const CHI2_2DOF_99: f64 = 9.21;

/// Costs are integers for the assignment solver: d² in units of 1e-6.
const SCALE: f64 = 1e6;
/// A pairing that is not allowed.
const FORBIDDEN: i64 = i64::MAX / 1024;

/// The host's decision for one scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Association {
    /// Per gated track: the chosen plot, or `None` to coast.
    pub assignments: Vec<Assignment>,
    /// Plots in no rough gate: candidates for new tracks.
    pub initiate: Vec<u16>,
    /// Pairs that passed the rough gate but not the refined one.
    pub refined_out: usize,
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

/// Associates one scan. `plots` are the scan's plots in the local frame, in the order the
/// device received them; `threshold` is the refined gate (d²).
pub fn associate(gates: &[GatedPlots], plots: &[EastNorth], threshold: f64) -> Association {
    let mut out = Association::default();
    let in_a_gate: BTreeSet<u16> = gates.iter().flat_map(|g| g.plots.iter().copied()).collect();
    out.initiate = (0..plots.len())
        .filter_map(|i| u16::try_from(i).ok())
        .filter(|i| !in_a_gate.contains(i))
        .collect();
    if gates.is_empty() {
        return out;
    }
    // Columns: every plot some track may take, then one "miss" column per track.
    let candidates: Vec<u16> = in_a_gate.iter().copied().collect();
    let n = gates.len();
    let m = candidates.len();
    let miss_cost = (threshold * SCALE) as i64;
    let mut rows = Vec::with_capacity(n);
    for (i, g) in gates.iter().enumerate() {
        let mut row = vec![FORBIDDEN; m + n];
        for &p in &g.plots {
            let Some(z) = plots.get(usize::from(p)) else {
                continue;
            };
            match mahalanobis2(*z, g.predicted_m, g.innovation_cov_m2) {
                Some(d2) if d2 <= threshold => {
                    if let Ok(col) = candidates.binary_search(&p) {
                        row[col] = (d2 * SCALE) as i64;
                    }
                }
                _ => out.refined_out += 1,
            }
        }
        row[m + i] = miss_cost;
        rows.push(row);
    }
    let Ok(matrix) = Matrix::from_rows(rows) else {
        return out;
    };
    let (_, columns) = kuhn_munkres_min(&matrix);
    out.assignments = gates
        .iter()
        .zip(columns)
        .map(|(g, col)| Assignment {
            track: g.track,
            plot: (col < m).then(|| candidates[col]),
        })
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let a = associate(&gates, &plots, CHI2_2DOF_99);
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
        let a = associate(&gates, &plots, CHI2_2DOF_99);
        assert_eq!(
            a.assignments,
            [Assignment {
                track: 7,
                plot: None
            }]
        );
        assert_eq!(a.refined_out, 1);
        assert!(a.initiate.is_empty(), "it was in a rough gate");
    }
}
