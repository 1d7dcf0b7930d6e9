//! The plot extractor's settings, with defaults for the two radars we decode, and their
//! validation.
//!
//! The defaults are chosen for the radars' own geometry:
//!
//! | | Navico 4-bit (Halo, 4G) | Garmin xHD 8-bit |
//! |---|---|---|
//! | spokes a rotation | 2,048 (0.176°) | 1,440 (0.25°) |
//! | samples | 0..=15 | 0..=255 |
//! | beam (−3 dB, horizontal) | 1.8° (≈ 10 spokes) | 1.8° (≈ 7 spokes) |
//! | CFAR | greatest-of two trimmed means: 3 guard + 12 reference cells a side, the 9 smallest of each, P_fa 10⁻³ | the same |
//! | absolute floor | level 4 | level 48 |
//! | blanked near range | 60 m | 60 m |
//! | a blob coasts through | 1 spoke without a run | the same |
//! | a plot needs | 2 spokes, 2 cells | 2 spokes, 2 cells |
//! | echo threshold | 4 × the band's 25th percentile, at least level 8 | the same, at least 128 |
//! | extended above | 100 range cells, 3,000 cells, 22.5° (12.5 beams); 1,000 m in range, 500 m across beyond 5 beams | the same |
//!
//! Why these numbers is in [`super::cfar`] (the detector), [`super::echo`] (the echo
//! threshold), [`ExtractorConfig::classify`] (point or extended) and [`super::extract`]
//! (the blobs); the figures they give on the synthetic radar are in `synthetic` (feature
//! `sim`).

use super::blob::RadarPlot;
use super::cfar::CfarConfig;

/// Everything the plot extractor is told.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractorConfig {
    /// The detector along range.
    pub cfar: CfarConfig,
    /// Samples nearer than this are never detected and take no part in the noise estimate:
    /// the transmitter's main bang and own ship's superstructure, m.
    pub min_range_m: f32,
    /// Missing spokes (angle steps of more than one) up to this many are bridged: a blob
    /// grows across them as if they were adjacent. A larger gap closes every open blob
    /// (marked partial), spokes.
    pub max_spoke_gap: u16,
    /// A blob stays open through this many consecutive spokes without a run overlapping
    /// it, and closes at the next: 0 closes it at the first such spoke. 1 (the default)
    /// bridges the one-spoke dropouts a weak echo has in noise at its beam's edges, which
    /// otherwise split off as extra plots beside the target, spokes.
    pub max_missed_spokes: u16,
    /// A blob must cover at least this many spokes to be reported: a real echo is as wide
    /// as the beam (≈ 10 spokes on a Navico), a lone noise crossing one spoke wide, spokes.
    pub min_spokes: u16,
    /// A blob must hold at least this many detected cells to be reported, cells.
    pub min_cells: u32,
    /// The widest a point target's return can be in bearing: the beam and, for strong
    /// echoes, its skirts above the threshold. Only the angular extent beyond this counts
    /// towards "extended", rad.
    pub point_angular_extent_rad: f32,
    /// A blob longer than this in range is an extended return (coast, jetty, rain), m.
    pub extended_range_m: f32,
    /// A blob wider than this across the beam, beyond
    /// [`ExtractorConfig::point_angular_extent_rad`], is an extended return, m.
    pub extended_cross_m: f32,
    /// An echo of more cells than this (samples × spokes at or above the echo threshold;
    /// detected cells for a CFAR blob measured alone) is an extended return, cells.
    pub extended_cells: u32,
    /// An echo deeper than this in range is an extended return, range cells (samples).
    pub extended_range_cells: u16,
    /// An echo wider than this in bearing is an extended return, rad (a quay's face or a
    /// coast seen as a thin line: few cells, but many beams wide).
    pub extended_angular_extent_rad: f32,
    /// A sample is part of an echo from this many times its range band's 25th percentile
    /// ([`super::echo`]), and at least from [`ExtractorConfig::echo_min_level`].
    pub echo_level_factor: f32,
    /// The least level a sample of an echo has, sample levels: half of full scale by
    /// default. An echo's core on a Navico's 4 bits is near full scale (the harbour's quays
    /// and boats are 15 with 0 around them); at the CFAR's floor (4) the skirts of ships a
    /// beam width apart at 14 km touched and made one echo with its centroid between them
    /// (HALO capture: 9 of 64 AIS ship-scans within 2 % of range against 14 at 8).
    pub echo_min_level: u8,
}

/// Whether a closed blob is something to track.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReturnClass {
    /// Small enough to be a ship or a buoy: a plot for the tracker.
    Point,
    /// Coastline, jetty, rain patch, sea-clutter band: reported apart, never tracked.
    Extended,
}

/// A setting out of range (what [`ExtractorConfig::validate`] and
/// [`super::cfar::Cfar::new`] refuse).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// Reference cells must be 1..=64 a side.
    ReferenceCells,
    /// Guard cells must be 0..=64 a side.
    GuardCells,
    /// The rank must be 1..=reference cells.
    Rank,
    /// The false-alarm probability must be in (10⁻¹², 0.5).
    FalseAlarmProbability,
    /// A range, angle or extent is negative or not a number.
    Geometry,
    /// A plot's minimum size must be at least one spoke and one cell.
    MinimumSize,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            ConfigError::ReferenceCells => "reference cells must be 1..=64 a side",
            ConfigError::GuardCells => "guard cells must be 0..=64 a side",
            ConfigError::Rank => "CFAR rank must be 1..=reference cells",
            ConfigError::FalseAlarmProbability => "false-alarm probability must be in (1e-12, 0.5)",
            ConfigError::Geometry => "a range, angle or extent is negative or not a number",
            ConfigError::MinimumSize => "a plot needs at least one spoke and one cell",
        })
    }
}

#[cfg(feature = "std")]
impl std::error::Error for ConfigError {}

const DEG: f32 = core::f32::consts::PI / 180.0;

impl ExtractorConfig {
    /// Navico (Halo, 4G: 2,048 spokes, 4-bit samples 0..=15).
    ///
    /// The absolute floor, level 4 of 15, is where the CFAR's estimate stops meaning
    /// anything: where the radar's own noise rejection leaves nearly all zeros, the
    /// trimmed means are those of zeros and any level 1 or 2 would cross their threshold.
    /// With noise of σ 1.5 levels or more (the synthetic radar's 2) the floor is below the
    /// CFAR's threshold (about 8) and changes nothing.
    pub const fn navico_4bit() -> Self {
        ExtractorConfig {
            cfar: CfarConfig {
                guard_cells: 3,
                reference_cells: 12,
                rank: 9,
                pfa: 1e-3,
                min_level: 4,
            },
            min_range_m: 60.0,
            max_spoke_gap: 4,
            max_missed_spokes: 1,
            min_spokes: 2,
            min_cells: 2,
            point_angular_extent_rad: 5.0 * 1.8 * DEG,
            extended_range_m: 1_000.0,
            extended_cross_m: 500.0,
            extended_cells: 3_000,
            extended_range_cells: 100,
            extended_angular_extent_rad: 22.5 * DEG,
            echo_level_factor: 4.0,
            echo_min_level: 8,
        }
    }

    /// Garmin xHD (1,440 spokes, 8-bit samples 0..=255). The same detector; the floor at
    /// 48 of 255 (the same fraction of full scale as Navico's 4 of 15, a little lower: the
    /// finer levels let the CFAR's own estimate work further down).
    pub fn garmin_xhd() -> Self {
        ExtractorConfig {
            cfar: CfarConfig {
                min_level: 48,
                ..ExtractorConfig::navico_4bit().cfar
            },
            echo_min_level: 128,
            ..ExtractorConfig::navico_4bit()
        }
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// The first setting out of range, as a [`ConfigError`] (the CFAR's through
    /// [`CfarConfig::validate`]).
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.cfar.validate()?;
        let non_negative = |x: f32| x >= 0.0 && x.is_finite();
        let geometry_ok = non_negative(self.min_range_m)
            && non_negative(self.point_angular_extent_rad)
            && non_negative(self.extended_range_m)
            && non_negative(self.extended_cross_m)
            && non_negative(self.extended_angular_extent_rad)
            && non_negative(self.echo_level_factor);
        if !geometry_ok {
            return Err(ConfigError::Geometry);
        }
        if self.min_spokes == 0 || self.min_cells == 0 {
            return Err(ConfigError::MinimumSize);
        }
        Ok(())
    }

    /// A closed echo's (or lone CFAR blob's) class by its size.
    ///
    /// Extended when it is larger than a point target can look at this range scale, in the
    /// radar's own resolution: deeper than [`ExtractorConfig::extended_range_cells`] range
    /// cells, of more than [`ExtractorConfig::extended_cells`] cells (samples × spokes: its
    /// area in the picture's cells), or wider than
    /// [`ExtractorConfig::extended_angular_extent_rad`]; or larger than a ship can be in
    /// metres: longer in range than [`ExtractorConfig::extended_range_m`], or wider across
    /// the beam than [`ExtractorConfig::extended_cross_m`] beyond a point target's own smear
    /// ([`ExtractorConfig::point_angular_extent_rad`]). A point target otherwise.
    ///
    /// The limits were chosen on the echoes of the five real captures (test
    /// `echo_sizes_by_detections` in `tracker-host/tests/radar_tracking.rs`, table in
    /// docs/radar.md): echoes holding one CFAR detection, mostly isolated buoys, boats and
    /// ships, are up to 38–69 range cells, 420–3,300 cells and 14–25° (99th percentiles);
    /// echoes holding three or more, mostly quays, pontoons and coasts whose edges the CFAR
    /// breaks into pieces, from 20–132 range cells, 560–7,800 cells and 10–76° (10th
    /// percentiles). In metres the two overlap across scales (a pontoon on the 195 m scale
    /// is shorter than a ship on the 25 km one); in the radar's own cells much less. The
    /// limits in metres stay for long range scales, where a few cells are a coast.
    pub fn classify(&self, plot: &RadarPlot) -> ReturnClass {
        let excess_rad = plot.angular_extent_rad - self.point_angular_extent_rad;
        let cross_m = if excess_rad > 0.0 {
            excess_rad * plot.range_m
        } else {
            0.0
        };
        if plot.range_cells > self.extended_range_cells
            || plot.cells > self.extended_cells
            || plot.angular_extent_rad > self.extended_angular_extent_rad
            || plot.range_extent_m > self.extended_range_m
            || cross_m > self.extended_cross_m
        {
            ReturnClass::Extended
        } else {
            ReturnClass::Point
        }
    }
}

impl Default for ExtractorConfig {
    fn default() -> Self {
        ExtractorConfig::navico_4bit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_valid_and_bad_settings_are_refused() {
        assert_eq!(ExtractorConfig::navico_4bit().validate(), Ok(()));
        assert_eq!(ExtractorConfig::garmin_xhd().validate(), Ok(()));
        let good = ExtractorConfig::default();
        let bad = |f: &dyn Fn(&mut ExtractorConfig)| {
            let mut c = good;
            f(&mut c);
            c.validate()
        };
        assert_eq!(
            bad(&|c| c.cfar.reference_cells = 0),
            Err(ConfigError::ReferenceCells)
        );
        assert_eq!(
            bad(&|c| c.cfar.guard_cells = 65),
            Err(ConfigError::GuardCells)
        );
        assert_eq!(bad(&|c| c.cfar.rank = 13), Err(ConfigError::Rank));
        assert_eq!(bad(&|c| c.cfar.rank = 0), Err(ConfigError::Rank));
        assert_eq!(
            bad(&|c| c.cfar.pfa = f32::NAN),
            Err(ConfigError::FalseAlarmProbability)
        );
        assert_eq!(
            bad(&|c| c.cfar.pfa = 0.7),
            Err(ConfigError::FalseAlarmProbability)
        );
        assert_eq!(bad(&|c| c.min_range_m = -1.0), Err(ConfigError::Geometry));
        assert_eq!(
            bad(&|c| c.extended_cross_m = f32::INFINITY),
            Err(ConfigError::Geometry)
        );
        assert_eq!(bad(&|c| c.min_spokes = 0), Err(ConfigError::MinimumSize));
        assert_eq!(
            bad(&|c| c.echo_level_factor = f32::NAN),
            Err(ConfigError::Geometry)
        );
    }
}
