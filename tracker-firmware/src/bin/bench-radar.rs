//! Instruction counts of plot extraction (the core's CFAR and blob growing) per spoke,
//! under `qemu-system-arm -icount shift=0`: for a board with Ethernet that takes a radar's
//! spokes itself.
//!
//! A binary of its own: beside the device's track table the extractor's 18.8 KiB would leave
//! the other rows too little stack. Same CSV as `bench` (`tracker-host bench-mcu` runs
//! every bench binary).
#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use semihosting::println;
use tracker_firmware::icount::report as row;
use tracker_firmware::{board, icount};

/// Quantiles of Rayleigh noise of scale σ = 2 levels (the synthetic radar's receiver noise),
/// as 16-bit thresholds: a uniform `u` below `RAYLEIGH_2[k]` and above `RAYLEIGH_2[k - 1]`
/// is level k. `RAYLEIGH_2[k] = 65,536 · (1 − exp(−(k + 1)² / 8))`.
const RAYLEIGH_2: [u16; 9] = [7700, 25790, 44257, 56665, 62661, 64808, 65392, 65514, 65533];

/// Plot extraction per spoke of 1,024 4-bit samples (Navico HALO/4G), with the Navico
/// defaults: two rotations of 2,048 spokes of Rayleigh noise (σ 2 levels), spiky sea
/// clutter in the first 60 samples (a quarter of them 6 levels up), 40 point echoes
/// (level 15, 10 spokes × 4 samples) and a coastline (200 samples of level 12 across 200
/// spokes) pushed through the extractor: a busy picture (the clutter alone makes about 170
/// plots a rotation). The spokes are painted outside the count, each push counted whole;
/// the second rotation is the one reported (the first starts the stream). RAM: the
/// extractor.
fn extract_row(counter: &mut icount::InstructionCounter) {
    use tracker_core::radar::{Extractor, ExtractorConfig, Spoke};
    // Built at compile time: the extractor (18.8 KiB) never passes through the stack, which
    // the track table and the other rows' statics leave at under 10 KiB.
    static mut EXTRACTOR: Extractor = Extractor::unconfigured();
    // SAFETY: this row runs once, and nothing else names EXTRACTOR.
    let extractor = unsafe { &mut *core::ptr::addr_of_mut!(EXTRACTOR) };
    // Configuring solves the CFAR's threshold factors in software f64 (12 reference cells:
    // both sides, one side, and a near side of 1–11 cells): counted once, its own row.
    let mut configured = false;
    let t = counter.ticks(|| {
        configured = black_box(&mut *extractor)
            .configure(black_box(ExtractorConfig::navico_4bit()))
            .is_ok();
    });
    if !configured {
        board::exit(1)
    }
    row(
        "extract-configure",
        "f64",
        (u64::from(t) * u64::from(icount::INSTRUCTIONS_PER_TICK)) as f32,
        0,
    );
    let Some(samples) = cortex_m::singleton!(: [u8; 1024] = [0; 1024]) else {
        board::exit(1)
    };
    let mut rng: u32 = 0x1234_5678;
    let (mut ticks, mut plots) = (0u64, 0u32);
    for rotation in 0..2u32 {
        for angle in 0..2048u16 {
            for (i, s) in samples.iter_mut().enumerate() {
                // xorshift32: cheap, and outside the count.
                rng ^= rng << 13;
                rng ^= rng >> 17;
                rng ^= rng << 5;
                let u = (rng >> 16) as u16;
                let mut level = RAYLEIGH_2.iter().take_while(|t| u >= **t).count() as u8;
                // Sea clutter: stronger within 60 samples of own ship.
                if i < 60 && rng & 3 == 0 {
                    level = level.saturating_add(6);
                }
                *s = level.min(15);
            }
            // 40 point echoes, 51 spokes apart, at ranges spread over the spoke.
            let k = usize::from(angle / 51);
            if angle % 51 < 10 && k < 40 {
                let r0 = 100 + (k * 211) % 850;
                samples[r0..r0 + 4].iter_mut().for_each(|s| *s = 15);
            }
            // A coastline.
            if (1000..1200).contains(&angle) {
                samples[800..1000].iter_mut().for_each(|s| *s = 12);
            }
            let spoke = Spoke {
                angle,
                spokes_per_rotation: 2048,
                north_up: false,
                heading_rad: Some(0.0),
                range_m: 7408.0,
                time_ms: u64::from(rotation * 2048 + u32::from(angle)),
                samples: &samples[..],
                max_sample: 15,
            };
            let t = counter.ticks(|| {
                black_box(&mut *extractor).push(black_box(&spoke), |e| {
                    if matches!(e, tracker_core::radar::Event::Plot(_)) {
                        plots += 1;
                    }
                });
            });
            if rotation == 1 {
                ticks += u64::from(t);
            }
        }
    }
    println!("# extraction row: {} point plots over two rotations", plots);
    let per_spoke = (ticks * u64::from(icount::INSTRUCTIONS_PER_TICK)) as f32 / 2048.0;
    row(
        "extract-spoke-1024",
        "f32",
        per_spoke,
        core::mem::size_of::<Extractor>(),
    );
}

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        board::exit(1)
    };
    let mut counter = icount::InstructionCounter::new(peripherals.SYST);
    println!("{}", icount::HEADER);
    extract_row(&mut counter);
    board::exit(0)
}
