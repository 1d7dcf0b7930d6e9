//! Own ship from NMEA: sentences in, paper 004's dead-reckoning filter (DRKF) out. GPS
//! position and velocity, the gyro's heading and the log's speed through the water, each
//! parsed by the `nmea` crate; a bad checksum, a malformed sentence, a void fix and a
//! sentence older than the newest one are each rejected and counted ([`NavCounts`]).

use tracker_core::geo::MPS_PER_KNOT;
use tracker_core::nav::drkf::{Drkf, DrkfConfig, NavFix, SpeedlogMode};
use tracker_core::nav::GaussMarkov;

use super::OwnShip;
use crate::origin::Origin;

/// What became of the own-ship sentences.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct NavCounts {
    /// Used by the dead-reckoning filter.
    pub accepted: u64,
    /// Checksum wrong.
    pub bad_checksum: u64,
    /// Not a sentence, or fields out of form.
    pub malformed: u64,
    /// A fix flagged invalid (RMC status V, GGA quality 0) or without its values.
    pub void: u64,
    /// Older than a sentence already used.
    pub stale: u64,
    /// Well-formed but not a sentence own ship needs (satellites, depth, …).
    pub ignored: u64,
}

impl NavCounts {
    /// Sentences rejected (errors, not the ignored ones).
    pub fn rejected(&self) -> u64 {
        self.bad_checksum + self.malformed + self.void + self.stale
    }
}

impl std::fmt::Display for NavCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} accepted, {} rejected (bad checksum {}, malformed {}, void {}, stale {}), {} ignored",
            self.accepted,
            self.rejected(),
            self.bad_checksum,
            self.malformed,
            self.void,
            self.stale,
            self.ignored
        )
    }
}

/// Own ship from NMEA: the dead-reckoning filter (paper 004's DRKF) fed GPS position and
/// velocity, the gyro's heading and the log's speed through the water.
pub struct OwnShipNav {
    origin: Origin,
    drkf: Option<Drkf<f64>>,
    /// Time of the filter's state, s of the day.
    time_s: f64,
    /// Newest sentence time seen.
    newest_s: Option<f64>,
    /// Velocity over ground from the last VTG before the first position.
    velocity: Option<[f64; 2]>,
    counts: NavCounts,
}

/// The DRKF's sensor model for bridge NMEA: GPS 5 m and 0.1 m/s, gyro 0.5°, log 0.1 m/s
/// through the water, a ship's accelerations.
fn drkf_config() -> DrkfConfig {
    let mut c = DrkfConfig::table_1(1).unwrap_or_else(|| unreachable!("test 1 exists"));
    c.acceleration = GaussMarkov::with_variance(0.05 * 0.05, 0.1);
    c.gps_position_var = 25.0;
    c.gps_velocity_var = 0.01;
    c.gyro_var = 0.5f64.to_radians().powi(2);
    c.speedlog_var = 0.01;
    c.speedlog_mode = SpeedlogMode::BottomLock;
    c
}

impl OwnShipNav {
    /// No fix yet.
    pub fn new(origin: Origin) -> Self {
        OwnShipNav {
            origin,
            drkf: None,
            time_s: 0.0,
            newest_s: None,
            velocity: None,
            counts: NavCounts::default(),
        }
    }

    /// The counts so far.
    pub fn counts(&self) -> NavCounts {
        self.counts
    }

    /// Takes one line. Timed sentences (GGA, RMC) set the time the others apply at.
    pub fn feed(&mut self, line: &str) {
        let line = line.trim();
        if line.is_empty() {
            return;
        }
        let parsed = match nmea::parse_str(line) {
            Ok(p) => p,
            Err(nmea::Error::ChecksumMismatch { .. }) => {
                self.counts.bad_checksum += 1;
                return;
            }
            Err(nmea::Error::Unsupported(_) | nmea::Error::Unknown(_)) => {
                self.counts.ignored += 1;
                return;
            }
            Err(_) => {
                self.counts.malformed += 1;
                return;
            }
        };
        let mut fix = NavFix::default();
        let knots = f64::from(MPS_PER_KNOT);
        let velocity = |sog_kn: f64, cog_deg: f64| {
            let c = cog_deg.to_radians();
            [sog_kn * knots * c.sin(), sog_kn * knots * c.cos()]
        };
        let mut time = None;
        match parsed {
            nmea::ParseResult::GGA(g) => {
                let valid = !matches!(g.fix_type, None | Some(nmea::sentences::FixType::Invalid));
                match (valid, g.latitude, g.longitude, g.fix_time) {
                    (true, Some(lat), Some(lon), Some(t)) => {
                        fix.gps_position_m = Some(self.origin.to_local(lat, lon));
                        time = Some(seconds(t));
                    }
                    _ => {
                        self.counts.void += 1;
                        return;
                    }
                }
            }
            nmea::ParseResult::RMC(r) => {
                // Status, the second field: A valid, V void (the crate keeps its enum private).
                let valid = line.split(',').nth(2) == Some("A");
                match (valid, r.lat, r.lon, r.fix_time) {
                    (true, Some(lat), Some(lon), Some(t)) => {
                        fix.gps_position_m = Some(self.origin.to_local(lat, lon));
                        if let (Some(s), Some(c)) = (r.speed_over_ground, r.true_course) {
                            fix.gps_velocity_mps = Some(velocity(f64::from(s), f64::from(c)));
                        }
                        time = Some(seconds(t));
                    }
                    _ => {
                        self.counts.void += 1;
                        return;
                    }
                }
            }
            nmea::ParseResult::VTG(v) => match (v.speed_over_ground, v.true_course) {
                (Some(s), Some(c)) => {
                    fix.gps_velocity_mps = Some(velocity(f64::from(s), f64::from(c)))
                }
                _ => {
                    self.counts.void += 1;
                    return;
                }
            },
            nmea::ParseResult::HDT(h) => match h.heading {
                Some(h) => fix.gyro_rad = Some(f64::from(h).to_radians()),
                None => {
                    self.counts.void += 1;
                    return;
                }
            },
            nmea::ParseResult::VHW(v) => match v.relative_speed_knots {
                Some(s) => fix.speedlog_mps = Some(s * knots),
                None => {
                    self.counts.void += 1;
                    return;
                }
            },
            _ => {
                self.counts.ignored += 1;
                return;
            }
        }
        if let Some(t) = time {
            if self.newest_s.is_some_and(|n| t < n) {
                self.counts.stale += 1;
                return;
            }
            self.newest_s = Some(t);
        }
        let at = time.unwrap_or(self.time_s);
        self.apply(at, &fix);
    }

    fn apply(&mut self, at: f64, fix: &NavFix) {
        let Some(drkf) = self.drkf.as_mut() else {
            if let Some(v) = fix.gps_velocity_mps {
                self.velocity = Some(v);
            }
            // The first position starts the filter.
            if let Some(p) = fix.gps_position_m {
                let v = fix.gps_velocity_mps.or(self.velocity);
                match Drkf::new(
                    drkf_config(),
                    p,
                    v.unwrap_or([0.0, 0.0]),
                    10.0,
                    if v.is_some() { 0.5 } else { 10.0 },
                ) {
                    Ok(d) => {
                        self.drkf = Some(d);
                        self.time_s = at;
                        self.counts.accepted += 1;
                    }
                    Err(_) => self.counts.void += 1,
                }
            } else {
                self.counts.accepted += 1;
            }
            return;
        };
        let dt = at - self.time_s;
        if dt > 0.0 {
            if drkf.predict(dt).is_err() {
                self.counts.stale += 1;
                return;
            }
            self.time_s = at;
        }
        match drkf.update(fix) {
            Ok(_) => self.counts.accepted += 1,
            Err(_) => self.counts.void += 1,
        }
    }

    /// Own ship at `time_s` (s of the day), predicted from the last sentence; `None` before
    /// the first position.
    pub fn own_ship_at(&self, time_s: f64) -> Option<OwnShip> {
        let mut d = self.drkf.clone()?;
        let dt = time_s - self.time_s;
        if dt > 0.0 {
            d.predict(dt).ok()?;
        }
        let p = d.position_m();
        let v = d.velocity_over_ground_mps();
        Some(OwnShip {
            position_m: [p[0] as f32, p[1] as f32],
            velocity_mps: [v[0] as f32, v[1] as f32],
        })
    }
}

fn seconds(t: chrono::NaiveTime) -> f64 {
    use chrono::Timelike;
    f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::bridge::own_ship_sentences;
    use crate::nmea::{sentence, ttm};

    #[test]
    fn own_ship_sentences_drive_the_dead_reckoning_filter() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin);
        let v = [0.0, 6.0];
        for k in 0..60 {
            let t = 10.0 * 3600.0 + f64::from(k);
            for s in own_ship_sentences([0.0, 6.0 * f64::from(k)], v, &origin, t) {
                // Every one of ours passes the independent parser.
                assert!(nmea::parse_str(s.trim()).is_ok(), "{s}");
                nav.feed(&s);
            }
        }
        assert_eq!(nav.counts().accepted, 300);
        assert_eq!(nav.counts().rejected(), 0);
        let own = nav.own_ship_at(10.0 * 3600.0 + 60.0).unwrap();
        assert!((own.position_m[1] - 360.0).abs() < 2.0, "{own:?}");
        assert!((own.velocity_mps[1] - 6.0).abs() < 0.05 && own.velocity_mps[0].abs() < 0.05);
    }

    #[test]
    fn bad_sentences_are_rejected_and_counted() {
        let origin = Origin::default();
        let mut nav = OwnShipNav::new(origin);
        let good = own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, 100.0);
        nav.feed(&good[0]);
        let before = nav.own_ship_at(100.0);
        // Checksum off by one.
        let mut bad = good[0].trim().to_string();
        let last = bad.pop().unwrap();
        bad.push(if last == '0' { '1' } else { '0' });
        nav.feed(&bad);
        // A void RMC and a GGA without fix.
        nav.feed(&sentence("GPRMC,000150.00,V,,,,,,,010126,,,N"));
        nav.feed(&sentence("GPGGA,000150.00,,,,,0,00,99.9,,M,,M,,"));
        // Older than what was used.
        nav.feed(&own_ship_sentences([0.0, 0.0], [0.0, 5.0], &origin, 50.0)[0]);
        // Garbage with a good checksum, no sentence at all, and one own ship does not need.
        nav.feed(&sentence("GPGGA,garbage"));
        nav.feed("not nmea at all");
        nav.feed(&ttm(&crate::session::target::example(), 100.0));
        let c = nav.counts();
        assert_eq!(c.accepted, 1);
        assert_eq!(c.bad_checksum, 1, "{c}");
        assert_eq!(c.void, 2, "{c}");
        assert_eq!(c.stale, 1, "{c}");
        assert_eq!(c.malformed, 2, "{c}");
        assert_eq!(c.ignored, 1, "{c}");
        assert_eq!(nav.own_ship_at(100.0), before);
    }
}
