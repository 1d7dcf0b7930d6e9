//! Course, speed, CPA and TCPA in f64 for the lab's reference computations (the product's
//! own, in f32, are `tracker_core::geo`'s).

/// Course (degrees true) and speed of a velocity.
pub fn course_speed(v: [f64; 2]) -> (f64, f64) {
    (
        v[0].atan2(v[1]).to_degrees().rem_euclid(360.0),
        v[0].hypot(v[1]),
    )
}

/// CPA, m, and TCPA, s, of a relative position and velocity (TCPA 0 without relative motion).
pub fn cpa(r: [f64; 2], v: [f64; 2]) -> (f64, f64) {
    let v2 = v[0] * v[0] + v[1] * v[1];
    if v2 < 1e-9 {
        return (r[0].hypot(r[1]), 0.0);
    }
    let t = -(r[0] * v[0] + r[1] * v[1]) / v2;
    ((r[0] + v[0] * t).hypot(r[1] + v[1] * t), t)
}
