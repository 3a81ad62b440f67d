//! The primary I2C target (DS: 4.4 primary interface, 6.3 I2C interface): address 0x68, or
//! 0x69 with SDO high. The first byte written after a START sets the register pointer; further
//! bytes write and move it on; reads start at the pointer and move it on, across repeated
//! STARTs. Bursts stay on the FIFO_DATA and INIT_DATA ports, so the `bmi2` crate's chunks of
//! the configuration file are one write each, as over SPI.
//!
//! Unlike SPI, an I2C read has **no dummy byte**: the first byte read is the addressed
//! register. The chip powers up (and resets) listening on I2C; once a chip-select rising edge
//! has switched it to SPI it no longer answers its I2C address, until a soft reset or a power
//! cycle (ArduPilot's driver quotes the datasheet: SPI "until a reset or the next power-up").
//! A soft reset written over I2C ends the transaction for the chip: the bytes after CMD = 0xB6
//! are not acknowledged. A data sample latched during a transaction appears at STOP.

use margemu_protocol::regmap::bmi270::next_address;

use super::super::{Bus, I2cTarget};
use super::Bmi270;

/// I2C transaction state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct I2cState {
    /// Our address was acknowledged since the last START.
    addressed: bool,
    /// The next written byte is the register pointer.
    pointer_next: bool,
    pointer: u8,
    /// Between a START and the STOP.
    active: bool,
}

impl I2cState {
    pub(super) fn is_active(self) -> bool {
        self.active
    }
}

impl I2cTarget for Bmi270 {
    fn start(&mut self, address: u8, read: bool) -> bool {
        if !self.i2c.active {
            self.reset_in_transaction = false;
        }
        self.i2c.active = true;
        self.i2c.addressed =
            address == self.i2c_address() && !self.spi_mode && !self.reset_in_transaction;
        self.i2c.pointer_next = !read;
        self.i2c.addressed
    }

    fn write(&mut self, byte: u8) -> bool {
        if !self.i2c.addressed {
            return false;
        }
        if self.i2c.pointer_next {
            self.i2c.pointer = byte & 0x7F;
            self.i2c.pointer_next = false;
        } else {
            let addr = self.i2c.pointer;
            self.write_register(Bus::I2c, addr, byte);
            self.i2c.pointer = next_address(addr);
            if self.reset_in_transaction {
                self.i2c.addressed = false;
            }
        }
        true
    }

    fn read(&mut self) -> u8 {
        if !self.i2c.addressed {
            return 0xFF; // nobody drives SDA: the pull-up reads 1s
        }
        let addr = self.i2c.pointer;
        let value = self.read_register(addr);
        self.commit_read(addr, value);
        self.i2c.pointer = next_address(addr);
        value
    }

    fn stop(&mut self) {
        self.i2c.addressed = false;
        self.i2c.active = false;
        self.reset_in_transaction = false;
        self.bus_went_idle();
    }
}
