//! The I2C and SPI target sides (DS §4.4, §4.5): a register address first, then data with
//! auto-increment. On SPI bit 7 of the address byte reads and MISO carries STATUS during it;
//! on I2C the first byte of a write sets the register pointer.

use margemu_protocol::regmap::rm3100::{next_address, reg};

use super::super::spi_phase::{SpiPhase, SpiRegisters};
use super::super::{Bus, I2cTarget, RegisterWrite, SpiTarget};
use super::Rm3100;

impl Rm3100 {
    /// Puts a write of the device under test in the write log.
    fn log_write(&mut self, bus: Bus, register: u8, value: u8) {
        let device = self.address;
        self.log.push(RegisterWrite {
            bus,
            device,
            register,
            value,
        });
    }
}

impl SpiRegisters for Rm3100 {
    fn prefetch(&mut self, addr: u8) -> u8 {
        self.peek(addr)
    }
    fn commit(&mut self, addr: u8, _value: u8) {
        self.commit_read(addr);
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.log_write(Bus::Spi, addr, value);
        self.write_byte(addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        next_address(addr)
    }
}

impl SpiTarget for Rm3100 {
    fn select(&mut self) -> u8 {
        self.spi = SpiPhase::Address;
        self.results_read = false;
        self.peek(reg::STATUS)
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        let phase = self.spi;
        if phase == SpiPhase::Address && mosi & 0x80 == 0 {
            self.clear_on_write(); // DRC0: at the address byte of a write
        }
        let (phase, miso) = phase.step(mosi, self);
        self.spi = phase;
        miso
    }

    fn deselect(&mut self) {
        self.spi = SpiPhase::Idle;
    }
}

impl I2cTarget for Rm3100 {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.addressed = address == self.address;
        self.expect_register = self.addressed && !read;
        self.results_read = false;
        self.addressed
    }

    fn write(&mut self, byte: u8) -> bool {
        if !self.addressed {
            return false;
        }
        if self.expect_register {
            self.expect_register = false;
            self.pointer = byte & 0x7F;
            return true;
        }
        self.clear_on_write(); // DRC0: at the first data byte (see the module docs)
        let addr = self.pointer;
        self.pointer = next_address(addr);
        self.log_write(Bus::I2c, addr, byte);
        self.write_byte(addr, byte)
    }

    fn read(&mut self) -> u8 {
        if !self.addressed {
            return 0xFF; // nobody drives SDA
        }
        let addr = self.pointer;
        self.pointer = next_address(addr);
        let value = self.peek(addr);
        self.commit_read(addr);
        value
    }

    fn stop(&mut self) {
        self.addressed = false;
        self.expect_register = false;
    }
}
