//! Register driver for the CMSDK APB UART (ARM DDI0479C, "Cortex-M System Design Kit TRM"), the
//! UART of the MPS2 FPGA images and of QEMU's `cmsdk-apb-uart` model. [`crate::serial`] drives it
//! from its interrupts.
//!
//! Registers, 32 bits each, at offsets from the base (UART0 of AN385/AN386 is at `0x4000_4000`,
//! RX IRQ 0, TX IRQ 1; the TX/RX overrun IRQs of UART0..2 are ORed onto IRQ 12):
//!
//! | offset | name      | bits                                                                   |
//! |--------|-----------|------------------------------------------------------------------------|
//! | 0x00   | DATA      | [7:0] write: transmit, read: received byte (clears RXFULL)             |
//! | 0x04   | STATE     | 0 TXFULL, 1 RXFULL, 2 TX overrun, 3 RX overrun (overrun bits are W1C)  |
//! | 0x08   | CTRL      | 0 TX enable, 1 RX enable, 2 TX int, 3 RX int, 4 TXO int, 5 RXO int     |
//! | 0x0C   | INTSTATUS | 0 TX, 1 RX, 2 TX overrun, 3 RX overrun (W1C)                           |
//! | 0x10   | BAUDDIV   | [19:0] PCLK / baud, at least 16 (QEMU ignores smaller values)          |
//!
//! There is no FIFO: one byte of buffer each way. The RX interrupt is raised when a byte arrives;
//! the TX interrupt when the transmit buffer empties (going from TXFULL to not full).
//!
//! Under QEMU (7.2, `hw/char/cmsdk-apb-uart.c`) the baud rate only reaches the host side as a
//! termios setting. A byte written to DATA goes straight to the chardev (one `write` system call
//! per byte), so TXFULL clears within the store unless the host side is full. RX takes one byte
//! per turn of QEMU's main loop: the chardev is offered a byte only while RXFULL is clear, and
//! reading DATA wakes the main loop for the next one, so the host side never overruns it.

use core::ptr::{read_volatile, write_volatile};

/// Base address of UART0 on the MPS2 AN385/AN386 images.
pub const UART0_BASE: usize = 0x4000_4000;

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const INTSTATUS: usize = 0x0C;
const BAUDDIV: usize = 0x10;

const STATE_TXFULL: u32 = 1 << 0;
const STATE_RXFULL: u32 = 1 << 1;
const STATE_TX_OVERRUN: u32 = 1 << 2;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;
const CTRL_TX_INT: u32 = 1 << 2;
const CTRL_RX_INT: u32 = 1 << 3;
const INT_TX: u32 = 1 << 0;
const INT_RX: u32 = 1 << 1;

/// The smallest divider the CMSDK UART accepts.
const BAUDDIV_MIN: u32 = 16;

/// One CMSDK APB UART. A copy is only an address: the receive half (DATA reads, INTSTATUS RX)
/// and the transmit half (DATA writes, INTSTATUS TX) touch disjoint bits, so the RX and TX
/// interrupt handlers each use their own copy.
#[derive(Clone, Copy)]
pub struct Uart {
    base: usize,
}

impl Uart {
    /// The UART at `base`.
    ///
    /// # Safety
    ///
    /// `base` must be the base of a CMSDK APB UART, driven only through copies of this value.
    pub const unsafe fn new(base: usize) -> Self {
        Self { base }
    }

    /// Sets the baud divider for `pclk_hz`/`baud` (8N1 is fixed), clears stale status, and
    /// enables TX and RX with their interrupts (the overrun interrupts stay off).
    pub fn init(&self, pclk_hz: u32, baud: u32) {
        let div = (pclk_hz / baud.max(1)).max(BAUDDIV_MIN);
        self.write(CTRL, 0);
        self.write(BAUDDIV, div);
        self.write(STATE, STATE_RX_OVERRUN | STATE_TX_OVERRUN);
        self.write(INTSTATUS, INT_TX | INT_RX);
        self.write(CTRL, CTRL_TX_EN | CTRL_RX_EN | CTRL_TX_INT | CTRL_RX_INT);
    }

    /// Acknowledges the RX interrupt. Call it before reading DATA, so that a byte arriving
    /// after the read raises the interrupt again.
    pub fn clear_rx_interrupt(&self) {
        self.write(INTSTATUS, INT_RX);
    }

    /// Acknowledges the TX interrupt.
    pub fn clear_tx_interrupt(&self) {
        self.write(INTSTATUS, INT_TX);
    }

    /// The received byte, if one is waiting.
    pub fn try_read_byte(&self) -> Option<u8> {
        if self.read(STATE) & STATE_RXFULL != 0 {
            Some(self.read(DATA) as u8)
        } else {
            None
        }
    }

    /// Sends `byte` if the transmit buffer is free; `false` if it is still full.
    pub fn try_write_byte(&self, byte: u8) -> bool {
        if self.read(STATE) & STATE_TXFULL != 0 {
            return false;
        }
        self.write(DATA, u32::from(byte));
        true
    }

    fn read(&self, offset: usize) -> u32 {
        // SAFETY: `new`'s contract: `base + offset` is a register of a CMSDK UART.
        unsafe { read_volatile((self.base + offset) as *const u32) }
    }

    fn write(&self, offset: usize, value: u32) {
        // SAFETY: as in `read`.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }
}
