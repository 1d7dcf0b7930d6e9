//! Any bytes as a plots file: opening refuses bad input with an error naming the line, and
//! what it accepts plays to its end with finite plots and own ship.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_host::source::plots_file::PlotsFileSource;
use tracker_host::source::PlotSource;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("fuzz-plots-{}.csv", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let Ok(mut source) = PlotsFileSource::open(&path) else {
        return;
    };
    while let Ok(Some(scan)) = source.next_scan() {
        assert!(scan
            .radar
            .plots
            .iter()
            .all(|p| p.range_m.is_finite() && p.bearing_rad.is_finite()));
        if let Some(own) = scan.own_ship {
            assert!(own.position_m.iter().all(|v| v.is_finite()));
        }
    }
});
