//! Scenario simulation: own ship, targets that manoeuvre, and the radar plots of each scan.
//!
//! Deterministic from a seed (PCG32 and `libm`, the same on the MCU and the host), so a run
//! repeats exactly on either, as the thesis's DSP generated its own data. Fixed capacity,
//! no heap.
//!
//! ## The sensor
//!
//! Range and bearing errors follow the IMO ARPA performance standard's sensor model
//! (A.823(19) Appendix 3, the figures the accuracy issue uses): range, Gaussian pulse error
//! σ 20 m plus target glint σ 30 m plus a uniform quantisation error of ±0.01 NM; bearing,
//! beam shape σ 0.05° and encoder σ 0.03° plus uniform backlash ±0.05° and quantisation
//! ±0.1°. Own-ship errors (gyro, log, roll) belong to the navigation filter and are not
//! modelled here. Each target is detected with probability `pd`; clutter is a Poisson
//! number of plots per scan spread uniformly over the radar's area.

use heapless::Vec;
use rand::RngExt;
use rand_core::SeedableRng;
use rand_distr::{Distribution, Normal, Poisson};
use rand_pcg::Pcg32;

use crate::geo::{self, EastNorth, METRES_PER_NM, MPS_PER_KNOT};
use crate::icd::Plot;

/// Most targets a scenario holds.
pub const MAX_TARGETS: usize = 64;

/// Most plots one scan produces (targets and clutter).
pub const MAX_PLOTS: usize = 256;

/// The radar's error and detection model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorModel {
    /// Gaussian range errors (pulse, glint), m.
    pub range_sigmas_m: [f32; 2],
    /// Uniform range quantisation half-width, m.
    pub range_quantisation_m: f32,
    /// Gaussian bearing errors (beam shape, encoder), rad.
    pub bearing_sigmas_rad: [f32; 2],
    /// Uniform bearing error half-widths (backlash, quantisation), rad.
    pub bearing_uniform_rad: [f32; 2],
    /// Probability of detecting a target on a scan.
    pub pd: f32,
    /// Mean clutter plots per scan.
    pub clutter_per_scan: f32,
    /// Radar range, m.
    pub max_range_m: f32,
    /// Blind range around own ship, m.
    pub min_range_m: f32,
    /// Targets closer than this in range *and* [`SensorModel::bearing_resolution_rad`] in
    /// bearing return one plot (the pulse length and the beam width), m.
    pub range_resolution_m: f32,
    /// See [`SensorModel::range_resolution_m`], rad.
    pub bearing_resolution_rad: f32,
}

impl SensorModel {
    /// The IMO model, P_d = 0.9, 10 clutter plots a scan, 12 NM range.
    pub fn imo() -> Self {
        let deg = core::f32::consts::PI / 180.0;
        SensorModel {
            range_sigmas_m: [20.0, 30.0],
            range_quantisation_m: 0.01 * METRES_PER_NM,
            bearing_sigmas_rad: [0.05 * deg, 0.03 * deg],
            bearing_uniform_rad: [0.05 * deg, 0.1 * deg],
            pd: 0.9,
            clutter_per_scan: 10.0,
            max_range_m: 12.0 * METRES_PER_NM,
            min_range_m: 0.2 * METRES_PER_NM,
            range_resolution_m: 50.0,
            bearing_resolution_rad: 1.0 * deg,
        }
    }

    /// Standard deviation of the range error, m.
    pub fn range_sigma_m(&self) -> f32 {
        let [a, b] = self.range_sigmas_m;
        let q = self.range_quantisation_m;
        libm::sqrtf(a * a + b * b + q * q / 3.0)
    }

    /// Standard deviation of the bearing error, rad.
    pub fn bearing_sigma_rad(&self) -> f32 {
        let [a, b] = self.bearing_sigmas_rad;
        let [u, v] = self.bearing_uniform_rad;
        libm::sqrtf(a * a + b * b + (u * u + v * v) / 3.0)
    }
}

/// The kinds of scenario.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ScenarioKind {
    /// Targets scattered 2–10 NM around own ship on random courses at 5–20 kn, each
    /// turning or changing speed now and then; a quarter of them in crossing pairs.
    OpenSea,
    /// Every target in a crossing pair: the two pass 0.2–0.6 NM apart 2–6 minutes in, at
    /// crossing angles from 20° to 160°.
    Crossing,
    /// Every target in a merging pair: one ship overtakes another on a course along the line
    /// of sight, 52–158 m abeam (more than the plots' noise, inside one bearing cell 4–7 NM
    /// out), so the two share a resolution cell for a minute or more (the radar gives one
    /// plot for both) and draw apart again; abeam 150–300 s in, both on steady courses.
    Merging,
}

/// Scenario parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScenarioConfig {
    /// Which scenario.
    pub kind: ScenarioKind,
    /// Number of targets (at most [`MAX_TARGETS`]).
    pub targets: usize,
    /// Seed of every random draw.
    pub seed: u64,
    /// Antenna period, s (2–3 s: 20–30 rpm).
    pub scan_s: f32,
    /// Own ship's speed, m/s, on a steady course.
    pub own_speed_mps: f32,
    /// Own ship's course, rad true.
    pub own_course_rad: f32,
    /// The radar.
    pub sensor: SensorModel,
}

impl ScenarioConfig {
    /// Open sea, 40 targets, 2.5 s scans, own ship 12 kn on 000°.
    pub fn open_sea(targets: usize, seed: u64) -> Self {
        ScenarioConfig {
            kind: ScenarioKind::OpenSea,
            targets,
            seed,
            scan_s: 2.5,
            own_speed_mps: 12.0 * MPS_PER_KNOT,
            own_course_rad: 0.0,
            sensor: SensorModel::imo(),
        }
    }
}

/// A ship in the simulation: where it is and how it moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ship {
    /// Identity (0 is own ship).
    pub id: u16,
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Course, rad true.
    pub course_rad: f32,
    /// Speed, m/s.
    pub speed_mps: f32,
    turn_rate_rad_s: f32,
    accel_mps2: f32,
    manoeuvre_left_s: f32,
    next_manoeuvre_s: f32,
}

impl Ship {
    fn new(id: u16, position_m: EastNorth, course_rad: f32, speed_mps: f32) -> Self {
        Ship {
            id,
            position_m,
            course_rad,
            speed_mps,
            turn_rate_rad_s: 0.0,
            accel_mps2: 0.0,
            manoeuvre_left_s: 0.0,
            next_manoeuvre_s: f32::INFINITY,
        }
    }

    /// Velocity, m/s.
    pub fn velocity_mps(&self) -> EastNorth {
        geo::velocity(self.course_rad, self.speed_mps)
    }

    fn step(&mut self, dt: f32) {
        // Midpoint rule on the course: exact for constant turn rate to second order.
        let mid = self.course_rad + 0.5 * self.turn_rate_rad_s * dt;
        let v = self.speed_mps + 0.5 * self.accel_mps2 * dt;
        let (s, c) = libm::sincosf(mid);
        self.position_m[0] += v * s * dt;
        self.position_m[1] += v * c * dt;
        self.course_rad = geo::wrap_2pi(self.course_rad + self.turn_rate_rad_s * dt);
        self.speed_mps = (self.speed_mps + self.accel_mps2 * dt).clamp(0.5, 20.0);
        if self.manoeuvre_left_s > 0.0 {
            self.manoeuvre_left_s -= dt;
            if self.manoeuvre_left_s <= 0.0 {
                self.turn_rate_rad_s = 0.0;
                self.accel_mps2 = 0.0;
            }
        }
        self.next_manoeuvre_s -= dt;
    }
}

/// The truth about one target at a scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Truth {
    /// Target identity.
    pub id: u16,
    /// Position, local frame, m.
    pub position_m: EastNorth,
    /// Velocity, m/s.
    pub velocity_mps: EastNorth,
    /// Whether this scan detected it.
    pub detected: bool,
    /// Whether it is inside the radar's range (blind range to maximum range) this scan.
    pub in_range: bool,
}

/// One antenna revolution's output.
#[derive(Clone, Debug, Default)]
pub struct ScanOutput {
    /// Scan number, from 0.
    pub scan: u32,
    /// Time of the scan, ms from the start.
    pub time_ms: u64,
    /// Own ship (truth), local frame.
    pub own_position_m: EastNorth,
    /// Own ship's velocity (truth), m/s.
    pub own_velocity_mps: EastNorth,
    /// Plots sorted by bearing, as the sweep delivers them.
    pub plots: Vec<Plot, MAX_PLOTS>,
    /// For each plot, the target it came from (`None`: clutter).
    pub plot_source: Vec<Option<u16>, MAX_PLOTS>,
    /// Every target's truth.
    pub truth: Vec<Truth, MAX_TARGETS>,
}

impl ScanOutput {
    /// No scan yet: what [`Default`] gives, as a constant, so that a static can hold one
    /// without building it on the stack (the firmware's benchmark).
    pub const EMPTY: ScanOutput = ScanOutput {
        scan: 0,
        time_ms: 0,
        own_position_m: [0.0, 0.0],
        own_velocity_mps: [0.0, 0.0],
        plots: Vec::new(),
        plot_source: Vec::new(),
        truth: Vec::new(),
    };
}

/// A running scenario.
#[derive(Clone, Debug)]
pub struct Scenario {
    config: ScenarioConfig,
    rng: Pcg32,
    own: Ship,
    targets: Vec<Ship, MAX_TARGETS>,
    scan: u32,
    time_s: f64,
}

impl Scenario {
    /// Places own ship and the targets.
    pub fn new(config: ScenarioConfig) -> Self {
        let mut rng = Pcg32::seed_from_u64(config.seed);
        let own = Ship::new(0, [0.0, 0.0], config.own_course_rad, config.own_speed_mps);
        let mut targets: Vec<Ship, MAX_TARGETS> = Vec::new();
        let n = config.targets.min(MAX_TARGETS);
        let paired = match config.kind {
            ScenarioKind::OpenSea => n / 4 * 2,
            ScenarioKind::Crossing | ScenarioKind::Merging => n / 2 * 2,
        };
        let mut id = 1u16;
        while (targets.len()) < paired {
            let [a, b] = match config.kind {
                ScenarioKind::Merging => merging_pair(&mut rng, &own, id),
                _ => crossing_pair(&mut rng, &own, id),
            };
            let _ = targets.push(a);
            let _ = targets.push(b);
            id += 2;
        }
        while targets.len() < n {
            let range = rng.random_range(2.0..10.0) * METRES_PER_NM;
            let bearing = rng.random_range(0.0..core::f32::consts::TAU);
            let course = rng.random_range(0.0..core::f32::consts::TAU);
            let speed = rng.random_range(5.0..20.0) * MPS_PER_KNOT;
            let mut ship = Ship::new(
                id,
                geo::polar_to_local(own.position_m, range, bearing),
                course,
                speed,
            );
            ship.next_manoeuvre_s = rng.random_range(60.0..600.0);
            let _ = targets.push(ship);
            id += 1;
        }
        Scenario {
            config,
            rng,
            own,
            targets,
            scan: 0,
            time_s: 0.0,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ScenarioConfig {
        &self.config
    }

    /// Own ship.
    pub fn own_ship(&self) -> &Ship {
        &self.own
    }

    /// Puts own ship at `position_m` moving at `velocity_mps` (a recorded track the picture
    /// moves with); it goes on from there at that velocity unless set again.
    pub fn set_own_ship(&mut self, position_m: EastNorth, velocity_mps: EastNorth) {
        let (course, speed) = geo::course_speed(velocity_mps);
        self.own.position_m = position_m;
        self.own.course_rad = course;
        self.own.speed_mps = speed;
        self.own.turn_rate_rad_s = 0.0;
        self.own.accel_mps2 = 0.0;
    }

    /// The targets.
    pub fn targets(&self) -> &[Ship] {
        &self.targets
    }

    /// Produces the next scan's plots, then moves everything on by one antenna period.
    pub fn next_scan(&mut self) -> ScanOutput {
        let mut out = ScanOutput::default();
        self.next_scan_into(&mut out);
        out
    }

    /// [`Scenario::next_scan`] into a buffer the caller keeps (on a small stack, a static).
    pub fn next_scan_into(&mut self, out: &mut ScanOutput) {
        let sensor = self.config.sensor;
        out.scan = self.scan;
        out.time_ms = (self.time_s * 1000.0) as u64;
        out.own_position_m = self.own.position_m;
        out.own_velocity_mps = self.own.velocity_mps();
        sense(
            &sensor,
            &mut self.rng,
            self.own.position_m,
            self.targets
                .iter()
                .map(|t| (t.id, t.position_m, t.velocity_mps())),
            out,
        );
        self.advance();
    }

    fn advance(&mut self) {
        let dt = self.config.scan_s;
        self.own.step(dt);
        for t in &mut self.targets {
            if t.next_manoeuvre_s <= 0.0 && t.manoeuvre_left_s <= 0.0 {
                // A turn of 1–3°/s, sometimes with a speed change, for 20–60 s.
                let deg = core::f32::consts::PI / 180.0;
                let rate = self.rng.random_range(1.0..3.0) * deg;
                t.turn_rate_rad_s = if self.rng.random::<bool>() {
                    rate
                } else {
                    -rate
                };
                t.accel_mps2 = if self.rng.random::<f32>() < 0.3 {
                    self.rng.random_range(-0.05..0.05)
                } else {
                    0.0
                };
                t.manoeuvre_left_s = self.rng.random_range(20.0..60.0);
                t.next_manoeuvre_s = self.rng.random_range(120.0..900.0);
            }
            t.step(dt);
        }
        self.scan += 1;
        self.time_s += f64::from(dt);
    }
}

/// One scan of the radar model: each target (id, position m, velocity m/s) in range is
/// detected with P_d and measured with the model's range and bearing errors, targets
/// sharing a resolution cell give one plot (the first's), Poisson clutter is added over the
/// annulus, and the plots are sorted by bearing; `out`'s plots, their sources and the truth
/// are replaced (its scan, time and own ship are the caller's). The draws come from `rng` in
/// a fixed order, so a seed gives the same scan.
fn sense(
    sensor: &SensorModel,
    rng: &mut Pcg32,
    own_m: EastNorth,
    targets: impl Iterator<Item = (u16, EastNorth, EastNorth)>,
    out: &mut ScanOutput,
) {
    out.plots.clear();
    out.plot_source.clear();
    out.truth.clear();
    let mut raw: Vec<(Plot, Option<u16>), MAX_PLOTS> = Vec::new();
    for (id, position_m, velocity_mps) in targets {
        let (range, bearing) = geo::range_bearing(own_m, position_m);
        let visible = range >= sensor.min_range_m && range <= sensor.max_range_m;
        let detected = visible && rng.random::<f32>() < sensor.pd;
        // Two targets in one resolution cell echo as one: the first one's plot stands.
        let merged = raw.iter().any(|(p, _)| {
            (p.range_m - range).abs() < sensor.range_resolution_m
                && geo::wrap_pi(p.bearing_rad - bearing).abs() < sensor.bearing_resolution_rad
        });
        if detected && !merged {
            let plot = Plot {
                range_m: range + range_error(rng, sensor),
                bearing_rad: geo::wrap_2pi(bearing + bearing_error(rng, sensor)),
            };
            let _ = raw.push((plot, Some(id)));
        }
        let _ = out.truth.push(Truth {
            id,
            position_m,
            velocity_mps,
            detected,
            in_range: visible,
        });
    }
    let clutter = Poisson::new(sensor.clutter_per_scan.max(1e-6))
        .map(|p| p.sample(rng) as usize)
        .unwrap_or(0);
    let (r0, r1) = (sensor.min_range_m, sensor.max_range_m);
    for _ in 0..clutter {
        // Uniform over the annulus: range² uniform.
        let u: f32 = rng.random();
        let range = libm::sqrtf(r0 * r0 + u * (r1 * r1 - r0 * r0));
        let bearing = rng.random_range(0.0..core::f32::consts::TAU);
        if raw
            .push((
                Plot {
                    range_m: range,
                    bearing_rad: bearing,
                },
                None,
            ))
            .is_err()
        {
            break;
        }
    }
    raw.sort_unstable_by(|a, b| a.0.bearing_rad.total_cmp(&b.0.bearing_rad));
    // By reference: moving the list into its iterator copies 3 KB of stack on the MCU.
    for &(p, s) in raw.iter() {
        let _ = out.plots.push(p);
        let _ = out.plot_source.push(s);
    }
}

/// The scenario's radar model on ships it does not move: targets from elsewhere (real ship
/// tracks) sensed scan by scan with the same errors, P_d, clutter and resolution as
/// [`Scenario`]'s.
#[derive(Clone, Debug)]
pub struct PlotModel {
    sensor: SensorModel,
    rng: Pcg32,
}

impl PlotModel {
    /// The model `sensor`, its draws from `seed`.
    pub fn new(sensor: SensorModel, seed: u64) -> Self {
        PlotModel {
            sensor,
            rng: Pcg32::seed_from_u64(seed),
        }
    }

    /// The sensor model.
    pub fn sensor(&self) -> &SensorModel {
        &self.sensor
    }

    /// One scan of `targets` (id, position m, velocity m/s; at most [`MAX_TARGETS`] are
    /// kept in the truth) from own ship at `own_m`, into `out` (its plots, their sources and
    /// the truth; the caller sets its scan, time and own ship).
    pub fn sense(
        &mut self,
        own_m: EastNorth,
        targets: impl Iterator<Item = (u16, EastNorth, EastNorth)>,
        out: &mut ScanOutput,
    ) {
        sense(&self.sensor, &mut self.rng, own_m, targets, out);
    }
}

fn range_error(rng: &mut Pcg32, s: &SensorModel) -> f32 {
    let mut e = 0.0;
    for sigma in s.range_sigmas_m {
        e += Normal::new(0.0, sigma).map_or(0.0, |n| n.sample(rng));
    }
    e + rng.random_range(-1.0f32..1.0) * s.range_quantisation_m
}

fn bearing_error(rng: &mut Pcg32, s: &SensorModel) -> f32 {
    let mut e = 0.0;
    for sigma in s.bearing_sigmas_rad {
        e += Normal::new(0.0, sigma).map_or(0.0, |n| n.sample(rng));
    }
    for half in s.bearing_uniform_rad {
        e += rng.random_range(-1.0f32..1.0) * half;
    }
    e
}

/// True when targets at `a` and `b` (m, local frame) lie in one resolution cell of `sensor`
/// seen from own ship at `own_m`: closer than [`SensorModel::range_resolution_m`] in range
/// and [`SensorModel::bearing_resolution_rad`] in bearing, by their true positions. (A scan
/// compares the first one's measured plot with the second's true position.)
pub fn in_one_cell(sensor: &SensorModel, own_m: EastNorth, a: EastNorth, b: EastNorth) -> bool {
    let (ra, ba) = geo::range_bearing(own_m, a);
    let (rb, bb) = geo::range_bearing(own_m, b);
    (ra - rb).abs() < sensor.range_resolution_m
        && geo::wrap_pi(ba - bb).abs() < sensor.bearing_resolution_rad
}

/// Two targets on one course, the second overtaking the first ([`ScenarioKind::Merging`]):
/// both head along the line of sight from own ship (±10°), 4–7 NM out when abeam, 150–300 s
/// in; B passes A abeam at 0.4–0.7 of a bearing cell (52–158 m: more than the plots' noise,
/// less than the cell) and 0.8–1.2 m/s faster, so the two share a cell while B is within a
/// range cell of A, 40–60 s either side of abeam. A is the first, whose plot a merged echo
/// gives; both steady, at 8–14 kn.
fn merging_pair(rng: &mut Pcg32, own: &Ship, id: u16) -> [Ship; 2] {
    let abeam_s = rng.random_range(150.0..300.0);
    let own_then = [
        own.position_m[0] + own.velocity_mps()[0] * abeam_s,
        own.position_m[1] + own.velocity_mps()[1] * abeam_s,
    ];
    let range_m = rng.random_range(4.0..7.0) * METRES_PER_NM;
    let bearing = rng.random_range(0.0..core::f32::consts::TAU);
    let meet = geo::polar_to_local(own_then, range_m, bearing);
    let deg = core::f32::consts::PI / 180.0;
    let outbound = rng.random::<bool>();
    let course = geo::wrap_2pi(
        bearing
            + if outbound { 0.0 } else { core::f32::consts::PI }
            + rng.random_range(-10.0..10.0) * deg,
    );
    let speed_a = rng.random_range(8.0..14.0) * MPS_PER_KNOT;
    let speed_b = speed_a + rng.random_range(0.8..1.2);
    let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
    let abeam_m =
        side * rng.random_range(0.4..0.7) * range_m * SensorModel::imo().bearing_resolution_rad;
    let (s, c) = libm::sincosf(course);
    let b_then = [meet[0] + abeam_m * c, meet[1] - abeam_m * s];
    let start = |p: EastNorth, v: f32| [p[0] - v * s * abeam_s, p[1] - v * c * abeam_s];
    [
        Ship::new(id, start(meet, speed_a), course, speed_a),
        Ship::new(id + 1, start(b_then, speed_b), course, speed_b),
    ]
}

/// Two targets that pass 0.2–0.6 NM apart 2–6 minutes in, crossing at 20°–160°, steady.
fn crossing_pair(rng: &mut Pcg32, own: &Ship, id: u16) -> [Ship; 2] {
    let meet_s = rng.random_range(120.0..360.0);
    // The meeting point is where own ship will be at that time, offset 1–6 NM.
    let own_then = [
        own.position_m[0] + own.velocity_mps()[0] * meet_s,
        own.position_m[1] + own.velocity_mps()[1] * meet_s,
    ];
    let meet = geo::polar_to_local(
        own_then,
        rng.random_range(1.0..6.0) * METRES_PER_NM,
        rng.random_range(0.0..core::f32::consts::TAU),
    );
    let course_a = rng.random_range(0.0..core::f32::consts::TAU);
    let angle = rng.random_range(20.0f32..160.0).to_radians();
    let course_b = geo::wrap_2pi(course_a + if rng.random::<bool>() { angle } else { -angle });
    // A reaches the meeting point at `meet_s`; B is then `miss` away across their relative
    // motion, so that is their closest approach, as ships keeping clear pass.
    let miss = rng.random_range(0.2..0.6) * METRES_PER_NM;
    let va = geo::velocity(course_a, rng.random_range(8.0..18.0) * MPS_PER_KNOT);
    let vb = geo::velocity(course_b, rng.random_range(8.0..18.0) * MPS_PER_KNOT);
    let vr = [vb[0] - va[0], vb[1] - va[1]];
    let norm = libm::hypotf(vr[0], vr[1]).max(1e-3);
    let side = if rng.random::<bool>() { 1.0 } else { -1.0 };
    let b_then = [
        meet[0] - side * miss * vr[1] / norm,
        meet[1] + side * miss * vr[0] / norm,
    ];
    let start = |p: EastNorth, v: EastNorth| [p[0] - v[0] * meet_s, p[1] - v[1] * meet_s];
    let (ca, sa) = geo::course_speed(va);
    let (cb, sb) = geo::course_speed(vb);
    let mut ships = [
        Ship::new(id, start(meet, va), ca, sa),
        Ship::new(id + 1, start(b_then, vb), cb, sb),
    ];
    for s in &mut ships {
        s.next_manoeuvre_s = meet_s + rng.random_range(120.0..600.0);
    }
    ships
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_gives_the_same_scans() {
        let cfg = ScenarioConfig::open_sea(40, 9);
        let (mut a, mut b) = (Scenario::new(cfg), Scenario::new(cfg));
        for _ in 0..50 {
            let (x, y) = (a.next_scan(), b.next_scan());
            assert_eq!(x.plots, y.plots);
            assert_eq!(x.truth, y.truth);
        }
        let mut c = Scenario::new(ScenarioConfig { seed: 10, ..cfg });
        assert_ne!(c.next_scan().plots, Scenario::new(cfg).next_scan().plots);
    }

    #[test]
    fn detections_clutter_and_errors_follow_the_model() {
        let cfg = ScenarioConfig::open_sea(40, 3);
        let mut s = Scenario::new(cfg);
        let (mut detected, mut visible, mut clutter, mut scans) = (0usize, 0usize, 0usize, 0usize);
        let (mut sum_sq_range, mut n_err) = (0.0f64, 0usize);
        for _ in 0..400 {
            let out = s.next_scan();
            scans += 1;
            clutter += out.plot_source.iter().filter(|p| p.is_none()).count();
            for t in &out.truth {
                let (r, _) = geo::range_bearing(out.own_position_m, t.position_m);
                if r >= cfg.sensor.min_range_m && r <= cfg.sensor.max_range_m {
                    visible += 1;
                    detected += usize::from(t.detected);
                }
            }
            for (p, src) in out.plots.iter().zip(&out.plot_source) {
                if let Some(id) = src {
                    let t = out.truth.iter().find(|t| t.id == *id).unwrap();
                    let (r, _) = geo::range_bearing(out.own_position_m, t.position_m);
                    sum_sq_range += f64::from(p.range_m - r).powi(2);
                    n_err += 1;
                }
            }
            assert!(out
                .plots
                .windows(2)
                .all(|w| w[0].bearing_rad <= w[1].bearing_rad));
        }
        let pd = detected as f64 / visible as f64;
        assert!((pd - 0.9).abs() < 0.01, "pd {pd}");
        let lambda = clutter as f64 / scans as f64;
        assert!((lambda - 10.0).abs() < 0.5, "clutter {lambda}");
        let sigma = (sum_sq_range / n_err as f64).sqrt();
        let expected = f64::from(cfg.sensor.range_sigma_m());
        assert!(
            (sigma - expected).abs() / expected < 0.05,
            "range sigma {sigma} vs {expected}"
        );
    }

    #[test]
    fn merging_pairs_share_a_cell_then_separate() {
        let cfg = ScenarioConfig {
            kind: ScenarioKind::Merging,
            ..ScenarioConfig::open_sea(12, 4)
        };
        let mut s = Scenario::new(cfg);
        // Per pair: scans in one cell, the first and the last of them, and B's own plots
        // while they share it.
        let mut cell = [(0u32, u32::MAX, 0u32, 0u32); 6];
        let mut last = std::vec::Vec::new();
        for _ in 0..240 {
            let out = s.next_scan();
            for (k, pair) in out.truth.chunks(2).enumerate() {
                let (a, b) = (pair[0], pair[1]);
                if in_one_cell(&cfg.sensor, out.own_position_m, a.position_m, b.position_m) {
                    let c = &mut cell[k];
                    c.0 += 1;
                    c.1 = c.1.min(out.scan);
                    c.2 = out.scan;
                    c.3 += u32::from(out.plot_source.contains(&Some(b.id)));
                }
            }
            last = out.truth.to_vec();
        }
        for (k, &(scans, first, end, b_plots)) in cell.iter().enumerate() {
            // One stretch of a minute or more, well after the start and before the end.
            assert!(
                scans >= 24 && end - first + 1 == scans,
                "pair {k}: {:?}",
                cell[k]
            );
            assert!(first >= 20 && end < 200, "pair {k}: {:?}", cell[k]);
            // Mostly one plot: B shows on its own where A is not detected (P_d 0.9) or A's
            // plot lands a range resolution off B (a scan compares A's measured plot).
            assert!(b_plots * 2 < scans, "pair {k}: {b_plots} of {scans}");
            // At the end they are apart.
            let d = libm::hypotf(
                last[2 * k].position_m[0] - last[2 * k + 1].position_m[0],
                last[2 * k].position_m[1] - last[2 * k + 1].position_m[1],
            );
            assert!(d > 200.0, "pair {k}: {d} m apart at the end");
        }
    }

    #[test]
    fn crossing_pairs_meet() {
        let cfg = ScenarioConfig {
            kind: ScenarioKind::Crossing,
            ..ScenarioConfig::open_sea(10, 5)
        };
        let mut s = Scenario::new(cfg);
        let mut closest = [f32::INFINITY; 5];
        for _ in 0..200 {
            let out = s.next_scan();
            for (k, pair) in out.truth.chunks(2).enumerate() {
                let d = libm::hypotf(
                    pair[0].position_m[0] - pair[1].position_m[0],
                    pair[0].position_m[1] - pair[1].position_m[1],
                );
                closest[k] = closest[k].min(d);
            }
        }
        // They pass 0.2–0.6 NM apart (the closest point lies between scans, so a little
        // more is seen here).
        assert!(
            closest
                .iter()
                .all(|&d| d > 0.15 * METRES_PER_NM && d < 0.7 * METRES_PER_NM),
            "{closest:?}"
        );
    }
}
