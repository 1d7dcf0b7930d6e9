//! The local frame's origin from a live own-ship source: its first position fix.
//!
//! A recording's or a capture's first fix is read ahead before the run
//! ([`super::recording`], [`crate::source::radar::CaptureSurvey`]); a live source's cannot
//! be, so without `--origin` the run waits for it a while at start-up. Without it the
//! frame's origin is the default's, which may be across the world from own ship: a flat
//! frame about a far origin distorts, and beyond 10,000 km the device refuses every plot
//! ([`super::FAR_FROM_ORIGIN_M`] raises an alarm then).

use std::time::{Duration, Instant};

use crate::nmea::input::{InSpec, NmeaIn, MAX_GIVEN_BACK_LINES};
use crate::origin::Origin;

use super::nav::OwnShipNav;

/// How long a run waits at start-up for a live source's first fix.
pub const FIRST_FIX_WAIT: Duration = Duration::from_secs(30);

/// The first position fix `spec` gives within `wait`, or `None`, and the source opened for
/// it, with the lines read meanwhile given back ([`crate::nmea::input::LiveLines::give_back`]):
/// the run goes on with this very source (a TCP server that serves one client gave a run
/// that connected again nothing), and its first scan has own ship's fix.
///
/// # Errors
/// The source does not open.
pub fn first_live_fix(spec: &InSpec, wait: Duration) -> anyhow::Result<(Option<Origin>, NmeaIn)> {
    let mut input = NmeaIn::open(spec)?;
    let NmeaIn::Live(live) = &mut input else {
        return Ok((None, input));
    };
    let mut nav = OwnShipNav::new(Origin::default(), crate::app::today(), None).keep_fixes();
    let mut read = Vec::new();
    let until = Instant::now() + wait;
    let mut fix = None;
    // Ctrl-C ends the wait (and then the run, with its summary).
    'wait: while Instant::now() < until && !crate::app::interrupt::interrupted() {
        // The whole batch is kept (the heading after the fix's sentence, AIS), then the fix
        // looked for.
        for line in live.available() {
            nav.feed(&line);
            read.push(line);
        }
        if let Some(&(_, lat_deg, lon_deg)) = nav.fixes().first() {
            fix = Some(Origin { lat_deg, lon_deg });
            break 'wait;
        }
        // Bounded while waiting, too.
        let over = read.len().saturating_sub(MAX_GIVEN_BACK_LINES);
        read.drain(..over);
        std::thread::sleep(Duration::from_millis(50));
    }
    live.give_back(read);
    Ok((fix, input))
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
            .0
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
        let none = first_live_fix(&InSpec::Udp(quiet), Duration::from_millis(200))
            .unwrap()
            .0;
        assert_eq!(none, None);
    }

    /// A TCP server that serves one client (as many a bridge's multiplexer does): the run
    /// reads the very connection the wait for the first fix opened, and has own ship's fix
    /// on its first scan (a new user's trial: the run connected again, was served nothing,
    /// and said "no position fix yet" throughout).
    #[test]
    fn the_run_reads_the_source_it_waited_on() {
        use crate::app::{own_ship_source, with_live_origin, OwnShipOptions};
        use std::io::Write;
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        let (asked, ask) = std::sync::mpsc::channel::<()>();
        let server = std::thread::spawn(move || {
            let (mut client, _) = listener.accept().unwrap();
            // One client only: a second connection is refused.
            drop(listener);
            // One fix and a heading in one write, then nothing until the run has asked for
            // own ship: what it has then is what the wait read and gave back.
            let s = crate::utc::now_s() % crate::own_ship::clock::DAY_S;
            let gga = sentence(&format!(
                "GPGGA,{:02}{:02}{:05.2},3331.800,S,15100.600,E,1,08,0.9,10.0,M,,M,,",
                (s / 3600.0) as u32,
                (s % 3600.0 / 60.0) as u32,
                s % 60.0
            ));
            let hdt = sentence("HEHDT,123.4,T");
            client.write_all((gga + &hdt).as_bytes()).unwrap();
            let _ = ask.recv();
        });
        let options = OwnShipOptions {
            nmea_in: Some(InSpec::Tcp(format!("127.0.0.1:{port}"))),
            ..OwnShipOptions::default()
        };
        let o = with_live_origin(&options).unwrap();
        let origin = o.origin.expect("the first fix");
        assert!((origin.lat_deg + 33.53).abs() < 1e-6, "{origin:?}");
        let mut own = own_ship_source(&o, origin).expect("the source opened once");
        let scan = crate::source::SourceScan {
            radar: crate::source::RadarScan {
                scan: 0,
                time_s: crate::utc::now_s(),
                plots: Default::default(),
            },
            ..Default::default()
        };
        let first = own.own_ship(&scan).unwrap();
        drop(asked);
        assert!(!first.quality.no_fix_yet, "{:?}", first.quality);
        // The heading sent after the fix, in the same read.
        let heading_deg = first.heading_rad.map(f32::to_degrees);
        assert!(
            heading_deg.is_some_and(|h| (h - 123.4).abs() < 0.01),
            "{heading_deg:?}"
        );
        assert!(
            first.position_m[0].hypot(first.position_m[1]) < 1.0,
            "{:?}",
            first.position_m
        );
        server.join().unwrap();
    }
}
