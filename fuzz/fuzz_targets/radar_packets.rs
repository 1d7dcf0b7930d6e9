//! Any bytes as a radar spoke packet, to both makes' decoders: refused and counted or
//! decoded into spokes whose samples fit the packet's format, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_host::radar::garmin::GarminDecoder;
use tracker_host::radar::navico::NavicoDecoder;
use tracker_host::radar::SpokeDecoder;

fuzz_target!(|data: &[u8]| {
    let mut navico = NavicoDecoder::new();
    let _ = navico.note_report(data);
    let _ = navico.decode(data, 1, |s| {
        assert!(s.samples.iter().all(|v| *v <= s.max_sample));
        assert!(s.range_m.is_finite());
    });
    let mut garmin = GarminDecoder::new();
    let _ = garmin.decode(data, 1, |s| {
        assert!(s.samples.iter().all(|v| *v <= s.max_sample));
        assert!(s.range_m.is_finite());
    });
});
