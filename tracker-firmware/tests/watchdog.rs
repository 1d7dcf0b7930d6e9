//! The watchdog resets a stuck loop (on QEMU's model of the CMSDK watchdog): the first boot
//! arms it and stops feeding it; the second boot, told apart by a counter in RAM that reset
//! does not clear, reports success.
#![no_std]
#![no_main]

use core::mem::MaybeUninit;

use cortex_m_rt::entry;
use tracker_firmware::board;

#[link_section = ".uninit.WATCHDOG_TEST"]
static mut BOOTS: MaybeUninit<[u32; 2]> = MaybeUninit::uninit();
const MAGIC: u32 = 0x5744_4F47;

#[entry]
fn main() -> ! {
    // SAFETY: single-threaded start-up; a plain [u32; 2] has no invalid bit patterns.
    let boots = unsafe {
        let cell = &mut *core::ptr::addr_of_mut!(BOOTS);
        let [magic, count] = cell.assume_init_read();
        let count = if magic == MAGIC { count + 1 } else { 1 };
        cell.write([MAGIC, count]);
        count
    };
    if boots >= 2 {
        defmt::info!("watchdog reset the stuck loop: boot {}", boots);
        board::exit(0);
    }
    // 10,000 ticks a period: reset after 20,000 (0.8 ms at 25 MHz).
    let _watchdog = unsafe { board::CmsdkWatchdog::start(10_000) };
    // Stuck, not feeding. If nothing resets us, give up well after the watchdog's time.
    for _ in 0..50_000_000u32 {
        cortex_m::asm::nop();
    }
    defmt::error!("the watchdog did not reset the loop");
    board::exit(1)
}
