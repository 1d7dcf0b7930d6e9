//! The numbers the filters compute in: `f32` (the MCU), `f64` (the host's reference) and
//! fixed point ([`Fix`], for DSPs without an FPU).
//!
//! The g-h family needs only adds, multiplies by a gain, and a rescale when the scan interval
//! changes, so [`Scalar`] asks for little more. The Kalman filters need real arithmetic and
//! take [`Real`] (`f32`, `f64`).
//!
//! ## The fixed-point format
//!
//! States are [`Fix`] = `I18F14`: a signed 32-bit word with 14 fractional bits. 17 integer
//! bits and the sign span ±131,072 m, enough for ±100 km (54 NM, beyond the longest radar
//! range scale in use at sea) at a resolution of 61 µm, four orders of magnitude below a
//! radar's range resolution. A 32-bit word keeps the Cortex-M4 on single-cycle `SMULL` and
//! saturating adds. Gains are [`FixGain`] = `I2F30` (range ±2, resolution 9.3e-10): the
//! critically damped jerk gain at ξ = 0.9 is 1.7e-5, which `I18F14` could not hold. The
//! filters keep derivatives in per-scan units (v·T, a·T²/2, j·T³/6), so a gain never has to
//! be divided by T and every product is a state times a gain. Arithmetic saturates: an
//! overflow pins the value at the format's limit instead of wrapping to the opposite sign.

use core::fmt::Debug;

use fixed::types::{I18F14, I2F30};

/// Fixed-point state word: `I18F14` (see the module docs).
pub type Fix = I18F14;

/// Fixed-point gain word: `I2F30`.
pub type FixGain = I2F30;

/// A number a g-h-family filter can run in.
pub trait Scalar: Copy + Debug + PartialEq + PartialOrd {
    /// A gain: the same type for floats, a finer format for fixed point.
    type Gain: Copy + Debug + PartialEq;
    /// Zero.
    const ZERO: Self;
    /// Name in tables (`f32`, `f64`, `fixed`).
    const NAME: &'static str;

    /// Nearest value (saturating for fixed point; NaN becomes 0 there).
    fn of(v: f64) -> Self;
    /// The value as `f64`.
    fn to_f64(self) -> f64;
    /// Nearest gain.
    fn gain_from_f64(v: f64) -> Self::Gain;
    /// The gain `num / den`, exactly where the format allows (gain schedules).
    fn gain_from_ratio(num: u32, den: u32) -> Self::Gain;
    /// `self + e·g`: the filter's update step.
    fn add_scaled(self, e: Self, g: Self::Gain) -> Self;
    /// `self · num / den`, for rescaling per-scan derivatives when the interval changes;
    /// rounds to nearest. `den` must be positive (fixed point gives 0 otherwise).
    fn rescale(self, num: Self, den: Self) -> Self;
    /// `self / den` (for output conversion; `den` positive).
    fn div(self, den: Self) -> Self;
    /// `self + o` (saturating for fixed point: one `QADD` on the M4).
    fn plus(self, o: Self) -> Self;
    /// `self − o` (saturating for fixed point: one `QSUB`).
    fn minus(self, o: Self) -> Self;
    /// `self · o` (saturating for fixed point).
    fn mul(self, o: Self) -> Self;
    /// `self · k` for a small integer `k` (the prediction's binomial coefficients).
    fn times(self, k: u8) -> Self;
    /// False for NaN and infinities; always true for fixed point.
    fn is_finite(self) -> bool;
}

macro_rules! float_scalar {
    ($t:ty, $name:literal) => {
        impl Scalar for $t {
            type Gain = $t;
            const ZERO: Self = 0.0;
            const NAME: &'static str = $name;

            #[inline]
            fn of(v: f64) -> Self {
                v as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn gain_from_f64(v: f64) -> Self::Gain {
                v as $t
            }
            #[inline]
            fn gain_from_ratio(num: u32, den: u32) -> Self::Gain {
                num as $t / den as $t
            }
            #[inline]
            fn add_scaled(self, e: Self, g: Self) -> Self {
                self + e * g
            }
            #[inline]
            fn rescale(self, num: Self, den: Self) -> Self {
                self * (num / den)
            }
            #[inline]
            fn div(self, den: Self) -> Self {
                self / den
            }
            #[inline]
            fn plus(self, o: Self) -> Self {
                self + o
            }
            #[inline]
            fn minus(self, o: Self) -> Self {
                self - o
            }
            #[inline]
            fn mul(self, o: Self) -> Self {
                self * o
            }
            #[inline]
            fn times(self, k: u8) -> Self {
                self * k as $t
            }
            #[inline]
            fn is_finite(self) -> bool {
                // x − x is 0 for every finite x and NaN for NaN and ±∞: one subtract and
                // one compare on the FPU, where the bit test costs a dozen integer ops.
                #[allow(clippy::eq_op)]
                let zero = self - self;
                zero == 0.0
            }
        }
    };
}

float_scalar!(f32, "f32");
float_scalar!(f64, "f64");

impl Scalar for Fix {
    type Gain = FixGain;
    const ZERO: Self = Fix::ZERO;
    const NAME: &'static str = "fixed";

    fn of(v: f64) -> Self {
        if v.is_nan() {
            Fix::ZERO
        } else {
            Fix::saturating_from_num(v)
        }
    }
    fn to_f64(self) -> f64 {
        self.to_num()
    }
    fn gain_from_f64(v: f64) -> FixGain {
        if v.is_nan() {
            FixGain::ZERO
        } else {
            FixGain::saturating_from_num(v)
        }
    }
    fn gain_from_ratio(num: u32, den: u32) -> FixGain {
        // Integer division of the shifted numerator: no float on a chip without an FPU.
        let bits = (i64::from(num) << FixGain::FRAC_NBITS)
            .checked_div(i64::from(den))
            .unwrap_or(i64::MAX);
        FixGain::from_bits(bits.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32)
    }
    #[inline]
    fn add_scaled(self, e: Self, g: FixGain) -> Self {
        // e·g rounded to nearest, as the high word of a 64-bit product: I18F14 × I2F30 has
        // 44 fractional bits, so scale e by 4 first (two saturating adds) and keep bits
        // 32..64, which the M4 does in one SMMULR. Rounding, not truncation: truncation
        // biases every update the same way, and a long-memory filter (least-squares
        // schedule, ξ near 1) integrates that bias into a velocity drift. The scaling
        // saturates innovations beyond ±32,768 m, far outside any validation gate; in
        // exchange the product always fits 32 bits and needs no clamp.
        let e2 = e.to_bits().saturating_add(e.to_bits());
        let e4 = e2.saturating_add(e2);
        let product = (i64::from(e4) * i64::from(g.to_bits()) + (1 << 31)) >> 32;
        self.saturating_add(Fix::from_bits(product as i32))
    }
    #[inline]
    fn plus(self, o: Self) -> Self {
        self.saturating_add(o)
    }
    #[inline]
    fn minus(self, o: Self) -> Self {
        self.saturating_sub(o)
    }
    fn rescale(self, num: Self, den: Self) -> Self {
        // Widen so the product cannot overflow before the division brings it back.
        let wide = i64::from(self.to_bits()) * i64::from(num.to_bits());
        let den = i64::from(den.to_bits());
        if den <= 0 {
            return Fix::ZERO;
        }
        // Round to nearest: truncation would bias every rescale the same way, and a filter
        // with a long memory (the least-squares schedule) integrates that bias.
        let half = if wide < 0 { -(den / 2) } else { den / 2 };
        let q = wide.saturating_add(half) / den;
        Fix::from_bits(q.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32)
    }
    fn div(self, den: Self) -> Self {
        self.checked_div(den)
            .unwrap_or(if self < Fix::ZERO { Fix::MIN } else { Fix::MAX })
    }
    #[inline]
    fn mul(self, o: Self) -> Self {
        self.saturating_mul(o)
    }
    #[inline]
    fn times(self, k: u8) -> Self {
        // The prediction's coefficients (1 to 3) as saturating adds, one `QADD` each, where
        // the saturating multiply took 4 (×2) and 8 (×3) instructions on the M4. The same
        // result: x, 2x and 3x have one sign, so once a partial sum saturates the product
        // does too (tested against the multiply).
        match k {
            0 => Fix::ZERO,
            1 => self,
            2 => self.saturating_add(self),
            3 => self.saturating_add(self).saturating_add(self),
            _ => self.saturating_mul_int(i32::from(k)),
        }
    }
    fn is_finite(self) -> bool {
        true
    }
}

/// Float scalars: what the Kalman filters need on top of [`Scalar`].
pub trait Real: Scalar<Gain = Self> + nalgebra::RealField + Copy {
    /// A value in hundredths (of a metre per second, say), stored as `i16`.
    fn from_centi(v: i16) -> Self;
    /// The value in hundredths, rounded to nearest and saturated to the `i16` range.
    fn to_centi(self) -> i16;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            #[inline]
            fn from_centi(v: i16) -> Self {
                <$t>::from(v) * 0.01
            }
            #[inline]
            fn to_centi(self) -> i16 {
                let x = self * 100.0;
                // `as` saturates (and maps NaN to 0); the half rounds to nearest.
                let r = (x + if x >= 0.0 { 0.5 } else { -0.5 }) as i32;
                r.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16
            }
        }
    };
}

real!(f32);
real!(f64);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed_spans_a_radar_picture_at_sub_millimetre_resolution() {
        assert!(Fix::MAX.to_num::<f64>() > 100_000.0);
        assert!(Fix::MIN.to_num::<f64>() < -100_000.0);
        assert!(Fix::DELTA.to_num::<f64>() < 1e-4);
        // The smallest gain a critically damped α-β-γ-η needs at ξ = 0.9.
        let l = (1.0f64 - 0.9).powi(4) / 6.0;
        let q = Fix::gain_from_f64(l).to_num::<f64>();
        assert!((q - l).abs() / l < 1e-4);
    }

    #[test]
    fn fixed_saturates_instead_of_wrapping() {
        let big = Fix::of(120_000.0);
        assert_eq!(big.add_scaled(big, FixGain::from_num(1.5)), Fix::MAX);
        assert_eq!(
            Fix::ZERO.add_scaled(Fix::MIN, FixGain::from_num(1.99)),
            Fix::of(-65_536.0 * 0.995)
        );
        // Products round to nearest: 3 LSB × 0.5 = 1.5 LSB → 2 LSB; −1.5 → −1 (ties up).
        let half = FixGain::from_num(0.5);
        assert_eq!(
            Fix::ZERO.add_scaled(Fix::from_bits(3), half),
            Fix::from_bits(2)
        );
        assert_eq!(
            Fix::ZERO.add_scaled(Fix::from_bits(-3), half),
            Fix::from_bits(-1)
        );
        assert_eq!(Fix::of(1e9), Fix::MAX);
        assert_eq!(Fix::of(f64::NAN), Fix::ZERO);
        assert_eq!(big.times(3), Fix::MAX);
        for bits in [
            0,
            1,
            -1,
            12_345,
            -98_765,
            i32::MAX / 3,
            i32::MIN / 2 - 1,
            i32::MAX,
            i32::MIN,
        ] {
            let x = Fix::from_bits(bits);
            for k in 0..=5u8 {
                assert_eq!(
                    x.times(k),
                    x.saturating_mul_int(i32::from(k)),
                    "{bits} × {k}"
                );
            }
        }
        assert_eq!(Fix::of(5.0).div(Fix::ZERO), Fix::MAX);
        assert_eq!(
            Fix::of(100.0).rescale(Fix::of(3.0), Fix::of(2.0)),
            Fix::of(150.0)
        );
    }
}
