//! The tracker firmware: serves the host link on UART0.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use tracker_core::device::Device;
use tracker_firmware::{board, device_config, serve};

#[entry]
fn main() -> ! {
    let config = device_config();
    defmt::info!(
        "{=str} up, boot id {=u32:#010x}",
        config.firmware,
        config.boot_id
    );
    // SAFETY: the only place UART0 is taken.
    let mut uart = unsafe { board::link_uart() };
    // In .bss rather than on the stack, so the RAM report counts it.
    let device: &'static mut Device =
        cortex_m::singleton!(: Device = Device::new(config)).unwrap_or_else(|| board::exit(1));
    serve(&mut uart, device)
}
