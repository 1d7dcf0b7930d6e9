//! `f32` minimum and maximum as two comparisons.
//!
//! The Cortex-M4F's FPU has no `VMAXNM`/`VMINNM` (ARMv8), so `f32::max` and `f32::min`
//! compile to calls of `fmaxf`/`fminf` there (about 20 instructions each); these are a
//! compare and a select. The results are `f32::max`'s and `f32::min`'s for every input,
//! NaN included (a NaN argument gives the other one); the sign of a zero when both are
//! zeros may differ, which nothing here depends on.

/// The larger of `a` and `b`; the other when one is NaN (as `f32::max`).
#[inline(always)]
pub fn max(a: f32, b: f32) -> f32 {
    if a > b || b.is_nan() {
        a
    } else {
        b
    }
}

/// The smaller of `a` and `b`; the other when one is NaN (as `f32::min`).
#[inline(always)]
pub fn min(a: f32, b: f32) -> f32 {
    if a < b || b.is_nan() {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn as_the_library_functions() {
        let values = [
            f32::NAN,
            f32::NEG_INFINITY,
            -1e30,
            -2.5,
            -0.0,
            0.0,
            1e-40,
            3.0,
            f32::MAX,
            f32::INFINITY,
        ];
        for &a in &values {
            for &b in &values {
                let same = |x: f32, y: f32| x == y || (x.is_nan() && y.is_nan());
                assert!(same(super::max(a, b), a.max(b)), "max({a}, {b})");
                assert!(same(super::min(a, b), a.min(b)), "min({a}, {b})");
            }
        }
    }
}
