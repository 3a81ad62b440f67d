//! Polled driver for the CMSDK APB UART (ARM DDI0479C, "Cortex-M System Design Kit TRM"), the
//! UART of the MPS2 FPGA images and of QEMU's `cmsdk-apb-uart` model.
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
//! There is no FIFO: one byte of buffer each way. Under QEMU the baud rate only reaches the
//! host side as a termios setting; bytes move as fast as the chardev takes them, and QEMU does
//! not accept a new RX byte until the guest has read DATA (no RX overrun from the host side).

use core::fmt;
use core::ptr::{read_volatile, write_volatile};

/// Base address of UART0 on the MPS2 AN385/AN386 images.
pub const UART0_BASE: usize = 0x4000_4000;

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;

const STATE_TXFULL: u32 = 1 << 0;
const STATE_RXFULL: u32 = 1 << 1;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;

/// The smallest divider the CMSDK UART accepts.
const BAUDDIV_MIN: u32 = 16;

/// One CMSDK APB UART, driven by polling (interrupts stay disabled).
pub struct Uart {
    base: usize,
}

impl Uart {
    /// Takes the UART at `base`.
    ///
    /// # Safety
    ///
    /// `base` must be the base of a CMSDK APB UART, and nothing else may drive it while this
    /// value lives.
    pub const unsafe fn new(base: usize) -> Self {
        Self { base }
    }

    /// Sets the baud divider for `pclk_hz`/`baud` (8N1 is fixed) and enables TX and RX, with
    /// every interrupt off.
    pub fn init(&mut self, pclk_hz: u32, baud: u32) {
        let div = (pclk_hz / baud.max(1)).max(BAUDDIV_MIN);
        self.write(CTRL, 0);
        self.write(BAUDDIV, div);
        self.write(STATE, STATE_RX_OVERRUN | (1 << 2));
        self.write(CTRL, CTRL_TX_EN | CTRL_RX_EN);
    }

    /// Waits until the transmit buffer is free, then sends `byte`.
    pub fn write_byte(&mut self, byte: u8) {
        self.flush();
        self.write(DATA, u32::from(byte));
    }

    /// Sends every byte of `bytes`.
    pub fn write_all(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_byte(b);
        }
    }

    /// Waits until the last byte written has left the transmit buffer.
    pub fn flush(&mut self) {
        while self.read(STATE) & STATE_TXFULL != 0 {}
    }

    /// The received byte, if one is waiting.
    pub fn try_read_byte(&mut self) -> Option<u8> {
        if self.read(STATE) & STATE_RXFULL != 0 {
            Some(self.read(DATA) as u8)
        } else {
            None
        }
    }

    /// Waits for a received byte.
    #[allow(dead_code)] // the link loop polls with `try_read_byte`
    pub fn read_byte(&mut self) -> u8 {
        loop {
            if let Some(b) = self.try_read_byte() {
                return b;
            }
        }
    }

    /// Whether a received byte was overwritten before it was read; clears the flag.
    #[allow(dead_code)] // QEMU never overruns RX; for a board with a faster host
    pub fn take_rx_overrun(&mut self) -> bool {
        let overrun = self.read(STATE) & STATE_RX_OVERRUN != 0;
        if overrun {
            self.write(STATE, STATE_RX_OVERRUN);
        }
        overrun
    }

    fn read(&self, offset: usize) -> u32 {
        // SAFETY: `new`'s contract: `base + offset` is a register of a CMSDK UART we own.
        unsafe { read_volatile((self.base + offset) as *const u32) }
    }

    fn write(&mut self, offset: usize, value: u32) {
        // SAFETY: as in `read`.
        unsafe { write_volatile((self.base + offset) as *mut u32, value) }
    }
}

impl fmt::Write for Uart {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.write_all(s.as_bytes());
        Ok(())
    }
}
