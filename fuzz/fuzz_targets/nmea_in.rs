//! Any bytes as an own-ship NMEA feed, line by line: every line is counted (used, refused,
//! malformed) without a panic, and own ship, when known, stays finite at any later time.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_host::origin::Origin;
use tracker_host::own_ship::nav::OwnShipNav;

fuzz_target!(|data: &[u8]| {
    // 2026-01-01: a date for sentences that carry none.
    let mut nav = OwnShipNav::new(Origin::default(), 20_454, None);
    for line in data.split(|b| *b == b'\n') {
        nav.feed(&String::from_utf8_lossy(line));
        if let Some(t) = nav.newest_s() {
            for dt in [0.0, 1.0, 3_600.0, 1.0e7] {
                if let Some(own) = nav.own_ship_at(t + dt) {
                    assert!(own
                        .position_m
                        .iter()
                        .chain(own.velocity_mps.iter())
                        .all(|v| v.is_finite()));
                }
            }
        }
    }
});
