//! Emulated time for drivers' delays: a [`Clock`] in integer nanoseconds and a [`Delay`] that
//! advances it instead of sleeping.

use embedded_hal::delay::DelayNs;
use std::cell::Cell;
use std::rc::Rc;

/// An emulated clock in nanoseconds from an arbitrary origin. Clones share the same time.
#[derive(Clone, Debug, Default)]
pub struct Clock(Rc<Cell<u64>>);

impl Clock {
    /// A clock at 0 ns.
    pub fn new() -> Self {
        Self::default()
    }

    /// Current time (ns).
    pub fn now_ns(&self) -> u64 {
        self.0.get()
    }

    /// Moves time forward by `ns` (saturating at `u64::MAX`).
    pub fn advance_ns(&self, ns: u64) {
        self.0.set(self.0.get().saturating_add(ns));
    }
}

/// A `DelayNs` that returns at once; with a [`Clock`] it first advances the clock by the
/// requested time, so a bench can see how long a driver would have waited.
#[derive(Clone, Debug, Default)]
pub struct Delay {
    clock: Option<Clock>,
}

impl Delay {
    /// A delay that only returns.
    pub fn new() -> Self {
        Self::default()
    }

    /// A delay that advances `clock`.
    pub fn with_clock(clock: Clock) -> Self {
        Self { clock: Some(clock) }
    }

    /// The clock it advances, if any.
    pub fn clock(&self) -> Option<&Clock> {
        self.clock.as_ref()
    }

    fn wait(&mut self, ns: u64) {
        if let Some(clock) = &self.clock {
            clock.advance_ns(ns);
        }
    }
}

impl DelayNs for Delay {
    fn delay_ns(&mut self, ns: u32) {
        self.wait(u64::from(ns));
    }

    fn delay_us(&mut self, us: u32) {
        self.wait(u64::from(us) * 1_000);
    }

    fn delay_ms(&mut self, ms: u32) {
        self.wait(u64::from(ms) * 1_000_000);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delay_advances_its_clock_exactly() {
        let clock = Clock::new();
        let mut delay = Delay::with_clock(clock.clone());
        delay.delay_ns(7);
        delay.delay_us(3);
        delay.delay_ms(2);
        assert_eq!(clock.now_ns(), 7 + 3_000 + 2_000_000);
        delay.delay_ms(u32::MAX);
        assert_eq!(clock.now_ns(), 2_003_007 + u64::from(u32::MAX) * 1_000_000);
    }

    #[test]
    fn delay_without_clock_only_returns() {
        let mut delay = Delay::new();
        delay.delay_ms(1_000);
        assert!(delay.clock().is_none());
    }

    #[test]
    fn clock_saturates() {
        let clock = Clock::new();
        clock.advance_ns(u64::MAX - 1);
        clock.advance_ns(5);
        assert_eq!(clock.now_ns(), u64::MAX);
    }
}
