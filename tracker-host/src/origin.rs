//! Where the tracker's local frame (east, north, metres) sits on the globe: an [`Origin`]
//! latitude and longitude, and a flat-earth mapping around it, accurate to well under a
//! metre over a radar's range.

use anyhow::{bail, Context};
use tracker_core::geo::METRES_PER_NM;

const METRES_PER_DEGREE_LATITUDE: f64 = 60.0 * METRES_PER_NM as f64;

/// Where the local frame's (0, 0) is on the globe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    /// Latitude, degrees north.
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
}

impl Default for Origin {
    /// The eastern approach to the Solent, 50°40′N 001°00′W: open water for the demo.
    fn default() -> Self {
        Origin {
            lat_deg: 50.0 + 40.0 / 60.0,
            lon_deg: -1.0,
        }
    }
}

impl Origin {
    /// Parses `LAT,LON` in decimal degrees.
    ///
    /// # Errors
    /// Not two numbers, or a latitude beyond ±85° or longitude beyond ±180°.
    pub fn parse(s: &str) -> anyhow::Result<Self> {
        let (lat, lon) = s.split_once(',').context("expected LAT,LON")?;
        let o = Origin {
            lat_deg: lat.trim().parse().context("latitude")?,
            lon_deg: lon.trim().parse().context("longitude")?,
        };
        if !(o.lat_deg.abs() < 85.0 && o.lon_deg.abs() <= 180.0) {
            bail!("{s}: latitude within ±85°, longitude within ±180°");
        }
        Ok(o)
    }

    /// Latitude and longitude of a local position, degrees; the longitude in
    /// [−180°, 180°) (across the antimeridian it wraps).
    pub fn to_lat_lon(&self, p: [f64; 2]) -> (f64, f64) {
        let lat = self.lat_deg + p[1] / METRES_PER_DEGREE_LATITUDE;
        let lon =
            self.lon_deg + p[0] / (METRES_PER_DEGREE_LATITUDE * self.lat_deg.to_radians().cos());
        (lat, (lon + 180.0).rem_euclid(360.0) - 180.0)
    }

    /// Local position (east, north), m, of a latitude and longitude in degrees.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64) -> [f64; 2] {
        let mut dlon = lon_deg - self.lon_deg;
        if dlon > 180.0 {
            dlon -= 360.0;
        } else if dlon < -180.0 {
            dlon += 360.0;
        }
        [
            dlon * METRES_PER_DEGREE_LATITUDE * self.lat_deg.to_radians().cos(),
            (lat_deg - self.lat_deg) * METRES_PER_DEGREE_LATITUDE,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_round_trip_through_latitude_and_longitude() {
        let o = Origin::default();
        for p in [[0.0, 0.0], [18_520.0, -9_000.0], [-40_000.0, 30_000.0]] {
            let (lat, lon) = o.to_lat_lon(p);
            let q = o.to_local(lat, lon);
            assert!((p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6);
        }
        assert!(Origin::parse("50.5,-1.2").is_ok());
        assert!(Origin::parse("95,0").is_err() && Origin::parse("x").is_err());
    }
}
