//! Where the tracker's local frame (east, north, metres) sits on the globe: an [`Origin`]
//! latitude and longitude, and a flat-earth mapping around it, accurate to well under a
//! metre over a radar's range of the origin.
//!
//! Own ship leaves the origin behind on a passage, and the frame's east metres are the
//! origin's (cos of its latitude): 60 NM north of it at 51° N they are 2.2 % short, and a
//! target 6 NM east of own ship would be placed 240 m off where its range and bearing put
//! it. So a target's latitude and longitude are taken about own ship
//! ([`Origin::to_lat_lon_near`], [`Origin::to_local_near`]): the offset from own ship in
//! metres at own ship's latitude, as a radar measures it, while own ship itself stays in the
//! origin's frame.

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
        let lon = self.lon_deg + p[0] / metres_per_degree_east(self.lat_deg);
        (lat, wrap_180(lon))
    }

    /// Local position (east, north), m, of a latitude and longitude in degrees.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64) -> [f64; 2] {
        [
            wrap_180(lon_deg - self.lon_deg) * metres_per_degree_east(self.lat_deg),
            (lat_deg - self.lat_deg) * METRES_PER_DEGREE_LATITUDE,
        ]
    }

    /// Latitude and longitude, degrees, of a local position `p` near own ship at `own_m`
    /// (local, m): own ship's own latitude and longitude ([`Origin::to_lat_lon`]) and the
    /// offset `p − own_m` taken in metres at own ship's latitude, as its range and bearing
    /// measure it. The longitude in [−180°, 180°).
    pub fn to_lat_lon_near(&self, p: [f64; 2], own_m: [f64; 2]) -> (f64, f64) {
        let (lat, lon) = self.to_lat_lon(own_m);
        (
            lat + (p[1] - own_m[1]) / METRES_PER_DEGREE_LATITUDE,
            wrap_180(lon + (p[0] - own_m[0]) / metres_per_degree_east(lat)),
        )
    }

    /// Local position (east, north), m, of a latitude and longitude near own ship at `own_m`
    /// (local, m): own ship's local position and the offset to the point in metres at own
    /// ship's latitude. The inverse of [`Origin::to_lat_lon_near`].
    pub fn to_local_near(&self, lat_deg: f64, lon_deg: f64, own_m: [f64; 2]) -> [f64; 2] {
        let (lat, lon) = self.to_lat_lon(own_m);
        [
            own_m[0] + wrap_180(lon_deg - lon) * metres_per_degree_east(lat),
            own_m[1] + (lat_deg - lat) * METRES_PER_DEGREE_LATITUDE,
        ]
    }

    /// The east metres at own ship's latitude over the origin's: a local offset east of own
    /// ship at `own_m` ([`Origin::to_local`]) times this is the same offset taken about own
    /// ship ([`Origin::to_local_near`]).
    pub fn east_scale_near(&self, own_m: [f64; 2]) -> f64 {
        let (lat, _) = self.to_lat_lon(own_m);
        metres_per_degree_east(lat) / metres_per_degree_east(self.lat_deg)
    }
}

/// Metres a degree of longitude at `lat_deg` (never zero: at the poles a degree of
/// longitude is taken as a micrometre, so nothing divides by zero).
fn metres_per_degree_east(lat_deg: f64) -> f64 {
    (METRES_PER_DEGREE_LATITUDE * lat_deg.to_radians().cos()).max(1e-6)
}

/// An angle in degrees wrapped to [−180°, 180°).
fn wrap_180(deg: f64) -> f64 {
    (deg + 180.0).rem_euclid(360.0) - 180.0
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
    }

    #[test]
    fn positions_about_own_ship_are_taken_at_its_latitude() {
        let o = Origin::default();
        // Own ship 60 NM north of the origin; a target 6 NM east of it.
        let own = o.to_local(o.lat_deg + 1.0, o.lon_deg);
        let target = [own[0] + 11_112.0, own[1]];
        let (lat, lon) = o.to_lat_lon_near(target, own);
        assert!((lat - (o.lat_deg + 1.0)).abs() < 1e-9);
        // 6 NM east at 51°40′N is 0.161° of longitude; in the origin's frame it would be
        // 0.158° (the 2.2 % of the module documentation: 240 m).
        let want = 0.1 / (o.lat_deg + 1.0).to_radians().cos();
        assert!((lon - o.lon_deg - want).abs() < 1e-9, "{lon}");
        let (_, far) = o.to_lat_lon(target);
        assert!((lon - far).abs() * 60.0 * 1852.0 * (lat.to_radians().cos()) > 200.0);
        // And back.
        let q = o.to_local_near(lat, lon, own);
        assert!((q[0] - target[0]).abs() < 1e-6 && (q[1] - target[1]).abs() < 1e-6);
        let k = o.east_scale_near(own);
        let p = o.to_local(lat, lon);
        assert!((own[0] + (p[0] - own[0]) * k - target[0]).abs() < 1e-6);
        // At the origin the two are the same mapping.
        let at = o.to_lat_lon_near([500.0, -300.0], [0.0, 0.0]);
        assert_eq!(at, o.to_lat_lon([500.0, -300.0]));
        // Across the antimeridian and at a pole: finite.
        let east = Origin {
            lat_deg: 0.0,
            lon_deg: 179.99,
        };
        assert!(east.to_lat_lon_near([5_000.0, 0.0], [0.0, 0.0]).1 < -179.0);
        // Own ship 1 km from the pole: a point 10 m east and south of it is there.
        let near_pole = o.to_local(89.99, 0.0);
        let (lat, lon) = o.to_lat_lon_near([near_pole[0] + 10.0, near_pole[1] - 10.0], near_pole);
        assert!((lat - (89.99 - 10.0 / METRES_PER_DEGREE_LATITUDE)).abs() < 1e-9);
        assert!(lon.is_finite() && lon > 0.0 && lon < 1.0, "{lon}");
        assert!(Origin::parse("95,0").is_err() && Origin::parse("x").is_err());
    }
}
