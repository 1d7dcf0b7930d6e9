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
//! Used through `#[serde(with = "...")]` on the ICD's fields, so the types the two sides
//! compute with stay plain `f32` arrays.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

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

/// `x_m` as the far side of the link will see it: rounded to [`LENGTH_RESOLUTION_M`].
pub fn on_length_grid(x_m: f32) -> f32 {
    length_from_tenths(length_to_tenths(x_m))
}

/// A position (east, north, m) as the far side of the link will see it.
pub fn position_on_grid(p_m: [f32; 2]) -> [f32; 2] {
    [on_length_grid(p_m[0]), on_length_grid(p_m[1])]
}

/// An east, north pair as two varints of `steps_per_unit`.
fn serialize_pair<S: Serializer>(
    v: &[f32; 2],
    steps_per_unit: f32,
    s: S,
) -> Result<S::Ok, S::Error> {
    (
        to_steps(v[0], steps_per_unit),
        to_steps(v[1], steps_per_unit),
    )
        .serialize(s)
}

fn deserialize_pair<'de, D: Deserializer<'de>>(
    d: D,
    steps_per_unit: f32,
) -> Result<[f32; 2], D::Error> {
    let (e, n) = <(i32, i32)>::deserialize(d)?;
    Ok([from_steps(e, steps_per_unit), from_steps(n, steps_per_unit)])
}

/// S = [s_xx, s_xy, s_yy] (m²) as its Cholesky factor [l11, l21, l22] (m), in tenths.
/// A matrix that is not positive definite gives a zero on the diagonal, which decodes to a
/// singular S that the receiver refuses (it is not rounded into a valid-looking one).
fn cholesky_tenths(s: [f32; 3]) -> [i32; 3] {
    let l11 = libm::sqrtf(s[0]);
    let l21 = if l11 > 0.0 { s[1] / l11 } else { 0.0 };
    let l22 = libm::sqrtf(s[2] - l21 * l21);
    [
        length_to_tenths(l11),
        length_to_tenths(l21),
        length_to_tenths(l22),
    ]
}

fn covariance_from_cholesky(l: [i32; 3]) -> [f32; 3] {
    let [l11, l21, l22] = l.map(length_from_tenths);
    [l11 * l11, l11 * l21, l21 * l21 + l22 * l22]
}

/// `s` (m²) as the far side of the link will see it.
pub fn covariance_on_grid(s_m2: [f32; 3]) -> [f32; 3] {
    covariance_from_cholesky(cholesky_tenths(s_m2))
}

/// A position or offset east, north (m), as two tenth-metre varints.
pub mod position_m {
    use super::*;

    /// Serializes as `(i32, i32)` tenths of a metre.
    ///
    /// # Errors
    /// The serializer's.
    pub fn serialize<S: Serializer>(p: &[f32; 2], s: S) -> Result<S::Ok, S::Error> {
        serialize_pair(p, LENGTH_STEPS_PER_M, s)
    }

    /// Deserializes from `(i32, i32)` tenths of a metre.
    ///
    /// # Errors
    /// The deserializer's.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 2], D::Error> {
        deserialize_pair(d, LENGTH_STEPS_PER_M)
    }
}

/// A velocity east, north (m/s), as two hundredth-metre-a-second varints.
pub mod velocity_mps {
    use super::*;

    /// Serializes as `(i32, i32)` hundredths of a metre a second.
    ///
    /// # Errors
    /// The serializer's.
    pub fn serialize<S: Serializer>(v: &[f32; 2], s: S) -> Result<S::Ok, S::Error> {
        serialize_pair(v, SPEED_STEPS_PER_MPS, s)
    }

    /// Deserializes from `(i32, i32)` hundredths of a metre a second.
    ///
    /// # Errors
    /// The deserializer's.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 2], D::Error> {
        deserialize_pair(d, SPEED_STEPS_PER_MPS)
    }
}

/// A 2 × 2 covariance [s_xx, s_xy, s_yy] (m²) as its Cholesky factor in tenths of a metre.
pub mod covariance_m2 {
    use super::*;

    /// Serializes as `[l11, l21, l22]`, tenths of a metre.
    ///
    /// # Errors
    /// The serializer's.
    pub fn serialize<S: Serializer>(cov: &[f32; 3], s: S) -> Result<S::Ok, S::Error> {
        let [l11, l21, l22] = cholesky_tenths(*cov);
        (l11, l21, l22).serialize(s)
    }

    /// Deserializes `[l11, l21, l22]` (tenths of a metre) into S = L·Lᵀ.
    ///
    /// # Errors
    /// The deserializer's.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f32; 3], D::Error> {
        let (l11, l21, l22) = <(i32, i32, i32)>::deserialize(d)?;
        Ok(covariance_from_cholesky([l11, l21, l22]))
    }
}

/// A list of positions east, north (m), each as two tenth-metre varints.
pub mod positions_m {
    use core::fmt;

    use heapless::Vec;
    use serde::de::{self, SeqAccess, Visitor};
    use serde::ser::SerializeSeq;

    use super::*;

    /// Serializes as a sequence of `(i32, i32)` tenths of a metre.
    ///
    /// # Errors
    /// The serializer's.
    pub fn serialize<S: Serializer, const N: usize>(
        ps: &Vec<[f32; 2], N>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(ps.len()))?;
        for p in ps {
            seq.serialize_element(&(length_to_tenths(p[0]), length_to_tenths(p[1])))?;
        }
        seq.end()
    }

    /// Deserializes a sequence of `(i32, i32)` tenths of a metre.
    ///
    /// # Errors
    /// The deserializer's, or more than `N` positions.
    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<Vec<[f32; 2], N>, D::Error> {
        d.deserialize_seq(Positions::<N>)
    }

    struct Positions<const N: usize>;

    impl<'de, const N: usize> Visitor<'de> for Positions<N> {
        type Value = Vec<[f32; 2], N>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "at most {N} positions")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
            let mut out = Vec::new();
            while let Some((e, n)) = seq.next_element::<(i32, i32)>()? {
                out.push([length_from_tenths(e), length_from_tenths(n)])
                    .map_err(|_| de::Error::invalid_length(N + 1, &self))?;
            }
            Ok(out)
        }
    }
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

    #[test]
    fn typical_values_take_few_bytes() {
        let mut buf = [0u8; 32];
        #[derive(Serialize)]
        struct P(#[serde(with = "position_m")] [f32; 2]);
        #[derive(Serialize)]
        struct V(#[serde(with = "velocity_mps")] [f32; 2]);
        #[derive(Serialize)]
        struct C(#[serde(with = "covariance_m2")] [f32; 3]);
        let n = |b: &[u8]| b.len();
        assert_eq!(
            n(postcard::to_slice(&P([800.0, -800.0]), &mut buf).unwrap()),
            4
        );
        assert_eq!(
            n(postcard::to_slice(&P([9000.0, -90_000.0]), &mut buf).unwrap()),
            6
        );
        assert_eq!(
            n(postcard::to_slice(&V([6.0, -80.0]), &mut buf).unwrap()),
            4
        );
        // A settled track's gate, about 55 m each way: 2 + 1 + 2 bytes.
        assert_eq!(
            n(postcard::to_slice(&C([3000.0, 20.0, 3000.0]), &mut buf).unwrap()),
            5
        );
    }
}
