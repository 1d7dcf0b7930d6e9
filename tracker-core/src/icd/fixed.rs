//! Fixed-point encodings of the lengths and speeds on the wire.
//!
//! Inside, both sides compute in `f32`; on the wire a length is a whole number of tenths of
//! a metre and a speed a whole number of hundredths of a metre a second, each a postcard
//! zigzag varint. An `f32` takes four bytes whatever its value; a tenth-metre varint takes
//! two up to ±819 m, three up to ±104 km and four up to the filters' ±10,000 km. These
//! resolutions are far below the radar's own errors (tens of metres, tenths of a metre a
//! second), and rounding is the same on every machine, so the host and the device see the
//! very same numbers whichever link runs the device.
//!
//! An innovation covariance S (2 × 2, symmetric, positive definite) travels as its Cholesky
//! factor L (S = L·Lᵀ, L lower triangular), whose entries are lengths: rounding L keeps the
//! decoded S positive semi-definite whatever the rounding, and its error is a fixed length
//! however elongated the gate. L goes in whole centimetres (at most 0.005 m off in each
//! factor), finer than a position: the host's refined gate is d² = νᵀS⁻¹ν against 9.21, and
//! with L in tenths (protocol 5) a 45 m factor was off by up to 0.1 %, d² by up to about
//! ±0.02, which decided plots at the gate's edge (docs/stonesoup.md: open-sea seed 3's plot at
//! d² 9.2125). In centimetres within 0.003 (about 0.002 on tracked targets' gates); a tracked target's factors (40–80 m) still take two
//! bytes each.
//!
//! The record lists ([`super::records`]) carry these integers; the types the two sides
//! compute with stay plain `f32` arrays.

/// Steps of a length per metre (tenths).
const LENGTH_STEPS_PER_M: f32 = 10.0;
/// Steps of a Cholesky factor per metre (centimetres).
const CHOLESKY_STEPS_PER_M: f32 = 100.0;
/// Steps of a speed per metre a second (hundredths).
const SPEED_STEPS_PER_MPS: f32 = 100.0;

/// Resolution of a length on the wire, m.
pub const LENGTH_RESOLUTION_M: f32 = 1.0 / LENGTH_STEPS_PER_M;

/// Resolution of a speed on the wire, m/s.
pub const SPEED_RESOLUTION_MPS: f32 = 1.0 / SPEED_STEPS_PER_MPS;

/// Resolution of an innovation covariance's Cholesky factor on the wire, m.
pub const CHOLESKY_RESOLUTION_M: f32 = 1.0 / CHOLESKY_STEPS_PER_M;

/// `x · steps_per_unit` rounded to the nearest whole number (halves away from zero);
/// values past `i32`'s range saturate and NaN becomes 0 (Rust's float-to-int conversion).
fn to_steps(x: f32, steps_per_unit: f32) -> i32 {
    libm::roundf(x * steps_per_unit) as i32
}

fn from_steps(n: i32, steps_per_unit: f32) -> f32 {
    n as f32 / steps_per_unit
}

/// A length as whole tenths of a metre.
pub fn length_to_tenths(x_m: f32) -> i32 {
    to_steps(x_m, LENGTH_STEPS_PER_M)
}

/// Tenths of a metre as a length, m.
pub fn length_from_tenths(n: i32) -> f32 {
    from_steps(n, LENGTH_STEPS_PER_M)
}

/// A speed as whole hundredths of a metre a second.
pub fn speed_to_hundredths(v_mps: f32) -> i32 {
    to_steps(v_mps, SPEED_STEPS_PER_MPS)
}

/// Hundredths of a metre a second as a speed, m/s.
pub fn speed_from_hundredths(n: i32) -> f32 {
    from_steps(n, SPEED_STEPS_PER_MPS)
}

/// `x_m` as the far side of the link will see it: rounded to [`LENGTH_RESOLUTION_M`].
pub fn on_length_grid(x_m: f32) -> f32 {
    length_from_tenths(length_to_tenths(x_m))
}

/// A position (east, north, m) as the far side of the link will see it.
pub fn position_on_grid(p_m: [f32; 2]) -> [f32; 2] {
    [on_length_grid(p_m[0]), on_length_grid(p_m[1])]
}

/// S = [s_xx, s_xy, s_yy] (m²) as its Cholesky factor [l11, l21, l22] (m), in whole
/// centimetres.
/// A matrix that is not positive definite gives a zero on the diagonal, which decodes to a
/// singular S that the receiver refuses (it is not rounded into a valid-looking one).
pub fn cholesky_cm(s: [f32; 3]) -> [i32; 3] {
    let l11 = libm::sqrtf(s[0]);
    let l21 = if l11 > 0.0 { s[1] / l11 } else { 0.0 };
    let l22 = libm::sqrtf(s[2] - l21 * l21);
    [l11, l21, l22].map(|l| to_steps(l, CHOLESKY_STEPS_PER_M))
}

/// S = L·Lᵀ (m²) from the Cholesky factor [l11, l21, l22] in whole centimetres.
pub fn covariance_from_cholesky(l: [i32; 3]) -> [f32; 3] {
    let [l11, l21, l22] = l.map(|n| from_steps(n, CHOLESKY_STEPS_PER_M));
    [l11 * l11, l11 * l21, l21 * l21 + l22 * l22]
}

/// `s` (m²) as the far side of the link will see it.
pub fn covariance_on_grid(s_m2: [f32; 3]) -> [f32; 3] {
    covariance_from_cholesky(cholesky_cm(s_m2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_round_to_the_nearest_tenth() {
        assert_eq!(length_to_tenths(1852.04), 18_520);
        assert_eq!(length_to_tenths(1852.06), 18_521);
        assert_eq!(length_to_tenths(-0.05), -1, "halves away from zero");
        assert_eq!(length_to_tenths(f32::NAN), 0);
        assert_eq!(length_to_tenths(1e12), i32::MAX, "saturates");
        assert_eq!(on_length_grid(12.34), 12.3);
        // Grid values are fixed points: sending one again changes nothing.
        for x in [0.0, 0.1, -4.7, 1234.5, 99_999.9] {
            assert_eq!(on_length_grid(on_length_grid(x)), on_length_grid(x));
        }
    }

    #[test]
    fn covariance_survives_as_its_cholesky_factor() {
        // An elongated, tilted gate: 200 m by 30 m at 30°.
        let (a, b, th) = (200.0f32, 30.0f32, core::f32::consts::FRAC_PI_6);
        let (c, s) = (libm::cosf(th), libm::sinf(th));
        let cov = [
            a * a * c * c + b * b * s * s,
            (a * a - b * b) * c * s,
            a * a * s * s + b * b * c * c,
        ];
        let back = covariance_on_grid(cov);
        for (x, y) in cov.iter().zip(back) {
            assert!((x - y).abs() / x.abs() < 2e-3, "{cov:?} {back:?}");
        }
        let det = back[0] * back[2] - back[1] * back[1];
        assert!(det > 0.0);
    }

    #[test]
    fn a_plot_on_the_gates_edge_stays_on_it_across_the_link() {
        // Tracked targets' innovation covariances (factors of 40–50 m, tilted), and plots
        // all round at d² = 9.21 exactly: after the link's rounding of the factor, d² is
        // within 0.003 of 9.21 (with the factor in tenths, protocol 5, it was off by up to
        // 0.011 and 0.015 on these two).
        for s in [[2031.7f32, 311.3, 1947.9], [1791.3, -95.2, 2602.6]] {
            let [sxx, sxy, syy] = s.map(f64::from);
            let l11 = sxx.sqrt();
            let l21 = sxy / l11;
            let l22 = (syy - l21 * l21).sqrt();
            let [rxx, rxy, ryy] = covariance_on_grid(s).map(f64::from);
            let det = rxx * ryy - rxy * rxy;
            for k in 0..360 {
                let th = f64::from(k).to_radians();
                let (u, v) = (9.21f64.sqrt() * th.cos(), 9.21f64.sqrt() * th.sin());
                let (dx, dy) = (l11 * u, l21 * u + l22 * v);
                let d2 = (ryy * dx * dx - 2.0 * rxy * dx * dy + rxx * dy * dy) / det;
                assert!((d2 - 9.21).abs() < 0.003, "{s:?} at {k}°: d² {d2}");
            }
        }
    }

    #[test]
    fn a_covariance_that_is_not_positive_definite_stays_singular() {
        for bad in [[0.0, 0.0, 100.0], [-1.0, 0.0, 1.0], [f32::NAN, 0.0, 1.0]] {
            let s = covariance_on_grid(bad);
            assert!(s[0] * s[2] - s[1] * s[1] <= 0.0, "{bad:?} -> {s:?}");
        }
    }
}
