//! The tracker on an STM32F4DISCOVERY: STM32F407VG, Cortex-M4F at 168 MHz from the board's
//! 8 MHz crystal.
//!
//! The same device and main loop as under QEMU (`tracker_firmware::serve`); only the chip
//! differs. The host link is USART2 at 115,200 Bd, 8N1, on PA2 (TX) and PA3 (RX), which the
//! board's ST-LINK/V2-A brings out as a USB virtual COM port (`/dev/ttyACM0` on Linux).
//! Received bytes are taken by the USART2 interrupt into a 1 KiB queue, so a byte that
//! arrives while the loop works on a scan is kept, not overrun; a byte lost all the same is
//! reported to the loop as an error (the frame's CRC then rejects that frame alone). Logs are
//! defmt over RTT (`probe-rs run` shows them). The independent watchdog resets a loop stuck
//! for 2 s.
//!
//! LEDs: green blinks while the main loop runs (about 1 Hz when idle), orange toggles on
//! every frame received, red stays on once a received byte was lost.
#![no_std]
#![no_main]

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::Mutex;
use cortex_m_rt::entry;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};
use heapless::Deque;
use stm32f4xx_hal::gpio::{AnyPin, Output, PushPull};
use stm32f4xx_hal::pac::{self, interrupt, USART2};
use stm32f4xx_hal::prelude::*;
#[cfg(not(feature = "qemu"))]
use stm32f4xx_hal::rcc::Config;
use stm32f4xx_hal::serial::{Rx, Tx};
use stm32f4xx_hal::watchdog::IndependentWatchdog;
use tracker_firmware::{serve, Watchdog};

/// The host link's rate (the ST-LINK's virtual COM port follows the host's setting).
const BAUD: u32 = 115_200;

/// Received bytes waiting for the main loop: more than a largest frame.
const RX_QUEUE: usize = 1024;

type Led = AnyPin<Output<PushPull>>;

static RX: Mutex<RefCell<Option<Rx<USART2>>>> = Mutex::new(RefCell::new(None));
static QUEUE: Mutex<RefCell<Deque<u8, RX_QUEUE>>> = Mutex::new(RefCell::new(Deque::new()));
/// Bytes lost: the queue full, or the USART's own overrun, framing or noise errors.
static LOST: AtomicU32 = AtomicU32::new(0);

#[interrupt]
fn USART2() {
    cortex_m::interrupt::free(|cs| {
        let mut rx = RX.borrow(cs).borrow_mut();
        let Some(rx) = rx.as_mut() else {
            return;
        };
        let mut queue = QUEUE.borrow(cs).borrow_mut();
        loop {
            match rx.read() {
                Ok(byte) => {
                    if queue.push_back(byte).is_err() {
                        LOST.fetch_add(1, Ordering::Relaxed);
                    }
                }
                Err(nb::Error::WouldBlock) => break,
                Err(nb::Error::Other(_)) => {
                    // Reading the status and data registers has cleared the error.
                    LOST.fetch_add(1, Ordering::Relaxed);
                    break;
                }
            }
        }
    });
}

/// A byte was lost between the wire and the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Lost;

impl embedded_hal_nb::serial::Error for Lost {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Overrun
    }
}

/// The link as the main loop sees it: bytes from the interrupt's queue, bytes out through
/// USART2's transmitter, the LEDs kept.
struct Link {
    tx: Tx<USART2>,
    lost_seen: u32,
    frame_led: Led,
    error_led: Led,
}

impl ErrorType for Link {
    type Error = Lost;
}

impl Read<u8> for Link {
    fn read(&mut self) -> nb::Result<u8, Lost> {
        let lost = LOST.load(Ordering::Relaxed);
        if lost != self.lost_seen {
            self.lost_seen = lost;
            self.error_led.set_high();
            return Err(nb::Error::Other(Lost));
        }
        match cortex_m::interrupt::free(|cs| QUEUE.borrow(cs).borrow_mut().pop_front()) {
            Some(byte) => {
                // COBS ends every frame with a zero byte.
                if byte == 0 {
                    self.frame_led.toggle();
                }
                Ok(byte)
            }
            None => Err(nb::Error::WouldBlock),
        }
    }
}

impl Write<u8> for Link {
    fn write(&mut self, byte: u8) -> nb::Result<(), Lost> {
        // The transmitter reports no errors of its own; it only makes us wait.
        self.tx.write(byte).map_err(|e| e.map(|_| Lost))
    }

    fn flush(&mut self) -> nb::Result<(), Lost> {
        self.tx.flush().map_err(|e| e.map(|_| Lost))
    }
}

/// The independent watchdog, fed once per pass of the main loop, and the heartbeat LED.
struct Alive {
    iwdg: IndependentWatchdog,
    led: Led,
    passes: u32,
}

impl Watchdog for Alive {
    fn feed(&mut self) {
        self.iwdg.feed();
        self.passes = self.passes.wrapping_add(1);
        // An idle pass is a few dozen cycles: this blinks at about 1 Hz.
        if self.passes % 2_000_000 == 0 {
            self.led.toggle();
        }
    }
}

#[entry]
fn main() -> ! {
    let Some(dp) = pac::Peripherals::take() else {
        cortex_m::peripheral::SCB::sys_reset()
    };
    // QEMU's netduinoplus2 models no clock controller: there the chip runs from its reset
    // clock (HSI, 16 MHz), which needs no waiting for oscillators to settle.
    #[cfg(feature = "qemu")]
    let mut rcc = dp.RCC.constrain();
    #[cfg(not(feature = "qemu"))]
    let mut rcc = dp.RCC.freeze(Config::hse(8.MHz()).sysclk(168.MHz()));
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiod = dp.GPIOD.split(&mut rcc);
    let mut green = gpiod.pd12.into_push_pull_output().erase();
    let frame_led = gpiod.pd13.into_push_pull_output().erase();
    let mut error_led = gpiod.pd14.into_push_pull_output().erase();
    green.set_high();
    error_led.set_low();
    let Ok(serial) = dp
        .USART2
        .serial((gpioa.pa2, gpioa.pa3), BAUD.bps(), &mut rcc)
    else {
        defmt::error!("USART2 refused {=u32} Bd", BAUD);
        cortex_m::peripheral::SCB::sys_reset()
    };
    let (tx, mut rx) = serial.split();
    rx.listen();
    cortex_m::interrupt::free(|cs| *RX.borrow(cs).borrow_mut() = Some(rx));
    // SAFETY: the handler only touches RX and QUEUE, through critical sections.
    unsafe { cortex_m::peripheral::NVIC::unmask(pac::Interrupt::USART2) };

    let Some(device) = tracker_firmware::device() else {
        cortex_m::peripheral::SCB::sys_reset()
    };
    defmt::info!(
        "{=str} up, host link USART2 at {=u32} Bd",
        tracker_firmware::FIRMWARE,
        BAUD
    );
    let mut iwdg = IndependentWatchdog::new(dp.IWDG);
    iwdg.start(2_000.millis());
    let mut link = Link {
        tx,
        lost_seen: 0,
        frame_led,
        error_led,
    };
    let mut alive = Alive {
        iwdg,
        led: green,
        passes: 0,
    };
    serve(&mut link, device, &mut alive)
}
