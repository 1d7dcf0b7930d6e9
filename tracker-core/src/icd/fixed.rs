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
//! factor L (S = L·Lᵀ, L lower triangular), whose entries are lengths: rounding L to tenths
//! of a metre keeps the decoded S positive semi-definite whatever the rounding, and its
//! error is a fixed length (at most 0.05 m in each factor) however elongated the gate.
//!
//! The record lists ([`super::records`]) carry these integers; the types the two sides
//! compute with stay plain `f32` arrays.

/// Resolution of a length on the wire, m.
pub const LENGTH_RESOLUTION_M: f32 = 0.1;

/// Resolution of a speed on the wire, m/s.
pub const SPEED_RESOLUTION_MPS: f32 = 0.01;

/// Steps of a length per metre, and of a speed per metre a second.
const LENGTH_STEPS_PER_M: f32 = 10.0;
const SPEED_STEPS_PER_MPS: f32 = 100.0;

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

/// S = [s_xx, s_xy, s_yy] (m²) as its Cholesky factor [l11, l21, l22] (m), in tenths.
/// A matrix that is not positive definite gives a zero on the diagonal, which decodes to a
/// singular S that the receiver refuses (it is not rounded into a valid-looking one).
pub fn cholesky_tenths(s: [f32; 3]) -> [i32; 3] {
    let l11 = libm::sqrtf(s[0]);
    let l21 = if l11 > 0.0 { s[1] / l11 } else { 0.0 };
    let l22 = libm::sqrtf(s[2] - l21 * l21);
    [
        length_to_tenths(l11),
        length_to_tenths(l21),
        length_to_tenths(l22),
    ]
}

/// S = L·Lᵀ (m²) from the Cholesky factor [l11, l21, l22] in tenths.
pub fn covariance_from_cholesky(l: [i32; 3]) -> [f32; 3] {
    let [l11, l21, l22] = l.map(length_from_tenths);
    [l11 * l11, l11 * l21, l21 * l21 + l22 * l22]
}

/// `s` (m²) as the far side of the link will see it.
pub fn covariance_on_grid(s_m2: [f32; 3]) -> [f32; 3] {
    covariance_from_cholesky(cholesky_tenths(s_m2))
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
    fn a_covariance_that_is_not_positive_definite_stays_singular() {
        for bad in [[0.0, 0.0, 100.0], [-1.0, 0.0, 1.0], [f32::NAN, 0.0, 1.0]] {
            let s = covariance_on_grid(bad);
            assert!(s[0] * s[2] - s[1] * s[1] <= 0.0, "{bad:?} -> {s:?}");
        }
    }
}
