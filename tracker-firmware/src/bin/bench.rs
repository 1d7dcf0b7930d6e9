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
use tracker_core::filter::alpha_beta::AlphaBetaGains;
use tracker_core::filter::alpha_beta_gamma::AbgGains;
use tracker_core::filter::alpha_beta_gamma_eta::AbgeGains;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::{Filter, Interval, Measurement};
use tracker_core::frame;
use tracker_core::icd::{
    Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, PROTOCOL_VERSION,
};
use tracker_core::scalar::{Fix, Scalar};
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

/// Instructions for one scan of a filter: predict to the scan time, update with the plot.
/// The filter is reached through `black_box` every call so its state lives in memory, as
/// it does in a track table.
fn filter_row<S: Scalar, F: Filter<S>>(
    counter: &mut icount::InstructionCounter,
    name: &str,
    built: Option<F>,
) {
    let Some(mut filter) = built else {
        row(name, S::NAME, f32::NAN, 0);
        return;
    };
    let (Ok(dt), Ok(z)) = (
        Interval::new(S::of(2.5)),
        Measurement::new([S::of(1234.5), S::of(-987.25)]),
    ) else {
        return;
    };
    filter.start(z);
    let per_scan = icount::per_call(counter, CALLS, || {
        scan(black_box(&mut filter), black_box(dt), black_box(z));
    });
    row(name, S::NAME, per_scan, core::mem::size_of::<F>());
}

/// One scan, as a track table runs it: a real call, so its cost is counted whole.
#[inline(never)]
fn scan<S: Scalar, F: Filter<S>>(f: &mut F, dt: Interval<S>, z: Measurement<S>) {
    f.predict(dt);
    f.update(z);
}

fn filter_rows<S: Scalar>(counter: &mut icount::InstructionCounter) {
    filter_row::<S, _>(
        counter,
        "alpha-beta",
        AlphaBetaGains::BenedictBordner { alpha: 0.5 }
            .build::<S>()
            .ok(),
    );
    filter_row::<S, _>(
        counter,
        "alpha-beta-gamma",
        AbgGains::FadingMemory { xi: 0.9 }.build::<S>().ok(),
    );
    filter_row::<S, _>(
        counter,
        "alpha-beta-gamma-eta",
        AbgeGains::FadingMemory { xi: 0.9 }.build::<S>().ok(),
    );
    let sswt = SswtConfig {
        window: 4,
        start: AlphaBetaGains::BenedictBordner { alpha: 0.5 },
    };
    filter_row::<S, _>(counter, "sswt", sswt.build::<S>().ok());
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

    filter_rows::<f32>(&mut counter);
    filter_rows::<Fix>(&mut counter);
    let kalman = KalmanConfig::new(0.1, QModel::Continuous, 100.0);
    filter_row::<f32, _>(&mut counter, "kalman-cv", kalman.build_cv::<f32>().ok());
    filter_row::<f32, _>(&mut counter, "kalman-ca", kalman.build_ca::<f32>().ok());
    board::exit(0)
}
