//! The I2C target (DS: I2C interface): address 0x68 | AD0; the first byte written after a START
//! sets the register pointer, further bytes write and move it on; reads start at the pointer
//! and move it on (within the selected bank, not on FIFO_DATA), across repeated STARTs
//! ([`I2cPointer`]). A data sample waiting for the bus appears at STOP.
//! INTF_CONFIG0.UI_SIFS_CFG = 11 (I2C disabled, as PX4 sets it on SPI boards) makes the chip
//! ignore its address; UI_SIFS_CFG = 10 (SPI disabled) is stored only.

use margemu_protocol::regmap::icm42688p::{bank0, next_address};

use super::super::i2c_pointer::{I2cByte, I2cPointer};
use super::super::{Bus, I2cTarget};
use super::Icm42688p;

impl I2cTarget for Icm42688p {
    fn start(&mut self, address: u8, read: bool) -> bool {
        let i2c_disabled = self.peek(0, bank0::INTF_CONFIG0) & 0x03 == 0x03;
        let ours = address == self.i2c_address() && !i2c_disabled;
        self.i2c.start(ours, read)
    }

    fn write(&mut self, byte: u8) -> bool {
        match self.i2c.write(byte) {
            I2cByte::Refused => false,
            I2cByte::Pointer => true,
            I2cByte::Data(addr) => {
                self.write_register(Bus::I2c, addr, byte);
                self.i2c.move_to(next_address(self.bank(), addr));
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
        self.i2c.move_to(next_address(self.bank(), addr));
        value
    }

    fn stop(&mut self) {
        self.i2c.stop();
        self.bus_went_idle();
    }
}

/// The ICM-42688-P's I2C transaction state.
pub(super) type I2cState = I2cPointer;
