//! The I2C target (DS: I2C interface): address 0x68 | AD0; the first byte written after a START
//! sets the register pointer, further bytes write and move it on; reads start at the pointer
//! and move it on (within the selected bank, not on FIFO_DATA), across repeated STARTs. A data
//! sample waiting for the bus appears at STOP. INTF_CONFIG0.UI_SIFS_CFG = 11 (I2C disabled, as
//! PX4 sets it on SPI boards) makes the chip ignore its address; UI_SIFS_CFG = 10 (SPI
//! disabled) is stored only.

use margemu_protocol::regmap::icm42688p::{bank0, next_address};

use super::super::{Bus, I2cTarget};
use super::Icm42688p;

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

impl I2cTarget for Icm42688p {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.i2c.active = true;
        let i2c_disabled = self.peek(0, bank0::INTF_CONFIG0) & 0x03 == 0x03;
        self.i2c.addressed = address == self.i2c_address() && !i2c_disabled;
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
            self.i2c.pointer = next_address(self.bank(), addr);
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
        self.i2c.pointer = next_address(self.bank(), addr);
        value
    }

    fn stop(&mut self) {
        self.i2c.addressed = false;
        self.i2c.active = false;
        self.bus_went_idle();
    }
}
