//! QEMU's mps2-an386 (Cortex-M4 with FPU): UART0 for the link, semihosting for logs and
//! exit codes.

use crate::uart::CmsdkUart;

/// Board name reported in the handshake.
pub const NAME: &str = "mps2-an386";

/// CMSDK UART0: the host link.
const UART0_BASE: usize = 0x4000_4000;

/// Takes UART0 for the link.
///
/// # Safety
/// Call once: the returned driver owns UART0.
pub unsafe fn link_uart() -> CmsdkUart {
    // 25 MHz / 16: QEMU ignores the rate, a real CMSDK UART would run at 1.5625 Mbd.
    CmsdkUart::new(UART0_BASE, 16)
}

/// Ends the program with an exit code the runner (QEMU) reports: 0 success, 1 failure.
pub fn exit(code: i32) -> ! {
    semihosting::process::exit(code)
}
