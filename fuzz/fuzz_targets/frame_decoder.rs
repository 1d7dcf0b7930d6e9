//! Any bytes through the frame decoder: no panic, nothing held past the maximum, and every
//! payload it accepts decodes (or is refused) without panicking, as either message type.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_core::frame::{decode_payload, FrameDecoder};
use tracker_core::icd::{
    DeviceToHost, HostToDevice, HOST_TO_DEVICE_VARIANTS, MAX_FRAME_BYTES,
};

fuzz_target!(|data: &[u8]| {
    let mut decoder = FrameDecoder::new();
    for &b in data {
        if let Some(Ok(payload)) = decoder.push(b) {
            let _ = decode_payload::<HostToDevice>(payload, HOST_TO_DEVICE_VARIANTS);
            let _ = decode_payload::<DeviceToHost>(payload, u32::MAX);
        }
        assert!(decoder.pending() <= MAX_FRAME_BYTES);
    }
});
