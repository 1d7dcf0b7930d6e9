//! A blob: detections connected across spokes, summed as they arrive; and the plot it
//! measures when it closes.
//!
//! Nothing per cell is kept: a blob is a handful of sums (strength, strength × range index,
//! strength × spoke offset, strength × time offset, strength × heading offset) and its
//! bounds, so it costs the same for a buoy as for a coastline, and two blobs merge by
//! adding their sums (rebased to the older one's first spoke).

use super::cfar::Run;
use crate::geo;
use crate::icd::Plot;

/// What one spoke contributes to a blob besides its run: where and when it was taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SpokeContext {
    /// The spoke's position in the unwrapped stream: increases by the angle step, through
    /// the 360° wrap (wrapping at 2³², far beyond a blob's life).
    pub spoke: u32,
    /// Its angle index in the rotation.
    pub angle: u16,
    /// When it was taken, ms.
    pub time_ms: u64,
    /// Own heading to add to a head-up angle, rad (0 when north-up or unknown).
    pub heading_rad: f32,
    /// A head-up spoke without a heading: its angle is relative to the bow only.
    pub heading_missing: bool,
    /// The blob may miss cells before this spoke (the first after a start or restart).
    pub partial: bool,
}

/// The geometry a blob is measured in (constant over its life: a change closes it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Geometry {
    /// Spokes in a rotation.
    pub spokes_per_rotation: u16,
    /// Metres per sample.
    pub sample_m: f32,
    /// Angles are from true north.
    pub north_up: bool,
}

/// An open blob's sums and bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Blob {
    /// First and last spoke it covers, unwrapped stream positions.
    pub first_spoke: u32,
    pub last_spoke: u32,
    /// Spokes received since the last one that extended it.
    pub misses: u16,
    /// The first spoke's angle index (its unwrapped position mod the rotation).
    first_angle: u16,
    min_cell: u16,
    max_cell: u16,
    cells: u32,
    peak: u8,
    /// Σ w, Σ w·cell, Σ w·(spoke − first), Σ w·(t − t0): w is the sample.
    sum: u64,
    cell_sum: u64,
    spoke_sum: u64,
    time0_ms: u64,
    time_sum: u64,
    /// The first spoke's heading and Σ w·(heading − it), rad.
    heading0_rad: f32,
    heading_sum: f32,
    relative: bool,
    partial: bool,
    /// For a CFAR blob: the echo it lies in (a slot of the extractor's echoes), or
    /// `u16::MAX` for none. For an echo: unused.
    pub echo: u16,
    /// For an echo: the CFAR blobs of a plot's size that closed inside it. For a CFAR blob:
    /// unused.
    pub detections: u16,
}

/// A blob's [`Blob::echo`] when it lies in no echo being followed.
pub(crate) const NO_ECHO: u16 = u16::MAX;

impl Blob {
    /// A blob of one run.
    pub fn start(ctx: &SpokeContext, run: &Run) -> Self {
        let mut b = Blob {
            first_spoke: ctx.spoke,
            last_spoke: ctx.spoke,
            misses: 0,
            first_angle: ctx.angle,
            min_cell: run.start,
            max_cell: run.end.saturating_sub(1),
            cells: 0,
            peak: 0,
            sum: 0,
            cell_sum: 0,
            spoke_sum: 0,
            time0_ms: ctx.time_ms,
            time_sum: 0,
            heading0_rad: ctx.heading_rad,
            heading_sum: 0.0,
            relative: false,
            partial: false,
            echo: NO_ECHO,
            detections: 0,
        };
        b.add(ctx, run);
        b
    }

    /// Adds a run of the spoke `ctx` (the blob's newest spoke, or the same one again).
    pub fn add(&mut self, ctx: &SpokeContext, run: &Run) {
        let w = u64::from(run.sum);
        let offset = u64::from(ctx.spoke.wrapping_sub(self.first_spoke));
        self.last_spoke = ctx.spoke;
        self.misses = 0;
        self.min_cell = self.min_cell.min(run.start);
        self.max_cell = self.max_cell.max(run.end.saturating_sub(1));
        self.cells = self.cells.saturating_add(u32::from(run.cells()));
        self.peak = self.peak.max(run.peak);
        self.sum += w;
        self.cell_sum += run.index_sum;
        self.spoke_sum += w * offset;
        // Saturating: a source clock that jumps by ages must not wrap the sum.
        let dt = ctx.time_ms.saturating_sub(self.time0_ms);
        self.time_sum = self.time_sum.saturating_add(w.saturating_mul(dt));
        self.heading_sum += run.sum as f32 * geo::wrap_pi(ctx.heading_rad - self.heading0_rad);
        self.relative |= ctx.heading_missing;
        self.partial |= ctx.partial;
    }

    /// Marks the blob as possibly missing cells (cut by a restart or a gap).
    pub fn mark_partial(&mut self) {
        self.partial = true;
    }

    /// Takes `other`'s cells: both are open on the spoke `current`; the merged blob counts
    /// from the older one's first spoke.
    pub fn merge(&mut self, other: &Blob, current: u32) {
        let age = |b: &Blob| current.wrapping_sub(b.first_spoke);
        if age(other) > age(self) {
            let shift = u64::from(self.first_spoke.wrapping_sub(other.first_spoke));
            self.spoke_sum += shift * self.sum;
            self.first_spoke = other.first_spoke;
            self.first_angle = other.first_angle;
        }
        let other_shift = u64::from(other.first_spoke.wrapping_sub(self.first_spoke));
        self.spoke_sum += other.spoke_sum + other_shift * other.sum;
        if other.time0_ms < self.time0_ms {
            let dt = self.time0_ms - other.time0_ms;
            self.time_sum = self.time_sum.saturating_add(dt.saturating_mul(self.sum));
            self.time0_ms = other.time0_ms;
        }
        let dt = other.time0_ms - self.time0_ms;
        self.time_sum = self
            .time_sum
            .saturating_add(other.time_sum)
            .saturating_add(dt.saturating_mul(other.sum));
        self.heading_sum += other.heading_sum
            + other.sum as f32 * geo::wrap_pi(other.heading0_rad - self.heading0_rad);
        if current.wrapping_sub(other.last_spoke) < current.wrapping_sub(self.last_spoke) {
            self.last_spoke = other.last_spoke;
        }
        self.misses = self.misses.min(other.misses);
        self.min_cell = self.min_cell.min(other.min_cell);
        self.max_cell = self.max_cell.max(other.max_cell);
        self.cells = self.cells.saturating_add(other.cells);
        self.peak = self.peak.max(other.peak);
        self.sum += other.sum;
        self.cell_sum += other.cell_sum;
        self.relative |= other.relative;
        self.partial |= other.partial;
        self.detections = self.detections.saturating_add(other.detections);
        if self.echo == NO_ECHO {
            self.echo = other.echo;
        }
    }

    /// Cells added (detected cells of a CFAR blob, cells of an echo).
    pub fn cells(&self) -> u32 {
        self.cells
    }

    /// Spokes from the first to the last, inclusive.
    pub fn spokes(&self) -> u32 {
        self.last_spoke
            .wrapping_sub(self.first_spoke)
            .saturating_add(1)
    }

    /// The plot this blob measures.
    pub fn measure(&self, geometry: &Geometry) -> RadarPlot {
        let sum = self.sum.max(1) as f32;
        let n = f32::from(geometry.spokes_per_rotation.max(1));
        let rad_per_spoke = core::f32::consts::TAU / n;
        // A sample's centre is half a cell out from its index.
        let range_m = (self.cell_sum as f32 / sum + 0.5) * geometry.sample_m;
        let angle = f32::from(self.first_angle) + self.spoke_sum as f32 / sum;
        let angle_rad = geo::wrap_2pi(angle * rad_per_spoke);
        let relative_bearing = !geometry.north_up && self.relative;
        let bearing_rad = if geometry.north_up || relative_bearing {
            angle_rad
        } else {
            geo::wrap_2pi(angle_rad + self.heading0_rad + self.heading_sum / sum)
        };
        let spokes = self.spokes();
        let angular_extent_rad = spokes as f32 * rad_per_spoke;
        let range_cells = self
            .max_cell
            .saturating_sub(self.min_cell)
            .saturating_add(1);
        RadarPlot {
            range_m,
            bearing_rad,
            relative_bearing,
            range_extent_m: f32::from(range_cells) * geometry.sample_m,
            range_cells,
            angular_extent_rad,
            cross_range_m: angular_extent_rad * range_m,
            peak: self.peak,
            strength: u32::try_from(self.sum).unwrap_or(u32::MAX),
            cells: self.cells,
            spokes,
            time_ms: self
                .time0_ms
                .saturating_add(self.time_sum / self.sum.max(1)),
            partial: self.partial,
            detections: self.detections.max(1),
        }
    }
}

/// What a closed blob measures: a point target's plot, or an extended return's outline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadarPlot {
    /// Range of the strength-weighted centroid from the antenna, m.
    pub range_m: f32,
    /// Bearing of the centroid, rad in [0, 2π): true, unless
    /// [`RadarPlot::relative_bearing`].
    pub bearing_rad: f32,
    /// The blob was on head-up spokes without own heading: the bearing is from the bow.
    pub relative_bearing: bool,
    /// From the nearest cell to the farthest, m.
    pub range_extent_m: f32,
    /// The same in range cells (samples): the extent in the radar's own resolution.
    pub range_cells: u16,
    /// From the first spoke to the last, rad.
    pub angular_extent_rad: f32,
    /// The angular extent at the centroid's range, m (a point target's is about the
    /// beam's width there).
    pub cross_range_m: f32,
    /// The strongest sample, sample levels.
    pub peak: u8,
    /// Sum of the detected samples, sample levels (saturates).
    pub strength: u32,
    /// Cells: of the echo (samples at or above the echo threshold) for a plot measured on
    /// its echo, detected cells for one measured on its CFAR blob alone.
    pub cells: u32,
    /// Spokes from the first to the last.
    pub spokes: u32,
    /// Strength-weighted mean time of its spokes (the centroid's time), ms on the spokes'
    /// clock.
    pub time_ms: u64,
    /// It may miss cells: it touched the first spoke after a start or restart, was cut by
    /// a restart or a gap of missing spokes, or was closed for covering a whole rotation.
    pub partial: bool,
    /// CFAR detections (blobs of a plot's size) it holds: 1 or more for an echo, 1 for a
    /// plot measured on its CFAR blob alone.
    pub detections: u16,
}

impl RadarPlot {
    /// The tracker's plot (range, true bearing), or `None` when the bearing is not true.
    pub fn to_icd(&self) -> Option<Plot> {
        (!self.relative_bearing).then_some(Plot {
            range_m: self.range_m,
            bearing_rad: self.bearing_rad,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(start: u16, end: u16, level: u8) -> Run {
        let mut r = Run {
            start,
            end,
            sum: 0,
            index_sum: 0,
            peak: level,
        };
        for i in start..end {
            r.sum += u32::from(level);
            r.index_sum += u64::from(level) * u64::from(i);
        }
        r
    }

    fn ctx(spoke: u32, angle: u16) -> SpokeContext {
        SpokeContext {
            spoke,
            angle,
            time_ms: 1000 + u64::from(spoke) * 10,
            heading_rad: 0.0,
            heading_missing: false,
            partial: false,
        }
    }

    const GEOMETRY: Geometry = Geometry {
        spokes_per_rotation: 360,
        sample_m: 10.0,
        north_up: true,
    };

    #[test]
    fn the_centroid_is_strength_weighted_and_extents_cover_the_cells() {
        let mut b = Blob::start(&ctx(5, 100), &run(10, 13, 4));
        b.add(&ctx(6, 101), &run(11, 14, 8));
        let p = b.measure(&GEOMETRY);
        // Cells 10–12 at 4 and 11–13 at 8: centroid cell (4·33 + 8·36)/36 = 11.67.
        assert!(
            (p.range_m - (420.0 / 36.0 + 0.5) * 10.0).abs() < 1e-3,
            "{p:?}"
        );
        // Spokes 100 (weight 12) and 101 (24): 100.67°.
        assert!((p.bearing_rad.to_degrees() - (100.0 + 24.0 / 36.0)).abs() < 1e-3);
        assert_eq!((p.cells, p.spokes, p.peak, p.strength), (6, 2, 8, 36));
        assert!((p.range_extent_m - 40.0).abs() < 1e-6);
        assert!((p.angular_extent_rad.to_degrees() - 2.0).abs() < 1e-4);
        assert_eq!(p.time_ms, 1050 + 240 / 36);
        assert!(!p.partial && !p.relative_bearing);
    }

    #[test]
    fn merging_rebases_to_the_older_blob_across_the_wrap() {
        // Spokes 358, 359 (one blob) and 0 (the next rotation), joined by a run on 1.
        let mut a = Blob::start(&ctx(1000, 358), &run(10, 11, 10));
        a.add(&ctx(1001, 359), &run(10, 11, 10));
        let mut b = Blob::start(&ctx(1002, 0), &run(20, 21, 10));
        b.add(&ctx(1003, 1), &run(10, 21, 1));
        a.add(&ctx(1003, 1), &run(10, 11, 10));
        // b is younger: merge into a either way round gives the same plot.
        let mut ab = a;
        ab.merge(&b, 1003);
        let mut ba = b;
        ba.merge(&a, 1003);
        let (p, q) = (ab.measure(&GEOMETRY), ba.measure(&GEOMETRY));
        assert_eq!(p, q);
        assert_eq!(p.spokes, 4);
        // Weights: 358: 10, 359: 10, 0: 10, 1: 11 + 10 = 21 → mean offset 1.41 from 358.
        let expected = 358.0 + (10.0 + 20.0 + 3.0 * 21.0) / 51.0 - 360.0;
        let got = geo::wrap_pi(p.bearing_rad).to_degrees();
        assert!((got - expected).abs() < 1e-3, "{got} vs {expected}");
    }

    #[test]
    fn head_up_bearings_add_the_heading_and_a_missing_one_makes_them_relative() {
        let geometry = Geometry {
            north_up: false,
            ..GEOMETRY
        };
        let mut c = ctx(0, 90);
        c.heading_rad = 0.5f32.to_radians();
        let mut b = Blob::start(&c, &run(10, 11, 5));
        c.spoke = 1;
        c.angle = 91;
        c.heading_rad = 1.5f32.to_radians();
        b.add(&c, &run(10, 11, 5));
        let p = b.measure(&geometry);
        assert!((p.bearing_rad.to_degrees() - 91.5).abs() < 1e-3, "{p:?}");
        assert!(p.to_icd().is_some());
        c.spoke = 2;
        c.angle = 92;
        c.heading_missing = true;
        b.add(&c, &run(10, 11, 5));
        let p = b.measure(&geometry);
        assert!(p.relative_bearing && p.to_icd().is_none());
        assert!((p.bearing_rad.to_degrees() - 91.0).abs() < 1e-3, "{p:?}");
    }
}
