//! Instruction counts of the firmware's hot paths, under `qemu-system-arm -icount shift=0`.
//!
//! Prints CSV on semihosting stdout (`name,scalar,instructions_per_call,ram_bytes`), then
//! exits 0. `tracker-host bench-mcu` runs it and relays the table. Each row is a product
//! code path called through `black_box`, the loop's own cost subtracted, the call included.
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use semihosting::println;
use tracker_core::device::Device;
use tracker_core::frame;
use tracker_core::icd::{
    Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, PROTOCOL_VERSION,
};
use tracker_firmware::{board, device_config, icount};

const CALLS: u32 = 200;

fn row(name: &str, scalar: &str, instructions: f32, ram_bytes: usize) {
    println!("{},{},{:.1},{}", name, scalar, instructions, ram_bytes);
}

/// One encoded request frame.
fn request(body: &HostToDevice) -> ([u8; MAX_ENCODED_FRAME_BYTES], usize) {
    let mut scratch = [0u8; MAX_FRAME_BYTES];
    let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
    let header = Header {
        protocol: PROTOCOL_VERSION,
        request_id: 1,
    };
    let n = frame::encode(&header, body, &mut scratch, &mut out).unwrap_or(0);
    (out, n)
}

/// Instructions to take one whole frame through the device (decode, dispatch, encode the
/// reply) with the reply bytes handed to a sink that only looks at them.
fn link_row(
    counter: &mut icount::InstructionCounter,
    device: &mut Device,
    name: &str,
    body: &HostToDevice,
) {
    let (bytes, n) = request(body);
    let frame = &bytes[..n];
    let per_frame = icount::per_call(counter, CALLS, || {
        for &b in black_box(frame) {
            device.receive(b, &mut |reply| {
                black_box(reply);
            });
        }
    });
    row(name, "-", per_frame, core::mem::size_of::<Device>());
}

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        board::exit(1)
    };
    let mut counter = icount::InstructionCounter::new(peripherals.SYST);
    let device: &'static mut Device = cortex_m::singleton!(: Device = Device::new(device_config()))
        .unwrap_or_else(|| board::exit(1));

    println!("name,scalar,instructions_per_call,ram_bytes");
    link_row(&mut counter, device, "link-hello", &HostToDevice::Hello);
    let echo16 = HostToDevice::Echo((0u8..16).collect());
    link_row(&mut counter, device, "link-echo-16B", &echo16);
    let echo_max = HostToDevice::Echo(
        (0..tracker_core::icd::MAX_ECHO_BYTES)
            .map(|i| i as u8)
            .collect(),
    );
    link_row(&mut counter, device, "link-echo-1000B", &echo_max);
    board::exit(0)
}
