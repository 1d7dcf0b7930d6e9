//! The device's request dispatch against any input: the fuzz data is read as a sequence of
//! messages (postcard-decoded where it can be, raw bytes otherwise), each framed properly
//! and fed to the device, so the fuzzer drives the scan state machine and the track table,
//! not only the framing. Invariants: no panic, exactly one reply frame per request frame
//! (or the parts of a report), the table within capacity, every track finite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_core::device::{Device, DeviceConfig};
use tracker_core::frame;
use tracker_core::icd::{Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, PROTOCOL_VERSION};
use tracker_core::track::MAX_TRACKS;

fuzz_target!(|data: &[u8]| {
    let mut device = Box::new(Device::new(DeviceConfig {
        firmware: "fuzz",
        boot_id: 1,
        max_tracks: MAX_TRACKS as u16,
        max_plots_per_scan: 256,
    }));
    let mut out = vec![0u8; MAX_ENCODED_FRAME_BYTES];
    let mut rest = data;
    let mut id = 1u32;
    while !rest.is_empty() {
        let mut sent = Vec::new();
        match postcard::take_from_bytes::<HostToDevice>(rest) {
            Ok((msg, tail)) if tail.len() < rest.len() => {
                let header = Header {
                    protocol: PROTOCOL_VERSION,
                    request_id: id,
                };
                if let Ok(n) = frame::encode(&header, &msg, &mut out) {
                    sent.extend_from_slice(&out[..n]);
                }
                rest = tail;
            }
            _ => {
                // Not a message: send a chunk of raw bytes as line noise.
                let n = rest.len().min(1 + usize::from(rest[0] % 64));
                sent.extend_from_slice(&rest[..n]);
                sent.push(0);
                rest = &rest[n..];
            }
        }
        id = id.wrapping_add(1).max(1);
        let mut replies = 0usize;
        // A byte at a time (a UART's) or all at once (a DMA buffer's), as the data says.
        if id % 2 == 0 {
            device.receive(&sent, &mut |_| replies += 1);
        } else {
            for b in &sent {
                device.receive(core::slice::from_ref(b), &mut |_| replies += 1);
            }
        }
        // One reply per frame (a raw chunk may hold several), a report in up to 4 parts.
        let frames = sent.iter().filter(|&&b| b == 0).count();
        assert!(
            replies <= 4 * frames.max(1),
            "{replies} reply frames for {frames} frames"
        );
        let table = device.tracker().table();
        assert!(table.len() <= MAX_TRACKS);
        for t in table.tracks() {
            let s = t.state();
            assert!(
                s.position_m
                    .iter()
                    .chain(&s.velocity_mps)
                    .all(|v| v.is_finite()),
                "{s:?}"
            );
        }
    }
});
