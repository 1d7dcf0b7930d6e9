//! One spoke: the echo strengths along one antenna bearing, from own ship outwards.

/// One spoke, borrowed from the buffer it was decoded into (no allocation).
///
/// Sample `i` of `n` covers ranges `[i, i + 1) · range_m / n` from the antenna; its centre is
/// at `(i + 0.5) · range_m / n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spoke<'a> {
    /// The spoke's angle as an index into the rotation, `0..spokes_per_rotation`, clockwise
    /// from the bow (from true north when `north_up`).
    pub angle: u16,
    /// Spokes in a full rotation (2,048 Navico, 1,440 Garmin xHD).
    pub spokes_per_rotation: u16,
    /// True when `angle` is already from true north (the radar applied its heading).
    pub north_up: bool,
    /// Own ship's heading when the spoke was taken, rad true, when known: a bow-relative
    /// angle plus it is a true bearing.
    pub heading_rad: Option<f32>,
    /// Range the samples cover, m.
    pub range_m: f32,
    /// When the spoke was taken, ms (the source's clock).
    pub time_ms: u64,
    /// Echo strengths, from the antenna outwards, `0..=max_sample`.
    pub samples: &'a [u8],
    /// The strongest echo a sample can hold (15 for Navico's 4 bits, 255 for Garmin's 8).
    pub max_sample: u8,
}

impl Spoke<'_> {
    /// The spoke's angle from the bow (or north when `north_up`), rad, in [0, 2π).
    pub fn angle_rad(&self) -> f32 {
        let n = f32::from(self.spokes_per_rotation.max(1));
        f32::from(self.angle) * core::f32::consts::TAU / n
    }

    /// The spoke's true bearing, rad in [0, 2π): its angle when north-up, else its angle
    /// plus the heading; `None` for a head-up spoke without a heading.
    pub fn bearing_rad(&self) -> Option<f32> {
        if self.north_up {
            return Some(self.angle_rad());
        }
        self.heading_rad
            .map(|h| crate::geo::wrap_2pi(self.angle_rad() + h))
    }

    /// Metres per sample.
    pub fn sample_m(&self) -> f32 {
        self.range_m / (self.samples.len().max(1) as f32)
    }
}
