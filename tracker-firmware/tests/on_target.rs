//! tracker-core's link path on the emulated Cortex-M4F (defmt-test under QEMU), on the
//! firmware's one device (the track table leaves no room for a second).
#![no_std]
#![no_main]

use tracker_firmware as _; // panic handler, HardFault handler, defmt transport

#[defmt_test::tests]
mod tests {
    use tracker_core::device::Device;
    use tracker_core::frame::{self, FrameDecoder};
    use tracker_core::icd::{
        DeviceToHost, Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES,
        PROTOCOL_VERSION,
    };

    #[init]
    fn init() -> &'static mut Device {
        tracker_firmware::device().unwrap()
    }

    #[test]
    fn echo_round_trips_through_the_device(device: &mut &'static mut Device) {
        let mut scratch = [0u8; MAX_FRAME_BYTES];
        let mut wire = [0u8; MAX_ENCODED_FRAME_BYTES];
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: 9,
        };
        let body = HostToDevice::Echo((0u8..200).collect());
        let n = frame::encode(&header, &body, &mut scratch, &mut wire).unwrap();
        let before = device.stats();
        let mut replies = 0;
        let mut decoder = FrameDecoder::new();
        for &b in &wire[..n] {
            device.receive(b, &mut |reply| {
                for &r in reply {
                    if let Some(payload) = decoder.push(r) {
                        let (h, msg): (Header, DeviceToHost) =
                            frame::decode_payload(payload.unwrap(), u32::MAX).unwrap();
                        defmt::assert_eq!(h.request_id, 9);
                        let DeviceToHost::Echo(bytes) = msg else {
                            defmt::panic!()
                        };
                        defmt::assert_eq!(bytes.len(), 200);
                        replies += 1;
                    }
                }
            });
        }
        defmt::assert_eq!(replies, 1);
        defmt::assert_eq!(device.stats().frames_ok, before.frames_ok + 1);
    }

    #[test]
    fn garbage_is_counted_not_fatal(device: &mut &'static mut Device) {
        let before = device.stats();
        for b in [1u8, 2, 3, 0, 0xff, 0xfe, 0] {
            device.receive(b, &mut |_| {});
        }
        defmt::assert_eq!(device.stats().rejected(), before.rejected() + 2);
        defmt::assert_eq!(device.stats().frames_out, before.frames_out + 2);
    }
}
