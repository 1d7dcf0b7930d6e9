//! What a bridge's sentences say about own ship: each well-formed sentence becomes readings
//! (a position, a velocity over ground, a heading, a speed through the water, the time), is
//! ignored (a sentence own ship does not use, counted by type), or is rejected with a reason.
//!
//! | sentence | reading | parsed by |
//! |---|---|---|
//! | `RMC` | position, time and date, SOG and COG, magnetic variation | `nmea` crate |
//! | `GGA` | position, time | `nmea` crate |
//! | `GLL` | position, time | here (B&G writes longitudes without leading zeros, some talkers omit the mode field) |
//! | `VTG` | SOG and COG (an empty course with a speed under 0.1 kn is a valid zero) | `nmea` crate |
//! | `HDT` | heading, true | `nmea` crate |
//! | `THS` | heading, true, with a mode (`V`: not valid) | here |
//! | `HDG` | heading, magnetic sensor, with deviation and variation | here |
//! | `HDM` | heading, magnetic | here |
//! | `VHW` | speed through the water | `nmea` crate |
//! | `VBW` | speed through the water and over ground, along the keel | here |
//! | `ZDA` | time and date (two- or four-digit year) | here |
//!
//! The `nmea` crate has no parser for `THS`, `HDG`, `HDM` or `VBW` and refuses real
//! equipment's variants of `GLL` and `ZDA` (measured on the recordings in
//! `../shared/realdata/nmea/`), so those are read here field by field (IEC 61162-1 §8).

use chrono::{Datelike, NaiveDate, Timelike};
use tracker_core::geo::MPS_PER_KNOT;

use crate::nmea::sentence::{angle, number, time_of_day, Sentence};

/// A day, as days since 1970-01-01.
pub type Day = i64;

/// The quantities own ship is built from, one per sensor kind. A source is chosen per
/// quantity (a talker), never several fed to one filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Quantity {
    /// Position (GNSS).
    Position,
    /// Velocity over ground (GNSS or a ground-referenced log).
    GroundVelocity,
    /// Heading (gyro, GNSS compass, magnetic compass).
    Heading,
    /// Speed through the water (log).
    WaterSpeed,
}

impl Quantity {
    /// Every quantity.
    pub const ALL: [Quantity; 4] = [
        Quantity::Position,
        Quantity::GroundVelocity,
        Quantity::Heading,
        Quantity::WaterSpeed,
    ];

    /// Its name on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Position => "position",
            Quantity::GroundVelocity => "velocity",
            Quantity::Heading => "heading",
            Quantity::WaterSpeed => "water-speed",
        }
    }
}

/// One thing a sentence says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reading {
    /// A position fix, degrees.
    Position {
        /// Latitude, degrees north.
        lat_deg: f64,
        /// Longitude, degrees east.
        lon_deg: f64,
    },
    /// Speed and course over ground; course `None` when stopped.
    GroundVelocity {
        /// Speed over ground, m/s.
        sog_mps: f64,
        /// Course over ground, degrees true.
        cog_deg: Option<f64>,
    },
    /// Speed over ground along the keel (VBW), m/s.
    GroundSpeedAlongKeel(f64),
    /// Heading, degrees true.
    HeadingTrue(f64),
    /// A magnetic heading, degrees, with the deviation and variation the sentence gives
    /// (east positive).
    HeadingMagnetic {
        /// Heading, degrees magnetic (deviation not yet applied when `deviation_deg` is
        /// given).
        heading_deg: f64,
        /// Deviation of the compass, degrees east.
        deviation_deg: Option<f64>,
        /// Magnetic variation, degrees east.
        variation_deg: Option<f64>,
    },
    /// Magnetic variation at own ship (RMC), degrees east.
    Variation(f64),
    /// Speed through the water, m/s.
    WaterSpeed(f64),
}

impl Reading {
    /// The quantity this reading measures (`None` for the variation, which is not a
    /// measurement of own ship).
    pub fn quantity(&self) -> Option<Quantity> {
        Some(match self {
            Reading::Position { .. } => Quantity::Position,
            Reading::GroundVelocity { .. } | Reading::GroundSpeedAlongKeel(_) => {
                Quantity::GroundVelocity
            }
            Reading::HeadingTrue(_) | Reading::HeadingMagnetic { .. } => Quantity::Heading,
            Reading::WaterSpeed(_) => Quantity::WaterSpeed,
            Reading::Variation(_) => return None,
        })
    }
}

/// The time a sentence carries.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stamp {
    /// Time of day, s after midnight UTC.
    pub time_of_day_s: Option<f64>,
    /// The date, when the sentence gives it (RMC, ZDA).
    pub day: Option<Day>,
}

/// Why a well-framed sentence is not used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Rejection {
    /// The fields do not parse as the sentence type says.
    Malformed,
    /// The sentence says its data is not valid (RMC `V`, GGA quality 0, GLL `V`, THS `V`,
    /// VBW `V`) or leaves it empty.
    Void,
    /// A heading sentence that names itself magnetic where true is required (`HDT,…,M`).
    NotTrue,
    /// A value out of its range (latitude beyond 90°, a speed over 100 kn).
    OutOfRange,
}

impl Rejection {
    /// The reason's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Rejection::Malformed => "malformed",
            Rejection::Void => "void",
            Rejection::NotTrue => "not-true",
            Rejection::OutOfRange => "out-of-range",
        }
    }
}

/// What a sentence comes to.
#[derive(Clone, Debug, PartialEq)]
pub enum Decoded {
    /// Readings (at most three) and the sentence's time.
    Readings(Stamp, Vec<Reading>),
    /// A time-only sentence (ZDA).
    Time(Stamp),
    /// Well formed, not used for own ship (GSV, DPT, MWV, AIS, proprietary, …).
    Ignored,
    /// Not used, for a reason.
    Rejected(Rejection),
}

/// Fastest own ship believed, m/s (100 kn).
const MAX_SPEED_MPS: f64 = 100.0 * MPS_PER_KNOT as f64;

/// Speed under which a missing course means "stopped", m/s (0.1 kn).
const STOPPED_MPS: f64 = 0.1 * MPS_PER_KNOT as f64;

fn day_of(date: NaiveDate) -> Day {
    date.num_days_from_ce() as i64 - 719_163
}

fn seconds(t: chrono::NaiveTime) -> f64 {
    f64::from(t.num_seconds_from_midnight()) + f64::from(t.nanosecond()) * 1e-9
}

fn knots(kn: f64) -> Option<f64> {
    let v = kn * f64::from(MPS_PER_KNOT);
    (v.is_finite() && (0.0..=MAX_SPEED_MPS).contains(&v)).then_some(v)
}

fn heading(deg: f64) -> Option<f64> {
    (deg.is_finite() && (0.0..=360.0).contains(&deg)).then_some(deg % 360.0)
}

/// Decodes `s`, the framed form of `line`.
pub fn decode(s: &Sentence<'_>, line: &str) -> Decoded {
    if s.proprietary || s.start == '!' {
        return Decoded::Ignored;
    }
    match s.kind {
        "RMC" | "GGA" | "VTG" | "HDT" | "VHW" => with_crate(s, line),
        "GLL" => gll(s),
        "THS" => ths(s),
        "HDG" => hdg(s),
        "HDM" => match s.field(0).and_then(number).and_then(heading) {
            Some(h) if s.field(1) == Some("M") => Decoded::Readings(
                Stamp::default(),
                vec![Reading::HeadingMagnetic {
                    heading_deg: h,
                    deviation_deg: None,
                    variation_deg: None,
                }],
            ),
            None if s.field(0).is_none() => Decoded::Rejected(Rejection::Void),
            _ => Decoded::Rejected(Rejection::Malformed),
        },
        "VBW" => vbw(s),
        "ZDA" => zda(s),
        _ => Decoded::Ignored,
    }
}

fn with_crate(s: &Sentence<'_>, line: &str) -> Decoded {
    use nmea::ParseResult;
    let parsed = match nmea::parse_str(line.trim()) {
        Ok(p) => p,
        // An HDT flagged magnetic fails the crate's parse: say so rather than malformed.
        Err(_) if s.kind == "HDT" && s.field(1) == Some("M") => {
            return Decoded::Rejected(Rejection::NotTrue)
        }
        Err(_) => return Decoded::Rejected(Rejection::Malformed),
    };
    match parsed {
        ParseResult::RMC(r) => {
            let stamp = Stamp {
                time_of_day_s: r.fix_time.map(seconds),
                day: r.fix_date.map(day_of),
            };
            if r.status_of_fix == nmea::sentences::rmc::RmcStatusOfFix::Invalid {
                return Decoded::Rejected(Rejection::Void);
            }
            let (Some(lat), Some(lon), Some(_)) = (r.lat, r.lon, r.fix_time) else {
                return Decoded::Rejected(Rejection::Void);
            };
            if !(lat.abs() <= 90.0 && lon.abs() <= 180.0) {
                return Decoded::Rejected(Rejection::OutOfRange);
            }
            let mut readings = vec![Reading::Position {
                lat_deg: lat,
                lon_deg: lon,
            }];
            if let Some(sog) = r.speed_over_ground {
                let Some(sog_mps) = knots(f64::from(sog)) else {
                    return Decoded::Rejected(Rejection::OutOfRange);
                };
                let cog_deg = r.true_course.map(f64::from).and_then(heading);
                if cog_deg.is_some() || sog_mps < STOPPED_MPS {
                    readings.push(Reading::GroundVelocity { sog_mps, cog_deg });
                }
            }
            if let Some(v) = r.magnetic_variation {
                if f64::from(v).abs() <= 180.0 {
                    readings.push(Reading::Variation(f64::from(v)));
                }
            }
            Decoded::Readings(stamp, readings)
        }
        ParseResult::GGA(g) => {
            let valid = !matches!(g.fix_type, None | Some(nmea::sentences::FixType::Invalid));
            match (valid, g.latitude, g.longitude, g.fix_time) {
                (true, Some(lat), Some(lon), Some(t))
                    if lat.abs() <= 90.0 && lon.abs() <= 180.0 =>
                {
                    Decoded::Readings(
                        Stamp {
                            time_of_day_s: Some(seconds(t)),
                            day: None,
                        },
                        vec![Reading::Position {
                            lat_deg: lat,
                            lon_deg: lon,
                        }],
                    )
                }
                (true, Some(_), Some(_), Some(_)) => Decoded::Rejected(Rejection::OutOfRange),
                _ => Decoded::Rejected(Rejection::Void),
            }
        }
        ParseResult::VTG(v) => match v.speed_over_ground {
            Some(sog) => {
                let Some(sog_mps) = knots(f64::from(sog)) else {
                    return Decoded::Rejected(Rejection::OutOfRange);
                };
                let cog_deg = v.true_course.map(f64::from).and_then(heading);
                if cog_deg.is_none() && sog_mps >= STOPPED_MPS {
                    return Decoded::Rejected(Rejection::Void);
                }
                Decoded::Readings(
                    Stamp::default(),
                    vec![Reading::GroundVelocity { sog_mps, cog_deg }],
                )
            }
            None => Decoded::Rejected(Rejection::Void),
        },
        ParseResult::HDT(h) => match h.heading.map(f64::from) {
            Some(deg) => match heading(deg) {
                Some(d) => Decoded::Readings(Stamp::default(), vec![Reading::HeadingTrue(d)]),
                None => Decoded::Rejected(Rejection::OutOfRange),
            },
            None => Decoded::Rejected(Rejection::Void),
        },
        ParseResult::VHW(v) => {
            let kn = v
                .relative_speed_knots
                .or(v.relative_speed_kmph.map(|k| k / 1.852));
            match kn {
                Some(kn) => match knots(kn) {
                    Some(mps) => {
                        Decoded::Readings(Stamp::default(), vec![Reading::WaterSpeed(mps)])
                    }
                    None => Decoded::Rejected(Rejection::OutOfRange),
                },
                None => Decoded::Rejected(Rejection::Void),
            }
        }
        _ => Decoded::Ignored,
    }
}

/// `GLL`: lat, N/S, lon, E/W, time, status A/V[, mode].
fn gll(s: &Sentence<'_>) -> Decoded {
    let f = |i| s.field(i).unwrap_or("");
    if s.field(0).is_none() || s.field(2).is_none() {
        return Decoded::Rejected(Rejection::Void);
    }
    if s.field(5) != Some("A") || s.field(6) == Some("N") {
        return Decoded::Rejected(Rejection::Void);
    }
    let (Some(lat), Some(lon)) = (
        angle(f(0), f(1), 'N', 'S', 90.0),
        angle(f(2), f(3), 'E', 'W', 180.0),
    ) else {
        return Decoded::Rejected(Rejection::Malformed);
    };
    let time = match s.field(4) {
        Some(t) => match time_of_day(t) {
            Some(t) => Some(t),
            None => return Decoded::Rejected(Rejection::Malformed),
        },
        None => None,
    };
    Decoded::Readings(
        Stamp {
            time_of_day_s: time,
            day: None,
        },
        vec![Reading::Position {
            lat_deg: lat,
            lon_deg: lon,
        }],
    )
}

/// `THS`: heading true, mode (A autonomous, E estimated, M manual, S simulator, V invalid).
fn ths(s: &Sentence<'_>) -> Decoded {
    match (s.field(0), s.field(1)) {
        (_, Some("V")) | (None, _) => Decoded::Rejected(Rejection::Void),
        (Some(h), Some("A" | "E" | "M" | "S") | None) => match number(h).and_then(heading) {
            Some(d) => Decoded::Readings(Stamp::default(), vec![Reading::HeadingTrue(d)]),
            None => Decoded::Rejected(Rejection::Malformed),
        },
        _ => Decoded::Rejected(Rejection::Malformed),
    }
}

/// A signed angle `value,E|W`, east positive.
fn east_positive(value: Option<&str>, side: Option<&str>) -> Result<Option<f64>, Rejection> {
    match (value, side) {
        (None, _) => Ok(None),
        (Some(v), Some(side)) => {
            let v = number(v)
                .filter(|v| (0.0..=180.0).contains(v))
                .ok_or(Rejection::Malformed)?;
            match side {
                "E" => Ok(Some(v)),
                "W" => Ok(Some(-v)),
                _ => Err(Rejection::Malformed),
            }
        }
        (Some(_), None) => Err(Rejection::Malformed),
    }
}

/// `HDG`: magnetic sensor heading, deviation, E/W, variation, E/W.
fn hdg(s: &Sentence<'_>) -> Decoded {
    let Some(h) = s.field(0) else {
        return Decoded::Rejected(Rejection::Void);
    };
    let Some(heading_deg) = number(h).and_then(heading) else {
        return Decoded::Rejected(Rejection::Malformed);
    };
    match (
        east_positive(s.field(1), s.field(2)),
        east_positive(s.field(3), s.field(4)),
    ) {
        (Ok(deviation_deg), Ok(variation_deg)) => Decoded::Readings(
            Stamp::default(),
            vec![Reading::HeadingMagnetic {
                heading_deg,
                deviation_deg,
                variation_deg,
            }],
        ),
        (Err(e), _) | (_, Err(e)) => Decoded::Rejected(e),
    }
}

/// `VBW`: longitudinal and transverse water speed (kn), status, longitudinal and transverse
/// ground speed (kn), status, …
fn vbw(s: &Sentence<'_>) -> Decoded {
    let mut readings = Vec::new();
    let speed = |i: usize| s.field(i).map(|f| number(f).and_then(knots));
    if s.field(2) == Some("A") {
        match speed(0) {
            Some(Some(v)) => readings.push(Reading::WaterSpeed(v)),
            Some(None) => return Decoded::Rejected(Rejection::Malformed),
            None => {}
        }
    }
    if s.field(5) == Some("A") {
        match speed(3) {
            Some(Some(v)) => readings.push(Reading::GroundSpeedAlongKeel(v)),
            Some(None) => return Decoded::Rejected(Rejection::Malformed),
            None => {}
        }
    }
    if readings.is_empty() {
        return Decoded::Rejected(Rejection::Void);
    }
    Decoded::Readings(Stamp::default(), readings)
}

/// `ZDA`: time, day, month, year (4 digits; 2 from some B&G units), local zone.
fn zda(s: &Sentence<'_>) -> Decoded {
    let Some(t) = s.field(0) else {
        return Decoded::Rejected(Rejection::Void);
    };
    let Some(time) = time_of_day(t) else {
        return Decoded::Rejected(Rejection::Malformed);
    };
    let day = match (s.field(1), s.field(2), s.field(3)) {
        (Some(d), Some(m), Some(y)) => {
            let (Ok(d), Ok(m), Ok(mut y)) = (d.parse::<u32>(), m.parse::<u32>(), y.parse::<i32>())
            else {
                return Decoded::Rejected(Rejection::Malformed);
            };
            if y < 100 {
                y += 2000;
            }
            match NaiveDate::from_ymd_opt(y, m, d) {
                Some(date) => Some(day_of(date)),
                None => return Decoded::Rejected(Rejection::Malformed),
            }
        }
        _ => None,
    };
    Decoded::Time(Stamp {
        time_of_day_s: Some(time),
        day,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::sentence::{parse, sentence, Line};

    fn decoded(line: &str) -> Decoded {
        match parse(line) {
            Ok(Line::Sentence(s)) => decode(&s, line),
            other => panic!("{line}: {other:?}"),
        }
    }

    #[test]
    fn real_equipment_sentences_are_understood() {
        // B&G Zeus² (gpsd bundg_zeus_9.log).
        let Decoded::Readings(st, r) =
            decoded("$GPRMC,094737,A,5251.0093,N,00518.8170,E,5.6,230.5,200818,1.4,E,A*1F")
        else {
            panic!()
        };
        assert_eq!(st.time_of_day_s, Some(9.0 * 3600.0 + 47.0 * 60.0 + 37.0));
        assert_eq!(
            st.day,
            Some(day_of(NaiveDate::from_ymd_opt(2018, 8, 20).unwrap()))
        );
        assert_eq!(r.len(), 3);
        assert!(matches!(r[2], Reading::Variation(v) if (v - 1.4).abs() < 1e-6));
        assert!(matches!(
            decoded("$SDHDG,229.8,,,1.3,E*36"),
            Decoded::Readings(_, ref r) if matches!(r[0], Reading::HeadingMagnetic { heading_deg, deviation_deg: None, variation_deg: Some(v) } if heading_deg == 229.8 && v == 1.3)
        ));
        // B&G's GLL without leading zeros, no time (mayara HALO capture).
        let Decoded::Readings(st, r) = decoded("$BMGLL,5310.7378,N,516.0582,E,,A,D*5B") else {
            panic!()
        };
        assert_eq!(st.time_of_day_s, None);
        assert!(
            matches!(r[0], Reading::Position { lon_deg, .. } if (lon_deg - (5.0 + 16.0582 / 60.0)).abs() < 1e-9)
        );
        // GLL without the mode field (Humminbird).
        assert!(matches!(
            decoded("$INGLL,4426.1130,N,07140.5579,W,194102,A*2C"),
            Decoded::Readings(_, _)
        ));
        // A stopped receiver's VTG: empty course, a tiny speed.
        assert!(matches!(
            decoded(&sentence("GNVTG,,T,,M,0.017,N,0.032,K,A")),
            Decoded::Readings(_, ref r) if matches!(r[0], Reading::GroundVelocity { cog_deg: None, .. })
        ));
        // Empty HDT, THS, ZDA without a date, a 2-digit-year ZDA, HDM, VHW, VBW.
        assert_eq!(decoded("$IIHDT,,T*0C"), Decoded::Rejected(Rejection::Void));
        assert!(matches!(
            decoded("$GNTHS,244.28,A*11"),
            Decoded::Readings(_, _)
        ));
        assert_eq!(
            decoded(&sentence("GNTHS,244.28,V")),
            Decoded::Rejected(Rejection::Void)
        );
        assert!(matches!(
            decoded("$GPZDA,095559,,,,00,*4D"),
            Decoded::Time(Stamp { day: None, .. })
        ));
        assert!(matches!(
            decoded(&sentence("GPZDA,094737,20,08,18,-01,00")),
            Decoded::Time(Stamp { day: Some(_), .. })
        ));
        assert!(matches!(
            decoded("$BKHDM,277.5,M*2C"),
            Decoded::Readings(_, _)
        ));
        assert!(matches!(
            decoded("$IIVHW,,T,,M,06.11,N,11.31,K*51"),
            Decoded::Readings(_, ref r) if matches!(r[0], Reading::WaterSpeed(v) if (v - 6.11 * 1852.0 / 3600.0).abs() < 1e-6)
        ));
        assert!(matches!(
            decoded(&sentence("VDVBW,6.1,0.1,A,5.7,0.2,A")),
            Decoded::Readings(_, ref r) if r.len() == 2
        ));
        // An HDT flagged magnetic, a GGA without fix, a void RMC, other sentences.
        assert_eq!(
            decoded(&sentence("APHDT,6.3,M")),
            Decoded::Rejected(Rejection::NotTrue)
        );
        assert_eq!(
            decoded(&sentence("GPGGA,000150.00,,,,,0,00,99.9,,M,,M,,")),
            Decoded::Rejected(Rejection::Void)
        );
        assert_eq!(
            decoded(&sentence("GPRMC,000150.00,V,,,,,,,010126,,,N")),
            Decoded::Rejected(Rejection::Void)
        );
        for other in [
            "$GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00*74",
            "!AIVDM,1,1,,A,13biI07P000HjtRNKQ89QOwL0003,0*76",
        ] {
            assert_eq!(decoded(other), Decoded::Ignored, "{other}");
        }
        assert_eq!(decoded(&sentence("PASHR,1,2")), Decoded::Ignored);
        assert_eq!(
            decoded(&sentence("GPGGA,garbage")),
            Decoded::Rejected(Rejection::Malformed)
        );
        assert_eq!(
            decoded(&sentence(
                "GPGGA,120000,9130.0,N,00100.0,W,1,8,1.0,1,M,1,M,,"
            )),
            Decoded::Rejected(Rejection::OutOfRange)
        );
    }
}
