//! # tracker-firmware
//!
//! The tracker on a DSP-class Cortex-M4F, standing in for the source thesis's TMS320C6711
//! board. All tracking logic lives in `tracker-core`; this crate owns the chip: reset and
//! fault handling, the UART the host link runs on, logging, and the instruction counter the
//! benchmarks use.
//!
//! The main loop ([`serve`]) moves bytes between the UART and
//! [`tracker_core::device::Device`], which decodes frames, dispatches requests and encodes
//! replies. Any byte sequence is valid input: damaged frames become counted errors.
//!
//! Logging is defmt: over semihosting under QEMU (decoded by `defmt-print`, see
//! `scripts/qemu-run`). Panics print through defmt and end in a HardFault, whose handler
//! exits QEMU with code 1 so a test run fails loudly.
#![no_std]
#![deny(missing_docs)]

pub mod board;
pub mod icount;
pub mod uart;

use core::mem::MaybeUninit;

use cortex_m_rt::{exception, ExceptionFrame};
use embedded_hal_nb::serial::{Read, Write};
use tracker_core::device::{Device, DeviceConfig};

#[cfg(all(feature = "rtt", not(feature = "qemu")))]
use defmt_rtt as _;
#[cfg(feature = "qemu")]
use defmt_semihosting as _;
#[cfg(all(feature = "panic-probe", not(feature = "panic-never")))]
use panic_probe as _;

/// With `panic-never` the panic handler calls a function that exists nowhere: the firmware
/// then links only if the optimiser proved every panic unreachable.
#[cfg(feature = "panic-never")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "Rust" {
        fn firmware_has_a_reachable_panic() -> !;
    }
    // SAFETY: never runs; if it could, the link fails.
    unsafe { firmware_has_a_reachable_panic() }
}

/// Tracks the firmware holds (reported to the host; the table itself comes with tracking).
pub const MAX_TRACKS: u16 = tracker_core::track::MAX_TRACKS as u16;

/// Plots accepted per scan.
pub const MAX_PLOTS_PER_SCAN: u16 = tracker_core::tracker::MAX_PLOTS_PER_SCAN as u16;

/// Firmware name and board, reported in the handshake.
#[cfg(not(feature = "stm32f4-discovery"))]
pub const FIRMWARE: &str = concat!(
    "tracker-firmware ",
    env!("CARGO_PKG_VERSION"),
    " (mps2-an386)"
);
/// Firmware name and board, reported in the handshake.
#[cfg(feature = "stm32f4-discovery")]
pub const FIRMWARE: &str = concat!(
    "tracker-firmware ",
    env!("CARGO_PKG_VERSION"),
    " (STM32F4DISCOVERY)"
);

/// Device configuration of this build (the boot id is filled in at start-up).
pub const DEVICE_CONFIG: DeviceConfig = DeviceConfig {
    firmware: FIRMWARE,
    boot_id: 0,
    max_tracks: MAX_TRACKS,
    max_plots_per_scan: MAX_PLOTS_PER_SCAN,
};

/// The device, once: `None` on a second call.
///
/// It lives in a `static` with a constant initialiser, so it is built in place (its initial
/// image is in flash and copied to RAM at reset). Built at run time it would pass through
/// the stack, which is smaller than the device (the track table is most of the RAM).
pub fn device() -> Option<&'static mut Device> {
    use core::sync::atomic::{AtomicBool, Ordering};
    static TAKEN: AtomicBool = AtomicBool::new(false);
    static mut DEVICE: Device = Device::new(DEVICE_CONFIG);
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: TAKEN hands out the one reference, once.
    let device = unsafe { &mut *core::ptr::addr_of_mut!(DEVICE) };
    device.set_boot_id(boot_id());
    Some(device)
}

/// A watchdog the main loop feeds; a loop stuck anywhere stops feeding it and the chip is
/// reset.
pub trait Watchdog {
    /// Tells the watchdog the loop is alive.
    fn feed(&mut self);
}

/// No watchdog.
impl Watchdog for () {
    fn feed(&mut self) {}
}

/// Serves the host link forever: every received byte goes to the device, every reply goes
/// out through `uart`; the watchdog is fed once per pass. Work per pass is bounded (one
/// frame, at most a scan's gating or update), far inside the watchdog's period.
pub fn serve<U, W>(uart: &mut U, device: &mut Device, watchdog: &mut W) -> !
where
    U: Read<u8> + Write<u8>,
    W: Watchdog,
{
    let mut overruns: u32 = 0;
    loop {
        watchdog.feed();
        match uart.read() {
            Ok(byte) => device.receive(core::slice::from_ref(&byte), &mut |reply| {
                for &b in reply {
                    // The UART reports no TX errors; WouldBlock just waits.
                    let _ = nb::block!(uart.write(b));
                }
            }),
            Err(nb::Error::WouldBlock) => {}
            Err(nb::Error::Other(_)) => {
                // A lost byte damages at most the frame it was in; the CRC catches that.
                overruns = overruns.wrapping_add(1);
                defmt::warn!("uart overrun #{}", overruns);
            }
        }
    }
}

/// A number that changes on every reset without power loss: a counter kept in RAM that
/// cortex-m-rt does not initialise, mixed with a constant so a cold boot's garbage and a
/// warm boot's count are both valid ids.
fn boot_id() -> u32 {
    #[link_section = ".uninit.BOOT_COUNT"]
    static mut BOOT_COUNT: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();
    const MAGIC: u32 = 0xB007_C0DE;
    // SAFETY: called from `main` before anything else runs; a plain [u32; 2] has no
    // invalid bit patterns, so reading whatever RAM held is sound.
    unsafe {
        let cell = &mut *core::ptr::addr_of_mut!(BOOT_COUNT);
        let [magic, count] = cell.assume_init_read();
        let next = if magic == MAGIC {
            count.wrapping_add(1)
        } else {
            1
        };
        cell.write([MAGIC, next]);
        next.wrapping_mul(0x9E37_79B9) ^ MAGIC
    }
}

/// A fault ends the run: under QEMU with exit code 1 (a test fails loudly), on a board
/// with a reset (the host sees a new boot id and re-acquires).
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc={=u32:#010x}", frame.pc());
    #[cfg(feature = "qemu")]
    board::exit(1);
    #[cfg(not(feature = "qemu"))]
    cortex_m::peripheral::SCB::sys_reset()
}
