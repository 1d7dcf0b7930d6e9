//! A synthetic radar: spokes painted from own ship and targets, with the beam, the pulse,
//! receiver noise, sea clutter and rain, quantised like a Navico's 4 bits; for tests and
//! the host (feature `sim`).
//!
//! Deterministic from a seed (PCG32 and `libm`, like [`crate::sim`]). No heap: the radar
//! keeps two rows of `f32` ([`MAX_SAMPLES`] each) and paints into a buffer the caller
//! lends, calling back with each [`Spoke`] as it is painted.
//!
//! ## The model
//!
//! Each cell is the amplitude of a complex sum: the targets' echoes (in phase, so they
//! add) plus circular Gaussian noise whose power is the receiver's plus the sea clutter's
//! plus any rain's. With no echo the amplitude is Rayleigh; with one, Rician. Then it is
//! floored to an integer level and capped at the radar's largest sample, like an ADC.
//!
//! - Beam: a Gaussian azimuth pattern whose one-way −3 dB width is
//!   [`SyntheticConfig::beamwidth_rad`]: the echo's amplitude (two-way voltage) halves
//!   ±half a beam from the target, `2^-(2Δθ/θ₃)²`.
//! - Pulse: the same shape in range, halving ±half of [`SyntheticConfig::pulse_m`].
//! - Size: a target of size s is flat-topped over ±s/2 in range and across the beam before
//!   the beam and pulse shapes take over (a disc seen through the radar's blur).
//! - Receiver noise: Rayleigh of scale [`SyntheticConfig::noise_sigma`] levels.
//! - Sea clutter: Rayleigh of scale `sea_sigma · (sea_reference_m / r)^sea_exponent`
//!   (1.5: clutter power falling as r⁻³, the usual beyond the near-grazing region), strong
//!   near own ship and under the noise beyond 655 m with the defaults. Independent
//!   cell to cell and spoke to spoke: no spiky texture, which real sea clutter has.
//! - Sea control ([`SyntheticConfig::auto_sea`], on by default): a navigator's radar
//!   attenuates its receiver near own ship (sensitivity time control) so that the sea
//!   clutter stays at the noise's level instead of saturating the samples. Nearer than
//!   where the clutter falls to the noise, the echoes, clutter and rain are scaled by
//!   `(r / r_sea)^sea_exponent` before the receiver noise and the quantiser. Without it, on
//!   4 bits, the clutter inside about 450 m sets the CFAR's threshold (10⁻³) above full
//!   scale, and an echo there, saturated at 15, cannot cross it.
//! - Rain: discs of extra Rayleigh noise ([`RainPatch`]).
//! - Main bang: everything nearer than [`SyntheticConfig::main_bang_m`] saturates.
//! - Fluctuation: with [`SyntheticConfig::fluctuating`], each target's echo power is drawn
//!   anew each rotation from an exponential distribution (Swerling I), else steady.
//!
//! Targets and own ship stand still during a rotation. Spoke `i` of a rotation points at
//! `i · 2π/n` from the bow (head-up) or from north (north-up), carries the scene's heading,
//! and is timed `i / n` of the rotation period after the rotation's start. A running
//! scene's ([`Scene::continues`]) pass of the beam across spoke 0 is painted from one
//! state, the last rotation's, as a real antenna sweeps it.
//!
//! ## What the extractor makes of it
//!
//! With the Navico defaults of both ([`SyntheticConfig::navico_4bit`],
//! [`super::config::ExtractorConfig::navico_4bit`]), measured by the test
//! `end_to_end_detection_false_plots_and_accuracy` over 200 rotations of 16 targets
//! 800–7,000 m off in sea clutter (it holds P_d and the false plots within ±10 % of their
//! design, derived there; the CFAR's rate is tested on its own; 2026-12-06, with the sea
//! control; without it the false plots were 4.14 a rotation and the CFAR's rates 0.98,
//! 0.95 and 0.91 × 10⁻³, the clutter near own ship saturating cells that then could not
//! alarm):
//!
//! | | design | measured |
//! |---|---|---|
//! | CFAR false alarms a cell, on this 4-bit noise at σ 3, 2, 1.5 levels | 10⁻³ | 1.033, 1.019, 0.978 × 10⁻³ |
//! | P_d, Swerling I, mean amplitude 21.6 levels | 0.90 | 0.898 |
//! | false plots a rotation | 4.16 | 4.24 |
//! | extra plots split off a target | – | 2.7 % of targets |
//! | RMS plot position error | – | 8.2 m |
//!
//! A rain patch 2 km across at twice the noise's amplitude makes a false plot about once
//! in ten rotations (2 in 20); a breakwater (a line of scatterers 1.5 km long) is one extended return a
//! rotation, a ship 300 m from it a plot.

use heapless::Vec;
use rand::RngExt;
use rand_core::SeedableRng;
use rand_pcg::Pcg32;

use super::spoke::Spoke;
use crate::geo::{self, EastNorth, METRES_PER_NM};
use crate::sim::{Scenario, MAX_TARGETS};

/// Most samples a synthetic spoke holds.
pub const MAX_SAMPLES: usize = 4096;
/// Most rain patches a scene holds.
pub const MAX_RAIN: usize = 8;

/// The synthetic radar's set-up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SyntheticConfig {
    /// Spokes a rotation.
    pub spokes_per_rotation: u16,
    /// Samples a spoke, at most [`MAX_SAMPLES`].
    pub samples: u16,
    /// Range the samples cover, m.
    pub range_m: f32,
    /// The largest sample (15: 4 bits).
    pub max_sample: u8,
    /// Antenna period, ms.
    pub rotation_ms: u32,
    /// Spokes from north (true) or from the bow (false).
    pub north_up: bool,
    /// One-way −3 dB horizontal beamwidth, rad.
    pub beamwidth_rad: f32,
    /// Range over which an echo's amplitude stays above half its peak, m.
    pub pulse_m: f32,
    /// Receiver noise, Rayleigh scale σ, sample levels.
    pub noise_sigma: f32,
    /// Sea clutter's Rayleigh scale at [`SyntheticConfig::sea_reference_m`], sample levels.
    pub sea_sigma: f32,
    /// See [`SyntheticConfig::sea_sigma`], m.
    pub sea_reference_m: f32,
    /// Sea clutter's scale falls as range to minus this.
    pub sea_exponent: f32,
    /// The receiver's sea-clutter control on "auto" (sensitivity time control, STC): nearer
    /// than [`SyntheticConfig::sea_control_range_m`], where the clutter falls to the noise,
    /// the echoes, the clutter and the rain are attenuated as the clutter rises, by
    /// `(r / r_sea)^sea_exponent` in amplitude, before the receiver's noise (which arises
    /// after the attenuator) and the quantiser. The clutter then stays at the noise's level
    /// near own ship instead of saturating the 4 bits: what a navigator's radar does with its
    /// sea control. An echo is attenuated with the clutter but the noise is not: without its
    /// growth as it nears ([`SyntheticConfig::echo_reference_m`] 0) a target of the Navico
    /// defaults' 21.6 levels is attenuated to 10.3 at 400 m and 5.9 at 275 m; with it (the
    /// default), it stands at 27.6 and 33.3, saturating. Off, with the
    /// Navico defaults, inside about 450 m the clutter sets a 10⁻³ threshold above full
    /// scale, which no echo can cross.
    pub auto_sea: bool,
    /// Nearer than this the receiver saturates, m.
    pub main_bang_m: f32,
    /// Echo amplitude of a target when the scene does not say, at the beam's and pulse's
    /// centre, sample levels (may exceed the largest sample: it saturates).
    pub target_amplitude: f32,
    /// Swerling I: each target's echo power drawn each rotation (exponential, mean the
    /// amplitude squared).
    pub fluctuating: bool,
    /// Nearer than this, m, a target's echo grows as it nears: its amplitude is its own
    /// times `(r_ref / r)²`, the radar equation's r⁻⁴ in power (Skolnik, Introduction to
    /// Radar Systems, 3rd ed., 2001, §1.2, the simple form of the radar equation), which a
    /// radar's sea control, attenuating by `(r / r_sea)^sea_exponent`, is set to leave
    /// standing above the clutter it holds down. At and beyond it a target has its own amplitude at every range, as the plot
    /// model's P_d is the same at every range. 0: the same at every range.
    pub echo_reference_m: f32,
}

impl SyntheticConfig {
    /// A Navico-like radar: 2,048 spokes of 1,024 4-bit samples on the 4 NM range (7.2 m
    /// samples), 24 rpm, head-up, 1.8° beam, 25 m pulse, noise σ 2 levels, sea clutter σ 3
    /// at 500 m falling as r^−1.5 with the sea control on auto (so inside 655 m, where
    /// the clutter falls to the noise, it is held there), main bang to 40 m; targets Swerling I of mean amplitude
    /// 21.6 levels (often saturating), which the extractor's Navico defaults detect with
    /// P_d 0.90, the simulator's (see the end-to-end test); a target's echo growing as r⁻²
    /// in amplitude nearer than the sea control's reach, 655 m.
    pub fn navico_4bit() -> Self {
        let config = SyntheticConfig {
            spokes_per_rotation: 2048,
            samples: 1024,
            range_m: 4.0 * METRES_PER_NM,
            max_sample: 15,
            rotation_ms: 2500,
            north_up: false,
            beamwidth_rad: 1.8f32.to_radians(),
            pulse_m: 25.0,
            noise_sigma: 2.0,
            sea_sigma: 3.0,
            sea_reference_m: 500.0,
            sea_exponent: 1.5,
            auto_sea: true,
            main_bang_m: 40.0,
            target_amplitude: 21.6,
            fluctuating: true,
            echo_reference_m: 0.0,
        };
        SyntheticConfig {
            echo_reference_m: config.sea_control_range_m(),
            ..config
        }
    }

    /// Metres per sample.
    pub fn sample_m(&self) -> f32 {
        self.range_m / f32::from(self.samples.max(1))
    }

    /// Where the sea clutter's scale falls to the receiver noise's, m: the sea control's
    /// reach when [`SyntheticConfig::auto_sea`] is on (0 when there is no clutter or no
    /// falling clutter; infinite when there is no noise, and the control then does
    /// nothing: there is no level to hold the clutter at).
    pub fn sea_control_range_m(&self) -> f32 {
        if self.sea_sigma <= 0.0 || self.sea_exponent <= 0.0 {
            return 0.0;
        }
        self.sea_reference_m
            * libm::powf(self.sea_sigma / self.noise_sigma, 1.0 / self.sea_exponent)
    }

    /// The sea control's gain on the echoes, the clutter and the rain at `range_m` (an
    /// amplitude ratio in [0, 1]): `(r / r_sea)^sea_exponent` nearer than the control's
    /// reach (0 at or below range 0, and for a range that is not a number); 1 at and beyond
    /// it, and everywhere when [`SyntheticConfig::auto_sea`] is off or the reach is
    /// infinite.
    pub fn sea_control_gain(&self, range_m: f32) -> f32 {
        self.gain_within(self.sea_control_range_m(), range_m)
    }

    /// [`SyntheticConfig::sea_control_gain`] with the reach worked out once.
    fn gain_within(&self, reach: f32, range_m: f32) -> f32 {
        if !self.auto_sea || !reach.is_finite() || range_m >= reach {
            return 1.0;
        }
        if range_m.is_nan() || range_m <= 0.0 {
            return 0.0;
        }
        libm::powf(range_m / reach, self.sea_exponent)
    }
}

/// Why the synthetic radar refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SyntheticError {
    /// A setting is out of range (no spokes, no samples or more than [`MAX_SAMPLES`], a
    /// range, beam or pulse not positive, a noise level negative).
    Config,
    /// The caller's buffer is shorter than a spoke.
    BufferTooSmall,
    /// More than [`MAX_TARGETS`] targets or [`MAX_RAIN`] rain patches.
    TooMany,
}

impl core::fmt::Display for SyntheticError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            SyntheticError::Config => "synthetic radar setting out of range",
            SyntheticError::BufferTooSmall => "buffer shorter than a spoke",
            SyntheticError::TooMany => "too many targets or rain patches",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for SyntheticError {}

/// Something that echoes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SyntheticTarget {
    /// Where, local frame, m.
    pub position_m: EastNorth,
    /// Its size (a disc's diameter), m; 0 for a point.
    pub size_m: f32,
    /// Echo amplitude at the beam's and pulse's centre, sample levels.
    pub amplitude: f32,
}

/// A patch of rain: extra noise over a disc.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RainPatch {
    /// Centre, local frame, m.
    pub centre_m: EastNorth,
    /// Radius, m.
    pub radius_m: f32,
    /// Rayleigh scale of its return, sample levels.
    pub sigma: f32,
}

/// What the radar sees this rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene<'a> {
    /// Own ship's antenna, local frame, m.
    pub own_position_m: EastNorth,
    /// Own ship's heading, rad true.
    pub heading_rad: f32,
    /// The targets (at most [`MAX_TARGETS`]).
    pub targets: &'a [SyntheticTarget],
    /// The rain (at most [`MAX_RAIN`]).
    pub rain: &'a [RainPatch],
    /// The targets are the last rotation's, in the same order, moved on (a running
    /// scenario): a pass of the beam across the seam is painted from one state
    /// ([`SyntheticRadar::rotation`]). `false` for a scene drawn afresh.
    pub continues: bool,
}

/// The synthetic radar: its set-up, its random numbers, its clock, and two rows of work
/// space (the noise power per range cell, and the echoes of the spoke being painted).
#[derive(Clone, Debug)]
pub struct SyntheticRadar {
    config: SyntheticConfig,
    rng: Pcg32,
    time_ms: u64,
    /// Receiver noise plus sea clutter power, per cell, levels².
    noise_power: [f32; MAX_SAMPLES],
    /// The echoes' amplitude on the spoke being painted, per cell, levels.
    signal: [f32; MAX_SAMPLES],
    /// Each target as the last rotation painted it (by its place in the scene), for the
    /// part of its pass after the seam: see [`SyntheticRadar::rotation`].
    last: Vec<Polar, MAX_TARGETS>,
    /// Where the last rotation's seam pointed, rad true (its heading, head-up).
    last_seam_rad: f32,
}

/// A target as the antenna sees it this rotation.
#[derive(Clone, Copy, Debug)]
struct Polar {
    range_m: f32,
    bearing_rad: f32,
    half_size_m: f32,
    amplitude: f32,
}

impl Polar {
    /// How far a spoke pointing at `pointing` (rad true) is off the target's edge, rad (0
    /// across it).
    fn off_edge_rad(&self, pointing: f32) -> f32 {
        let off = geo::wrap_pi(self.bearing_rad - pointing).abs();
        (off - self.half_size_m / self.range_m.max(1.0)).max(0.0)
    }
}

impl SyntheticRadar {
    /// A radar whose first rotation starts at time 0.
    ///
    /// # Errors
    /// [`SyntheticError::Config`] for a setting out of range.
    pub fn new(config: SyntheticConfig, seed: u64) -> Result<Self, SyntheticError> {
        let positive = |x: f32| x > 0.0 && x.is_finite();
        let non_negative = |x: f32| x >= 0.0 && x.is_finite();
        let ok = config.spokes_per_rotation > 0
            && config.samples > 0
            && usize::from(config.samples) <= MAX_SAMPLES
            && positive(config.range_m)
            && positive(config.beamwidth_rad)
            && positive(config.pulse_m)
            && positive(config.sea_reference_m)
            && non_negative(config.noise_sigma)
            && non_negative(config.sea_sigma)
            && non_negative(config.sea_exponent)
            && non_negative(config.target_amplitude)
            && non_negative(config.echo_reference_m)
            && config.main_bang_m.is_finite();
        if !ok {
            return Err(SyntheticError::Config);
        }
        let mut noise_power = [0.0f32; MAX_SAMPLES];
        let cell = config.sample_m();
        // Clutter nearer than this would only saturate: cap its scale at 4 × full scale.
        let cap = 4.0 * f32::from(config.max_sample);
        let reach = config.sea_control_range_m();
        for (j, p) in noise_power
            .iter_mut()
            .enumerate()
            .take(usize::from(config.samples))
        {
            let r = (j as f32 + 0.5) * cell;
            let sea = if config.auto_sea && reach.is_finite() && r < reach {
                // Held at the noise's scale: the gain's definition, written as such (the
                // product of a huge power and a tiny gain would overflow to NaN).
                config.noise_sigma
            } else {
                config.sea_sigma * libm::powf(config.sea_reference_m / r, config.sea_exponent)
            };
            let sea = if sea < cap { sea } else { cap };
            *p = config.noise_sigma * config.noise_sigma + sea * sea;
        }
        Ok(SyntheticRadar {
            config,
            rng: Pcg32::seed_from_u64(seed),
            time_ms: 0,
            noise_power,
            signal: [0.0; MAX_SAMPLES],
            last: Vec::new(),
            last_seam_rad: 0.0,
        })
    }

    /// The set-up.
    pub fn config(&self) -> &SyntheticConfig {
        &self.config
    }

    /// When the next rotation starts, ms.
    pub fn time_ms(&self) -> u64 {
        self.time_ms
    }

    /// Paints one rotation of `scene`, spoke 0 first, into `buf` (at least
    /// [`SyntheticConfig::samples`] long), calling `on_spoke` with each; then moves the
    /// clock on by a rotation.
    ///
    /// The scene stands still for the rotation, but one pass of the beam over a target is
    /// painted from one state: a target whose echo reaches across the seam (spoke 0, where
    /// one rotation ends and the next begins) is painted in this rotation's first half as
    /// the last rotation painted it (its position, its Swerling draw), the part of its pass
    /// that rotation began at its end. Painted from two states, 2.5 s apart, the two parts
    /// of one echo lay apart (a ship dead ahead running away at 15 m/s by 37 m in range,
    /// two plots each half a beam off its bearing; test
    /// `an_echo_across_the_bow_is_one_plot_on_its_bearing`), where a real antenna sweeps
    /// across the seam in a millisecond. Targets are matched to the last rotation's by
    /// their place in `scene.targets`, so a caller that reorders them must say the scene
    /// does not continue. Known limit: the carry takes every target within two beamwidths
    /// of the seam, on either side, so a target whose echo lies just after the seam is
    /// painted a rotation late while there, one coming into that reach paints one state
    /// twice after the seam, and one leaving it skips one (a one-rotation stall and jump,
    /// of its motion in 2.5 s, once as it passes).
    ///
    /// # Errors
    /// [`SyntheticError::BufferTooSmall`], or [`SyntheticError::TooMany`] targets or rain
    /// patches; nothing is painted then.
    pub fn rotation(
        &mut self,
        scene: &Scene<'_>,
        buf: &mut [u8],
        mut on_spoke: impl FnMut(&Spoke<'_>),
    ) -> Result<(), SyntheticError> {
        let c = self.config;
        let n = usize::from(c.samples);
        let buf = buf.get_mut(..n).ok_or(SyntheticError::BufferTooSmall)?;
        if scene.targets.len() > MAX_TARGETS || scene.rain.len() > MAX_RAIN {
            return Err(SyntheticError::TooMany);
        }
        let mut targets: Vec<Polar, MAX_TARGETS> = Vec::new();
        for t in scene.targets {
            let (range_m, bearing_rad) = geo::range_bearing(scene.own_position_m, t.position_m);
            let scale = if c.fluctuating {
                // Exponential power of mean 1: amplitude √E.
                libm::sqrtf(-libm::logf(uniform(&mut self.rng)))
            } else {
                1.0
            };
            // Nearer than the reference, the echo grows as r⁻² (the main bang's 40 m bounds
            // it: 270 times at the Navico defaults, saturated whatever the control).
            let near = if range_m < c.echo_reference_m {
                let ratio = c.echo_reference_m / range_m.max(c.main_bang_m).max(1.0);
                ratio * ratio
            } else {
                1.0
            };
            let _ = targets.push(Polar {
                range_m,
                bearing_rad,
                half_size_m: 0.5 * t.size_m.max(0.0),
                amplitude: t.amplitude * scale * near,
            });
        }
        let mut rain: Vec<Polar, MAX_RAIN> = Vec::new();
        for p in scene.rain {
            let (range_m, bearing_rad) = geo::range_bearing(scene.own_position_m, p.centre_m);
            let _ = rain.push(Polar {
                range_m,
                bearing_rad,
                half_size_m: p.radius_m.max(0.0),
                amplitude: p.sigma * p.sigma,
            });
        }
        let spokes = c.spokes_per_rotation;
        let rad_per_spoke = core::f32::consts::TAU / f32::from(spokes);
        let seam = if c.north_up { 0.0 } else { scene.heading_rad };
        // The first half's targets: the last rotation's for those whose echo it painted
        // up to the seam.
        let mut first_half = targets.clone();
        let last = if scene.continues { &self.last[..] } else { &[] };
        for (now, last) in first_half.iter_mut().zip(last) {
            if reaches(last, self.last_seam_rad, c.beamwidth_rad) {
                *now = *last;
            }
        }
        for angle in 0..spokes {
            let relative = f32::from(angle) * rad_per_spoke;
            let pointing = relative + seam;
            let painted = if angle < spokes / 2 {
                &first_half
            } else {
                &targets
            };
            self.paint_echoes(painted, pointing);
            let rain_cells = rain_intervals(&rain, pointing, c.sample_m(), n);
            self.paint_noise(buf, &rain_cells);
            let spoke = Spoke {
                angle,
                spokes_per_rotation: spokes,
                north_up: c.north_up,
                heading_rad: Some(geo::wrap_2pi(scene.heading_rad)),
                range_m: c.range_m,
                time_ms: self.time_ms
                    + u64::from(angle) * u64::from(c.rotation_ms) / u64::from(spokes),
                samples: buf,
                max_sample: c.max_sample,
            };
            on_spoke(&spoke);
        }
        self.last = targets;
        self.last_seam_rad = seam;
        self.time_ms += u64::from(c.rotation_ms);
        Ok(())
    }

    /// One rotation of a running scenario: own ship (its course as heading) and every
    /// target as a point of [`SyntheticConfig::target_amplitude`].
    ///
    /// # Errors
    /// As [`SyntheticRadar::rotation`].
    pub fn rotation_from_scenario(
        &mut self,
        scenario: &Scenario,
        rain: &[RainPatch],
        buf: &mut [u8],
        on_spoke: impl FnMut(&Spoke<'_>),
    ) -> Result<(), SyntheticError> {
        let amplitude = self.config.target_amplitude;
        let mut targets: Vec<SyntheticTarget, MAX_TARGETS> = Vec::new();
        for ship in scenario.targets() {
            let _ = targets.push(SyntheticTarget {
                position_m: ship.position_m,
                size_m: 0.0,
                amplitude,
            });
        }
        let own = scenario.own_ship();
        let scene = Scene {
            own_position_m: own.position_m,
            heading_rad: own.course_rad,
            targets: &targets,
            rain,
            continues: true,
        };
        self.rotation(&scene, buf, on_spoke)
    }

    /// The echoes' amplitudes along the spoke pointing at `pointing` (rad true).
    fn paint_echoes(&mut self, targets: &[Polar], pointing: f32) {
        let c = self.config;
        let cell = c.sample_m();
        let n = usize::from(c.samples);
        if let Some(row) = self.signal.get_mut(..n) {
            row.fill(0.0);
        }
        for t in targets {
            let beyond = t.off_edge_rad(pointing);
            if beyond > 2.0 * c.beamwidth_rad {
                continue;
            }
            let x = 2.0 * beyond / c.beamwidth_rad;
            let amplitude = t.amplitude * libm::exp2f(-x * x);
            let reach = t.half_size_m + 2.0 * c.pulse_m;
            let first = ((t.range_m - reach) / cell).max(0.0) as usize;
            let last = (((t.range_m + reach) / cell).max(0.0) as usize + 1).min(n);
            let Some(row) = self.signal.get_mut(first..last) else {
                continue;
            };
            for (j, s) in (first..).zip(row.iter_mut()) {
                let r = (j as f32 + 0.5) * cell;
                let beyond_r = ((r - t.range_m).abs() - t.half_size_m).max(0.0);
                let y = 2.0 * beyond_r / c.pulse_m;
                *s += amplitude * libm::exp2f(-y * y);
            }
        }
    }

    /// Adds noise, clutter and rain to the painted echoes and quantises into `buf`.
    fn paint_noise(&mut self, buf: &mut [u8], rain: &Vec<(usize, usize, f32), MAX_RAIN>) {
        let c = self.config;
        let cell = c.sample_m();
        let max = u32::from(c.max_sample);
        // The sea control's reach: nearer, the echoes and rain are attenuated as the
        // clutter already is in `noise_power` (`new`).
        let reach = if c.auto_sea {
            c.sea_control_range_m()
        } else {
            0.0
        };
        let rng = &mut self.rng;
        for (j, ((out, &s), &p)) in buf
            .iter_mut()
            .zip(self.signal.iter())
            .zip(self.noise_power.iter())
            .enumerate()
        {
            let r = (j as f32 + 0.5) * cell;
            if r < c.main_bang_m {
                *out = c.max_sample;
                continue;
            }
            // Worked out only where there is an echo or rain to attenuate (the clutter's
            // share is in `noise_power` already).
            let near = r < reach;
            let mut power = p;
            for &(a, b, extra) in rain {
                if (a..b).contains(&j) {
                    let gain = if near { c.gain_within(reach, r) } else { 1.0 };
                    power += extra * gain * gain;
                }
            }
            let sigma = libm::sqrtf(power);
            let s = if near && s != 0.0 {
                s * c.gain_within(reach, r)
            } else {
                s
            };
            // Two draws a cell whether or not an echo is painted there: the noise is the
            // same wherever the echoes are, so that two ways of painting them are compared
            // on the same noise (one draw without an echo shifted every later cell's).
            let radius = libm::sqrtf(-2.0 * libm::logf(uniform(rng)));
            let phase = uniform(rng);
            let amplitude = if s == 0.0 {
                sigma * radius
            } else {
                let (sin, cos) = libm::sincosf(core::f32::consts::TAU * phase);
                libm::hypotf(s + sigma * radius * cos, sigma * radius * sin)
            };
            // `as` saturates (and takes NaN to 0): no clamp on a float.
            *out = (amplitude as u32).min(max) as u8;
        }
    }
}

/// Whether `t`'s echo reaches the spoke pointing at `pointing` (rad true) of a beam
/// `beamwidth_rad` wide: beyond two beamwidths off its edge it is below 2⁻¹⁶ of its peak.
fn reaches(t: &Polar, pointing: f32, beamwidth_rad: f32) -> bool {
    t.off_edge_rad(pointing) <= 2.0 * beamwidth_rad
}

/// A uniform draw in (0, 1] (never 0: its logarithm is taken).
fn uniform(rng: &mut Pcg32) -> f32 {
    1.0 - rng.random::<f32>()
}

/// The cells of a spoke pointing at `pointing` inside each rain disc, with its power.
fn rain_intervals(
    rain: &[Polar],
    pointing: f32,
    cell_m: f32,
    samples: usize,
) -> Vec<(usize, usize, f32), MAX_RAIN> {
    let mut out = Vec::new();
    for p in rain {
        let (sin, cos) = libm::sincosf(p.bearing_rad - pointing);
        let across = p.range_m * sin;
        let radius = p.half_size_m;
        if across.abs() >= radius {
            continue;
        }
        let along = p.range_m * cos;
        let half_chord = libm::sqrtf(radius * radius - across * across);
        let near = ((along - half_chord) / cell_m).max(0.0) as usize;
        let far = (((along + half_chord) / cell_m).max(0.0) as usize).min(samples);
        if far > near {
            let _ = out.push((near, far, p.amplitude));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radar::{Event, Extractor, ExtractorConfig, RadarPlot};
    use std::vec::Vec as StdVec;

    fn targets_at(rng: &mut Pcg32, count: usize, near_m: f32, far_m: f32) -> StdVec<EastNorth> {
        // Uniform over the annulus, at least 500 m apart so no two share a blob.
        let mut out: StdVec<EastNorth> = StdVec::new();
        while out.len() < count {
            let u: f32 = rng.random();
            let r = libm::sqrtf(near_m * near_m + u * (far_m * far_m - near_m * near_m));
            let b = rng.random_range(0.0..core::f32::consts::TAU);
            let p = geo::polar_to_local([0.0, 0.0], r, b);
            if out
                .iter()
                .all(|q| libm::hypotf(p[0] - q[0], p[1] - q[1]) > 500.0)
            {
                out.push(p);
            }
        }
        out
    }

    /// A scene about own ship at the origin, drawn afresh (not continuing a last one).
    fn at_origin<'a>(
        targets: &'a [SyntheticTarget],
        rain: &'a [RainPatch],
        heading_rad: f32,
    ) -> Scene<'a> {
        Scene {
            own_position_m: [0.0, 0.0],
            heading_rad,
            targets,
            rain,
            continues: false,
        }
    }

    #[test]
    fn the_same_seed_paints_the_same_spokes() {
        let config = SyntheticConfig {
            spokes_per_rotation: 64,
            samples: 256,
            fluctuating: true,
            ..SyntheticConfig::navico_4bit()
        };
        let target = [SyntheticTarget {
            position_m: [300.0, 900.0],
            size_m: 0.0,
            amplitude: 12.0,
        }];
        let scene = at_origin(&target, &[], 0.3);
        let paint = |seed| {
            let mut radar = SyntheticRadar::new(config, seed).unwrap();
            let mut buf = [0u8; 256];
            let mut all = StdVec::new();
            for _ in 0..2 {
                radar
                    .rotation(&scene, &mut buf, |s| all.extend_from_slice(s.samples))
                    .unwrap();
            }
            (all, radar.time_ms())
        };
        assert_eq!(paint(5), paint(5));
        assert_ne!(paint(5).0, paint(6).0);
        assert_eq!(paint(5).1, 5000);
        // The buffer must hold a spoke.
        let mut radar = SyntheticRadar::new(config, 1).unwrap();
        assert_eq!(
            radar.rotation(&scene, &mut [0u8; 10], |_| {}),
            Err(SyntheticError::BufferTooSmall)
        );
        assert!(SyntheticRadar::new(
            SyntheticConfig {
                samples: 5000,
                ..config
            },
            1
        )
        .is_err());
    }

    #[test]
    fn noise_clutter_rain_and_a_target_look_as_modelled() {
        let config = SyntheticConfig {
            fluctuating: false,
            auto_sea: false,
            ..SyntheticConfig::navico_4bit()
        };
        let mut radar = SyntheticRadar::new(config, 2).unwrap();
        let cell = config.sample_m();
        let target = [SyntheticTarget {
            position_m: [0.0, 5000.0],
            size_m: 0.0,
            amplitude: 12.0,
        }];
        let rain = [RainPatch {
            centre_m: [-4000.0, 0.0],
            radius_m: 1000.0,
            sigma: 4.0,
        }];
        let scene = at_origin(&target, &rain, 0.0);
        let mut buf = [0u8; 1024];
        let (mut far, mut near, mut in_rain, mut peak) = (0.0f64, 0.0f64, 0.0f64, 0u8);
        let (mut n_far, mut n_near, mut n_rain) = (0, 0, 0);
        radar
            .rotation(&scene, &mut buf, |s| {
                let target_cell = (5000.0 / cell) as usize;
                if s.angle == 0 {
                    peak = s.samples[target_cell - 1..=target_cell + 1]
                        .iter()
                        .copied()
                        .max()
                        .unwrap();
                }
                for (j, &v) in s.samples.iter().enumerate() {
                    let r = (j as f32 + 0.5) * cell;
                    let a = f64::from(v) + 0.5;
                    if s.angle == 1536 && (3200.0..4800.0).contains(&r) {
                        in_rain += a * a;
                        n_rain += 1;
                    } else if (s.angle as i32 - 1024).abs() < 200 && r > 5000.0 {
                        far += a * a;
                        n_far += 1;
                    } else if (200.0..300.0).contains(&r) {
                        near += a * a;
                        n_near += 1;
                    }
                }
            })
            .unwrap();
        // Mean power 2σ² (the floor's half level added back): noise 8, rain 8 + 32.
        let far = far / f64::from(n_far);
        let in_rain = in_rain / f64::from(n_rain);
        let near = near / f64::from(n_near);
        assert!((far - 8.0).abs() < 0.8, "noise {far}");
        assert!((in_rain - 40.0).abs() < 6.0, "rain {in_rain}");
        assert!(near > 3.0 * far, "clutter {near} vs noise {far}");
        assert!(peak >= 9, "target peak {peak}");
    }

    /// The sea control on auto: nearer than where the clutter falls to the noise (655 m
    /// with the Navico defaults), the clutter is held at the noise's level (mean power
    /// 2σ² + 2σ² at 200–300 m, twice the noise's alone, and over 6 times without the
    /// control), an echo is attenuated with it (a steady one of 21.6 levels at 400 m to
    /// 21.6 · (400/655)^1.5 = 10.3 on the beam's axis; without the control full scale, 15,
    /// in clutter reaching 15 too), and rain with them (a patch of σ 8 at 250 m adds 2 · (0.236 · 8)² = 7 to the
    /// power, not 128). Printed: the figures measured.
    #[test]
    fn the_sea_control_holds_the_clutter_at_the_noise_near_own_ship() {
        let paint = |auto_sea: bool| {
            // The echo of one amplitude at every range: the control's own effect.
            let config = SyntheticConfig {
                fluctuating: false,
                auto_sea,
                echo_reference_m: 0.0,
                ..SyntheticConfig::navico_4bit()
            };
            assert!((config.sea_control_range_m() - 655.0).abs() < 1.0);
            let mut radar = SyntheticRadar::new(config, 7).unwrap();
            let cell = config.sample_m();
            let target = [SyntheticTarget {
                position_m: [0.0, 400.0],
                size_m: 0.0,
                amplitude: 21.6,
            }];
            // South of own ship, 190–310 m.
            let rain = [RainPatch {
                centre_m: [0.0, -250.0],
                radius_m: 60.0,
                sigma: 8.0,
            }];
            let scene = at_origin(&target, &rain, 0.0);
            let mut buf = [0u8; 1024];
            let [mut far, mut near, mut in_rain, mut echo] = [0.0f64; 4];
            let [mut n_far, mut n_near, mut n_rain, mut n_echo] = [0u32; 4];
            let target_cell = (400.0 / cell) as usize;
            for _ in 0..8 {
                radar
                    .rotation(&scene, &mut buf, |s| {
                        if s.angle <= 1 || s.angle >= 2046 {
                            echo += f64::from(s.samples[target_cell]);
                            n_echo += 1;
                        }
                        let off_south = (i32::from(s.angle) - 1024).abs();
                        for (j, &v) in s.samples.iter().enumerate() {
                            let r = (j as f32 + 0.5) * cell;
                            let a = f64::from(v) + 0.5;
                            if off_south < 200 && r > 5000.0 {
                                far += a * a;
                                n_far += 1;
                            } else if off_south <= 2 && (230.0..270.0).contains(&r) {
                                in_rain += a * a;
                                n_rain += 1;
                            } else if (300..800).contains(&off_south) && (230.0..270.0).contains(&r)
                            {
                                near += a * a;
                                n_near += 1;
                            }
                        }
                    })
                    .unwrap();
            }
            let mean = |sum: f64, n: u32| sum / f64::from(n);
            let noise = mean(far, n_far);
            (
                mean(near, n_near) / noise,
                mean(in_rain, n_rain) / noise,
                mean(echo, n_echo),
            )
        };
        let (clutter, rain, echo) = paint(true);
        eprintln!(
            "sea control on: clutter / noise power {clutter:.2}, in rain {rain:.2}, echo {echo:.1}"
        );
        assert!(
            (clutter - 2.0).abs() < 0.3,
            "clutter / noise power {clutter}"
        );
        assert!(rain < clutter + 2.0, "rain / noise power {rain}");
        // 10.3 on the beam's axis, 0.9–0.97 of it on the spokes either side, Rician with
        // the noise and clutter (σ 2.8 together), floored to a level: about 9.7.
        assert!((echo - 9.7).abs() < 2.0, "echo {echo}");
        let (clutter, rain, echo) = paint(false);
        eprintln!(
            "sea control off: clutter / noise power {clutter:.2}, in rain {rain:.2}, echo {echo:.1}"
        );
        assert!(clutter > 6.0, "clutter / noise power {clutter}");
        assert!(rain > clutter + 2.0, "rain / noise power {rain}");
        assert!(echo >= 14.0, "echo {echo}");
    }

    /// A target's echo grows as it nears own ship (r⁻² in amplitude nearer than the sea
    /// control's reach, 655 m), so the control leaves it standing above the clutter it holds
    /// at the noise: a steady echo of 8 levels at 400 m reads 8 · (655/400)^0.5 = 10.2 on
    /// the beam's axis with the sea control on (3.8 without the growth), Rician with the
    /// noise and clutter (σ 2.8 together). Printed: the means measured.
    #[test]
    fn a_near_echo_grows_as_the_radar_equation_has_it() {
        let paint = |echo_reference_m: f32| {
            let config = SyntheticConfig {
                fluctuating: false,
                echo_reference_m,
                ..SyntheticConfig::navico_4bit()
            };
            let mut radar = SyntheticRadar::new(config, 11).unwrap();
            let target = [SyntheticTarget {
                position_m: [0.0, 400.0],
                size_m: 0.0,
                amplitude: 8.0,
            }];
            let scene = at_origin(&target, &[], 0.0);
            let target_cell = (400.0 / config.sample_m()) as usize;
            let mut buf = [0u8; 1024];
            let (mut sum, mut n) = (0.0f64, 0u32);
            for _ in 0..16 {
                radar
                    .rotation(&scene, &mut buf, |s| {
                        if s.angle == 0 {
                            sum += f64::from(s.samples[target_cell]);
                            n += 1;
                        }
                    })
                    .unwrap();
            }
            sum / f64::from(n)
        };
        let default = SyntheticConfig::navico_4bit().echo_reference_m;
        assert!((default - 655.0).abs() < 1.0, "{default}");
        let grown = paint(default);
        let flat = paint(0.0);
        eprintln!("echo of 8 levels at 400 m: {grown:.1} growing as r⁻², {flat:.1} without");
        assert!((grown - 10.2).abs() < 2.0, "grown {grown}");
        assert!(flat < 7.0, "flat {flat}");
        // A reference that is not a range is refused.
        let config = SyntheticConfig::navico_4bit();
        assert!(SyntheticRadar::new(
            SyntheticConfig {
                echo_reference_m: -1.0,
                ..config
            },
            1
        )
        .is_err());
    }

    /// The per-cell false-alarm rate on the synthetic Navico's own noise (4 bits, with
    /// sea clutter near own ship held at the noise by the sea control): the CFAR holds its
    /// 10⁻³ design within ±10 % at noise σ 2 and 3 levels, though a level is a half to a
    /// third of σ (measured 1.019 and 1.033 × 10⁻³, 12,500 false alarms each: a standard
    /// error of 0.9 %). Coarser still, at σ 1.5 (two fifths of the noise in levels 0 and
    /// 1), the levels bias it: 0.978 × 10⁻³ (0.91 without the sea control), held within
    /// ±15 %.
    #[test]
    fn four_bit_noise_false_alarms_are_within_ten_per_cent_of_the_design() {
        let extractor_config = ExtractorConfig::navico_4bit();
        for (sigma, seed) in [(1.5f32, 1u64), (2.0, 2), (3.0, 3)] {
            let config = SyntheticConfig {
                noise_sigma: sigma,
                ..SyntheticConfig::navico_4bit()
            };
            let mut radar = SyntheticRadar::new(config, seed).unwrap();
            let mut extractor: Extractor = Extractor::new(extractor_config).unwrap();
            let scene = at_origin(&[], &[], 0.0);
            let mut buf = [0u8; 1024];
            for _ in 0..6 {
                radar
                    .rotation(&scene, &mut buf, |s| extractor.push(s, |_| {}))
                    .unwrap();
            }
            let s = extractor.stats();
            let blank = (extractor_config.min_range_m / config.sample_m()).ceil() as u64;
            let cells = s.spokes * (u64::from(config.samples) - blank);
            let pfa = s.detections as f64 / cells as f64;
            eprintln!("4-bit noise σ {sigma}: P_fa {pfa:.3e} over {cells} cells");
            let tolerance = if sigma < 2.0 { 0.15 } else { 0.1 };
            assert!(
                (pfa - 1e-3).abs() < tolerance * 1e-3,
                "σ {sigma}: P_fa {pfa:.3e}"
            );
        }
    }

    #[test]
    fn rain_stays_quiet_and_a_breakwater_is_extended_beside_a_ship_that_is_not() {
        let config = SyntheticConfig {
            fluctuating: false,
            ..SyntheticConfig::navico_4bit()
        };
        let mut radar = SyntheticRadar::new(config, 4).unwrap();
        let mut extractor: Extractor = Extractor::new(ExtractorConfig::navico_4bit()).unwrap();
        // Rain 2 km across, 4 km east, its return twice the noise's amplitude.
        let rain = [RainPatch {
            centre_m: [4000.0, 0.0],
            radius_m: 1000.0,
            sigma: 4.0,
        }];
        // A breakwater 1.5 km long 2.5 km north (scatterers every 30 m along an arc), and
        // a ship 300 m nearer than it.
        let mut targets: StdVec<SyntheticTarget> = (0..50)
            .map(|i| SyntheticTarget {
                position_m: geo::polar_to_local([0.0, 0.0], 2500.0, (i as f32 - 25.0) * 0.012),
                size_m: 0.0,
                amplitude: 15.0,
            })
            .collect();
        let ship = [500.0, 2150.0];
        targets.push(SyntheticTarget {
            position_m: ship,
            size_m: 0.0,
            amplitude: 15.0,
        });
        let scene = at_origin(&targets, &rain, 0.0);
        let mut buf = [0u8; 1024];
        let (mut plots, mut extended) = (StdVec::new(), StdVec::new());
        let rotations = 20;
        for _ in 0..rotations {
            radar
                .rotation(&scene, &mut buf, |s| {
                    extractor.push(s, |e| match e {
                        Event::Plot(p) => plots.push(p),
                        Event::Extended(p) => extended.push(p),
                        Event::Wrap { .. } => {}
                    })
                })
                .unwrap();
        }
        let near = |p: &RadarPlot, at: EastNorth, within: f32| {
            let q = geo::polar_to_local([0.0, 0.0], p.range_m, p.bearing_rad);
            libm::hypotf(q[0] - at[0], q[1] - at[1]) < within
        };
        let on_breakwater = |p: &RadarPlot| {
            (p.range_m - 2500.0).abs() < 60.0 && geo::wrap_pi(p.bearing_rad).abs() < 0.32
        };
        let in_rain = plots
            .iter()
            .filter(|p| near(p, rain[0].centre_m, 1100.0))
            .count();
        let breakwater_plots = plots.iter().filter(|p| on_breakwater(p)).count();
        let breakwater = extended.iter().filter(|p| on_breakwater(p)).count();
        let ship_plots = plots.iter().filter(|p| near(p, ship, 50.0)).count();
        eprintln!(
            "{rotations} rotations: {in_rain} plots in the rain, breakwater {breakwater} \
             extended + {breakwater_plots} plots, ship {ship_plots} plots"
        );
        // A 24-cell trimmed mean without greatest-of made 75 plots here (its near edge).
        assert!(in_rain <= rotations / 2, "rain {in_rain}");
        // Whole rotations: the first after the start and the last before the end.
        assert!(
            breakwater >= rotations - 1 && breakwater_plots <= 2,
            "{extended:?}"
        );
        assert!(ship_plots >= rotations - 1, "ship {ship_plots}");
    }

    /// A ship dead ahead running away at 15 m/s: 37.5 m a rotation, more than its echo's
    /// depth, so the part of its echo painted before the seam (the end of one rotation) and
    /// the part after it (the start of the next) would lie apart in range were each painted
    /// where the ship stands at its own rotation. A real antenna sweeps across the bow in a
    /// millisecond; the echo must stay one, on the ship's bearing.
    #[test]
    fn an_echo_across_the_bow_is_one_plot_on_its_bearing() {
        let config = SyntheticConfig {
            fluctuating: false,
            ..SyntheticConfig::navico_4bit()
        };
        let mut radar = SyntheticRadar::new(config, 9).unwrap();
        let mut extractor: Extractor = Extractor::new(ExtractorConfig::navico_4bit()).unwrap();
        let mut buf = [0u8; 1024];
        // Head-up, heading 040°: the seam is the bow, not north.
        let heading_rad = 40f32.to_radians();
        let bearing_rad = heading_rad + 0.3f32.to_radians();
        let rotations = 12;
        let mut plots = StdVec::new();
        for k in 0..rotations {
            let range_m = 3000.0 + 37.5 * k as f32;
            let target = [SyntheticTarget {
                position_m: geo::polar_to_local([0.0, 0.0], range_m, bearing_rad),
                size_m: 0.0,
                amplitude: 15.0,
            }];
            let scene = Scene {
                continues: true,
                ..at_origin(&target, &[], heading_rad)
            };
            radar
                .rotation(&scene, &mut buf, |s| {
                    extractor.push(s, |e| {
                        if let Event::Plot(p) = e {
                            plots.push(p);
                        }
                    })
                })
                .unwrap();
        }
        // Noise crossing at the beam's edge beside the echo makes a weak plot now and then
        // (strength 16 here, 2–3 spokes); the echo's own parts hold 45 and more.
        let ahead: StdVec<&RadarPlot> = plots
            .iter()
            .filter(|p| {
                !p.partial && geo::wrap_pi(p.bearing_rad - heading_rad).abs() < 3f32.to_radians()
            })
            .filter(|p| (2900.0..3500.0).contains(&p.range_m) && p.strength >= 40)
            .collect();
        let worst_deg = ahead
            .iter()
            .map(|p| geo::wrap_pi(p.bearing_rad - bearing_rad).abs().to_degrees())
            .fold(0.0f32, f32::max);
        eprintln!(
            "{rotations} rotations: {} whole plots ahead, worst bearing error {worst_deg:.2}°",
            ahead.len()
        );
        // The first rotation's echo is cut at the start (partial); each later pass is one.
        assert_eq!(ahead.len(), rotations - 1, "{ahead:?}");
        assert!(worst_deg < 0.2, "{worst_deg}°");
    }

    /// One rotation's outcome against the truth.
    #[derive(Default)]
    struct Score {
        targets: usize,
        detected: usize,
        false_plots: usize,
        split_plots: usize,
        extended: usize,
        sq_err_m2: f64,
        errors: usize,
    }

    fn score(plots: &[RadarPlot], truth: &[EastNorth], own: EastNorth, out: &mut Score) {
        // Each plot goes to its nearest target; within 100 m it is that target's, else
        // false. A target's nearest plot is its detection; its others are splits.
        let mut best: StdVec<Option<f32>> = std::vec![None; truth.len()];
        for p in plots {
            let Some(icd) = p.to_icd() else {
                continue;
            };
            let pos = geo::polar_to_local(own, icd.range_m, icd.bearing_rad);
            let nearest = truth
                .iter()
                .enumerate()
                .map(|(i, t)| (i, libm::hypotf(pos[0] - t[0], pos[1] - t[1])))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match nearest {
                Some((i, d)) if d < 100.0 => match best[i] {
                    Some(e) => {
                        out.split_plots += 1;
                        best[i] = Some(e.min(d));
                    }
                    None => best[i] = Some(d),
                },
                _ => out.false_plots += 1,
            }
        }
        out.targets += truth.len();
        for d in best.iter().flatten() {
            out.detected += 1;
            out.sq_err_m2 += f64::from(d * d);
            out.errors += 1;
        }
    }

    /// Swerling I targets of mean amplitude 21.6 levels, 16 a rotation at 800–7,000 m,
    /// seen by the Navico defaults of the synthetic radar and the extractor.
    ///
    /// The design:
    ///
    /// - P_d 0.90, the simulator's. A steady echo makes a plot half the time at an
    ///   amplitude of a_min = 7.0 levels (3.5 σ of the noise; measured over 40 rotations,
    ///   amplitudes 6.5, 7, 7.5, 8: P_d 0.36, 0.49, 0.63, 0.78); a Swerling I echo's amplitude is A·√E with E exponential,
    ///   so P_d ≈ P(A·√E > a_min) = exp(−(a_min/A)²), and A = 21.6 gives 0.90.
    /// - False plots: two noise crossings at the same range cell on adjacent spokes, or
    ///   with one spoke between (bridged: `max_missed_spokes` 1), make a blob of two spokes
    ///   (the minimum), so a rotation of S spokes and R tested cells has about 2·S·R·P_fa²
    ///   of them: 2 × 2,048 × 1,015 × 10⁻⁶ = 4.16. (Closing strictly, S·R·P_fa² = 2.08:
    ///   measured 2.24.)
    ///
    /// Measured over 200 rotations (2026-12-07, with the noise drawn two numbers a cell):
    /// P_d 0.898, false plots 4.24 a rotation, extra (split) plots beside 2.7 % of the
    /// targets, RMS position error 8.2 m (on the noise drawn before, 2026-12-06, with the
    /// sea control: 0.901, 4.47, 2.3 % and 7.8 m; 4.14 false plots without the control:
    /// clutter cells near own ship that saturated and could not alarm now alarm like
    /// noise). `SYNTHETIC_ROTATIONS` sets the
    /// rotations. The test runs 200 (a false-plot count's standard error 3.5 %) and holds
    /// P_d and false plots within ±10 % of the design, the RMS error under 12 m and split
    /// plots under 8 %.
    #[test]
    fn end_to_end_detection_false_plots_and_accuracy() {
        let rotations: usize = std::env::var("SYNTHETIC_ROTATIONS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(200);
        let config = SyntheticConfig::navico_4bit();
        let extractor_config = ExtractorConfig::navico_4bit();
        let a_min = 7.0f64;
        let design_pd = (-(a_min / f64::from(config.target_amplitude)).powi(2)).exp();
        let blank = (extractor_config.min_range_m / config.sample_m()).ceil();
        let tested = f64::from(config.samples) - f64::from(blank);
        let pfa = f64::from(extractor_config.cfar.pfa);
        let design_false = 2.0 * f64::from(config.spokes_per_rotation) * tested * pfa * pfa;
        let mut radar = SyntheticRadar::new(config, 1).unwrap();
        let mut extractor: Extractor = Extractor::new(ExtractorConfig::navico_4bit()).unwrap();
        let mut rng = Pcg32::seed_from_u64(100);
        let mut buf = [0u8; 1024];
        let mut total = Score::default();
        let heading = 0.7;
        for _ in 0..rotations {
            let truth = targets_at(&mut rng, 16, 800.0, 7000.0);
            let targets: StdVec<SyntheticTarget> = truth
                .iter()
                .map(|&p| SyntheticTarget {
                    position_m: p,
                    size_m: 0.0,
                    amplitude: config.target_amplitude,
                })
                .collect();
            let scene = at_origin(&targets, &[], heading);
            // Each rotation is scored on its own: flushed at its end (the picture changes
            // between rotations here, unlike a real one).
            let mut plots = StdVec::new();
            let mut extended = 0;
            let mut on_event = |e| match e {
                Event::Plot(p) => plots.push(p),
                Event::Extended(_) => extended += 1,
                Event::Wrap { .. } => {}
            };
            radar
                .rotation(&scene, &mut buf, |s| extractor.push(s, &mut on_event))
                .unwrap();
            extractor.flush(&mut on_event);
            total.extended += extended;
            score(&plots, &truth, [0.0, 0.0], &mut total);
        }
        let pd = total.detected as f64 / total.targets as f64;
        let false_per_rotation = total.false_plots as f64 / rotations as f64;
        let rms = (total.sq_err_m2 / total.errors.max(1) as f64).sqrt();
        let split = total.split_plots as f64 / total.targets as f64;
        let stats = extractor.stats();
        eprintln!(
            "{rotations} rotations: P_d {pd:.3} (design {design_pd:.3}), false plots \
             {false_per_rotation:.2} a rotation (design {design_false:.2}), split plots \
             {:.1} % of targets, extended {}, RMS position error {rms:.1} m",
            100.0 * split,
            total.extended,
        );
        assert!((pd - design_pd).abs() <= 0.1 * design_pd, "P_d {pd}");
        assert!(
            (false_per_rotation - design_false).abs() <= 0.1 * design_false,
            "false plots {false_per_rotation}"
        );
        assert!(rms < 12.0, "RMS {rms}");
        assert!(split < 0.08, "split plots {split}");
        assert_eq!(stats.blobs_dropped + stats.runs_dropped, 0);
    }
}
