//! The primary I2C target (DS: 4.4 primary interface, 6.3 I2C interface): address 0x68, or
//! 0x69 with SDO high. The first byte written after a START sets the register pointer; further
//! bytes write and move it on; reads start at the pointer and move it on, across repeated
//! STARTs ([`I2cPointer`]). Bursts stay on the FIFO_DATA and INIT_DATA ports, so the `bmi2` crate's chunks of
//! the configuration file are one write each, as over SPI.
//!
//! Unlike SPI, an I2C read has **no dummy byte**: the first byte read is the addressed
//! register. The chip powers up (and resets) listening on I2C; once a chip-select rising edge
//! has switched it to SPI it no longer answers its I2C address, until a soft reset or a power
//! cycle (ArduPilot's driver quotes the datasheet: SPI "until a reset or the next power-up").
//! A soft reset written over I2C ends the transaction for the chip: the bytes after CMD = 0xB6
//! are not acknowledged. A data sample latched during a transaction appears at STOP.

use margemu_protocol::regmap::bmi270::next_address;

use super::super::i2c_pointer::{I2cByte, I2cPointer};
use super::super::{Bus, I2cTarget};
use super::Bmi270;

/// The BMI270's I2C transaction state.
pub(super) type I2cState = I2cPointer;

impl I2cTarget for Bmi270 {
    fn start(&mut self, address: u8, read: bool) -> bool {
        if !self.i2c.is_active() {
            self.i2c_resetting = false;
        }
        let ours = address == self.i2c_address() && !self.is_spi_mode() && !self.i2c_resetting;
        self.i2c.start(ours, read)
    }

    fn write(&mut self, byte: u8) -> bool {
        match self.i2c.write(byte) {
            I2cByte::Refused => false,
            I2cByte::Pointer => true,
            I2cByte::Data(addr) => {
                self.write_register(Bus::I2c, addr, byte);
                self.i2c.move_to(next_address(addr));
                if core::mem::take(&mut self.soft_reset_seen) {
                    self.i2c_resetting = true;
                    self.i2c.release();
                }
                true
            }
        }
    }

    fn read(&mut self) -> u8 {
        let Some(addr) = self.i2c.read() else {
            return 0xFF; // nobody drives SDA: the pull-up reads 1s
        };
        let value = self.read_register(addr);
        self.commit_read(addr, value);
        self.i2c.move_to(next_address(addr));
        value
    }

    fn stop(&mut self) {
        self.i2c.stop();
        self.i2c_resetting = false;
        self.bus_went_idle();
    }
}
