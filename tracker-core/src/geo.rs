//! Plane geometry of the radar picture: polar plots to the local frame, and the quantities
//! a navigator reads off a target (range, bearing, course and speed, CPA and TCPA).
//!
//! The local frame is east/north in metres from a fixed origin (own ship's position when
//! tracking started); bearings and courses are radians clockwise from true north in
//! [0, 2π). Everything here is `f32`, the MCU's number, and plain `libm`.

use core::f32::consts::{PI, TAU};

/// A point or a vector in the local frame: `[east, north]`, metres or m/s.
pub type EastNorth = [f32; 2];

/// Wraps an angle to [0, 2π).
pub fn wrap_2pi(a: f32) -> f32 {
    let w = a % TAU;
    if w < 0.0 {
        w + TAU
    } else {
        w
    }
}

/// Wraps an angle to [−π, π).
pub fn wrap_pi(a: f32) -> f32 {
    wrap_2pi(a + PI) - PI
}

/// Sine and cosine of an angle, in single precision.
///
/// `libm`'s `sincosf` works in double precision internally, which a Cortex-M4F (single
/// precision FPU) runs in software: about 2,000 instructions a call. `idsp::cossin` uses a
/// 512-byte table and integer interpolation, about 40 instructions; with the f32 phase
/// conversion the error stays below 2e-5 (tested): 0.45 m at 12 NM, far below a plot's
/// 40 m.
pub fn sin_cos(angle_rad: f32) -> (f32, f32) {
    // The phase word: −π..π maps onto i32::MIN..i32::MAX.
    const PHASE_PER_RAD: f32 = 2_147_483_648.0 / PI;
    const FULL_SCALE: f32 = 1.0 / 2_147_483_648.0;
    let phase = (wrap_pi(angle_rad) * PHASE_PER_RAD) as i32;
    let (c, s) = idsp::cossin(phase);
    (s as f32 * FULL_SCALE, c as f32 * FULL_SCALE)
}

/// The point at `range_m`, `bearing_rad` (true) from `origin`.
pub fn polar_to_local(origin: EastNorth, range_m: f32, bearing_rad: f32) -> EastNorth {
    let (s, c) = sin_cos(bearing_rad);
    [origin[0] + range_m * s, origin[1] + range_m * c]
}

/// The point at `range_m`, `bearing_rad` (true) from `origin`, worked in `f64` (the sine and
/// cosine from `libm::sincos`) and rounded to `f32` once: for the host, where double
/// precision costs nothing. [`polar_to_local`]'s table sine is off by up to 2e-5, 0.45 m at
/// 12 NM; the host placed every plot so until 2026-12-07, and that, not `f32`, was the
/// millimetres of OSPA between our tracker and Stone Soup on the same plots
/// (docs/stonesoup.md).
pub fn polar_to_local_f64(origin: EastNorth, range_m: f32, bearing_rad: f32) -> EastNorth {
    let (s, c) = libm::sincos(f64::from(bearing_rad));
    let range_m = f64::from(range_m);
    [
        (f64::from(origin[0]) + range_m * s) as f32,
        (f64::from(origin[1]) + range_m * c) as f32,
    ]
}

/// Range (m) and true bearing (rad, [0, 2π)) of `target` from `observer`.
pub fn range_bearing(observer: EastNorth, target: EastNorth) -> (f32, f32) {
    let de = target[0] - observer[0];
    let dn = target[1] - observer[1];
    (libm::hypotf(de, dn), wrap_2pi(libm::atan2f(de, dn)))
}

/// Course (rad true, [0, 2π)) and speed (m/s) of a velocity.
pub fn course_speed(velocity_mps: EastNorth) -> (f32, f32) {
    (
        wrap_2pi(libm::atan2f(velocity_mps[0], velocity_mps[1])),
        libm::hypotf(velocity_mps[0], velocity_mps[1]),
    )
}

/// The velocity of a course (rad true) and speed (m/s).
pub fn velocity(course_rad: f32, speed_mps: f32) -> EastNorth {
    let (s, c) = libm::sincosf(course_rad);
    [speed_mps * s, speed_mps * c]
}

/// Closest point of approach between own ship and a target, both moving straight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cpa {
    /// Distance at the closest point, m.
    pub cpa_m: f32,
    /// Time to the closest point, s; negative when it has passed.
    pub tcpa_s: f32,
}

/// A target's velocity relative to own ship: `target_v − own_v`, m/s (east, north).
pub fn relative_velocity(own_v: EastNorth, target_v: EastNorth) -> EastNorth {
    [target_v[0] - own_v[0], target_v[1] - own_v[1]]
}

/// CPA and TCPA of a target at `target` moving at `target_v`, seen from own ship at `own`
/// moving at `own_v`. With no relative motion the range never changes: TCPA is 0 and CPA
/// is the present range.
pub fn cpa(own: EastNorth, own_v: EastNorth, target: EastNorth, target_v: EastNorth) -> Cpa {
    let rel = [target[0] - own[0], target[1] - own[1]];
    let rv = relative_velocity(own_v, target_v);
    let v2 = rv[0] * rv[0] + rv[1] * rv[1];
    // Below (1 mm/s)² the relative motion carries no useful time to closest approach.
    if v2 < 1e-6 {
        return Cpa {
            cpa_m: libm::hypotf(rel[0], rel[1]),
            tcpa_s: 0.0,
        };
    }
    let tcpa = -(rel[0] * rv[0] + rel[1] * rv[1]) / v2;
    Cpa {
        cpa_m: libm::hypotf(rel[0] + rv[0] * tcpa, rel[1] + rv[1] * tcpa),
        tcpa_s: tcpa,
    }
}

/// Metres in a nautical mile.
pub const METRES_PER_NM: f32 = 1852.0;
/// m/s in a knot.
pub const MPS_PER_KNOT: f32 = 1852.0 / 3600.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bearings_are_clockwise_from_north() {
        let (r, b) = range_bearing([0.0, 0.0], [100.0, 0.0]);
        assert!((r - 100.0).abs() < 1e-4 && (b - PI / 2.0).abs() < 1e-6);
        let (_, b) = range_bearing([0.0, 0.0], [-1.0, -1.0]);
        assert!((b - 1.25 * PI).abs() < 1e-6);
        let p = polar_to_local([10.0, 20.0], 50.0, PI);
        assert!(
            (p[0] - 10.0).abs() < 1e-2 && (p[1] + 30.0).abs() < 1e-2,
            "{p:?}"
        );
        let (c, s) = course_speed(velocity(0.3, 7.0));
        assert!((c - 0.3).abs() < 1e-6 && (s - 7.0).abs() < 1e-5);
    }

    #[test]
    fn single_precision_sin_cos_is_within_2e5() {
        let mut worst = 0.0f64;
        for i in -20_000..20_000 {
            let a = i as f32 * 0.000_37;
            let (s, c) = sin_cos(a);
            let (es, ec) = (f64::from(a).sin(), f64::from(a).cos());
            worst = worst
                .max((f64::from(s) - es).abs())
                .max((f64::from(c) - ec).abs());
        }
        assert!(worst < 2e-5, "{worst}");
    }

    #[test]
    fn a_plot_placed_in_double_precision_is_within_f32_rounding() {
        // At 12 NM the table sine's 2e-5 is up to 0.45 m; worked in f64 the point is off
        // only by its f32 rounding (ulp 2 mm at 16–32 km).
        let (mut worst_f64, mut worst_table) = (0.0f64, 0.0f64);
        for i in 0..3_600 {
            let b = i as f32 * 0.001_745_3;
            let range_m = 22_224.0;
            let (e, n) = (
                f64::from(range_m) * f64::from(b).sin(),
                f64::from(range_m) * f64::from(b).cos(),
            );
            let off = |p: EastNorth| (f64::from(p[0]) - e).hypot(f64::from(p[1]) - n);
            worst_f64 = worst_f64.max(off(polar_to_local_f64([0.0, 0.0], range_m, b)));
            worst_table = worst_table.max(off(polar_to_local([0.0, 0.0], range_m, b)));
        }
        assert!(worst_f64 < 0.002, "{worst_f64}");
        assert!(worst_table > 0.05, "{worst_table}");
    }

    #[test]
    fn wraps() {
        assert!((wrap_2pi(-0.1) - (TAU - 0.1)).abs() < 1e-6);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-6);
        assert!(wrap_2pi(TAU) < 1e-6);
    }

    #[test]
    fn cpa_of_a_crossing_and_a_parallel_target() {
        // Target 8 NM dead ahead, closing at 20 kn on a reciprocal course: CPA 0 in 24 min.
        let own_v = velocity(0.0, 10.0 * MPS_PER_KNOT);
        let tgt_v = velocity(PI, 10.0 * MPS_PER_KNOT);
        let c = cpa([0.0, 0.0], own_v, [0.0, 8.0 * METRES_PER_NM], tgt_v);
        assert!(c.cpa_m < 1.0, "{c:?}");
        assert!((c.tcpa_s - 24.0 * 60.0).abs() < 0.5, "{c:?}");
        // Crossing from starboard: passes 1309.5 m (1852/√2) off in 385.2 s.
        let c = cpa(
            [0.0, 0.0],
            [0.0, 5.0],
            [1000.0, 1852.0 + 1000.0],
            [-5.0, 0.0],
        );
        assert!(
            (c.tcpa_s - 385.2).abs() < 1e-2 && (c.cpa_m - 1852.0 / 2f32.sqrt()).abs() < 0.5,
            "{c:?}"
        );
        // Same velocity: the range never changes.
        let c = cpa([0.0, 0.0], [3.0, 4.0], [100.0, 0.0], [3.0, 4.0]);
        assert_eq!(
            c,
            Cpa {
                cpa_m: 100.0,
                tcpa_s: 0.0
            }
        );
    }
}
