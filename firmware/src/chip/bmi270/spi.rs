//! The SPI target (DS: 6.2 SPI interface, mode 0/3) on the shared state machine ([`SpiPhase`]),
//! with the BMI270's two additions: the interface is I2C until a chip-select rising edge, and
//! every read clocks out one dummy byte before the data.
//!
//! The dummy byte is threaded through [`SpiRegisters`]: the first prefetch of a read returns the
//! dummy, its commit has no side effect and the burst stays on the addressed register for the
//! byte after it.

use margemu_protocol::regmap::bmi270::next_address;

use super::super::spi_phase::{SpiPhase, SpiRegisters};
use super::super::{Bus, SpiTarget};
use super::Bmi270;

/// The MISO value of the dummy byte (undefined in the DS).
pub(super) const DUMMY: u8 = 0x00;

/// Where a read is with respect to its dummy byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Dummy {
    /// The next prefetch is the dummy byte.
    Due,
    /// The dummy was prefetched and is being clocked out.
    Out,
    /// The dummy went out: the burst stays on the addressed register once.
    Hold,
    /// Data bytes.
    None,
}

impl SpiRegisters for Bmi270 {
    fn prefetch(&mut self, addr: u8) -> u8 {
        match self.dummy {
            Dummy::Due => {
                self.dummy = Dummy::Out;
                DUMMY
            }
            _ => {
                self.dummy = Dummy::None;
                self.read_register(addr)
            }
        }
    }
    fn commit(&mut self, addr: u8, value: u8) {
        match self.dummy {
            Dummy::Out => self.dummy = Dummy::Hold,
            _ => self.commit_read(addr, value),
        }
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.write_register(Bus::Spi, addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        match self.dummy {
            Dummy::Hold => addr,
            _ => next_address(addr),
        }
    }
}

impl SpiTarget for Bmi270 {
    fn select(&mut self) -> u8 {
        self.reset_in_transaction = false;
        self.dummy = Dummy::Due;
        // In I2C mode the SPI bytes are not decoded and MISO is not driven.
        self.spi = if self.spi_mode {
            SpiPhase::Address
        } else {
            SpiPhase::Idle
        };
        0x00
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        let (phase, miso) = self.spi.step(mosi, self);
        // A soft reset ends the transaction for the chip: what follows is not decoded.
        self.spi = if self.reset_in_transaction {
            SpiPhase::Idle
        } else {
            phase
        };
        miso
    }

    fn deselect(&mut self) {
        // The chip-select rising edge selects SPI, unless the chip was resetting.
        if !self.reset_in_transaction {
            self.spi_mode = true;
        }
        self.reset_in_transaction = false;
        self.spi = SpiPhase::Idle;
        self.dummy = Dummy::None;
        self.bus_went_idle();
    }
}
