//! The board's interrupts: their numbers on the MPS2 AN385/AN386 images, their priorities, and
//! the dispatch from cortex-m-rt's `DefaultHandler` (no device crate supplies a vector table, so
//! every interrupt arrives there with its number).
//!
//! UART0 RX has the highest priority: under QEMU each transmitted byte is a system call, and a
//! long frame being sent must not hold up the bytes coming in.

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;

use crate::serial;
use crate::timer::Tick;

/// The interrupts the board uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(i16)]
pub enum Irq {
    /// UART0 receive.
    Uart0Rx = 0,
    /// UART0 transmit.
    Uart0Tx = 1,
    /// TIMER1: the wake-up tick.
    Timer1 = 9,
}

// SAFETY: the discriminants are the AN385/AN386 interrupt numbers (QEMU `hw/arm/mps2.c`).
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self as u16
    }
}

impl Irq {
    const ALL: [Irq; 3] = [Irq::Uart0Rx, Irq::Uart0Tx, Irq::Timer1];

    fn from_number(irqn: i16) -> Option<Self> {
        Self::ALL.into_iter().find(|&i| i as i16 == irqn)
    }

    /// NVIC priority (lower is more urgent; the M4 implements the top bits).
    fn priority(self) -> u8 {
        match self {
            Irq::Uart0Rx => 0x00,
            Irq::Uart0Tx | Irq::Timer1 => 0x80,
        }
    }
}

/// Set by the tick's handler, cleared by [`take_tick`].
static TICKED: AtomicBool = AtomicBool::new(false);

/// Whether the tick has fired since the last call.
pub fn take_tick() -> bool {
    TICKED.swap(false, Ordering::Relaxed)
}

/// Sets every priority, then unmasks the interrupts.
pub fn enable(nvic: &mut NVIC) {
    for irq in Irq::ALL {
        // SAFETY: priorities only order these handlers; no critical section depends on them.
        unsafe { nvic.set_priority(irq, irq.priority()) };
    }
    for irq in Irq::ALL {
        // SAFETY: each handler touches only state that exists before this call (see `dispatch`).
        unsafe { NVIC::unmask(irq) };
    }
}

/// Runs the handler of interrupt `irqn`; `false` if the board does not use it.
pub fn dispatch(irqn: i16, tick: Tick) -> bool {
    match Irq::from_number(irqn) {
        Some(Irq::Uart0Rx) => serial::on_rx_interrupt(),
        Some(Irq::Uart0Tx) => serial::on_tx_interrupt(),
        Some(Irq::Timer1) => {
            tick.clear_interrupt();
            TICKED.store(true, Ordering::Relaxed);
        }
        None => return false,
    }
    true
}
