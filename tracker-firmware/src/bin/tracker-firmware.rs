//! The tracker firmware: serves the host link on UART0.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use tracker_firmware::{board, serve};

#[entry]
fn main() -> ! {
    let Some(device) = tracker_firmware::device() else {
        board::exit(1)
    };
    defmt::info!("{=str} up", tracker_firmware::DEVICE_CONFIG.firmware);
    // SAFETY: the only place UART0 and the watchdog are taken.
    let mut uart = unsafe { board::link_uart() };
    // One second a period at 25 MHz: reset after two seconds stuck. A scan's work is
    // about 15 ms of this clock.
    let mut watchdog = unsafe { board::CmsdkWatchdog::start(25_000_000) };
    serve(&mut uart, device, &mut watchdog)
}
