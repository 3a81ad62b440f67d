//! The emulated chip's INT output on PB0: level and driver type follow the chip
//! (`Chip::int_pin_at` and `Chip::int_open_drain`), updated by the main loop after every
//! device access. In open-drain mode the pin only pulls low; the flight controller's input
//! needs a pull-up (its own, or 10 kΩ to 3V3).

use stm32f4xx_hal::gpio::{Output, PushPull, PB0};
use stm32f4xx_hal::pac::{self, GPIOB};

const PIN: u32 = 0;

/// PB0 as the INT pin.
pub struct IntPin {
    level: Option<bool>,
    open_drain: bool,
}

impl IntPin {
    /// Takes PB0 (already an output) and drives it low, push-pull (the chip's power-on INT
    /// level: active high, not asserted).
    pub fn new(_pin: PB0<Output<PushPull>>) -> Self {
        let mut pin = Self {
            level: None,
            open_drain: false,
        };
        pin.set(false, false);
        pin
    }

    /// Drives `high` (or releases the line, for a high level in open-drain mode).
    pub fn set(&mut self, high: bool, open_drain: bool) {
        let gpio = regs();
        if open_drain != self.open_drain {
            let otyper = gpio.otyper().read().bits() & !(1 << PIN);
            gpio.otyper()
                .write(|w| unsafe { w.bits(otyper | u32::from(open_drain) << PIN) });
            self.open_drain = open_drain;
        }
        if self.level != Some(high) {
            let bit = if high { 1 << PIN } else { 1 << (PIN + 16) };
            gpio.bsrr().write(|w| unsafe { w.bits(bit) });
            self.level = Some(high);
        }
    }
}

fn regs() -> &'static pac::gpiob::RegisterBlock {
    // SAFETY: BSRR writes are atomic per pin and OTYPER is only written here, for PB0, which
    // this type owns; no other code changes GPIOB's OTYPER after set-up.
    unsafe { &*GPIOB::ptr() }
}
