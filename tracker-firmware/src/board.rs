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

/// CMSDK APB watchdog (QEMU models it on mps2-an386 at 0x4000_8000).
const WATCHDOG_BASE: usize = 0x4000_8000;

/// The CMSDK APB watchdog: counts down from LOAD at the 25 MHz system clock; at zero it
/// raises its interrupt and reloads; reaching zero again with the interrupt still pending
/// resets the chip. Feeding clears the interrupt and reloads, so a loop that stops feeding
/// is reset after twice the period.
pub struct CmsdkWatchdog {
    base: usize,
}

impl CmsdkWatchdog {
    const LOAD: usize = 0x000;
    const CONTROL: usize = 0x008;
    const INTCLR: usize = 0x00C;
    const LOCK: usize = 0xC00;
    const UNLOCK_KEY: u32 = 0x1ACC_E551;

    /// Starts the watchdog with `ticks` of the 25 MHz clock per period (reset after two).
    ///
    /// # Safety
    /// Call once: the returned driver owns the watchdog.
    pub unsafe fn start(ticks: u32) -> Self {
        let w = CmsdkWatchdog {
            base: WATCHDOG_BASE,
        };
        w.write(Self::LOCK, Self::UNLOCK_KEY);
        w.write(Self::LOAD, ticks.max(1));
        // INTEN | RESEN.
        w.write(Self::CONTROL, 0b11);
        w.write(Self::LOCK, 0);
        w
    }

    fn write(&self, offset: usize, value: u32) {
        // SAFETY: `start` was given the watchdog's register block, owned by this driver.
        unsafe { core::ptr::write_volatile((self.base + offset) as *mut u32, value) }
    }
}

impl crate::Watchdog for CmsdkWatchdog {
    fn feed(&mut self) {
        self.write(Self::LOCK, Self::UNLOCK_KEY);
        self.write(Self::INTCLR, 1);
        self.write(Self::LOCK, 0);
    }
}
