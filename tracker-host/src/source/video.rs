//! `demo --video`: the simulator's ships seen through the synthetic radar
//! ([`SyntheticRadar`]: beam shape, pulse, receiver noise, sea clutter falling with range,
//! Swerling I echoes) and the core's plot extractor, instead of the IMO plot model: spokes →
//! plots → tracks on the same scenario as the plot-level demo, so the two summaries can be
//! set side by side. The radar spans the plot model's 12 NM on 1,024 samples (21.7 m each),
//! 2,048 spokes a rotation, one rotation a scan, head-up with the scenario's own heading.
//!
//! The plots are scored against the scenario's truth ([`PlotScores`]): a target in range
//! is detected when a plot lies within [`DETECTION_GATE_M`] of it; a plot near no target is
//! a false plot; the detected ones' distances give the plot position error.

use tracker_core::geo::{self, METRES_PER_NM};
use tracker_core::icd::Plot;
use tracker_core::radar::synthetic::{SyntheticConfig, SyntheticRadar};
use tracker_core::radar::{Event, Extractor, ExtractorConfig};
use tracker_core::sim::Scenario;

/// A plot this near a target detects it, m (about three times the plot error at 12 NM).
pub const DETECTION_GATE_M: f32 = 150.0;

/// The plots' positions, local frame, m, seen from own ship at `own_m`.
pub fn plot_points(own_m: [f32; 2], plots: &[Plot]) -> Vec<[f32; 2]> {
    plots
        .iter()
        .map(|p| geo::polar_to_local_f64(own_m, p.range_m, p.bearing_rad))
        .collect()
}

/// Distance between two points, m.
fn distance_m(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// True when one of `points` lies within [`DETECTION_GATE_M`] of `target_m`.
pub fn detects(points: &[[f32; 2]], target_m: [f32; 2]) -> bool {
    points
        .iter()
        .any(|p| distance_m(*p, target_m) <= DETECTION_GATE_M)
}

/// The plots against the truth, over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PlotScores {
    /// Target-scans in the radar's range (beyond its blanking).
    pub target_scans: u64,
    /// … of which a plot lay within the gate.
    pub detected: u64,
    /// Plots near no target.
    pub false_plots: u64,
    /// Scans.
    pub scans: u64,
    /// Sum of squared distances of the detecting plots, m².
    pub sum_sq_error_m2: f64,
    /// Extended returns (not plots).
    pub extended: u64,
    /// Spokes painted and extracted.
    pub spokes: u64,
    /// Plots handed to the tracker.
    pub plots: u64,
}

impl PlotScores {
    /// Detection probability.
    pub fn pd(&self) -> f64 {
        self.detected as f64 / self.target_scans.max(1) as f64
    }

    /// False plots a scan.
    pub fn false_per_scan(&self) -> f64 {
        self.false_plots as f64 / self.scans.max(1) as f64
    }

    /// RMS distance of a detecting plot from its target, m.
    pub fn rms_error_m(&self) -> f64 {
        (self.sum_sq_error_m2 / self.detected.max(1) as f64).sqrt()
    }
}

impl std::fmt::Display for PlotScores {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "P_d {:.3}, {:.2} false plots a scan, plot error RMS {:.1} m, {} extended returns",
            self.pd(),
            self.false_per_scan(),
            self.rms_error_m(),
            self.extended
        )
    }
}

/// The synthetic radar and the extractor, one rotation a scan.
pub struct Video {
    radar: SyntheticRadar,
    extractor: Box<Extractor>,
    buf: Vec<u8>,
    scores: PlotScores,
}

impl Video {
    /// A radar for a scenario of `scan_s` per scan that sees nothing nearer than
    /// `min_range_m` (the plot model's own blind range, so both see the same ships), its
    /// noise drawn from `seed`, its sea control on auto (the clutter held at the noise's
    /// level inside 655 m). The extractor blanks (does not test) below that range too;
    /// the blanked samples still serve as the first tested cells' near reference.
    ///
    /// # Errors
    /// A synthetic radar or extractor setting out of range (none with these).
    pub fn new(scan_s: f32, min_range_m: f32, seed: u64) -> anyhow::Result<Self> {
        let config = SyntheticConfig {
            range_m: 12.0 * METRES_PER_NM,
            rotation_ms: (scan_s * 1000.0) as u32,
            ..SyntheticConfig::navico_4bit()
        };
        let radar = SyntheticRadar::new(config, seed ^ 0x5EED_F00D)
            .map_err(|e| anyhow::anyhow!("synthetic radar: {e}"))?;
        let extractor = Extractor::new(ExtractorConfig {
            min_range_m,
            ..ExtractorConfig::navico_4bit()
        })
        .map_err(|e| anyhow::anyhow!("extractor: {e}"))?;
        Ok(Video {
            radar,
            extractor: Box::new(extractor),
            buf: vec![0; usize::from(config.samples)],
            scores: PlotScores::default(),
        })
    }

    /// The plots' scores so far.
    pub fn scores(&self) -> PlotScores {
        self.scores
    }

    /// One rotation of `scenario` as it stands (call before the scenario's own scan, which
    /// moves it on): the plots (range, true bearing from own ship), scored against the
    /// targets.
    ///
    /// # Errors
    /// The synthetic radar refused the scene (more targets than it holds).
    pub fn rotation(&mut self, scenario: &Scenario) -> anyhow::Result<Vec<Plot>> {
        let mut plots = Vec::new();
        let mut extended = 0;
        let mut spokes = 0;
        let (radar, extractor) = (&mut self.radar, &mut self.extractor);
        radar
            .rotation_from_scenario(scenario, &[], &mut self.buf, |spoke| {
                spokes += 1;
                extractor.push(spoke, |e| match e {
                    Event::Plot(p) => plots.extend(p.to_icd()),
                    Event::Extended(_) => extended += 1,
                    Event::Wrap { .. } => {}
                });
            })
            .map_err(|e| anyhow::anyhow!("synthetic radar: {e}"))?;
        // The device's limit: the nearest kept, as from a real radar.
        if plots.len() > tracker_core::tracker::MAX_PLOTS_PER_SCAN {
            plots.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
            plots.truncate(tracker_core::tracker::MAX_PLOTS_PER_SCAN);
        }
        self.scores.plots += plots.len() as u64;
        self.score(scenario, &plots);
        self.scores.extended += extended;
        self.scores.spokes += spokes;
        Ok(plots)
    }

    fn score(&mut self, scenario: &Scenario, plots: &[Plot]) {
        let own = scenario.own_ship().position_m;
        let points = plot_points(own, plots);
        let dist = distance_m;
        let sensor = scenario.config().sensor;
        let mut near_any = vec![false; points.len()];
        for t in scenario.targets() {
            let (range, _) = geo::range_bearing(own, t.position_m);
            let in_range = range >= sensor.min_range_m && range <= sensor.max_range_m;
            let nearest = points
                .iter()
                .enumerate()
                .map(|(i, p)| (i, dist(*p, t.position_m)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            for (i, p) in points.iter().enumerate() {
                if dist(*p, t.position_m) <= DETECTION_GATE_M {
                    near_any[i] = true;
                }
            }
            if !in_range {
                continue;
            }
            self.scores.target_scans += 1;
            if let Some((_, d)) = nearest.filter(|(_, d)| *d <= DETECTION_GATE_M) {
                self.scores.detected += 1;
                self.scores.sum_sq_error_m2 += f64::from(d) * f64::from(d);
            }
        }
        self.scores.false_plots += near_any.iter().filter(|n| !**n).count() as u64;
        self.scores.scans += 1;
    }
}
