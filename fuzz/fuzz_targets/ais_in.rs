//! Any bytes as AIS sentences, line by line, into the decoder and the AIS target table:
//! every AIS sentence is counted without a panic, the table stays within its bound, and
//! every target's extrapolated position stays finite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_host::ais::targets::MAX_AIS_TARGETS;
use tracker_host::ais::{AisDecoder, AisTargets};
use tracker_host::origin::Origin;

fuzz_target!(|data: &[u8]| {
    let mut decoder = AisDecoder::new();
    let mut table = AisTargets::new(Origin::default());
    for (i, line) in data.split(|b| *b == b'\n').enumerate() {
        if let Some(r) = decoder.feed(&String::from_utf8_lossy(line)) {
            table.report(i as f64, &r);
        }
    }
    assert!(table.len() <= MAX_AIS_TARGETS);
    for t in table.targets() {
        if let Some((p, v)) = t.position_at(&Origin::default(), [0.0, 0.0], 1.0e6) {
            assert!(p.iter().chain(&v).all(|x| x.is_finite()), "{t:?}");
        }
    }
});
