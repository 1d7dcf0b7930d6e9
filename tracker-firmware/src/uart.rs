//! Driver for the ARM CMSDK APB UART (QEMU's mps2 boards), behind the `embedded-hal-nb`
//! serial traits so a real board's HAL UART can take its place in [`crate::serve`].
//!
//! Registers (CMSDK APB UART TRM): DATA 0x00, STATE 0x04 (bit 0 TX full, bit 1 RX full,
//! bit 2 TX overrun, bit 3 RX overrun; write 1 to clear an overrun), CTRL 0x08 (bit 0 TX
//! enable, bit 1 RX enable), BAUDDIV 0x10 (must be at least 16).

use core::ptr::{read_volatile, write_volatile};
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;

/// One CMSDK UART.
pub struct CmsdkUart {
    base: usize,
}

impl CmsdkUart {
    /// Enables the UART at `base` for TX and RX with the given clock divider.
    ///
    /// # Safety
    /// `base` must be a CMSDK UART's register block, and nothing else may use it.
    pub unsafe fn new(base: usize, bauddiv: u32) -> Self {
        let uart = CmsdkUart { base };
        uart.write_reg(BAUDDIV, bauddiv.max(16));
        uart.write_reg(CTRL, CTRL_TX_EN | CTRL_RX_EN);
        // QEMU re-polls its character backend only on a DATA read: without this read the
        // first frame from the host waits about a second.
        let _ = uart.read_reg(DATA);
        uart
    }

    fn read_reg(&self, offset: usize) -> u32 {
        // SAFETY: `new` was given a valid, exclusively owned register block.
        unsafe { read_volatile((self.base + offset) as *const u32) }
    }

    fn write_reg(&self, offset: usize, value: u32) {
        // SAFETY: as in `read_reg`.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }
}

impl ErrorType for CmsdkUart {
    type Error = ErrorKind;
}

impl Read<u8> for CmsdkUart {
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        let state = self.read_reg(STATE);
        if state & STATE_RX_OVERRUN != 0 {
            self.write_reg(STATE, STATE_RX_OVERRUN);
            return Err(nb::Error::Other(ErrorKind::Overrun));
        }
        if state & STATE_RX_FULL == 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(self.read_reg(DATA) as u8)
    }
}

impl Write<u8> for CmsdkUart {
    fn write(&mut self, byte: u8) -> nb::Result<(), ErrorKind> {
        if self.read_reg(STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        self.write_reg(DATA, u32::from(byte));
        Ok(())
    }

    fn flush(&mut self) -> nb::Result<(), ErrorKind> {
        if self.read_reg(STATE) & STATE_TX_FULL != 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(())
    }
}
