//! CMSDK APB timers (ARM DDI0479C), clocked by PCLK (25 MHz): TIMER0 (`0x4000_0000`, IRQ 8) as
//! the polled time base, TIMER1 (`0x4000_1000`, IRQ 9) as the periodic wake-up tick.
//!
//! | offset | name      | bits                                                              |
//! |--------|-----------|-------------------------------------------------------------------|
//! | 0x00   | CTRL      | 0 enable, 1 external input as enable, 2 external clock, 3 IRQ en  |
//! | 0x04   | VALUE     | current value of the 32-bit down-counter                          |
//! | 0x08   | RELOAD    | value loaded when the counter reaches 0                           |
//! | 0x0C   | INTSTATUS | 0 interrupt (W1C)                                                 |
//!
//! The counter runs free from `0xFFFF_FFFF` (one wrap every ~171.8 s at 25 MHz). [`Timer::now_ns`]
//! adds the ticks elapsed since its previous call (wrapping subtraction of the down-counter), so
//! it must be called at least once per wrap period; the main loop calls it every iteration.
//! (The DWT cycle counter is not modelled by QEMU, hence a peripheral timer.)
//!
//! [`Tick`] counts down from `RELOAD` and raises its interrupt each time it reaches 0; its only
//! job is to wake the core from WFI in time for the next sample instant.

use core::ptr::{read_volatile, write_volatile};

/// Base address of TIMER0 on the MPS2 AN385/AN386 images.
pub const TIMER0_BASE: usize = 0x4000_0000;
/// Base address of TIMER1 on the MPS2 AN385/AN386 images.
pub const TIMER1_BASE: usize = 0x4000_1000;

const CTRL: usize = 0x00;
const VALUE: usize = 0x04;
const RELOAD: usize = 0x08;
const INTSTATUS: usize = 0x0C;

const CTRL_EN: u32 = 1 << 0;
const CTRL_IRQ_EN: u32 = 1 << 3;

/// A free-running CMSDK timer extended to a 64-bit nanosecond clock by polling.
pub struct Timer {
    base: usize,
    ns_per_tick_num: u64,
    ns_per_tick_den: u64,
    last: u32,
    ticks: u64,
}

impl Timer {
    /// Takes the timer at `base`, clocked at `pclk_hz`.
    ///
    /// # Safety
    ///
    /// `base` must be the base of a CMSDK APB timer, and nothing else may drive it while this
    /// value lives.
    pub const unsafe fn new(base: usize, pclk_hz: u32) -> Self {
        Self {
            base,
            ns_per_tick_num: 1_000_000_000,
            ns_per_tick_den: pclk_hz as u64,
            last: u32::MAX,
            ticks: 0,
        }
    }

    /// Starts the counter from `0xFFFF_FFFF`, free-running, interrupt off.
    pub fn start(&mut self) {
        self.write(CTRL, 0);
        self.write(RELOAD, u32::MAX);
        self.write(VALUE, u32::MAX);
        self.write(INTSTATUS, 1);
        self.last = u32::MAX;
        self.ticks = 0;
        self.write(CTRL, CTRL_EN);
    }

    /// Nanoseconds since [`Timer::start`] (monotonic while called at least once per wrap).
    pub fn now_ns(&mut self) -> u64 {
        let value = self.read(VALUE);
        self.ticks += u64::from(self.last.wrapping_sub(value));
        self.last = value;
        // 25 MHz: exactly 40 ns a tick; the general form stays exact for any PCLK.
        self.ticks / self.ns_per_tick_den * self.ns_per_tick_num
            + self.ticks % self.ns_per_tick_den * self.ns_per_tick_num / self.ns_per_tick_den
    }

    fn read(&self, offset: usize) -> u32 {
        // SAFETY: `new`'s contract: `base + offset` is a register of a CMSDK timer we own.
        unsafe { read_volatile((self.base + offset) as *const u32) }
    }

    fn write(&mut self, offset: usize, value: u32) {
        // SAFETY: as in `read`.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }
}

/// A CMSDK timer raising its interrupt periodically. A copy is only an address (the handler
/// acknowledges through its own copy).
#[derive(Clone, Copy)]
pub struct Tick {
    base: usize,
}

impl Tick {
    /// Takes the timer at `base`.
    ///
    /// # Safety
    ///
    /// `base` must be the base of a CMSDK APB timer driven only through copies of this value.
    pub const unsafe fn new(base: usize) -> Self {
        Self { base }
    }

    /// Starts the interrupt every `period_ticks` PCLK cycles (at least 2).
    pub fn start(&self, period_ticks: u32) {
        let reload = period_ticks.max(2) - 1;
        self.write(CTRL, 0);
        self.write(RELOAD, reload);
        self.write(VALUE, reload);
        self.write(INTSTATUS, 1);
        self.write(CTRL, CTRL_EN | CTRL_IRQ_EN);
    }

    /// Acknowledges the interrupt (from its handler; INTSTATUS is write-one-to-clear, so this
    /// cannot disturb the counter).
    pub fn clear_interrupt(&self) {
        self.write(INTSTATUS, 1);
    }

    fn write(&self, offset: usize, value: u32) {
        // SAFETY: `new`'s contract: `base + offset` is a register of a CMSDK timer.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }
}
