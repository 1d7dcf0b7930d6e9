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
//! ([`Origin::to_lat_lon_near`], [`Origin::to_local_near`]): at the geodesic distance and
//! azimuth from own ship that its offset in the frame gives, as a radar measures range and
//! bearing, while own ship itself stays in the origin's frame. The geodesics are Karney's
//! (C. F. F. Karney, "Algorithms for geodesics", J. Geodesy 87, 2013), from the
//! `geographiclib-rs` crate. They replaced an offset in metres at own ship's latitude, a
//! plane whose meridians do not converge: a target 10 NM from own ship at 50° N lay up to
//! 37 m (35 m of it across its bearing) from where TTM's range and bearing put it on the
//! ellipsoid, and 85 m at 70° N, growing with the square of the range.

use std::sync::LazyLock;

use anyhow::{bail, Context};
use geographiclib_rs::{DirectGeodesic, Geodesic, InverseGeodesic};

/// WGS84 semi-major axis, m (NIMA TR8350.2, Table 3.1).
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS84 flattening (NIMA TR8350.2, Table 3.1).
const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS84 first eccentricity squared, e² = f(2 − f).
const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

/// The WGS84 ellipsoid's geodesics (its series' coefficients, computed once).
static WGS84: LazyLock<Geodesic> = LazyLock::new(|| Geodesic::new(WGS84_A_M, WGS84_F));

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
        // Each error names the value and the form: clap shows only the outermost words
        // (`--origin 50,1,2` was answered "longitude").
        let form = "expected LAT,LON in decimal degrees, e.g. 50.67,-1.0";
        let (lat, lon) = s
            .split_once(',')
            .with_context(|| format!("`{s}`: {form}"))?;
        let number = |x: &str, what: &str| {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .with_context(|| format!("`{s}`: the {what} `{x}` is not a number ({form})"))
        };
        let o = Origin {
            lat_deg: number(lat, "latitude")?,
            lon_deg: number(lon, "longitude")?,
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
    /// (local, m): the point at the geodesic distance |p − own_m| from own ship's own
    /// latitude and longitude ([`Origin::to_lat_lon`]) on the azimuth of p − own_m, as its
    /// range and bearing measure it. The longitude in [−180°, 180°). Not a number when
    /// either position is not, or own ship's is no place on the globe (dead reckoned past a
    /// pole: the frame's latitude beyond ±90°).
    pub fn to_lat_lon_near(&self, p: [f64; 2], own_m: [f64; 2]) -> (f64, f64) {
        let (lat, lon) = self.to_lat_lon(own_m);
        let d = [p[0] - own_m[0], p[1] - own_m[1]];
        along_geodesic(lat, lon, d[0].atan2(d[1]).to_degrees(), d[0].hypot(d[1]))
    }

    /// Local position (east, north), m, of a latitude and longitude near own ship at `own_m`
    /// (local, m): own ship's local position and the geodesic from own ship to the point,
    /// its length along its azimuth at own ship. The inverse of [`Origin::to_lat_lon_near`].
    /// Not a number when the point is not on the globe (a latitude beyond ±90°).
    pub fn to_local_near(&self, lat_deg: f64, lon_deg: f64, own_m: [f64; 2]) -> [f64; 2] {
        let (lat, lon) = self.to_lat_lon(own_m);
        if !(on_globe(lat, lon) && on_globe(lat_deg, lon_deg)) {
            return [f64::NAN, f64::NAN];
        }
        let (s_m, azi_deg, _, _): (f64, f64, f64, f64) = WGS84.inverse(lat, lon, lat_deg, lon_deg);
        let (sin, cos) = azi_deg.to_radians().sin_cos();
        [own_m[0] + s_m * sin, own_m[1] + s_m * cos]
    }

    /// A position `p` and velocity `v` in the origin's frame (local, m and m/s) taken about
    /// own ship at `own_m` ([`Origin::to_local_near`] of the position's latitude and
    /// longitude; the velocity as the motion of the point over a second): where the same
    /// ship's AIS report is put, and where own ship's radar sees it.
    pub fn about_own_ship(
        &self,
        p: [f64; 2],
        v: [f64; 2],
        own_m: [f64; 2],
    ) -> ([f64; 2], [f64; 2]) {
        let near = |x: [f64; 2]| {
            let (lat, lon) = self.to_lat_lon(x);
            self.to_local_near(lat, lon, own_m)
        };
        let a = near(p);
        let b = near([p[0] + v[0], p[1] + v[1]]);
        (a, [b[0] - a[0], b[1] - a[1]])
    }
}

/// The point `distance_m` along the WGS84 geodesic from `lat_deg`, `lon_deg` (degrees) on
/// the azimuth `azimuth_deg` (degrees true) there: latitude and longitude, degrees, the
/// longitude in [−180°, 180°). Not a number for a start off the globe or a distance not a
/// number.
pub fn along_geodesic(lat_deg: f64, lon_deg: f64, azimuth_deg: f64, distance_m: f64) -> (f64, f64) {
    if !(on_globe(lat_deg, lon_deg) && azimuth_deg.is_finite() && distance_m.is_finite()) {
        return (f64::NAN, f64::NAN);
    }
    let (lat, lon): (f64, f64) = WGS84.direct(lat_deg, lon_deg, azimuth_deg, distance_m);
    (lat, wrap_180(lon))
}

/// A latitude and longitude, degrees, that are a place on the globe (what the geodesics
/// take; anything else gives not a number).
fn on_globe(lat_deg: f64, lon_deg: f64) -> bool {
    lat_deg.abs() <= 90.0 && lon_deg.is_finite()
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

    /// Vincenty's inverse on WGS84 (T. Vincenty, "Direct and inverse solutions of geodesics
    /// on the ellipsoid", Survey Review 23, 1975, eqs. 13–21 and 3–6): a second, independent
    /// algorithm to check the geodesics against (within a millimetre at these distances).
    /// The distance, m, and the azimuth at the first point, degrees.
    fn vincenty(lat1: f64, lon1: f64, lat2: f64, lon2: f64) -> (f64, f64) {
        let b = WGS84_A_M * (1.0 - WGS84_F);
        let u1 = ((1.0 - WGS84_F) * lat1.to_radians().tan()).atan();
        let u2 = ((1.0 - WGS84_F) * lat2.to_radians().tan()).atan();
        let l = (lon2 - lon1).to_radians();
        let (su1, cu1) = u1.sin_cos();
        let (su2, cu2) = u2.sin_cos();
        let mut lambda = l;
        let (mut sigma, mut ss, mut cs, mut c2a, mut c2sm) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for _ in 0..100 {
            let (sl, cl) = lambda.sin_cos();
            ss = ((cu2 * sl).powi(2) + (cu1 * su2 - su1 * cu2 * cl).powi(2)).sqrt();
            cs = su1 * su2 + cu1 * cu2 * cl;
            sigma = ss.atan2(cs);
            let sa = cu1 * cu2 * sl / ss;
            c2a = 1.0 - sa * sa;
            c2sm = cs - 2.0 * su1 * su2 / c2a;
            let c = WGS84_F / 16.0 * c2a * (4.0 + WGS84_F * (4.0 - 3.0 * c2a));
            let next = l
                + (1.0 - c)
                    * WGS84_F
                    * sa
                    * (sigma + c * ss * (c2sm + c * cs * (-1.0 + 2.0 * c2sm * c2sm)));
            let done = (next - lambda).abs() < 1e-13;
            lambda = next;
            if done {
                break;
            }
        }
        let u2sq = c2a * (WGS84_A_M * WGS84_A_M - b * b) / (b * b);
        let aa =
            1.0 + u2sq / 16_384.0 * (4_096.0 + u2sq * (-768.0 + u2sq * (320.0 - 175.0 * u2sq)));
        let bb = u2sq / 1_024.0 * (256.0 + u2sq * (-128.0 + u2sq * (74.0 - 47.0 * u2sq)));
        let ds = bb
            * ss
            * (c2sm
                + bb / 4.0
                    * (cs * (-1.0 + 2.0 * c2sm * c2sm)
                        - bb / 6.0 * c2sm * (-3.0 + 4.0 * ss * ss) * (-3.0 + 4.0 * c2sm * c2sm)));
        let (sl, cl) = lambda.sin_cos();
        let azi = (cu2 * sl).atan2(cu1 * su2 - su1 * cu2 * cl).to_degrees();
        (b * aa * (sigma - ds), azi)
    }

    #[test]
    fn positions_about_own_ship_are_at_their_range_and_bearing() {
        let o = Origin::default();
        // Own ship at the origin, 60 NM north of it (where the origin's east metres are
        // 2.2 % short) and at 70° N; targets at 1, 6 and 10 NM all round.
        let north = Origin {
            lat_deg: 70.0,
            lon_deg: 20.0,
        };
        for (frame, own) in [
            (o, [0.0, 0.0]),
            (o, o.to_local(o.lat_deg + 1.0, o.lon_deg + 0.3)),
            (north, [5_000.0, -3_000.0]),
        ] {
            let (own_lat, own_lon) = frame.to_lat_lon(own);
            for range_m in [1_852.0, 11_112.0, 18_520.0] {
                for bearing in (0..360).step_by(15) {
                    let b = f64::from(bearing).to_radians();
                    let p = [own[0] + range_m * b.sin(), own[1] + range_m * b.cos()];
                    let (lat, lon) = frame.to_lat_lon_near(p, own);
                    let (s, azi) = vincenty(own_lat, own_lon, lat, lon);
                    let turn = (azi - f64::from(bearing) + 540.0).rem_euclid(360.0) - 180.0;
                    assert!(
                        (s - range_m).abs() < 1e-3,
                        "{own:?} {range_m} {bearing}: {s}"
                    );
                    assert!(turn.abs() < 1e-7, "{own:?} {range_m} {bearing}: {azi}");
                    // And back.
                    let q = frame.to_local_near(lat, lon, own);
                    assert!((q[0] - p[0]).abs() < 1e-6 && (q[1] - p[1]).abs() < 1e-6);
                }
            }
        }
        // A ship's position and velocity in the origin's frame taken about own ship: at the
        // geodesic's distance and azimuth from own ship, moving as before within 0.25 % (the
        // origin's east metres are not those at own ship's latitude).
        let own = o.to_local(o.lat_deg - 0.2, o.lon_deg + 0.1);
        let (own_lat, own_lon) = o.to_lat_lon(own);
        let (p, v) = o.about_own_ship([3_000.0, 4_000.0], [2.0, -1.0], own);
        let (lat, lon) = o.to_lat_lon([3_000.0, 4_000.0]);
        let (s, azi) = vincenty(own_lat, own_lon, lat, lon);
        let (sin, cos) = azi.to_radians().sin_cos();
        assert!((own[0] + s * sin - p[0]).abs() < 1e-3, "{p:?}");
        assert!((own[1] + s * cos - p[1]).abs() < 1e-3, "{p:?}");
        assert!(
            (v[0] - 2.0).abs() < 5e-3 && (v[1] + 1.0).abs() < 2.5e-3,
            "{v:?}"
        );
        // Across the antimeridian: wrapped.
        let east = Origin {
            lat_deg: 0.0,
            lon_deg: 179.99,
        };
        assert!(east.to_lat_lon_near([5_000.0, 0.0], [0.0, 0.0]).1 < -179.0);
        // Own ship 1 km from the pole: a point 10 m east and south of it is there.
        let near_pole = o.to_local(89.99, 0.0);
        let (lat, lon) = o.to_lat_lon_near([near_pole[0] + 10.0, near_pole[1] - 10.0], near_pole);
        assert!(lat < 89.99 && lat > 89.9898, "{lat}");
        assert!(lon.is_finite() && lon > 0.0 && lon < 1.0, "{lon}");
        // Not on the globe, or not a number: not a number, never a panic.
        assert!(o.to_local_near(91.0, 0.0, [0.0, 0.0])[0].is_nan());
        assert!(o.to_local_near(f64::NAN, 0.0, [0.0, 0.0])[1].is_nan());
        assert!(o.to_lat_lon_near([f64::NAN, 0.0], [0.0, 0.0]).0.is_nan());
        assert!(o
            .to_lat_lon_near([f64::INFINITY, 0.0], [0.0, 0.0])
            .0
            .is_nan());
        assert!(Origin::parse("95,0").is_err() && Origin::parse("x").is_err());
    }

    #[test]
    fn an_origin_that_does_not_parse_is_answered_with_its_value_and_the_form() {
        for (bad, said) in [
            ("50,1,2", "the longitude `1,2` is not a number"),
            ("x,1", "the latitude `x` is not a number"),
            ("50", "expected LAT,LON"),
            ("nan,1", "the latitude `nan` is not a number"),
        ] {
            let e = Origin::parse(bad).unwrap_err().to_string();
            assert!(e.contains(said) && e.contains(bad), "{bad}: {e}");
        }
    }
}
