//! The link on UART0, interrupt-driven: the RX interrupt moves each received byte into a ring
//! that the main loop drains, and the main loop queues whole frames into a TX ring that the TX
//! interrupt empties. Both rings are `heapless` single-producer single-consumer queues, so the
//! main loop and the handlers never block each other.
//!
//! - **RX.** [`on_rx_interrupt`] acknowledges the interrupt, then moves the received byte into
//!   the RX ring. A byte that finds the ring full is dropped and counted (`RX_DROPPED`); the
//!   link's CRC then rejects the frame it belonged to.
//! - **TX.** [`Serial::send`] queues a frame only if all of it fits (a frame cut short is worse
//!   than one left out: the host counts a lost frame by its sequence number), counts it in
//!   `TX_DROPPED` otherwise, and pends the TX interrupt. [`on_tx_interrupt`] writes bytes while
//!   the UART takes them. The main loop never waits for the line, so a host that stops reading
//!   cannot stall the serving of samples.

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::{self, Mutex};
use cortex_m::peripheral::NVIC;
use heapless::spsc::{Consumer, Producer, Queue};

use crate::irq::Irq;
use crate::uart::{Uart, UART0_BASE};

/// RX ring size (one slot stays empty): ~100 ms of the fastest RX QEMU delivers.
pub const RX_RING: usize = 4096;
/// TX ring size (one slot stays empty): a few of the largest frames.
pub const TX_RING: usize = 8192;

// SAFETY: UART0 is a CMSDK APB UART on this machine; only this module drives it.
const UART0: Uart = unsafe { Uart::new(UART0_BASE) };

static RX_PRODUCER: Mutex<RefCell<Option<Producer<'static, u8>>>> = Mutex::new(RefCell::new(None));
static TX_CONSUMER: Mutex<RefCell<Option<Consumer<'static, u8>>>> = Mutex::new(RefCell::new(None));
/// Received bytes dropped because the RX ring was full, since boot (for a debugger:
/// `print margemu_board_qemu_mps2_an386::serial::RX_DROPPED`).
static RX_DROPPED: AtomicU32 = AtomicU32::new(0);
/// Frames dropped because the TX ring had no room for them, since boot (as `RX_DROPPED`).
static TX_DROPPED: AtomicU32 = AtomicU32::new(0);

/// The main loop's ends of the two rings.
pub struct Serial {
    rx: Consumer<'static, u8>,
    tx: Producer<'static, u8>,
}

impl Serial {
    /// Sets UART0 up for `baud` at `pclk_hz` and hands the rings' other ends to the interrupt
    /// handlers ([`crate::irq::enable`] then unmasks them). `None` if called a second time.
    pub fn take(pclk_hz: u32, baud: u32) -> Option<Self> {
        let rx_ring = cortex_m::singleton!(: Queue<u8, RX_RING> = Queue::new())?;
        let tx_ring = cortex_m::singleton!(: Queue<u8, TX_RING> = Queue::new())?;
        let (rx_producer, rx) = rx_ring.split();
        let (tx, tx_consumer) = tx_ring.split();
        interrupt::free(|cs| {
            RX_PRODUCER.borrow(cs).replace(Some(rx_producer));
            TX_CONSUMER.borrow(cs).replace(Some(tx_consumer));
        });
        UART0.init(pclk_hz, baud);
        Some(Self { rx, tx })
    }

    /// Moves received bytes into `buf`; returns how many.
    pub fn read(&mut self, buf: &mut [u8]) -> usize {
        let mut n = 0;
        for slot in buf.iter_mut() {
            match self.rx.dequeue() {
                Some(b) => *slot = b,
                None => break,
            }
            n += 1;
        }
        n
    }

    /// Received bytes waiting.
    pub fn rx_len(&self) -> usize {
        self.rx.len()
    }

    /// Queues `frame` for sending if all of it fits; otherwise drops it and counts it.
    pub fn send(&mut self, frame: &[u8]) {
        let free = self.tx.capacity() - self.tx.len();
        if frame.len() > free {
            TX_DROPPED.fetch_add(1, Ordering::Relaxed);
            return;
        }
        for &b in frame {
            // Cannot fail: the space was checked, and only this end adds bytes.
            let _ = self.tx.enqueue(b);
        }
        NVIC::pend(Irq::Uart0Tx);
    }
}

/// UART0 RX interrupt: the received byte into the RX ring.
pub fn on_rx_interrupt() {
    UART0.clear_rx_interrupt();
    interrupt::free(|cs| {
        let mut producer = RX_PRODUCER.borrow(cs).borrow_mut();
        // No FIFO: the interrupt means one byte, and the next one raises it again.
        if let Some(b) = UART0.try_read_byte() {
            let stored = producer.as_mut().is_some_and(|p| p.enqueue(b).is_ok());
            if !stored {
                RX_DROPPED.fetch_add(1, Ordering::Relaxed);
            }
        }
    });
}

/// UART0 TX interrupt (also pended by [`Serial::send`]): bytes from the TX ring while the UART
/// takes them. Each byte is taken in a critical section of its own, so the RX interrupt (of
/// higher priority) is served between bytes: under QEMU every byte written is a system call.
pub fn on_tx_interrupt() {
    UART0.clear_tx_interrupt();
    loop {
        let next = interrupt::free(|cs| {
            let consumer = TX_CONSUMER.borrow(cs).borrow();
            consumer.as_ref().and_then(|c| c.peek().copied())
        });
        let Some(b) = next else { return };
        if !UART0.try_write_byte(b) {
            return; // the TX interrupt fires again when the buffer empties
        }
        interrupt::free(|cs| {
            if let Some(c) = TX_CONSUMER.borrow(cs).borrow_mut().as_mut() {
                c.dequeue();
            }
        });
    }
}
