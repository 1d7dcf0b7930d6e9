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
        Bytes, DeviceToHost, Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, PROTOCOL_VERSION,
    };

    #[init]
    fn init() -> &'static mut Device {
        tracker_firmware::device().unwrap()
    }

    #[test]
    fn echo_round_trips_through_the_device(device: &mut &'static mut Device) {
        let mut wire = [0u8; MAX_ENCODED_FRAME_BYTES];
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: 9,
        };
        let mut sent = [0u8; 200];
        for (i, b) in sent.iter_mut().enumerate() {
            *b = i as u8;
        }
        let body = HostToDevice::Echo(Bytes(&sent));
        let n = frame::encode(&header, &body, &mut wire).unwrap();
        let before = device.stats();
        let mut replies = 0;
        let mut decoder = FrameDecoder::new();
        // A byte at a time, as the UART hands them over.
        for b in &wire[..n] {
            device.receive(core::slice::from_ref(b), &mut |reply| {
                for &r in reply {
                    if let Some(payload) = decoder.push(r) {
                        let (h, msg): (Header, DeviceToHost) =
                            frame::decode_payload(payload.unwrap(), u32::MAX).unwrap();
                        defmt::assert_eq!(h.request_id, 9);
                        let DeviceToHost::Echo(bytes) = msg else {
                            defmt::panic!()
                        };
                        defmt::assert_eq!(bytes.0, &sent[..]);
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
        device.receive(&[1u8, 2, 3, 0, 0xff, 0xfe, 0], &mut |_| {});
        defmt::assert_eq!(device.stats().rejected(), before.rejected() + 2);
        defmt::assert_eq!(device.stats().frames_out, before.frames_out + 2);
    }
}
