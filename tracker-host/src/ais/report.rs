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
        macro_rules! hull {
            ($r:expr, $m:expr) => {{
                $r.ship_type = Some($m.ship_type);
                let l = $m.dimension_to_bow + $m.dimension_to_stern;
                let b = u16::from($m.dimension_to_port) + u16::from($m.dimension_to_starboard);
                $r.size_m = (l > 0 && b > 0).then_some((l, b));
                let (bow, stern) = (
                    f32::from($m.dimension_to_bow),
                    f32::from($m.dimension_to_stern),
                );
                let (port, starboard) = (
                    f32::from($m.dimension_to_port),
                    f32::from($m.dimension_to_starboard),
                );
                // 0 is "not available" for each distance.
                $r.centre_from_antenna_m = [bow, stern, port, starboard]
                    .iter()
                    .all(|d| *d > 0.0)
                    .then_some(((bow - stern) / 2.0, (starboard - port) / 2.0));
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
            cog_deg: m.cog_degrees(),
            heading_deg: m.heading_degrees().filter(|h| *h < 360),
            nav_status: m.navigation_status().map(|s| format!("{s:?}")),
            ..AisReport::default()
        };
        match m {
            AisMessage::PositionReportClassA(p) => {
                r.msg_type = p.message_type;
                r.class = Some(StationClass::ClassA);
                r.rot_deg_min = p.rate_of_turn.degrees_per_minute();
            }
            AisMessage::StaticVoyageData(s) => {
                r.msg_type = 5;
                r.class = Some(StationClass::ClassA);
                r.name = text(s.name.as_str());
                r.call_sign = text(s.call_sign.as_str());
                hull!(r, s);
            }
            AisMessage::PositionReportClassB(_) => {
                r.msg_type = 18;
                r.class = Some(StationClass::ClassB);
            }
            AisMessage::PositionReportClassBExtended(s) => {
                r.msg_type = 19;
                r.class = Some(StationClass::ClassB);
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
