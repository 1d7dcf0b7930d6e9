//! Accuracy metrics as the source papers compute them, beside the textbook ones.
//!
//! All take the per-scan radial distances between two tracks (true and estimated, or
//! observed and estimated), in metres.
//!
//! - [`two_drms_95`]: the 2drms of `000_1d4538ac71ce8a6a.txt`: the distances sorted and the
//!   one at 95 % taken (the 9,500th of 10,000): the radius of the circle holding 95 % of the
//!   points. This is *not* the textbook 2drms, [`twice_rms`] = 2·√(mean d²); for a circular
//!   Gaussian error the two differ (2.45σ against 2.83σ).
//! - [`ErrorSummary`]: the thesis's error function (eq. 2-5, the sum of the distances between
//!   true and predicted positions), `001_13aaa989b195c0a5.txt`'s total tracking and total
//!   estimation errors (the same sum, against predicted and against smoothed positions) with
//!   their standard deviations, and the RMSE.

/// The radius holding 95 % of the points (`000_1d4538ac71ce8a6a.txt`): `distances` sorted
/// in place, the element at rank ⌈0.95·n⌉ taken (the 9,500th of 10,000). NaN sorts last.
/// `None` when empty.
pub fn two_drms_95(distances: &mut [f64]) -> Option<f64> {
    if distances.is_empty() {
        return None;
    }
    distances.sort_unstable_by(f64::total_cmp);
    let n = distances.len();
    // ⌈0.95·n⌉ in integers, as a 1-based rank.
    let rank = (95 * n).div_ceil(100).max(1);
    distances.get(rank - 1).copied()
}

/// The textbook 2drms: twice the root mean square distance. `None` when empty.
pub fn twice_rms(distances: &[f64]) -> Option<f64> {
    if distances.is_empty() {
        return None;
    }
    let ms = distances.iter().map(|d| d * d).sum::<f64>() / distances.len() as f64;
    Some(2.0 * libm::sqrt(ms))
}

/// Sum, spread and RMS of per-scan distances.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorSummary {
    /// Distances summed.
    pub count: usize,
    /// Σ d, m: the thesis's eq. 2-5 and paper 001's total error.
    pub total_m: f64,
    /// Mean distance, m.
    pub mean_m: f64,
    /// Standard deviation of the distances (population), m.
    pub std_m: f64,
    /// √(mean d²), m.
    pub rms_m: f64,
}

impl ErrorSummary {
    /// The summary of `distances`.
    pub fn of(distances: impl IntoIterator<Item = f64>) -> Self {
        let (mut n, mut sum, mut sq) = (0usize, 0.0, 0.0);
        for d in distances {
            n += 1;
            sum += d;
            sq += d * d;
        }
        if n == 0 {
            return ErrorSummary::default();
        }
        let mean = sum / n as f64;
        let ms = sq / n as f64;
        ErrorSummary {
            count: n,
            total_m: sum,
            mean_m: mean,
            std_m: libm::sqrt((ms - mean * mean).max(0.0)),
            rms_m: libm::sqrt(ms),
        }
    }
}

/// Distance between two points, m.
pub fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    libm::hypot(a[0] - b[0], a[1] - b[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_drms_takes_the_9500th_of_10000() {
        let mut d: std::vec::Vec<f64> = (1..=10_000).rev().map(f64::from).collect();
        assert_eq!(two_drms_95(&mut d), Some(9_500.0));
        assert_eq!(two_drms_95(&mut [3.0]), Some(3.0));
        assert_eq!(two_drms_95(&mut []), None);
        // Twenty points: the 19th.
        let mut d: std::vec::Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(two_drms_95(&mut d), Some(19.0));
    }

    #[test]
    fn the_two_2drms_differ_for_a_gaussian() {
        // Radial distances of a circular Gaussian, σ = 1 per axis: Rayleigh quantiles.
        let n = 100_000;
        let mut d: std::vec::Vec<f64> = (0..n)
            .map(|i| {
                let p = (i as f64 + 0.5) / n as f64;
                libm::sqrt(-2.0 * libm::log(1.0 - p))
            })
            .collect();
        let textbook = twice_rms(&d).unwrap();
        let paper = two_drms_95(&mut d).unwrap();
        assert!((textbook - 2.0 * 2f64.sqrt()).abs() < 1e-2, "{textbook}");
        assert!((paper - 2.4477).abs() < 1e-3, "{paper}");
    }

    #[test]
    fn summary_of_known_distances() {
        let s = ErrorSummary::of([1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.count, 4);
        assert_eq!(s.total_m, 10.0);
        assert_eq!(s.mean_m, 2.5);
        assert!((s.std_m - 1.25f64.sqrt()).abs() < 1e-12);
        assert!((s.rms_m - 7.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(ErrorSummary::of([]), ErrorSummary::default());
        assert_eq!(distance([0.0, 0.0], [3.0, 4.0]), 5.0);
    }
}
