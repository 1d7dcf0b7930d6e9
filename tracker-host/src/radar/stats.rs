//! The spoke stream of one radar kind, followed spoke by spoke: rotations (angle wraps),
//! spokes per rotation, range changes, and angles that go backwards, repeat or skip.
//!
//! A rotation starts where the angle wraps: a spoke whose angle is more than half a turn
//! below the previous one's. A step backwards of less than half a turn is an out-of-order
//! spoke (the 3G capture jumps back twice by 242 spokes just after transmit starts); a step
//! of 0 repeats an angle; a step forward of more than one spoke skips angles (the 3G's
//! status-0x12 spokes follow one). Rotations are placed by angle, never by count.

use tracker_core::radar::Spoke;

/// Complete rotations whose spoke counts are kept (the first ones; the count goes on).
pub const KEPT_ROTATIONS: usize = 1024;
/// Distinct ranges kept, in the order first seen.
pub const KEPT_RANGES: usize = 16;

/// What a spoke meant for its stream.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpokeMeta {
    /// Its angle wrapped: it starts a rotation.
    pub new_rotation: bool,
    /// Its range differs from the previous spoke's (samples are spaced differently now).
    pub range_changed: bool,
    /// Its angle went back from the previous spoke's (by less than half a turn).
    pub out_of_order: bool,
}

/// One radar kind's spoke stream, counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpokeStats {
    /// Spokes seen.
    pub spokes: u64,
    /// Angle wraps (rotations begun; the first partial rotation is not one).
    pub rotations: u64,
    /// Spokes in each complete rotation (wrap to wrap), the first [`KEPT_ROTATIONS`].
    pub rotation_spokes: Vec<u32>,
    /// Capture or receive time of the first wrap and of the last, s since 1970: the mean
    /// rotation period is their difference over `rotations - 1`.
    pub wrap_times_s: Option<(f64, f64)>,
    /// Spokes whose range differs from the previous spoke's.
    pub range_changes: u64,
    /// The ranges seen, m, in order (the first [`KEPT_RANGES`]).
    pub ranges_m: Vec<f32>,
    /// Spokes whose angle went back.
    pub out_of_order: u64,
    /// Spokes with the previous spoke's angle.
    pub repeated_angles: u64,
    /// Forward steps of more than one spoke.
    pub skips: u64,
    /// Spokes with a heading (`heading_rad` set).
    pub with_heading: u64,
    /// Samples per spoke, the last seen.
    pub samples_per_spoke: usize,
    last: Option<(u16, f32)>,
    in_rotation: Option<u32>,
}

impl SpokeStats {
    /// Counts one spoke taken at `time_s` and says what it meant.
    pub fn observe(&mut self, spoke: &Spoke<'_>, time_s: f64) -> SpokeMeta {
        self.spokes += 1;
        self.with_heading += u64::from(spoke.heading_rad.is_some());
        self.samples_per_spoke = spoke.samples.len();
        if !self.ranges_m.contains(&spoke.range_m) && self.ranges_m.len() < KEPT_RANGES {
            self.ranges_m.push(spoke.range_m);
        }
        let n = i32::from(spoke.spokes_per_rotation.max(1));
        let angle = i32::from(spoke.angle);
        let mut meta = SpokeMeta::default();
        if let Some((prev, prev_range)) = self.last {
            let prev = i32::from(prev);
            meta.range_changed = prev_range != spoke.range_m;
            meta.new_rotation = angle < prev - n / 2;
            let step = (angle - prev).rem_euclid(n);
            meta.out_of_order = step > n / 2 && !meta.new_rotation;
            self.repeated_angles += u64::from(step == 0);
            self.skips += u64::from(step > 1 && step <= n / 2);
        }
        self.range_changes += u64::from(meta.range_changed);
        self.out_of_order += u64::from(meta.out_of_order);
        if meta.new_rotation {
            self.rotations += 1;
            if let Some(count) = self.in_rotation {
                if self.rotation_spokes.len() < KEPT_ROTATIONS {
                    self.rotation_spokes.push(count);
                }
            }
            self.in_rotation = Some(0);
            self.wrap_times_s = Some(match self.wrap_times_s {
                Some((first, _)) => (first, time_s),
                None => (time_s, time_s),
            });
        }
        if let Some(count) = self.in_rotation.as_mut() {
            *count += 1;
        }
        self.last = Some((spoke.angle, spoke.range_m));
        meta
    }

    /// The mean rotation period, s, once two wraps have been seen.
    pub fn mean_rotation_s(&self) -> Option<f64> {
        let (first, last) = self.wrap_times_s?;
        (self.rotations >= 2).then(|| (last - first) / (self.rotations - 1) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spoke(angle: u16, range_m: f32) -> Spoke<'static> {
        Spoke {
            angle,
            spokes_per_rotation: 8,
            north_up: false,
            heading_rad: None,
            range_m,
            time_ms: 0,
            samples: &[],
            max_sample: 15,
        }
    }

    #[test]
    fn rotations_gaps_and_backward_steps() {
        let mut s = SpokeStats::default();
        let angles = [5, 6, 7, 0, 1, 2, 4, 5, 5, 6, 7, 1, 2, 0, 3];
        let mut metas = Vec::new();
        for (i, a) in angles.iter().enumerate() {
            let range = if i < 9 { 100.0 } else { 200.0 };
            metas.push(s.observe(&spoke(*a, range), i as f64));
        }
        // Wraps at 7→0 (i 3) and 7→1 (i 11); 2→0 (i 13) is a step back.
        assert_eq!(s.rotations, 2);
        assert_eq!(s.rotation_spokes, [8]);
        assert_eq!(s.mean_rotation_s(), Some(8.0));
        assert!(metas[3].new_rotation && metas[11].new_rotation);
        assert!(metas[13].out_of_order && !metas[13].new_rotation);
        assert_eq!((s.out_of_order, s.repeated_angles, s.skips), (1, 1, 3));
        assert_eq!(
            (s.range_changes, s.ranges_m.clone()),
            (1, vec![100.0, 200.0])
        );
    }
}
