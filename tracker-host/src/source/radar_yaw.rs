//! Own ship's yaw measured from the radar picture, for a head-up radar with no heading at
//! all (no heading sensor, no NMEA): the fixed heading of a moored ship
//! ([`super::radar::RadarOptions::fixed_heading_rad`]) is only where the bow pointed at the
//! start. A moored or anchored ship swings; head-up, the whole picture turns the other way
//! about own ship, and every stationary echo (buoys, moored boats, quays) moves across the
//! frame: on the Garmin xHD capture 10–25° over 75 s, at 200–300 m tens of metres, which its
//! tracks show as 1–2 kn.
//!
//! [`PictureYaw`] measures the turn of each rotation's point plots against the previous
//! rotation's, about own ship (scan-to-scan registration, as a radar's own "picture
//! stabilisation" does): the rotation within [`MAX_STEP_RAD`] of the last rotation's (a
//! swing is smooth) that brings most plots onto
//! a plot of the previous rotation (a kernel score, so that moving targets, clutter and
//! echoes seen in one rotation only count for nothing), refined by the least-squares
//! rotation of the plots it matched. The sum of those turns is own ship's heading change
//! since the first rotation; the source adds it to the fixed heading. A rotation with too
//! few matches (a near-empty picture) is taken as not turned.
//!
//! What it cannot see: a turn of own ship and a turn of every target about own ship are the
//! same picture; with most of the echoes stationary (a harbour, a coast) the measurement is
//! own ship's. It measures the heading's change only: the fixed heading's own error stays.

/// How far from the last rotation's turn this rotation's is searched for, rad (3°: a
/// change of yaw rate of 1.2°/s over a 2.5 s rotation; the Garmin capture's swing turns
/// up to 3.2° a rotation, smoothly).
pub const MAX_STEP_RAD: f32 = 3.0 * core::f32::consts::PI / 180.0;

/// The largest turn between two rotations taken, rad (10°: 4°/s over 2.5 s).
pub const MAX_TURN_RAD: f32 = 10.0 * core::f32::consts::PI / 180.0;

/// The search step, rad (0.05°).
const STEP_RAD: f32 = 0.05 * core::f32::consts::PI / 180.0;

/// The least distance within which a plot counts as on a previous plot, m.
pub const MIN_MATCH_M: f32 = 10.0;

/// … or this fraction of its range, when more.
pub const MATCH_FRACTION: f32 = 0.01;

/// The fewest plots that must match for a turn to be taken.
pub const MIN_MATCHES: usize = 6;

/// Own ship's heading change measured from the picture. See the module documentation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PictureYaw {
    /// Heading change since the first rotation, rad (clockwise positive).
    yaw_rad: f32,
    /// The last rotation's plots relative to own ship, with the yaw applied, m (east,
    /// north), and the distance each needs to be matched within, m.
    last: Vec<([f32; 2], f32)>,
    /// Rotations measured.
    measured: u64,
    /// Rotations with too few matches, taken as not turned.
    unmatched: u64,
    /// The last rotation's turn, rad: this one's is searched for about it.
    last_step_rad: f32,
}

impl PictureYaw {
    /// No turn yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Own ship's heading change since the first rotation, rad (clockwise positive).
    pub fn yaw_rad(&self) -> f32 {
        self.yaw_rad
    }

    /// Rotations whose turn was measured, and those with too few plots matched.
    pub fn counts(&self) -> (u64, u64) {
        (self.measured, self.unmatched)
    }

    /// Measures this rotation's turn from its point plots (range m, true bearing rad as
    /// extracted with the yaw so far), adds it to the yaw and returns it (rad, clockwise
    /// positive; 0 for the first rotation or too few matches). Non-finite plots are ignored.
    pub fn measure(&mut self, plots: &[(f32, f32)]) -> f32 {
        let current: Vec<(f32, f32)> = plots
            .iter()
            .copied()
            .filter(|(r, b)| r.is_finite() && b.is_finite() && *r > 0.0)
            .collect();
        let step = if self.last.is_empty() {
            0.0
        } else {
            match self.turn(&current) {
                Some(t) => {
                    self.measured += 1;
                    t
                }
                None => {
                    self.unmatched += 1;
                    0.0
                }
            }
        };
        self.last_step_rad = step;
        self.yaw_rad = tracker_core::geo::wrap_pi(self.yaw_rad + step);
        self.last = current
            .iter()
            .map(|&(r, b)| (at(r, b + step), tolerance(r)))
            .collect();
        step
    }

    /// The turn that brings `current` onto the last rotation's plots, if enough match.
    fn turn(&self, current: &[(f32, f32)]) -> Option<f32> {
        let steps = (MAX_STEP_RAD / STEP_RAD).round() as i32;
        let mut best: Option<(f32, f32)> = None;
        for k in -steps..=steps {
            let turn = self.last_step_rad + k as f32 * STEP_RAD;
            let score: f32 = current
                .iter()
                .filter_map(|&(r, b)| self.nearest(at(r, b + turn)))
                .map(|(d, tol, _)| (1.0 - (d / tol).powi(2)).max(0.0))
                .sum();
            // Ties go to the turn nearer the last one.
            let nearer =
                |t: f32| (turn - self.last_step_rad).abs() < (t - self.last_step_rad).abs();
            if best.is_none_or(|(s, t)| score > s || (score == s && nearer(t))) {
                best = Some((score, turn));
            }
        }
        let (_, coarse) = best?;
        // Refine: the least-squares rotation about own ship of the pairs matched there.
        let (mut cross, mut dot, mut matched) = (0.0f64, 0.0f64, 0usize);
        for &(r, b) in current {
            let p = at(r, b + coarse);
            let Some((d, tol, q)) = self.nearest(p) else {
                continue;
            };
            if d > tol {
                continue;
            }
            matched += 1;
            // Clockwise from north: east = r sin b, north = r cos b; turning p onto q
            // clockwise by ε has sin ε ∝ p_north q_east − p_east q_north.
            cross += f64::from(p[1]) * f64::from(q[0]) - f64::from(p[0]) * f64::from(q[1]);
            dot += f64::from(p[0]) * f64::from(q[0]) + f64::from(p[1]) * f64::from(q[1]);
        }
        let enough =
            matched >= MIN_MATCHES && matched * 10 >= current.len().min(self.last.len()) * 3;
        if !enough || dot <= 0.0 {
            return None;
        }
        let fine = coarse + cross.atan2(dot) as f32;
        (fine.is_finite() && fine.abs() <= MAX_TURN_RAD).then_some(fine)
    }

    /// The last rotation's plot nearest `p`: its distance, its matching distance and where
    /// it is.
    fn nearest(&self, p: [f32; 2]) -> Option<(f32, f32, [f32; 2])> {
        self.last
            .iter()
            .map(|&(q, tol)| ((p[0] - q[0]).hypot(p[1] - q[1]), tol, q))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}

/// East, north of range `r` m, bearing `b` rad.
fn at(r: f32, b: f32) -> [f32; 2] {
    let (s, c) = b.sin_cos();
    [r * s, r * c]
}

/// The distance within which a plot at range `r` m counts as on a previous plot, m.
fn tolerance(r: f32) -> f32 {
    (MATCH_FRACTION * r).max(MIN_MATCH_M)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A harbour's echoes: `n` plots between 100 and 1,300 m, all round, deterministic.
    fn harbour(n: usize) -> Vec<(f32, f32)> {
        (0..n)
            .map(|i| {
                let f = i as f32;
                (
                    100.0 + (f * 137.0) % 1200.0,
                    (f * 2.399).rem_euclid(core::f32::consts::TAU),
                )
            })
            .collect()
    }

    fn turned(p: &[(f32, f32)], by: f32) -> Vec<(f32, f32)> {
        p.iter().map(|&(r, b)| (r, b + by)).collect()
    }

    #[test]
    fn a_swinging_ships_turns_are_measured_and_summed() {
        let echoes = harbour(30);
        let mut yaw = PictureYaw::new();
        assert_eq!(yaw.measure(&echoes), 0.0);
        // The ship turns to port 1.5°, then 0.7° more, then back 2.9°: head-up with the
        // heading fixed the picture turns the other way, the plots' bearings grow; the
        // plots are extracted with the fixed heading plus the yaw measured so far, and the
        // heading change measured is the turn that takes them back.
        let mut picture = 0.0f32;
        for ship in [-1.5f32, -0.7, 2.9] {
            picture -= ship.to_radians();
            let step = yaw.measure(&turned(&echoes, picture + yaw.yaw_rad()));
            assert!(
                (step - ship.to_radians()).abs() < 0.01f32.to_radians(),
                "{step}"
            );
        }
        assert!((yaw.yaw_rad() - 0.7f32.to_radians()).abs() < 0.02f32.to_radians());
        assert_eq!(yaw.counts(), (3, 0));
    }

    #[test]
    fn a_steady_swing_faster_than_the_search_is_followed() {
        // 2.5°, then 4.5° a rotation three times: each within 3° of the last.
        let echoes = harbour(30);
        let mut yaw = PictureYaw::new();
        yaw.measure(&echoes);
        let mut picture = 0.0f32;
        for ship in [2.5f32, 4.5, 4.5, 4.5] {
            picture -= ship.to_radians();
            let step = yaw.measure(&turned(&echoes, picture + yaw.yaw_rad()));
            assert!(
                (step - ship.to_radians()).abs() < 0.01f32.to_radians(),
                "{step}"
            );
        }
        assert!((yaw.yaw_rad() - 16.0f32.to_radians()).abs() < 0.05f32.to_radians());
    }

    #[test]
    fn moving_targets_and_clutter_do_not_turn_the_picture() {
        let echoes = harbour(30);
        let mut yaw = PictureYaw::new();
        yaw.measure(&echoes);
        // A third of the plots elsewhere (moving, new, clutter): still no turn.
        let mut next = echoes.clone();
        for p in next.iter_mut().step_by(3) {
            p.0 += 60.0;
            p.1 += 0.3;
        }
        assert!(yaw.measure(&next).abs() < 0.01f32.to_radians());
    }

    #[test]
    fn too_few_plots_or_bad_input_are_no_turn() {
        let mut yaw = PictureYaw::new();
        yaw.measure(&harbour(4));
        assert_eq!(yaw.measure(&turned(&harbour(4), 0.02)), 0.0);
        assert_eq!(yaw.counts(), (0, 1));
        assert_eq!(yaw.measure(&[(f32::NAN, 0.0), (10.0, f32::INFINITY)]), 0.0);
        assert_eq!(yaw.measure(&[]), 0.0);
        assert!(yaw.yaw_rad().abs() < 1e-6);
    }
}
