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
use tracker_firmware::{board, icount};

const CALLS: u32 = 200;

use icount::report as row;

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
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
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
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
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

/// Instructions per scan of the device's tracking work for 40 targets and about 200 plots:
/// plots in (converted to the local frame), every track predicted and rough-gated,
/// assignments applied (updates, coasts, initiations, life cycle). The assignments are
/// the nearest gated plot, chosen outside the measurement (the host's job).
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn scan_row(counter: &mut icount::InstructionCounter, device: &mut Device) {
    use tracker_core::device::Reply;
    use tracker_core::icd::{Assignment, AssignmentBatch, PlotBatch, MAX_PLOTS_PER_MESSAGE};
    use tracker_core::sim::{Scenario, ScenarioConfig};
    let mut config = ScenarioConfig::open_sea(40, 1);
    config.sensor.clutter_per_scan = 160.0;
    // In .bss rather than on the stack, which the track table leaves small.
    let Some(sim) = cortex_m::singleton!(: Scenario = Scenario::new(config)) else {
        board::exit(1)
    };
    let (mut ticks, mut scans, mut plots) = (0u64, 0u32, 0usize);
    let Some(out) = cortex_m::singleton!(: tracker_core::sim::ScanOutput = tracker_core::sim::ScanOutput::default())
    else {
        board::exit(1)
    };
    for k in 0..40 {
        sim.next_scan_into(out);
        let parts = out.plots.len().div_ceil(MAX_PLOTS_PER_MESSAGE).max(1) as u8;
        let mut t = 0u32;
        for (i, chunk) in out.plots.chunks(MAX_PLOTS_PER_MESSAGE).enumerate() {
            let batch = HostToDevice::Plots(PlotBatch {
                scan: out.scan,
                time_ms: out.time_ms,
                part: i as u8,
                parts,
                plots: chunk.iter().copied().collect(),
            });
            let dt = counter.ticks(|| {
                black_box(device.handle(black_box(&batch)));
            });
            t += dt;
        }
        let tracker = device.tracker();
        let n = tracker.table().tracks().len();
        let mut assignments: heapless::Vec<Assignment, 64> = heapless::Vec::new();
        let mut taken = [false; 256];
        let mut gated = [false; 256];
        for i in 0..n {
            if let Some(g) = tracker.table().gated(i) {
                for &p in &g.plots {
                    gated[usize::from(p)] = true;
                }
                let plot = g.plots.iter().copied().find(|&p| !taken[usize::from(p)]);
                if let Some(p) = plot {
                    taken[usize::from(p)] = true;
                }
                let _ = assignments.push(Assignment {
                    track: g.track,
                    plot,
                });
            }
        }
        let initiate: heapless::Vec<u16, 256> = (0..out.plots.len() as u16)
            .filter(|&p| !gated[usize::from(p)])
            .collect();
        let per = 48;
        let aparts = assignments
            .len()
            .div_ceil(per)
            .max(initiate.len().div_ceil(per))
            .max(1);
        for part in 0..aparts {
            let batch = HostToDevice::Assign(AssignmentBatch {
                scan: out.scan,
                part: part as u8,
                parts: aparts as u8,
                assignments: assignments
                    .iter()
                    .skip(part * per)
                    .take(per)
                    .copied()
                    .collect(),
                initiate: initiate
                    .iter()
                    .skip(part * per)
                    .take(per)
                    .copied()
                    .collect(),
            });
            let dt = counter.ticks(|| {
                let reply = device.handle(black_box(&batch));
                black_box(matches!(reply, Reply::Tracks { .. }));
            });
            t += dt;
        }
        // Score the scans once the picture has settled (tracks confirmed).
        if k >= 20 {
            ticks += u64::from(t);
            scans += 1;
            plots += out.plots.len();
        }
    }
    let per_scan = (ticks * u64::from(icount::INSTRUCTIONS_PER_TICK)) as f32 / scans as f32;
    println!(
        "# scan row: {} plots a scan on average",
        plots / scans as usize
    );
    row(
        "scan-40-targets-200-plots",
        "f32",
        per_scan,
        core::mem::size_of::<tracker_core::tracker::Tracker>(),
    );
}

/// RAM per track: the table's slot (sized for the largest filter, so any can be chosen at
/// run time), and what a slot would take with one filter only. Instruction column 0: these
/// are sizes, not costs.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn capacity_rows() {
    use core::mem::size_of;
    use tracker_core::filter::alpha_beta::AlphaBeta;
    use tracker_core::filter::alpha_beta_gamma::AlphaBetaGamma;
    use tracker_core::filter::kalman::{ca::KalmanCa, cv::KalmanCv};
    use tracker_core::filter::sswt::Sswt;
    use tracker_core::track::{Track, TrackFilter};
    let slot = size_of::<Track>();
    let overhead = slot - size_of::<TrackFilter>();
    row("track-slot", "f32", 0.0, slot);
    for (name, filter) in [
        ("track-slot-alpha-beta", size_of::<AlphaBeta<f32>>()),
        (
            "track-slot-alpha-beta-gamma",
            size_of::<AlphaBetaGamma<f32>>(),
        ),
        ("track-slot-sswt", size_of::<Sswt<f32>>()),
        ("track-slot-kalman-cv", size_of::<KalmanCv<f32>>()),
        ("track-slot-kalman-ca", size_of::<KalmanCa<f32>>()),
    ] {
        row(name, "f32", 0.0, overhead + filter);
    }
}

/// One scan, as a track table runs it: a real call, so its cost is counted whole.
#[inline(never)]
fn scan<S: Scalar, F: Filter<S>>(f: &mut F, dt: Interval<S>, z: Measurement<S>) {
    f.predict(dt);
    f.update(z);
}

// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
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
    let Some(device) = tracker_firmware::device() else {
        board::exit(1)
    };

    println!("{}", icount::HEADER);
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
    scan_row(&mut counter, device);
    capacity_rows();
    let kalman = KalmanConfig::new(0.1, QModel::Continuous, 100.0);
    filter_row::<f32, _>(&mut counter, "kalman-cv", kalman.build_cv::<f32>().ok());
    filter_row::<f32, _>(&mut counter, "kalman-ca", kalman.build_ca::<f32>().ok());
    filter_row::<f32, _>(
        &mut counter,
        "grnn",
        tracker_core::filter::grnn::GrnnConfig::default()
            .build::<f32>()
            .ok(),
    );
    board::exit(0)
}
