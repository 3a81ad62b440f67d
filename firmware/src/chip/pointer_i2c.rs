//! The I2C front end shared by the chips addressed through a register pointer (the IST8310 and
//! the QMC5883L): a write's first byte sets the pointer, the following bytes write registers
//! from it on, reads return registers from it on. A START to another address is not
//! acknowledged, and the bytes that follow it are ignored until the next START (the
//! [`I2cTarget`](super::I2cTarget) contract).
//!
//! ```
//! use margemu_firmware::chip::pointer_i2c::{PointerI2c, Step};
//! let mut bus = PointerI2c::default();
//! assert!(bus.start(true, false));
//! assert_eq!(bus.write(0x0A), Step::Pointer(0x0A));
//! assert_eq!(bus.write(0x01), Step::Data(0x01));
//! assert!(!bus.start(false, false)); // another address
//! assert_eq!(bus.write(0x0B), Step::Ignored);
//! assert!(!bus.may_read());
//! ```

/// What a written byte does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// The first byte of a write: the register pointer.
    Pointer(u8),
    /// A data byte, for the register at the pointer.
    Data(u8),
    /// Not addressed, or a read transaction: the byte is ignored.
    Ignored,
}

/// The state of the front end between bus events.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PointerI2c {
    state: State,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum State {
    /// No transaction addressed to this chip.
    #[default]
    Idle,
    /// A write whose pointer byte is due.
    WritePointer,
    /// A write past its pointer byte.
    WriteData,
    /// A read.
    Read,
}

impl PointerI2c {
    /// Idle: no transaction.
    pub const fn new() -> Self {
        Self { state: State::Idle }
    }

    /// A START or repeated START; `addressed`: the address is the chip's. Returns ACK.
    pub fn start(&mut self, addressed: bool, read: bool) -> bool {
        self.state = match (addressed, read) {
            (false, _) => State::Idle,
            (true, false) => State::WritePointer,
            (true, true) => State::Read,
        };
        addressed
    }

    /// A byte written by the controller.
    pub fn write(&mut self, byte: u8) -> Step {
        match self.state {
            State::WritePointer => {
                self.state = State::WriteData;
                Step::Pointer(byte)
            }
            State::WriteData => Step::Data(byte),
            State::Idle | State::Read => Step::Ignored,
        }
    }

    /// Whether a byte read now comes from the chip (an addressed read); otherwise nobody drives
    /// SDA and the controller reads 0xFF.
    pub fn may_read(&self) -> bool {
        self.state == State::Read
    }

    /// STOP.
    pub fn stop(&mut self) {
        self.state = State::Idle;
    }
}
