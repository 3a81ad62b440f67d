//! The I2C target (PS-MPU-9250A-01 section 7.3): address 0x68 | AD0; the first byte written
//! after a START sets the register pointer, further bytes write and move it on; reads start at
//! the pointer and move it on (not on FIFO_R_W or MEM_R_W), across repeated STARTs. Pointer
//! bytes keep 7 bits. USER_CTRL.I2C_IF_DIS (and, on the ICM-20602, I2C_IF.I2C_IF_DIS) makes the
//! chip ignore its address until a reset.
//!
//! In bypass mode (INT_PIN_CFG.BYPASS_EN set, USER_CTRL.I2C_MST_EN clear) the AK8963 answers at
//! 0x0C; its register writes are logged like the MPU-9250's. A data sample waiting for the bus
//! appears at STOP.

use margemu_protocol::regmap::ak8963::I2C_ADDRESS as AK_ADDRESS;
use margemu_protocol::regmap::mpu6xxx::next_address;

use super::super::{Bus, I2cTarget};
use super::Mpu6xxx;

/// Which die the current I2C transaction addresses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Addressed {
    /// Nobody (not started, or the address was not acknowledged).
    #[default]
    None,
    /// The MPU-9250; `pointer_next` while the next written byte is the register pointer.
    Mpu { pointer_next: bool },
    /// The AK8963 in bypass mode.
    Ak,
}

/// I2C transaction state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct I2cState {
    addressed: Addressed,
    pointer: u8,
    /// Between a START and the STOP.
    active: bool,
}

impl I2cState {
    pub(super) fn is_active(self) -> bool {
        self.active
    }
}

impl I2cTarget for Mpu6xxx {
    fn start(&mut self, address: u8, read: bool) -> bool {
        self.i2c.active = true;
        let if_disabled = self.i2c_interface_disabled();
        self.i2c.addressed = if address == self.i2c_address() && !if_disabled {
            Addressed::Mpu {
                pointer_next: !read,
            }
        } else if address == AK_ADDRESS && self.bypass_active() {
            if let Some(ak) = &mut self.ak {
                ak.start(address, read);
            }
            Addressed::Ak
        } else {
            Addressed::None
        };
        self.i2c.addressed != Addressed::None
    }

    fn write(&mut self, byte: u8) -> bool {
        match self.i2c.addressed {
            Addressed::None => false,
            Addressed::Mpu { pointer_next: true } => {
                self.i2c.pointer = byte & 0x7F;
                self.i2c.addressed = Addressed::Mpu {
                    pointer_next: false,
                };
                true
            }
            Addressed::Mpu {
                pointer_next: false,
            } => {
                let addr = self.i2c.pointer;
                self.i2c.pointer = next_address(addr);
                self.write_register(Bus::I2c, addr, byte);
                true
            }
            Addressed::Ak => self.ak_bypass_write(byte),
        }
    }

    fn read(&mut self) -> u8 {
        match self.i2c.addressed {
            Addressed::None => 0xFF, // nobody drives SDA: the pull-up reads 1s
            Addressed::Mpu { .. } => {
                let addr = self.i2c.pointer;
                self.i2c.pointer = next_address(addr);
                let value = self.read_register(addr);
                self.commit_read(addr, value);
                value
            }
            Addressed::Ak => self.ak.as_mut().map_or(0xFF, |ak| ak.read()),
        }
    }

    fn stop(&mut self) {
        if let (Addressed::Ak, Some(ak)) = (self.i2c.addressed, &mut self.ak) {
            ak.stop();
        }
        self.i2c.addressed = Addressed::None;
        self.i2c.active = false;
        self.bus_went_idle();
    }
}

impl Mpu6xxx {
    fn ak_bypass_write(&mut self, byte: u8) -> bool {
        let Some(ak) = &mut self.ak else { return false };
        let pointer = ak.pointer();
        let was_data = ak.expects_data();
        ak.write(byte);
        if was_data {
            self.log_write(Bus::I2c, AK_ADDRESS, pointer, byte);
        }
        true
    }
}
