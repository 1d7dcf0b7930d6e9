//! Deterministic instruction counts on QEMU.
//!
//! QEMU models no cycles (DWT CYCCNT reads 0). Run with `-icount shift=0` and every
//! instruction takes 1 ns of virtual time; SysTick runs from the 25 MHz core clock of the
//! mps2 boards, so one tick is 40 instructions, and the same binary gives the same count on
//! every run. On real silicon the same code reads cycles at whatever the core clock is.

use cortex_m::peripheral::{syst::SystClkSource, SYST};

/// Instructions per SysTick tick under `qemu-system-arm -icount shift=0` on mps2 boards.
pub const INSTRUCTIONS_PER_TICK: u32 = 40;

const RELOAD: u32 = 0x00FF_FFFF;

/// A free-running 24-bit SysTick counter.
pub struct InstructionCounter {
    syst: SYST,
}

impl InstructionCounter {
    /// Starts SysTick from the core clock, counting down from its full 24-bit range.
    pub fn new(mut syst: SYST) -> Self {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_counter();
        InstructionCounter { syst }
    }

    /// Ticks elapsed while running `f`; `f` must take under 2^24 ticks (671 M instructions).
    pub fn ticks(&mut self, f: impl FnOnce()) -> u32 {
        region_begin();
        let start = SYST::get_current();
        f();
        let end = SYST::get_current();
        region_end();
        // SysTick counts down and wraps to RELOAD.
        start.wrapping_sub(end) & RELOAD
    }

    /// Releases SysTick.
    pub fn free(self) -> SYST {
        self.syst
    }
}

/// Marks where a measured region begins, for a profile of QEMU's block trace
/// (`tools/qemu_profile.py --regions`): outside the SysTick readings, so the counts are the
/// same with it. Its body differs from [`region_end`]'s, so LLVM cannot merge the two.
#[inline(never)]
pub fn region_begin() {
    core::hint::black_box(1u32);
}

/// Marks where a measured region ends; see [`region_begin`].
#[inline(never)]
pub fn region_end() {
    core::hint::black_box(2u32);
}

/// Instructions per call of `f`, with the loop's own cost (measured with an empty body)
/// taken out; `calls` repetitions.
pub fn per_call(counter: &mut InstructionCounter, calls: u32, mut f: impl FnMut()) -> f32 {
    let empty = counter.ticks(|| {
        for _ in 0..calls {
            core::hint::black_box(());
        }
    });
    let full = counter.ticks(|| {
        for _ in 0..calls {
            f();
        }
    });
    let net = full.saturating_sub(empty) as f32 * INSTRUCTIONS_PER_TICK as f32;
    net / calls.max(1) as f32
}

/// The bench table's header.
pub const HEADER: &str = "name,scalar,instructions_per_call,ram_bytes";

/// Prints one row of the bench table on semihosting stdout:
/// `name,scalar,instructions_per_call,ram_bytes`.
pub fn report(name: &str, scalar: &str, instructions: f32, ram_bytes: usize) {
    semihosting::println!("{},{},{:.1},{}", name, scalar, instructions, ram_bytes);
}
