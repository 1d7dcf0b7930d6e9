//! What a ship's bridge sensors send, for a simulated own ship: `GGA`, `RMC`, `VTG`, `HDT`
//! and `VHW` from a position and a velocity.

use tracker_core::geo::MPS_PER_KNOT;

use super::{angle_360, angle_field, date, sentence, utc};
use crate::origin::Origin;

/// What the bridge's sensors would say about own ship at `position_m`, `velocity_mps`
/// (heading taken as the course, no current): `GPGGA`, `GPRMC`, `GPVTG`, `HEHDT`, `VWVHW`.
pub fn own_ship_sentences(
    position_m: [f64; 2],
    velocity_mps: [f64; 2],
    origin: &Origin,
    time_s: f64,
) -> Vec<String> {
    let (lat, lon) = origin.to_lat_lon(position_m);
    let (lat, lon) = (angle_field(lat, 2, 'N', 'S'), angle_field(lon, 3, 'E', 'W'));
    let speed_kn = velocity_mps[0].hypot(velocity_mps[1]) / f64::from(MPS_PER_KNOT);
    let course = angle_360(velocity_mps[0].atan2(velocity_mps[1]).to_degrees(), 2);
    let (time, date) = (utc(time_s), date(time_s));
    vec![
        sentence(&format!(
            "GPGGA,{time},{lat},{lon},1,10,0.9,12.0,M,47.0,M,,"
        )),
        sentence(&format!(
            "GPRMC,{time},A,{lat},{lon},{speed_kn:.2},{course},{date},,,A"
        )),
        sentence(&format!(
            "GPVTG,{course},T,,M,{speed_kn:.2},N,{:.2},K,A",
            speed_kn * 1.852
        )),
        sentence(&format!("HEHDT,{course},T")),
        sentence(&format!(
            "VWVHW,{course},T,,M,{speed_kn:.2},N,{:.2},K",
            speed_kn * 1.852
        )),
    ]
}
