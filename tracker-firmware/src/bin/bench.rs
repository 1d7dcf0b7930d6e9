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
use tracker_core::filter::gh_fixed_scan::FixedScanGh;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::{Filter, Interval, Measurement};
use tracker_core::frame;
use tracker_core::icd::{Header, HostToDevice, MAX_ENCODED_FRAME_BYTES, PROTOCOL_VERSION};
use tracker_core::scalar::{Fix, Scalar};
use tracker_firmware::{board, icount};

const CALLS: u32 = 200;

/// The largest echo's bytes: 0, 1, 2, … (in flash, not on the bench's stack).
static ECHO_MAX: [u8; tracker_core::icd::MAX_ECHO_BYTES] = {
    let mut bytes = [0u8; tracker_core::icd::MAX_ECHO_BYTES];
    let mut i = 0;
    while i < bytes.len() {
        bytes[i] = i as u8;
        i += 1;
    }
    bytes
};

use icount::report as row;

/// One encoded request frame. Its own frame: its buffers are dead once it returns.
#[inline(never)]
fn request(body: &HostToDevice) -> ([u8; MAX_ENCODED_FRAME_BYTES], usize) {
    let mut out = [0u8; MAX_ENCODED_FRAME_BYTES];
    let header = Header {
        protocol: PROTOCOL_VERSION,
        request_id: 1,
    };
    let n = frame::encode(&header, body, &mut out).unwrap_or(0);
    (out, n)
}

/// Instructions to take one whole frame through the device (decode, dispatch, encode the
/// reply) with the reply bytes handed to a sink that only looks at them: the frame's bytes
/// handed over one at a time (as the firmware's UART loop does), or with `dma` all in one
/// slice (as a DMA buffer hands them over).
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn link_row(
    counter: &mut icount::InstructionCounter,
    device: &mut Device,
    name: &str,
    body: &HostToDevice,
    dma: bool,
) {
    let (bytes, n) = request(body);
    let frame = &bytes[..n];
    let per_frame = icount::per_call(counter, CALLS, || {
        let mut sink = |reply: &[u8]| {
            black_box(reply);
        };
        if dma {
            device.receive(black_box(frame), &mut sink);
        } else {
            for b in black_box(frame) {
                device.receive(core::slice::from_ref(b), &mut sink);
            }
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

/// Tracks in the fixed-scan g-h rows (their figures are per track): 64, the table's size
/// when they were first measured, kept so that the rows stay comparable with their history
/// (a per-track figure hardly depends on the count: the scan's fixed cost is shared out).
const FIXED_SCAN_TRACKS: usize = 64;

/// Scans the fixed-scan g-h rows time.
const FIXED_SCAN_SCANS: u32 = 20;

/// Instructions per track for one scan of the constant-gain g-h filters as the track table
/// runs them ([`FixedScanGh`]): the interval compared once for the scan (the table's
/// `predict`, which then predicts nothing), then every track updated with its plot and its
/// next scan predicted (the table's `apply`), the loop included. The filters are reached
/// through `black_box` every scan, so their states live in memory as in the table.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn fixed_scan_row<S: Scalar, const N: usize>(
    counter: &mut icount::InstructionCounter,
    name: &str,
    general: Option<tracker_core::filter::gh::GhFilter<S, N>>,
) {
    let Some(proto) = general.as_ref().and_then(FixedScanGh::from_filter) else {
        row(name, S::NAME, f32::NAN, 0);
        return;
    };
    let Ok(dt) = Interval::new(S::of(2.5)) else {
        return;
    };
    let Ok(origin) = Measurement::new([S::of(1234.5), S::of(-987.25)]) else {
        return;
    };
    let mut filters = [proto; FIXED_SCAN_TRACKS];
    let mut zs = [origin; FIXED_SCAN_TRACKS];
    for (i, (f, z)) in filters.iter_mut().zip(&mut zs).enumerate() {
        let at = [
            S::of(1234.5 + 250.0 * i as f64),
            S::of(-987.25 - 125.0 * i as f64),
        ];
        *z = Measurement::new(at).unwrap_or(origin);
        // Started and predicted at the table's interval, as the table starts a track.
        f.start(*z);
        f.predict(dt);
    }
    // The interval the table's tracks hold their predictions for.
    let held = Some(dt);
    let per_scan = icount::per_call(counter, FIXED_SCAN_SCANS, || {
        let filters = black_box(&mut filters);
        if black_box(held) != Some(dt) {
            for f in filters.iter_mut() {
                f.predict(dt);
            }
        }
        for (f, z) in filters.iter_mut().zip(black_box(&zs)) {
            f.update(*z);
        }
    });
    row(
        name,
        S::NAME,
        per_scan / FIXED_SCAN_TRACKS as f32,
        core::mem::size_of::<FixedScanGh<S, N>>(),
    );
}

/// What a scan bench feeds the device.
#[derive(Clone, Copy)]
struct ScanLoad {
    /// Targets simulated.
    targets: usize,
    /// The simulator's own clutter, plots a scan on average.
    sim_clutter: f32,
    /// Plots a scan in all: the simulator's, topped up with uniform clutter to this many
    /// (at most the simulator's capacity, which is the device's).
    plots: usize,
    /// Start tracks on clutter too (a plot in no gate starts one, which fills the table),
    /// or only on the targets' plots, which holds the table at about the targets' number.
    initiate_clutter: bool,
}

/// Storage of the scan benches, in `.host_side` (memory.x: RAM above the board's 64 KiB,
/// which QEMU has and the board has not) rather than on the stack, which the track table
/// leaves small, or in the board's RAM, which holds only what the firmware holds; shared by
/// every row.
struct ScanBench {
    out: tracker_core::sim::ScanOutput,
    /// Per plot: in some gate; assigned to a track.
    gated: [bool; tracker_core::tracker::MAX_PLOTS_PER_SCAN],
    taken: [bool; tracker_core::tracker::MAX_PLOTS_PER_SCAN],
    initiate: heapless::Vec<u16, { tracker_core::tracker::MAX_PLOTS_PER_SCAN }>,
    /// A plots part, packed.
    packed: [u8; tracker_core::icd::MAX_PLOT_BYTES],
    /// A plots part, read.
    positions: heapless::Vec<[f32; 2], { tracker_core::icd::MAX_PLOTS_PER_MESSAGE }>,
    /// An assignments part, packed.
    assign_buf: [u8; tracker_core::icd::MAX_ASSIGNMENT_BYTES],
    /// Scan times go on from row to row: the device refuses a scan not later than the last.
    time_base_ms: u64,
}

/// Scans a bench runs: the first half settles the picture, the second is counted.
const BENCH_SCANS: u32 = 40;

/// Instructions per scan of the device's tracking work: plots in (already in the local
/// frame: the host converts them, outside the count), every track predicted and
/// rough-gated, assignments applied (updates, coasts, initiations, life cycle). The
/// assignments are the nearest gated plot, chosen outside the measurement (the host's
/// job). With `read`, the plots and assignments are read from their packed lists as a
/// frame carries them ([`Device::handle`]); without, they are handed to the tracker read
/// (the tracking work alone). Prints the row, and a comment with the tracks and plots it
/// averaged.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn scan_row(
    counter: &mut icount::InstructionCounter,
    device: &mut Device,
    bench: &mut ScanBench,
    sim: &mut tracker_core::sim::Scenario,
    name: &str,
    load: ScanLoad,
    read: bool,
) {
    use tracker_core::device::Reply;
    use tracker_core::icd::records;
    use tracker_core::icd::{
        AssignmentBatch, Bytes, Plot, PlotBatch, TrackCommand, MAX_PLOTS_PER_MESSAGE,
    };
    use tracker_core::sim::ScenarioConfig;
    use tracker_core::tracker::{AssignHead, PlotsHead};
    let _ = device.handle(&HostToDevice::Command(TrackCommand::CancelAll));
    let mut config = ScenarioConfig::open_sea(load.targets, 1);
    config.sensor.clutter_per_scan = load.sim_clutter;
    let max_range_m = config.sensor.max_range_m;
    restart(sim, config);
    // Uniform clutter over the radar's disc, from a fixed LCG: the same plots every run.
    let mut seed = 0x2545_f491u32;
    let mut uniform = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    let (mut ticks, mut scans, mut plots, mut tracks) = (0u64, 0u32, 0usize, 0usize);
    // The plot half (plots in, predict, gate) apart from the whole.
    let mut plot_ticks = 0u64;
    for k in 0..BENCH_SCANS {
        next_scan(sim, &mut bench.out);
        let out = &mut bench.out;
        let time_ms = bench.time_base_ms + out.time_ms;
        // The top-up clutter goes after the simulator's plots, with no source.
        while out.plots.len() < load.plots {
            // The larger of two uniforms has density 2u: uniform over the disc's area.
            let u = uniform().max(uniform());
            let plot = Plot {
                range_m: max_range_m * u,
                bearing_rad: core::f32::consts::TAU * uniform(),
            };
            if out.plots.push(plot).is_err() {
                break;
            }
        }
        let out = &bench.out;
        let all = &out.plots;
        let parts = all.len().div_ceil(MAX_PLOTS_PER_MESSAGE).max(1) as u8;
        let mut t = 0u32;
        for (i, chunk) in all.chunks(MAX_PLOTS_PER_MESSAGE).enumerate() {
            // The host's part, outside the count: plots to the local frame (own ship at
            // the origin), on the wire's grid, packed. Reading them is the device's.
            let head = PlotBatch {
                scan: out.scan,
                time_ms,
                part: i as u8,
                parts,
                base_scan: None,
                plots: Bytes(&[]),
            };
            let packed = pack_plots(head, chunk, &mut bench.packed);
            let dt = if read {
                let batch = HostToDevice::Plots(packed);
                counter.ticks(|| {
                    black_box(device.handle(black_box(&batch)));
                })
            } else {
                let positions = &mut bench.positions;
                positions.clear();
                let _ = records::read_plots(packed.plots.0, |p| {
                    let _ = positions.push(p);
                });
                let head = PlotsHead::of(&packed);
                let tracker = device.tracker_mut();
                counter.ticks(|| {
                    let _ =
                        black_box(tracker.take_positions(head, positions.iter().map(|&p| Ok(p))));
                })
            };
            t += dt;
        }
        let t_plots = t;
        let tracker = device.tracker();
        let n = tracker.table().len();
        let mut assignments: heapless::Vec<(u16, u16), { tracker_core::track::MAX_TRACKS }> =
            heapless::Vec::new();
        let (taken, gated) = (&mut bench.taken, &mut bench.gated);
        taken.fill(false);
        gated.fill(false);
        for i in 0..n {
            if let Some(g) = tracker.table().gated(i) {
                for &p in &g.plots {
                    gated[usize::from(p)] = true;
                }
                let plot = g.plots.iter().copied().find(|&p| !taken[usize::from(p)]);
                // As the host does: only updates are sent, the rest coast.
                if let Some(p) = plot {
                    taken[usize::from(p)] = true;
                    let _ = assignments.push((g.track, p));
                }
            }
        }
        let target_plot = |p: usize| out.plot_source.get(p).is_some_and(|s| s.is_some());
        let initiate = &mut bench.initiate;
        initiate.clear();
        for (p, &in_gate) in gated.iter().enumerate().take(all.len()) {
            if !in_gate && (load.initiate_clutter || target_plot(p)) {
                let _ = initiate.push(p as u16);
            }
        }
        let parts = AssignmentBatch::parts(assignments.len(), initiate.len());
        for part in 0..parts {
            let buf = &mut bench.assign_buf;
            let b = AssignmentBatch::pack(out.scan, (part, parts), &assignments, initiate, buf);
            let dt = if read {
                let batch = HostToDevice::Assign(b);
                counter.ticks(|| {
                    let reply = device.handle(black_box(&batch));
                    black_box(matches!(reply, Reply::Tracks));
                })
            } else {
                let head = AssignHead {
                    scan: b.scan,
                    part: b.part,
                    parts: b.parts,
                };
                let per = tracker_core::icd::MAX_ASSIGNMENTS_PER_MESSAGE;
                let from = usize::from(part) * per;
                let window = |n: usize| from.min(n)..(from + per).min(n);
                let (u, i) = (
                    assignments.get(window(assignments.len())).unwrap_or(&[]),
                    initiate.get(window(initiate.len())).unwrap_or(&[]),
                );
                let tracker = device.tracker_mut();
                counter.ticks(|| {
                    let r = tracker.take_assignments(
                        head,
                        u.iter().map(|&a| Ok(a)),
                        i.iter().map(|&p| Ok(p)),
                    );
                    black_box(r.is_ok());
                })
            };
            t += dt;
        }
        // Score the scans once the picture has settled (tracks confirmed).
        if k >= BENCH_SCANS / 2 {
            ticks += u64::from(t);
            plot_ticks += u64::from(t_plots);
            scans += 1;
            plots += all.len();
            tracks += n;
        }
        if k + 1 == BENCH_SCANS {
            bench.time_base_ms = time_ms + 60_000;
        }
    }
    let per_scan = (ticks * u64::from(icount::INSTRUCTIONS_PER_TICK)) as f32 / scans as f32;
    let plot_half = (plot_ticks * u64::from(icount::INSTRUCTIONS_PER_TICK)) as f32 / scans as f32;
    println!(
        "# {}: {} tracks and {} plots a scan on average; plots in, predict and gate {}, assignments applied {}",
        name,
        tracks / scans as usize,
        plots / scans as usize,
        plot_half,
        per_scan - plot_half
    );
    row(
        name,
        "f32",
        per_scan,
        core::mem::size_of::<tracker_core::tracker::Tracker>(),
    );
}

/// The simulator's next scan. Its own frame: the simulator's temporaries are dead before the
/// device is called.
#[inline(never)]
fn next_scan(sim: &mut tracker_core::sim::Scenario, out: &mut tracker_core::sim::ScanOutput) {
    sim.next_scan_into(out);
}

/// A plots part as the host makes it: to the local frame (own ship at the origin), on the
/// wire's grid, packed into `packed`. Its own frame: the positions are dead once packed.
/// The host places plots with the sine in f64 (`geo::polar_to_local_f64`); this simulated
/// host side keeps the MCU's table sine, as it is not the device's work being counted.
#[inline(never)]
fn pack_plots<'b>(
    head: tracker_core::icd::PlotBatch<'static>,
    chunk: &[tracker_core::icd::Plot],
    packed: &'b mut [u8; tracker_core::icd::MAX_PLOT_BYTES],
) -> tracker_core::icd::PlotBatch<'b> {
    use tracker_core::icd::fixed::position_on_grid;
    let local: heapless::Vec<[f32; 2], { tracker_core::icd::MAX_PLOTS_PER_MESSAGE }> = chunk
        .iter()
        .map(|p| {
            position_on_grid(tracker_core::geo::polar_to_local(
                [0.0, 0.0],
                p.range_m,
                p.bearing_rad,
            ))
        })
        .collect();
    tracker_core::icd::PlotBatch::pack(head, &local, packed)
}

/// The scan benches' storage, once, in the RAM above the board's 64 KiB (`memory.x`:
/// `.host_side`): the simulated host's scenario and buffers are the thesis's PC's, not the
/// board's, so the board's RAM holds what the firmware holds and the stack. Written here
/// before anything reads it (the section is neither loaded nor zeroed); the scan bench's
/// storage from a constant, not built on the stack.
#[inline(never)]
fn scan_storage() -> Option<(
    &'static mut ScanBench,
    &'static mut tracker_core::sim::Scenario,
)> {
    use core::mem::MaybeUninit;
    use core::sync::atomic::{AtomicBool, Ordering};
    use tracker_core::sim::{ScanOutput, Scenario, ScenarioConfig};
    const EMPTY: ScanBench = ScanBench {
        out: ScanOutput::EMPTY,
        gated: [false; tracker_core::tracker::MAX_PLOTS_PER_SCAN],
        taken: [false; tracker_core::tracker::MAX_PLOTS_PER_SCAN],
        initiate: heapless::Vec::new(),
        packed: [0; tracker_core::icd::MAX_PLOT_BYTES],
        positions: heapless::Vec::new(),
        assign_buf: [0; tracker_core::icd::MAX_ASSIGNMENT_BYTES],
        time_base_ms: 0,
    };
    static TAKEN: AtomicBool = AtomicBool::new(false);
    #[link_section = ".host_side"]
    static mut BENCH: MaybeUninit<ScanBench> = MaybeUninit::uninit();
    #[link_section = ".host_side"]
    static mut SIM: MaybeUninit<Scenario> = MaybeUninit::uninit();
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: TAKEN hands out the one reference to each, once; each is written whole before
    // the reference is made.
    let (bench, sim) = unsafe {
        (
            (*core::ptr::addr_of_mut!(BENCH)).write(EMPTY),
            (*core::ptr::addr_of_mut!(SIM)).write(Scenario::new(ScenarioConfig::open_sea(1, 1))),
        )
    };
    Some((bench, sim))
}

/// A new scenario in place. Its own frame, as [`scan_storage`].
#[inline(never)]
fn restart(sim: &mut tracker_core::sim::Scenario, config: tracker_core::sim::ScenarioConfig) {
    *sim = tracker_core::sim::Scenario::new(config);
}

/// The scan rows: today's product picture (40 targets, the simulator's clutter, every
/// plot in no gate starting a track, so the table runs full), the growth with tracks and
/// plots, then a full table with the g-h filters and the CV Kalman filter side by side.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn scan_rows(counter: &mut icount::InstructionCounter, device: &mut Device) {
    let Some((bench, sim)) = scan_storage() else {
        board::exit(1)
    };
    let product = ScanLoad {
        targets: 40,
        sim_clutter: 160.0,
        plots: 0,
        initiate_clutter: true,
    };
    scan_row(
        counter,
        device,
        bench,
        sim,
        "scan-40-targets-200-plots",
        product,
        false,
    );
    scan_row(
        counter,
        device,
        bench,
        sim,
        "scan-40-targets-200-plots-read-from-frames",
        product,
        true,
    );
    for (name, targets, plots) in [
        ("scan-16-tracks-50-plots", 16, 50),
        ("scan-16-tracks-200-plots", 16, 200),
        ("scan-16-tracks-250-plots", 16, 250),
        ("scan-64-tracks-50-plots", 64, 50),
        ("scan-64-tracks-200-plots", 64, 200),
        ("scan-64-tracks-250-plots", 64, 250),
    ] {
        let load = ScanLoad {
            targets,
            sim_clutter: 0.0,
            plots,
            initiate_clutter: false,
        };
        scan_row(counter, device, bench, sim, name, load, false);
    }
    // The device's scan with each of the filters the table runs differently: the g-h
    // filters in their fixed-scan form, the CV Kalman filter predicted and updated.
    use tracker_core::filter::FilterKind;
    let load = ScanLoad {
        targets: 64,
        sim_clutter: 0.0,
        plots: 64,
        initiate_clutter: false,
    };
    for (name, kind) in [
        ("scan-64-tracks-64-plots-alpha-beta", FilterKind::AlphaBeta),
        (
            "scan-64-tracks-64-plots-alpha-beta-gamma",
            FilterKind::AlphaBetaGamma,
        ),
        ("scan-64-tracks-64-plots-kalman-cv", FilterKind::KalmanCv),
    ] {
        configure(device, Some(kind));
        scan_row(counter, device, bench, sim, name, load, false);
    }
    configure(device, None);
}

/// Configures the device's tracks to run `filter` as the product does
/// ([`tracker_core::filter::FilterConfig::tracking`], 50 m plots, 20 m/s targets), or
/// back to the default configuration. Its own frame: the request is a kilobyte, too much
/// for [`scan_rows`]'s frame on the bench's stack.
#[inline(never)]
fn configure(device: &mut Device, filter: Option<tracker_core::filter::FilterKind>) {
    use tracker_core::icd::TrackerConfig;
    let config = match filter {
        Some(kind) => TrackerConfig {
            filter: tracker_core::filter::FilterConfig::tracking(kind, 50.0, 20.0),
            ..TrackerConfig::DEFAULT
        },
        None => TrackerConfig::DEFAULT,
    };
    let _ = device.handle(&HostToDevice::Configure(config));
}

/// RAM per track: the table's slot (sized for the largest filter, so any can be chosen at
/// run time), and what a slot would take with one filter only. Instruction column 0: these
/// are sizes, not costs.
// Its own frame: inlined into `main`, every row's locals would share one huge frame.
#[inline(never)]
fn capacity_rows() {
    use core::mem::size_of;
    use tracker_core::filter::gh_fixed_scan::{FixedScanAlphaBeta, FixedScanAlphaBetaGamma};
    use tracker_core::filter::kalman::{ca::KalmanCa, cv::KalmanCv};
    use tracker_core::filter::sswt::Sswt;
    use tracker_core::track::{Track, TrackFilter};
    let slot = size_of::<Track>();
    let overhead = slot - size_of::<TrackFilter>();
    row("track-slot", "f32", 0.0, slot);
    for (name, filter) in [
        (
            "track-slot-alpha-beta",
            size_of::<FixedScanAlphaBeta<f32>>(),
        ),
        (
            "track-slot-alpha-beta-gamma",
            size_of::<FixedScanAlphaBetaGamma<f32>>(),
        ),
        ("track-slot-sswt", size_of::<Sswt<f32>>()),
        ("track-slot-kalman-cv", size_of::<KalmanCv<f32>>()),
        ("track-slot-kalman-ca", size_of::<KalmanCa<f32>>()),
        (
            "track-slot-imm",
            size_of::<tracker_core::filter::imm::Imm<f32>>(),
        ),
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
    fixed_scan_row::<S, 2>(
        counter,
        "alpha-beta-fixed-scan",
        AlphaBetaGains::BenedictBordner { alpha: 0.5 }
            .build::<S>()
            .ok(),
    );
    fixed_scan_row::<S, 3>(
        counter,
        "alpha-beta-gamma-fixed-scan",
        AbgGains::FadingMemory { xi: 0.9 }.build::<S>().ok(),
    );
    fixed_scan_row::<S, 4>(
        counter,
        "alpha-beta-gamma-eta-fixed-scan",
        AbgeGains::FadingMemory { xi: 0.9 }.build::<S>().ok(),
    );
}

extern "C" {
    /// The stack's lowest address (cortex-m-rt; flip-link puts the stack at the start of
    /// RAM, below the static data, so that an overflow faults instead of corrupting it).
    static _stack_end: u32;
    /// The stack's top, where it starts (cortex-m-rt; flip-link sets it).
    static _stack_start: u32;
}

/// What the unused stack is painted with.
const STACK_PAINT: u32 = 0x5aa5_5aa5;

/// The stack's bounds, `(lowest, top)` addresses.
fn stack_bounds() -> (usize, usize) {
    // Only the symbols' addresses are taken.
    (
        core::ptr::addr_of!(_stack_end) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
    )
}

/// Paints the stack below the stack pointer, so that [`stack_peak_bytes`] can tell how deep
/// the rows went. Called first thing in `main`, before any interrupt is enabled.
#[inline(never)]
fn paint_stack() {
    let sp = cortex_m::register::msp::read() as usize;
    let (mut at, top) = stack_bounds();
    if !(at < sp && sp <= top) {
        return;
    }
    // The 64 bytes below the stack pointer read here are left alone: the read may come
    // before this function's prologue, which pushes its saved registers there (8 bytes
    // today).
    while at + 64 < sp {
        // SAFETY: RAM of the stack below every live frame, which nothing else uses.
        unsafe { core::ptr::write_volatile(at as *mut u32, STACK_PAINT) };
        at += 4;
    }
}

/// The stack the deepest row used since [`paint_stack`], B: from the top of the stack down
/// to the lowest word no longer painted.
fn stack_peak_bytes() -> usize {
    let (mut at, top) = stack_bounds();
    // SAFETY: reads of the stack's own RAM, word aligned.
    while at < top && unsafe { core::ptr::read_volatile(at as *const u32) } == STACK_PAINT {
        at += 4;
    }
    top - at
}

#[entry]
fn main() -> ! {
    paint_stack();
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        board::exit(1)
    };
    let mut counter = icount::InstructionCounter::new(peripherals.SYST);
    let Some(device) = tracker_firmware::device() else {
        board::exit(1)
    };

    println!("{}", icount::HEADER);
    link_row(
        &mut counter,
        device,
        "link-hello",
        &HostToDevice::Hello,
        false,
    );
    let echo16_bytes: [u8; 16] = core::array::from_fn(|i| i as u8);
    let echo16 = HostToDevice::Echo(tracker_core::icd::Bytes(&echo16_bytes));
    link_row(&mut counter, device, "link-echo-16B", &echo16, false);
    let echo_max = HostToDevice::Echo(tracker_core::icd::Bytes(&ECHO_MAX));
    link_row(&mut counter, device, "link-echo-1000B", &echo_max, false);
    link_row(
        &mut counter,
        device,
        "link-hello-dma",
        &HostToDevice::Hello,
        true,
    );
    link_row(&mut counter, device, "link-echo-16B-dma", &echo16, true);
    link_row(&mut counter, device, "link-echo-1000B-dma", &echo_max, true);

    filter_rows::<f32>(&mut counter);
    filter_rows::<Fix>(&mut counter);
    scan_rows(&mut counter, device);
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
    // The IMM as the product runs it (CV, CA and settling CV, plots of 40 m).
    let imm = match tracker_core::filter::FilterConfig::tracking(
        tracker_core::filter::FilterKind::Imm,
        40.0,
        20.0,
    ) {
        tracker_core::filter::FilterConfig::Imm(c) => c.build::<f32>().ok(),
        _ => None,
    };
    filter_row::<f32, _>(&mut counter, "imm", imm);
    // The deepest any row went, the bench's own code included (its simulator's reset is
    // among the deepest chains), so an upper bound on what the device's paths take: painted
    // once, read once (a reading between rows would move the next rows' SysTick phase and
    // their figures by a few instructions).
    row("stack-peak", "-", 0.0, stack_peak_bytes());
    board::exit(0)
}
