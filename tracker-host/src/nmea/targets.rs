//! Targets out to a chart plotter: `TTM` (tracked target message) and `TLL` (target
//! latitude and longitude), IEC 61162-1.

use tracker_core::geo::{METRES_PER_NM, MPS_PER_KNOT};
use tracker_core::icd::TrackStatus;

use super::{angle_field, degrees, sentence, utc, NmeaOut, OutSpec};
use crate::origin::Origin;
use crate::session::target::TargetData;
use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::SourceScan;

/// `TTM`, tracked target message, for one target: number, distance (NM) and true bearing,
/// speed (kn) and true course over ground, CPA (NM), TCPA (minutes, negative once passed),
/// units N, name, status (T tracking, L lost, Q acquiring), no reference target, UTC, A
/// (automatic acquisition).
pub fn ttm(t: &TargetData, time_s: f64) -> String {
    let status = match t.status {
        TrackStatus::Tentative => 'Q',
        TrackStatus::Lost => 'L',
        TrackStatus::Confirmed | TrackStatus::Coasting => 'T',
    };
    let number = t.track % 100;
    sentence(&format!(
        "RATTM,{number:02},{:.3},{:.1},T,{:.1},{:.1},T,{:.3},{:.2},N,TGT{number:02},{status},,{},A",
        f64::from(t.range_m) / f64::from(METRES_PER_NM),
        degrees(t.bearing_rad),
        f64::from(t.speed_mps) / f64::from(MPS_PER_KNOT),
        degrees(t.course_rad),
        f64::from(t.cpa_m) / f64::from(METRES_PER_NM),
        f64::from(t.tcpa_s) / 60.0,
        utc(time_s)
    ))
}

/// `TLL`, target latitude and longitude: number, position, name, UTC, status, no reference.
pub fn tll(t: &TargetData, origin: &Origin, time_s: f64) -> String {
    let (lat, lon) = origin.to_lat_lon([f64::from(t.position_m[0]), f64::from(t.position_m[1])]);
    let number = t.track % 100;
    let status = if t.status == TrackStatus::Lost {
        'L'
    } else {
        'T'
    };
    sentence(&format!(
        "RATLL,{number:02},{},{},TGT{number:02},{},{status},",
        angle_field(lat, 2, 'N', 'S'),
        angle_field(lon, 3, 'E', 'W'),
        utc(time_s)
    ))
}

/// The sentences of one scan for every target a plotter should show (confirmed and
/// coasting): `TTM` and `TLL` each.
pub fn targets_sentences(targets: &[TargetData], origin: &Origin, time_s: f64) -> Vec<String> {
    targets
        .iter()
        .flat_map(|t| [ttm(t, time_s), tll(t, origin, time_s)])
        .collect()
}

/// Every confirmed and coasting target to chart plotters each scan, as `TTM` and `TLL`.
pub struct TargetsOut {
    out: NmeaOut,
    origin: Origin,
}

impl TargetsOut {
    /// Opens `spec`; `origin` ties the local frame to the chart.
    ///
    /// # Errors
    /// The socket does not open (an address that does not resolve, a port in use).
    pub fn open(spec: &OutSpec, origin: Origin) -> anyhow::Result<Self> {
        Ok(TargetsOut {
            out: NmeaOut::open(spec)?,
            origin,
        })
    }

    /// The socket's local address (for a TCP server: the port plotters connect to).
    ///
    /// # Errors
    /// The operating system's.
    pub fn local_addr(&self) -> std::io::Result<std::net::SocketAddr> {
        self.out.local_addr()
    }
}

impl ScanSink for TargetsOut {
    fn scan(&mut self, _: &SourceScan, report: &ScanReport) -> anyhow::Result<()> {
        self.out.send(&targets_sentences(
            &report.targets,
            &self.origin,
            report.time_s,
        ));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::checksum;

    #[test]
    fn ttm_reads_back_through_an_independent_parser() {
        let t = crate::session::target::example();
        let s = ttm(&t, 3723.5);
        assert!(s.ends_with("\r\n") && s.starts_with("$RATTM,07,"));
        let parsed = match nmea::parse_str(s.trim()).unwrap() {
            nmea::ParseResult::TTM(d) => d,
            other => panic!("{other:?}"),
        };
        assert_eq!(parsed.target_number, Some(7));
        let nm = 5000.0 / 1852.0;
        assert!((parsed.target_distance.unwrap() - nm as f32).abs() < 1e-3);
        assert!((parsed.target_speed.unwrap() - 5.0 / MPS_PER_KNOT).abs() < 0.06);
        assert_eq!(
            parsed.speed_or_distance_unit,
            Some(nmea::sentences::TtmDistanceUnit::NauticalMile)
        );
        assert_eq!(
            parsed.target_status,
            Some(nmea::sentences::TtmStatus::Tracking)
        );
        assert!((parsed.distance_of_cpa.unwrap() - t.cpa_m / METRES_PER_NM).abs() < 1e-3);
        assert!((parsed.time_to_cpa.unwrap() - t.tcpa_s / 60.0).abs() < 0.01);
        assert_eq!(
            parsed.time_of_data,
            chrono::NaiveTime::from_hms_milli_opt(1, 2, 3, 500)
        );
        assert_eq!(
            parsed.type_of_acquisition,
            Some(nmea::sentences::TtmTypeOfAcquisition::Automatic)
        );
        // Bearing 036.9° true (3 km east, 4 km north); course 270° true.
        assert!(s.contains(",36.9,T,") && s.contains(",270.0,T,"), "{s}");
    }

    #[test]
    fn tll_has_its_fields_in_order_and_a_valid_checksum() {
        let t = crate::session::target::example();
        let origin = Origin {
            lat_deg: 50.0,
            lon_deg: -1.0,
        };
        let s = tll(&t, &origin, 0.0);
        // The nmea crate checks the frame and checksum (it has no TLL field parser).
        let frame = nmea::parse_nmea_sentence(s.trim()).unwrap();
        assert_eq!(frame.checksum, checksum(&s[1..s.find('*').unwrap()]));
        let f: Vec<&str> = s.trim()[1..s.find('*').unwrap()].split(',').collect();
        assert_eq!(f[0], "RATLL");
        assert_eq!(f[1], "07");
        // 4 km north of 50°N: 50°02.15968′N; 3 km east of 1°W at 50°N: 0°57.20′W.
        assert_eq!((f[2], f[3]), ("5002.15983", "N"));
        assert_eq!(f[5], "W");
        let lon_min: f64 = f[4][3..].parse().unwrap();
        assert!((lon_min - (60.0 - 3000.0 / (1852.0 * 50f64.to_radians().cos()))).abs() < 1e-3);
        assert_eq!((f[6], f[7], f[8]), ("TGT07", "000000.00", "T"));
    }
}
