//! Where spokes come from, as the command line names it: `pcap:PATH`, `navico[@IFACE_IP]`,
//! `garmin[@IFACE_IP]`.

use std::fmt;
use std::net::Ipv4Addr;
use std::path::PathBuf;

use super::live::{Endpoint, GARMIN_SPOKE_GROUPS, NAVICO_GROUPS};

/// A radar brand, as far as its spoke format goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RadarKind {
    /// Navico BR24, 3G, 4G, HALO (Simrad, B&G, Lowrance): 2,048 spokes of 1,024 4-bit samples.
    Navico,
    /// Garmin xHD: 1,440 spokes of 8-bit samples.
    Garmin,
}

impl RadarKind {
    /// The multicast groups a live radar is heard on: its spokes' (first) and, for a
    /// Navico, its state reports' (its model and the range chosen).
    pub fn live_endpoints(self) -> &'static [Endpoint] {
        match self {
            RadarKind::Navico => &NAVICO_GROUPS,
            RadarKind::Garmin => &GARMIN_SPOKE_GROUPS,
        }
    }

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RadarKind::Navico => "navico",
            RadarKind::Garmin => "garmin",
        }
    }
}

impl fmt::Display for RadarKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Where spokes come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RadarSpec {
    /// `pcap:PATH`: a capture file (pcap or pcapng, plain or gzip), read as fast as asked;
    /// every radar in it is decoded, and the NMEA text in it is kept.
    Capture(PathBuf),
    /// `navico[@IFACE_IP]` or `garmin[@IFACE_IP]`: the radar's spoke groups joined on the
    /// interface with that address (`0.0.0.0`, the default: the one the system chooses).
    Live {
        /// Which groups.
        kind: RadarKind,
        /// The interface's IPv4 address.
        interface: Ipv4Addr,
    },
}

impl std::str::FromStr for RadarSpec {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("{s}: expected pcap:PATH, navico[@IFACE_IP] or garmin[@IFACE_IP]");
        if let Some(path) = s.strip_prefix("pcap:") {
            if path.is_empty() {
                return Err(bad());
            }
            return Ok(RadarSpec::Capture(path.into()));
        }
        let (name, interface) = match s.split_once('@') {
            Some((n, ip)) => (
                n,
                ip.parse()
                    .map_err(|_| format!("{s}: {ip} is not an IPv4 interface address"))?,
            ),
            None => (s, Ipv4Addr::UNSPECIFIED),
        };
        let kind = match name {
            "navico" => RadarKind::Navico,
            "garmin" => RadarKind::Garmin,
            _ => return Err(bad()),
        };
        Ok(RadarSpec::Live { kind, interface })
    }
}

impl fmt::Display for RadarSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RadarSpec::Capture(p) => write!(f, "pcap:{}", p.display()),
            RadarSpec::Live { kind, interface } if interface.is_unspecified() => {
                write!(f, "{kind}")
            }
            RadarSpec::Live { kind, interface } => write!(f, "{kind}@{interface}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_three_forms() {
        assert_eq!(
            "pcap:/x/y.pcap.gz".parse(),
            Ok(RadarSpec::Capture("/x/y.pcap.gz".into()))
        );
        assert_eq!(
            "navico".parse(),
            Ok(RadarSpec::Live {
                kind: RadarKind::Navico,
                interface: Ipv4Addr::UNSPECIFIED
            })
        );
        let g: RadarSpec = "garmin@192.168.1.5".parse().unwrap();
        assert_eq!(
            g,
            RadarSpec::Live {
                kind: RadarKind::Garmin,
                interface: Ipv4Addr::new(192, 168, 1, 5)
            }
        );
        assert_eq!(g.to_string(), "garmin@192.168.1.5");
        for bad in [
            "pcap:",
            "furuno",
            "navico@",
            "navico@1.2.3",
            "garmin@::1",
            "",
        ] {
            assert!(bad.parse::<RadarSpec>().is_err(), "{bad}");
        }
    }
}
