//! The SPI target state machine (DS: SPI interface, 4-wire mode 0/3): the first byte after chip
//! select is `R/W̄ | address` (bit 7 set reads) in the bank REG_BANK_SEL selects; following
//! bytes are data; bursts move to the next register except on FIFO_DATA, which stays.
//!
//! Following the one-byte-ahead contract of [`SpiTarget`], [`SpiTarget::exchange`] returns the
//! *next* MISO byte, so a read is prefetched one byte before it is clocked out; its side
//! effects (FIFO pop, status clear) apply when the next exchange confirms the byte went out.
//! MISO is 0x00 during the address byte and during writes.

use margemu_protocol::regmap::icm42688p::next_address;

use super::super::{Bus, SpiTarget};
use super::Icm42688p;

/// Where the SPI transaction is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SpiPhase {
    /// Chip select released.
    Idle,
    /// Selected; the next byte is the address byte.
    Address,
    /// Reading; `value` of register `addr` was prefetched and is being clocked out.
    Read { addr: u8, value: u8 },
    /// Writing; the next byte goes to `addr`.
    Write { addr: u8 },
}

impl SpiPhase {
    pub(super) fn is_active(self) -> bool {
        self != Self::Idle
    }
}

impl SpiTarget for Icm42688p {
    fn select(&mut self) -> u8 {
        self.spi = SpiPhase::Address;
        0x00
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        match self.spi {
            SpiPhase::Idle => 0x00, // not selected: MISO is not driven
            SpiPhase::Address => {
                let addr = mosi & 0x7F;
                if mosi & 0x80 != 0 {
                    let value = self.read_register(addr);
                    self.spi = SpiPhase::Read { addr, value };
                    value
                } else {
                    self.spi = SpiPhase::Write { addr };
                    0x00
                }
            }
            SpiPhase::Read { addr, value } => {
                self.commit_read(addr, value);
                let addr = next_address(self.bank(), addr);
                let value = self.read_register(addr);
                self.spi = SpiPhase::Read { addr, value };
                value
            }
            SpiPhase::Write { addr } => {
                self.write_register(Bus::Spi, addr, mosi);
                self.spi = SpiPhase::Write {
                    addr: next_address(self.bank(), addr),
                };
                0x00
            }
        }
    }

    fn deselect(&mut self) {
        self.spi = SpiPhase::Idle;
        self.bus_went_idle();
    }
}
