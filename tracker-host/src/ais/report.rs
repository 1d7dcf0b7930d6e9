//! What an AIS message says about a station, as the target table takes it: decoded by the
//! `aivdm` crate (ITU-R M.1371-5), the fields the table keeps read out with their
//! "not available" values as `None`.

use aivdm::AisMessage;

/// The kind of station a report comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum StationClass {
    /// Class A shipborne (messages 1–3, 5).
    ClassA,
    /// Class B shipborne (18, 19, 24).
    ClassB,
    /// Long-range broadcast (27), from a class A ship far away or by satellite.
    LongRange,
}

/// One decoded message's content for the table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AisReport {
    /// Message type, 1–27.
    pub msg_type: u8,
    /// The station's MMSI.
    pub mmsi: u32,
    /// From own ship's transponder (`VDO`).
    pub own_ship: bool,
    /// The station's class, for the messages that tell.
    pub class: Option<StationClass>,
    /// Latitude and longitude, degrees (WGS 84), when the message has one and it is
    /// available and on the globe.
    pub position_deg: Option<(f64, f64)>,
    /// Speed over ground, kn.
    pub sog_kn: Option<f64>,
    /// Course over ground, degrees true.
    pub cog_deg: Option<f64>,
    /// True heading, degrees.
    pub heading_deg: Option<u16>,
    /// Rate of turn, degrees a minute (class A; the sensor's or the indicator's value).
    pub rot_deg_min: Option<f64>,
    /// Navigational status (class A, 27), as ITU-R M.1371 names it.
    pub nav_status: Option<String>,
    /// Name (5, 19, 24 part A).
    pub name: Option<String>,
    /// Call sign (5, 24 part B).
    pub call_sign: Option<String>,
    /// Ship and cargo type (5, 19, 24 part B).
    pub ship_type: Option<u8>,
    /// Length and beam, m (5, 19, 24 part B; from the antenna's distances to bow, stern,
    /// port and starboard).
    pub size_m: Option<(u16, u16)>,
    /// Where the position's antenna sits on the hull (5, 19, 24 part B): from its
    /// distances to bow, stern, port and starboard (ITU-R M.1371-5, Annex 2 §3.3.8.2.3.3,
    /// the reference point), the hull's centre from it, m forward and to starboard; only
    /// when all four are given.
    pub centre_from_antenna_m: Option<(f32, f32)>,
    /// The UTC second the position was taken (1–3, 18, 19; ITU-R M.1371-5 Table 48, time
    /// stamp): tells two reports of a ship that stands still apart
    /// ([`super::duplicates`]).
    pub utc_second: Option<u8>,
}

impl AisReport {
    /// Reads `m`; `None` for the message types the table has no use for (binary, safety
    /// text, base station, aids to navigation, link management).
    pub fn of(m: &AisMessage, own_ship: bool) -> Option<Self> {
        let text = |s: &str| {
            let t = s.trim_end_matches(['@', ' ']).trim();
            (!t.is_empty()).then(|| t.to_string())
        };
        // Ship type and size, as 5, 19 and 24 part B give them (the same field names in
        // each of aivdm's three types).
        // An auxiliary craft (MMSI 98MIDxxxx) sends its mothership's MMSI in the
        // dimension bits (ITU-R M.1371-5, Annex 8, message 24B): no size of its own.
        let auxiliary = m.mmsi().raw() / 10_000_000 == 98;
        macro_rules! hull {
            ($r:expr, $m:expr) => {{
                $r.ship_type = Some($m.ship_type);
                let (bow, stern) = ($m.dimension_to_bow, $m.dimension_to_stern);
                let (port, starboard) = ($m.dimension_to_port, $m.dimension_to_starboard);
                let l = bow + stern;
                let b = u16::from(port) + u16::from(starboard);
                $r.size_m = (!auxiliary && l > 0 && b > 0).then_some((l, b));
                // 0 is "not available" for each distance, and 511 (bow, stern) or 63 (port,
                // starboard) "that much or more": the antenna's place is then not known.
                let known = bow > 0 && stern > 0 && port > 0 && starboard > 0;
                let capped = bow >= 511 || stern >= 511 || port >= 63 || starboard >= 63;
                $r.centre_from_antenna_m = (!auxiliary && known && !capped).then(|| {
                    let along = (f32::from(bow) - f32::from(stern)) / 2.0;
                    (along, (f32::from(starboard) - f32::from(port)) / 2.0)
                });
            }};
        }
        let mut r = AisReport {
            mmsi: m.mmsi().raw(),
            own_ship,
            position_deg: m
                .position()
                .map(|p| (p.latitude, p.longitude))
                .filter(|(lat, lon)| lat.abs() <= 90.0 && lon.abs() <= 180.0),
            sog_kn: m.sog_knots(),
            // 360 is "not available" (3600 in tenths; message 27's whole degrees: 511).
            cog_deg: m.cog_degrees().filter(|c| *c < 360.0),
            heading_deg: m.heading_degrees().filter(|h| *h < 360),
            nav_status: m.navigation_status().map(|s| format!("{s:?}")),
            ..AisReport::default()
        };
        match m {
            AisMessage::PositionReportClassA(p) => {
                r.msg_type = p.message_type;
                r.class = Some(StationClass::ClassA);
                r.rot_deg_min = p.rate_of_turn.degrees_per_minute();
                r.utc_second = utc_second(p.timestamp);
            }
            AisMessage::StaticVoyageData(s) => {
                r.msg_type = 5;
                r.class = Some(StationClass::ClassA);
                r.name = text(s.name.as_str());
                r.call_sign = text(s.call_sign.as_str());
                hull!(r, s);
            }
            AisMessage::PositionReportClassB(b) => {
                r.msg_type = 18;
                r.class = Some(StationClass::ClassB);
                r.utc_second = utc_second(b.timestamp);
            }
            AisMessage::PositionReportClassBExtended(s) => {
                r.msg_type = 19;
                r.class = Some(StationClass::ClassB);
                r.utc_second = utc_second(s.timestamp);
                r.name = text(s.name.as_str());
                hull!(r, s);
            }
            AisMessage::StaticDataReport(aivdm::message::StaticDataReport::A(a)) => {
                r.msg_type = 24;
                r.class = Some(StationClass::ClassB);
                r.name = text(a.name.as_str());
            }
            AisMessage::StaticDataReport(aivdm::message::StaticDataReport::B(b)) => {
                r.msg_type = 24;
                r.class = Some(StationClass::ClassB);
                r.call_sign = text(b.call_sign.as_str());
                hull!(r, b);
            }
            AisMessage::LongRangeBroadcast(_) => {
                r.msg_type = 27;
                r.class = Some(StationClass::LongRange);
            }
            _ => return None,
        }
        Some(r)
    }
}

/// The UTC second of a time stamp, when it is one (60–63 say why there is none).
fn utc_second(t: aivdm::Timestamp) -> Option<u8> {
    match t {
        aivdm::Timestamp::Second(s) => Some(s),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use aivdm::message::{StaticDataReport, StaticDataReportPartB};

    /// A class B ship's message 24 part B from `mmsi` with the antenna's distances to bow,
    /// stern, port and starboard.
    fn part_b(mmsi: u32, bow: u16, stern: u16, port: u8, starboard: u8) -> AisReport {
        let m = AisMessage::StaticDataReport(StaticDataReport::B(StaticDataReportPartB {
            mmsi: aivdm::Mmsi::from_raw(mmsi),
            ship_type: 37,
            vendor_id: aivdm::string::FixedStr::from_raw(*b"@@@@@@@", 7),
            call_sign: aivdm::string::FixedStr::from_raw(*b"MABC1@@", 7),
            dimension_to_bow: bow,
            dimension_to_stern: stern,
            dimension_to_port: port,
            dimension_to_starboard: starboard,
        }));
        AisReport::of(&m, false).expect("a 24B is read")
    }

    #[test]
    fn the_antennas_place_on_the_hull_is_read_only_when_all_four_distances_are_given() {
        // 12 m from the bow, 4 from the stern, 1 to port, 3 to starboard: the hull's
        // centre 4 m forward of the antenna and 1 m to starboard.
        let r = part_b(235_000_001, 12, 4, 1, 3);
        assert_eq!(r.size_m, Some((16, 4)));
        assert_eq!(r.centre_from_antenna_m, Some((4.0, 1.0)));
        // One distance not available (0): the size may be, the place is not.
        assert_eq!(part_b(235_000_001, 12, 4, 0, 4).centre_from_antenna_m, None);
        // 511 and 63 are "that much or more".
        assert_eq!(
            part_b(235_000_001, 511, 4, 1, 3).centre_from_antenna_m,
            None
        );
        assert_eq!(
            part_b(235_000_001, 12, 4, 63, 3).centre_from_antenna_m,
            None
        );
        // An auxiliary craft's dimension bits hold its mothership's MMSI: no size, no place.
        let aux = part_b(982_350_001, 300, 100, 20, 12);
        assert_eq!((aux.size_m, aux.centre_from_antenna_m), (None, None));
    }
}
