//! The local frame's origin from a live own-ship source: its first position fix.
//!
//! A recording's or a capture's first fix is read ahead before the run
//! ([`super::recording`], [`crate::source::radar::CaptureSurvey`]); a live source's cannot
//! be, so without `--origin` the run waits for it a while at start-up. Without it the
//! frame's origin is the default's, which may be across the world from own ship: a flat
//! frame about a far origin distorts, and beyond 10,000 km the device refuses every plot
//! ([`super::FAR_FROM_ORIGIN_M`] raises an alarm then).

use std::time::{Duration, Instant};

use crate::nmea::input::{InSpec, NmeaIn};
use crate::origin::Origin;

use super::nav::OwnShipNav;

/// How long a run waits at start-up for a live source's first fix.
pub const FIRST_FIX_WAIT: Duration = Duration::from_secs(30);

/// The first position fix `spec` gives within `wait`, or `None`. The source is opened for
/// this alone and closed again (a UDP source's sentences meanwhile are not tracked; the
/// run opens it anew).
///
/// # Errors
/// The source does not open.
pub fn first_live_fix(spec: &InSpec, wait: Duration) -> anyhow::Result<Option<Origin>> {
    let mut input = NmeaIn::open(spec)?;
    let NmeaIn::Live(live) = &mut input else {
        return Ok(None);
    };
    let mut nav = OwnShipNav::new(Origin::default(), crate::app::today(), None).keep_fixes();
    let until = Instant::now() + wait;
    // Ctrl-C ends the wait (and then the run, with its summary).
    while Instant::now() < until && !crate::app::interrupt::interrupted() {
        for line in live.available() {
            nav.feed(&line);
            if let Some(&(_, lat_deg, lon_deg)) = nav.fixes().first() {
                return Ok(Some(Origin { lat_deg, lon_deg }));
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nmea::sentence;
    use std::net::UdpSocket;

    #[test]
    fn a_live_sources_first_fix_is_the_origin() {
        // A free port: bound, read, let go.
        let port = UdpSocket::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let spec = InSpec::Udp(port);
        let sender = std::thread::spawn(move || {
            let tx = UdpSocket::bind("127.0.0.1:0").unwrap();
            for _ in 0..40 {
                let rmc = sentence("GPRMC,120000.00,A,3331.800,S,15100.600,E,5.0,90.0,041226,,,A");
                let _ = tx.send_to(rmc.as_bytes(), ("127.0.0.1", port));
                std::thread::sleep(Duration::from_millis(50));
            }
        });
        let fix = first_live_fix(&spec, Duration::from_secs(5))
            .unwrap()
            .expect("a fix");
        sender.join().unwrap();
        assert!((fix.lat_deg + 33.53).abs() < 1e-6, "{fix:?}");
        assert!((fix.lon_deg - 151.01).abs() < 1e-6, "{fix:?}");
        // Nothing heard: none, after the wait.
        let quiet = UdpSocket::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        let none = first_live_fix(&InSpec::Udp(quiet), Duration::from_millis(200)).unwrap();
        assert_eq!(none, None);
    }
}
