//! The radar picture for the eye: the spokes max-pooled onto a coarse north-up polar grid
//! ([`EchoImage`]), which the terminal display draws under the plots and tracks and
//! `--snapshot` paints to a PNG. A HALO rotation is 2,048 × 1,024 samples; the grid keeps
//! [`BEARING_CELLS`] × [`RANGE_CELLS`] (the strongest sample in each cell), enough for a
//! terminal or a 1,000-pixel picture, in 128 KiB. As on a radar display, the sweep
//! repaints each bearing as it passes and leaves the rest as the last rotation drew it, so
//! a rotation cut short (a capture's end) still shows the whole picture.

/// Bearing cells in a rotation (0.7° each).
pub const BEARING_CELLS: usize = 512;
/// Range cells from own ship to the radar's range.
pub const RANGE_CELLS: usize = 256;

/// The echoes of the last rotation on a north-up polar grid, each bearing as the sweep last
/// painted it.
#[derive(Clone, Debug, PartialEq)]
pub struct EchoImage {
    /// The range the cells span, m (the last spoke's).
    pub range_m: f32,
    /// The strongest level a sample can hold (15 Navico, 255 Garmin).
    pub max_sample: u8,
    /// Spokes taken in this rotation.
    pub spokes: u32,
    cells: Vec<u8>,
    /// The rotation each bearing cell was last painted in: a row is cleared when the sweep
    /// first reaches it in a new rotation.
    painted_in: Vec<u32>,
    rotation: u32,
}

impl Default for EchoImage {
    fn default() -> Self {
        EchoImage {
            range_m: 0.0,
            max_sample: 1,
            spokes: 0,
            cells: vec![0; BEARING_CELLS * RANGE_CELLS],
            painted_in: vec![0; BEARING_CELLS],
            rotation: 0,
        }
    }
}

impl EchoImage {
    /// Adds a spoke at true bearing `bearing_rad` whose `samples` span `range_m`. A change of
    /// range clears what was there (its cells would be at the wrong ranges).
    pub fn add(&mut self, bearing_rad: f32, range_m: f32, samples: &[u8], max_sample: u8) {
        if !(range_m > 0.0 && range_m.is_finite() && bearing_rad.is_finite()) || samples.is_empty()
        {
            return;
        }
        if self.range_m != range_m {
            self.cells.iter_mut().for_each(|c| *c = 0);
            self.range_m = range_m;
        }
        self.max_sample = max_sample.max(1);
        self.spokes += 1;
        let turn = bearing_rad.rem_euclid(core::f32::consts::TAU) / core::f32::consts::TAU;
        let b = ((turn * BEARING_CELLS as f32) as usize).min(BEARING_CELLS - 1);
        let row = &mut self.cells[b * RANGE_CELLS..(b + 1) * RANGE_CELLS];
        if self.painted_in[b] != self.rotation {
            // The sweep is back at this bearing: the last rotation's echoes there go.
            row.iter_mut().for_each(|c| *c = 0);
            self.painted_in[b] = self.rotation;
        }
        let n = samples.len();
        for (i, &s) in samples.iter().enumerate() {
            let r = i * RANGE_CELLS / n;
            row[r] = row[r].max(s);
        }
    }

    /// Starts the next rotation: the picture stays until the sweep repaints each bearing,
    /// but a bearing the whole rotation just ended did not paint (spokes lost, a blanked
    /// sector, head-up spokes without a heading) is cleared: nothing older than one rotation
    /// is shown as if current.
    pub fn next_rotation(&mut self) {
        for (b, painted) in self.painted_in.iter().enumerate() {
            if *painted != self.rotation {
                self.cells[b * RANGE_CELLS..(b + 1) * RANGE_CELLS].fill(0);
            }
        }
        self.rotation = self.rotation.wrapping_add(1);
        self.spokes = 0;
    }

    /// The cells at or above `fraction` of full scale: (true bearing rad, range m, level as
    /// a fraction of full scale) at each cell's centre.
    pub fn echoes(&self, fraction: f32) -> impl Iterator<Item = (f32, f32, f32)> + '_ {
        let full = f32::from(self.max_sample);
        self.cells.iter().enumerate().filter_map(move |(i, &c)| {
            let level = f32::from(c) / full;
            (c > 0 && level >= fraction).then(|| {
                let (b, r) = (i / RANGE_CELLS, i % RANGE_CELLS);
                (
                    (b as f32 + 0.5) * core::f32::consts::TAU / BEARING_CELLS as f32,
                    (r as f32 + 0.5) * self.range_m / RANGE_CELLS as f32,
                    level,
                )
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spoke_lands_in_its_bearing_and_range_cells() {
        let mut im = EchoImage::default();
        let mut samples = [0u8; 1024];
        samples[512] = 15; // mid range
        im.add(core::f32::consts::FRAC_PI_2, 1000.0, &samples, 15);
        let e: Vec<_> = im.echoes(0.5).collect();
        assert_eq!(e.len(), 1);
        let (b, r, level) = e[0];
        assert!((b - core::f32::consts::FRAC_PI_2).abs() < 0.01);
        assert!((r - 500.0).abs() < 4.0);
        assert_eq!(level, 1.0);
        // A new range clears the picture; nonsense is ignored.
        im.add(0.0, 2000.0, &[0; 8], 15);
        assert_eq!(im.echoes(0.1).count(), 0);
        im.add(f32::NAN, 2000.0, &samples, 15);
        im.add(0.0, -1.0, &samples, 15);
        assert_eq!(im.spokes, 2);
    }

    #[test]
    fn the_sweep_repaints_only_the_bearings_it_has_passed() {
        let mut im = EchoImage::default();
        let echo_at = |level: u8| {
            let mut s = [0u8; 256];
            s[128] = level;
            s
        };
        let east = core::f32::consts::FRAC_PI_2;
        let west = 3.0 * core::f32::consts::FRAC_PI_2;
        im.add(east, 1000.0, &echo_at(15), 15);
        im.add(west, 1000.0, &echo_at(15), 15);
        assert_eq!(im.echoes(0.5).count(), 2);
        // The next rotation is cut short after the east: the west stays as it was, the
        // east is what this rotation saw there (nothing), not the two rotations' maximum.
        im.next_rotation();
        assert_eq!(im.spokes, 0);
        im.add(east, 1000.0, &echo_at(0), 15);
        let e: Vec<_> = im.echoes(0.5).collect();
        assert_eq!(e.len(), 1);
        assert!((e[0].0 - west).abs() < 0.01, "{e:?}");
        // A bearing the whole rotation did not reach is cleared as the next one starts:
        // nothing older than one rotation stays.
        im.next_rotation();
        assert_eq!(
            im.echoes(0.5).count(),
            0,
            "the west was last painted two rotations ago"
        );
        // Two spokes in one bearing cell within a rotation keep the stronger.
        im.add(west, 1000.0, &echo_at(4), 15);
        im.add(west, 1000.0, &echo_at(12), 15);
        im.add(west, 1000.0, &echo_at(8), 15);
        assert_eq!(im.echoes(0.0).next().map(|e| e.2), Some(0.8));
    }
}
