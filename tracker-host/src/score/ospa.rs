//! OSPA and GOSPA: the multi-target tracking field's distances between the set of true
//! positions and the set of track positions at one time, as Stone Soup computes them.
//!
//! Both cut each distance at `c` and raise it to `p`, and both find the assignment of
//! tracks to targets that minimises the sum (solved exactly by Kuhn–Munkres). They differ in
//! how a cardinality mismatch is charged:
//!
//! - **OSPA** (Schuhmacher, Vo & Vo, "A consistent metric for performance evaluation of
//!   multi-object filters", IEEE Trans. SP 56(8), 2008, eq. 3): for |X| = m ≤ n = |Y|,
//!   d = ((1/n)·(min_π Σᵢ min(c, ‖xᵢ − y_π(i)‖)^p + c^p·(n − m)))^{1/p}. Normalised by n: a
//!   mean per object, between 0 and c. Both sets empty: 0.
//! - **GOSPA** with α = 2 (Rahmathullah, García-Fernández & Svensson, "Generalized optimal
//!   sub-pattern assignment metric", FUSION 2017, eq. 1 and Prop. 1):
//!   d = (min_γ Σ_{(i,j)∈γ} ‖xᵢ − yⱼ‖^p + (c^p/2)·(|X| + |Y| − 2|γ|))^{1/p}, γ pairing only
//!   objects closer than c. Not normalised: it grows with the number of objects, and it splits
//!   into localisation, missed targets and false tracks.
//!
//! Positions are in the local frame, metres.

use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;

/// Cut-off distance the product reports with, m: an error beyond it counts as a miss. The
/// issue's choice (c = 500 m), about twice a confirmed track's gate at 12 NM.
pub const OSPA_C_M: f64 = 500.0;

/// Order of the metrics the product reports with (p = 2: localisation errors weigh as in
/// an RMS).
pub const OSPA_P: f64 = 2.0;

/// Costs are integers for the assignment solver: distance^p in units of 1e-6.
const SCALE: f64 = 1e6;

/// One time's OSPA and GOSPA, with GOSPA's parts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SetDistance {
    /// OSPA, m (0 ≤ OSPA ≤ c).
    pub ospa_m: f64,
    /// GOSPA (α = 2), m.
    pub gospa_m: f64,
    /// GOSPA's localisation part: Σ d^p over the pairs closer than c, m^p.
    pub localisation_mp: f64,
    /// True targets left unpaired (counted in GOSPA at c^p/2 each).
    pub missed: usize,
    /// Tracks left unpaired (counted in GOSPA at c^p/2 each).
    pub false_tracks: usize,
}

/// OSPA and GOSPA between `truth` and `tracks` (positions, m) with cut-off `c_m` and order
/// `p`.
///
/// Returns zeros when both sets are empty. `c_m` must be positive and `p` at least 1; other
/// values give meaningless (but finite or NaN, never panicking) results.
pub fn set_distance(truth: &[[f64; 2]], tracks: &[[f64; 2]], c_m: f64, p: f64) -> SetDistance {
    let cp = c_m.powf(p);
    // Rows are the smaller set (the solver needs rows ≤ columns).
    let (rows, cols) = if truth.len() <= tracks.len() {
        (truth, tracks)
    } else {
        (tracks, truth)
    };
    let (m, n) = (rows.len(), cols.len());
    if n == 0 {
        return SetDistance::default();
    }
    let cut = |a: &[f64; 2], b: &[f64; 2]| {
        let d = (a[0] - b[0]).hypot(a[1] - b[1]);
        d.min(c_m).powf(p)
    };
    // min_π Σ min(c, d)^p: the same optimal assignment serves OSPA and GOSPA (α = 2), where a
    // pair at c or beyond costs c^p either way (paired, or both unpaired at c^p/2 each).
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    if m > 0 {
        let weights: Vec<Vec<i64>> = rows
            .iter()
            .map(|r| {
                cols.iter()
                    .map(|c| (cut(r, c) * SCALE).round() as i64)
                    .collect()
            })
            .collect();
        if let Ok(matrix) = Matrix::from_rows(weights) {
            let (_, assignment) = kuhn_munkres_min(&matrix);
            pairs = assignment.into_iter().enumerate().collect();
        }
    }
    let mut sum_cut = 0.0;
    let mut localisation = 0.0;
    let mut close_pairs = 0usize;
    for &(i, j) in &pairs {
        let (a, b) = (&rows[i], &cols[j]);
        let d = (a[0] - b[0]).hypot(a[1] - b[1]);
        sum_cut += d.min(c_m).powf(p);
        if d < c_m {
            localisation += d.powf(p);
            close_pairs += 1;
        }
    }
    let ospa = ((sum_cut + cp * (n - m) as f64) / n as f64).powf(1.0 / p);
    let missed = truth.len() - close_pairs;
    let false_tracks = tracks.len() - close_pairs;
    let gospa = (localisation + cp / 2.0 * (missed + false_tracks) as f64).powf(1.0 / p);
    SetDistance {
        ospa_m: ospa,
        gospa_m: gospa,
        localisation_mp: localisation,
        missed,
        false_tracks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-6 * b.abs().max(1.0)
    }

    #[test]
    fn empty_sets_are_zero_and_one_empty_set_is_c() {
        let d = set_distance(&[], &[], 500.0, 2.0);
        assert_eq!(d, SetDistance::default());
        // Three targets, no track: OSPA = c; GOSPA = (3·c²/2)^½.
        let d = set_distance(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], &[], 500.0, 2.0);
        assert!(close(d.ospa_m, 500.0));
        assert!(close(d.gospa_m, (3.0 * 250_000.0 / 2.0_f64).sqrt()));
        assert_eq!((d.missed, d.false_tracks), (3, 0));
    }

    #[test]
    fn a_hand_worked_case() {
        // Targets at (0,0) and (1000,0); tracks at (30,40) (50 m off the first) and
        // (1000,300) (300 m off the second) and a false one at (5000,5000).
        let truth = [[0.0, 0.0], [1000.0, 0.0]];
        let tracks = [[30.0, 40.0], [1000.0, 300.0], [5000.0, 5000.0]];
        let d = set_distance(&truth, &tracks, 500.0, 2.0);
        // OSPA² = (50² + 300² + 500²·1)/3 = (2500 + 90000 + 250000)/3.
        assert!(close(d.ospa_m, (342_500.0_f64 / 3.0).sqrt()), "{d:?}");
        // GOSPA² = 50² + 300² + 500²/2·1 = 217,500.
        assert!(close(d.gospa_m, 217_500.0_f64.sqrt()), "{d:?}");
        assert!(close(d.localisation_mp, 92_500.0));
        assert_eq!((d.missed, d.false_tracks), (0, 1));
    }

    #[test]
    fn the_assignment_is_global_not_greedy() {
        // Track A at 0 is nearest to target 1 at 10, but giving it target 0 at -10 and
        // track B at 30 target 1 costs less: 10² + 20² = 500 against 10² + 40² = 1700.
        let truth = [[-10.0, 0.0], [10.0, 0.0]];
        let tracks = [[0.0, 0.0], [30.0, 0.0]];
        let d = set_distance(&truth, &tracks, 500.0, 2.0);
        assert!(close(d.ospa_m, 250.0_f64.sqrt()), "{d:?}");
        assert!(close(d.gospa_m, 500.0_f64.sqrt()), "{d:?}");
    }

    #[test]
    fn a_pair_beyond_c_is_a_miss_and_a_false_track() {
        // 800 m apart with c = 500: OSPA charges c (one pair cut at c); GOSPA charges a
        // missed target and a false track at c²/2 each: the same c here.
        let d = set_distance(&[[0.0, 0.0]], &[[800.0, 0.0]], 500.0, 2.0);
        assert!(close(d.ospa_m, 500.0));
        assert!(close(d.gospa_m, 500.0));
        assert_eq!((d.missed, d.false_tracks), (1, 1));
        assert_eq!(d.localisation_mp, 0.0);
    }

    #[test]
    fn p_one_is_a_mean_distance() {
        let d = set_distance(
            &[[0.0, 0.0], [0.0, 100.0]],
            &[[3.0, 4.0], [0.0, 110.0]],
            500.0,
            1.0,
        );
        assert!(close(d.ospa_m, 7.5), "{d:?}");
        assert!(close(d.gospa_m, 15.0), "{d:?}");
    }
}
