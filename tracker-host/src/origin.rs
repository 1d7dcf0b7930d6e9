//! Where the tracker's local frame (east, north, metres) sits on the globe: an [`Origin`]
//! latitude and longitude, and a flat-earth mapping around it on the WGS84 ellipsoid,
//! accurate to well under a metre over a radar's range of the origin.
//!
//! The metres of a degree are the ellipsoid's radii of curvature at the latitude (NIMA
//! TR8350.2, WGS84: a = 6,378,137 m, f = 1/298.257223563): north the meridian's, M =
//! a(1−e²)/(1−e² sin²φ)^{3/2}, taken at the mean latitude of the two points; east the prime
//! vertical's, N cos φ with N = a/(1−e² sin²φ)^{1/2}. A sphere of 1′ = 1,852 m, which this
//! replaced, put a point 10 NM east of own ship at 52.9° N 0.39 % (73 m) nearer than its
//! range, and one north 0.15 % (a nautical mile is a minute of latitude only near 45° and
//! there only north).
//!
//! Own ship leaves the origin behind on a passage, and the frame's east metres are the
//! origin's (cos of its latitude): 60 NM north of it at 51° N they are 2.2 % short, and a
//! target 6 NM east of own ship would be placed 240 m off where its range and bearing put
//! it. So a target's latitude and longitude are taken about own ship
//! ([`Origin::to_lat_lon_near`], [`Origin::to_local_near`]): the offset from own ship in
//! metres at own ship's latitude, as a radar measures it, while own ship itself stays in the
//! origin's frame.

use anyhow::{bail, Context};

/// WGS84 semi-major axis, m (NIMA TR8350.2, Table 3.1).
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS84 flattening (NIMA TR8350.2, Table 3.1).
const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS84 first eccentricity squared, e² = f(2 − f).
const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

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
        let lat = latitude_north_of(self.lat_deg, p[1]);
        let lon = self.lon_deg + p[0] / metres_per_degree_east(self.lat_deg);
        (lat, wrap_180(lon))
    }

    /// Local position (east, north), m, of a latitude and longitude in degrees.
    pub fn to_local(&self, lat_deg: f64, lon_deg: f64) -> [f64; 2] {
        [
            wrap_180(lon_deg - self.lon_deg) * metres_per_degree_east(self.lat_deg),
            metres_north(self.lat_deg, lat_deg),
        ]
    }

    /// Latitude and longitude, degrees, of a local position `p` near own ship at `own_m`
    /// (local, m): own ship's own latitude and longitude ([`Origin::to_lat_lon`]) and the
    /// offset `p − own_m` taken in metres at own ship's latitude, as its range and bearing
    /// measure it. The longitude in [−180°, 180°).
    pub fn to_lat_lon_near(&self, p: [f64; 2], own_m: [f64; 2]) -> (f64, f64) {
        let (lat, lon) = self.to_lat_lon(own_m);
        (
            latitude_north_of(lat, p[1] - own_m[1]),
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
            own_m[1] + metres_north(lat, lat_deg),
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

/// 1 − e² sin²φ, the ellipsoid's radii's common term at latitude `lat_deg`.
fn w2(lat_deg: f64) -> f64 {
    1.0 - WGS84_E2 * lat_deg.to_radians().sin().powi(2)
}

/// Metres a degree of latitude at `lat_deg`: the meridian's radius of curvature M.
fn metres_per_degree_north(lat_deg: f64) -> f64 {
    WGS84_A_M * (1.0 - WGS84_E2) / w2(lat_deg).powf(1.5) * core::f64::consts::PI / 180.0
}

/// Metres north from latitude `from_deg` to `to_deg`: M at their mean latitude (the arc to
/// second order: within 5 mm over a degree at 50°, 3 cm at the equator or the poles; so
/// offsets taken about own ship and about the origin agree within decimetres a few degrees
/// from the origin).
fn metres_north(from_deg: f64, to_deg: f64) -> f64 {
    (to_deg - from_deg) * metres_per_degree_north(0.5 * (from_deg + to_deg))
}

/// The latitude `north_m` metres north of `from_deg`: the inverse of [`metres_north`], by
/// fixed-point iteration (M changes by about 10⁻⁴ a degree, so a step gains at least two
/// digits even 40° away; bounded, for a non-finite input).
fn latitude_north_of(from_deg: f64, north_m: f64) -> f64 {
    let mut lat = from_deg + north_m / metres_per_degree_north(from_deg);
    for _ in 0..10 {
        let next = from_deg + north_m / metres_per_degree_north(0.5 * (from_deg + lat));
        let done = (next - lat).abs() < 1e-13;
        lat = next;
        if done {
            break;
        }
    }
    lat
}

/// Metres a degree of longitude at `lat_deg`: N cos φ, the prime vertical's radius of
/// curvature times cos φ (never zero: at the poles a degree of longitude is taken as a
/// micrometre, so nothing divides by zero).
fn metres_per_degree_east(lat_deg: f64) -> f64 {
    let n = WGS84_A_M / w2(lat_deg).sqrt();
    (n * lat_deg.to_radians().cos() * core::f64::consts::PI / 180.0).max(1e-6)
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
    fn a_degree_is_as_long_as_the_wgs84_tables_say() {
        // Lengths of a degree on WGS84, m (the published tables: a degree of latitude
        // centred on φ, a degree of longitude at φ).
        for (lat, north, east) in [
            (0.0, 110_574.0, 111_320.0),
            (45.0, 111_132.0, 78_847.0),
            (60.0, 111_412.0, 55_800.0),
        ] {
            let o = Origin {
                lat_deg: lat - 0.5,
                lon_deg: 0.0,
            };
            let p = o.to_local(lat + 0.5, 1.0);
            assert!((p[1] - north).abs() < 1.0, "{lat}°: {p:?}");
            assert!((metres_per_degree_east(lat) - east).abs() < 1.0, "{lat}°");
        }
        // The sphere of 1′ = 1,852 m this replaced: a point 10 NM east at 52.9° N was
        // placed 73 m short.
        let cos = 52.9f64.to_radians().cos();
        let sphere = 18_520.0 / metres_per_degree_east(52.9) * 1852.0 * 60.0 * cos;
        assert!((18_520.0 - sphere - 72.8).abs() < 0.5, "{sphere}");
    }

    #[test]
    fn positions_about_own_ship_are_taken_at_its_latitude() {
        let o = Origin::default();
        // Own ship 60 NM north of the origin; a target 6 NM east of it.
        let own = o.to_local(o.lat_deg + 1.0, o.lon_deg);
        let target = [own[0] + 11_112.0, own[1]];
        let (lat, lon) = o.to_lat_lon_near(target, own);
        assert!((lat - (o.lat_deg + 1.0)).abs() < 1e-9);
        // 6 NM east at 51°40′N is 0.1606° of longitude; in the origin's frame it would be
        // 0.1571° (the 2.2 % of the module documentation: 240 m).
        let want = 11_112.0 / metres_per_degree_east(o.lat_deg + 1.0);
        assert!((lon - o.lon_deg - want).abs() < 1e-9, "{lon}");
        assert!((want - 0.1606).abs() < 1e-4, "{want}");
        let (_, far) = o.to_lat_lon(target);
        assert!((lon - far).abs() * metres_per_degree_east(lat) > 200.0);
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
        assert!((lat - (89.99 - 10.0 / metres_per_degree_north(89.99))).abs() < 1e-9);
        assert!(lon.is_finite() && lon > 0.0 && lon < 1.0, "{lon}");
        assert!(Origin::parse("95,0").is_err() && Origin::parse("x").is_err());
    }
}
