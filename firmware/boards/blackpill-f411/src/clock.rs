//! Monotonic time base: TIM5, a 32-bit general-purpose up-counter, free-running at 8 MHz
//! (125 ns a tick) and extended to 64-bit nanoseconds by polling.
//!
//! The counter wraps every 2³² ticks (536.9 s at 8 MHz); [`Clock::now_ns`] adds the ticks since
//! its previous call, so it must be called at least once per wrap. The main loop calls it every
//! iteration.

use stm32f4xx_hal::pac::TIM5;
use stm32f4xx_hal::rcc::{Enable, Rcc, Reset};

/// Counter rate: a whole number of nanoseconds per tick.
const TICK_HZ: u32 = 8_000_000;

/// TIM5 as a 64-bit nanosecond clock.
pub struct Clock {
    tim: TIM5,
    tick_hz: u64,
    last: u32,
    ticks: u64,
}

impl Clock {
    /// Starts TIM5 from 0, counting at [`TICK_HZ`] from its kernel clock `timer_hz` (or as close
    /// as the 16-bit prescaler allows; the conversion uses the rate actually reached).
    pub fn start(tim: TIM5, rcc: &mut Rcc, timer_hz: u32) -> Self {
        TIM5::enable(rcc);
        TIM5::reset(rcc);
        let psc = (timer_hz / TICK_HZ).clamp(1, 1 << 16) - 1;
        tim.psc().write(|w| w.psc().set(psc as u16));
        tim.arr().write(|w| w.arr().set(u32::MAX));
        // UG loads the prescaler (it is buffered) and clears the counter.
        tim.egr().write(|w| w.ug().set_bit());
        tim.sr().write(|w| w.uif().clear_bit());
        tim.cr1().write(|w| w.cen().set_bit());
        Self {
            tim,
            tick_hz: u64::from(timer_hz / (psc + 1)),
            last: 0,
            ticks: 0,
        }
    }

    /// Nanoseconds since [`Clock::start`].
    pub fn now_ns(&mut self) -> u64 {
        let count = self.tim.cnt().read().bits();
        self.ticks += u64::from(count.wrapping_sub(self.last));
        self.last = count;
        const NS: u64 = 1_000_000_000;
        self.ticks / self.tick_hz * NS + self.ticks % self.tick_hz * NS / self.tick_hz
    }
}
