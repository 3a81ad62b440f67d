//! The I2C target protocol the register-file chips share: the first byte written after a
//! START to the chip's address sets the register pointer, further bytes are data for the
//! register it points at, reads start at the pointer, and the pointer survives repeated STARTs.
//! Where the pointer moves after each byte (the next register, or the same one on a port) is
//! the chip's: it calls [`I2cPointer::move_to`].

/// What a written byte is ([`I2cPointer::write`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum I2cByte {
    /// The chip is not addressed: not acknowledged.
    Refused,
    /// It set the register pointer.
    Pointer,
    /// Data for register `.0` (the pointer).
    Data(u8),
}

/// Where one chip's I2C target is in a transaction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct I2cPointer {
    /// Our address was acknowledged since the last START.
    addressed: bool,
    /// The next written byte is the register pointer.
    pointer_next: bool,
    pointer: u8,
    /// Between a START and the STOP.
    active: bool,
}

impl I2cPointer {
    /// Between a START and the STOP (to any address).
    pub(crate) fn is_active(self) -> bool {
        self.active
    }

    /// A START or repeated START; `ours`: the chip answers this address now. Returns the ACK.
    pub(crate) fn start(&mut self, ours: bool, read: bool) -> bool {
        self.active = true;
        self.addressed = ours;
        self.pointer_next = !read;
        ours
    }

    /// A byte written by the controller (7 bits of a pointer kept).
    pub(crate) fn write(&mut self, byte: u8) -> I2cByte {
        if !self.addressed {
            I2cByte::Refused
        } else if self.pointer_next {
            self.pointer = byte & 0x7F;
            self.pointer_next = false;
            I2cByte::Pointer
        } else {
            I2cByte::Data(self.pointer)
        }
    }

    /// The register a read takes its byte from; `None` when the chip is not addressed (nobody
    /// drives SDA).
    pub(crate) fn read(&self) -> Option<u8> {
        self.addressed.then_some(self.pointer)
    }

    /// Moves the pointer (after a byte, as the chip's burst order says).
    pub(crate) fn move_to(&mut self, addr: u8) {
        self.pointer = addr;
    }

    /// The chip stops acknowledging until the next START.
    pub(crate) fn release(&mut self) {
        self.addressed = false;
    }

    /// STOP.
    pub(crate) fn stop(&mut self) {
        self.addressed = false;
        self.active = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pointer_then_data_across_a_repeated_start() {
        let mut i2c = I2cPointer::default();
        assert!(i2c.start(true, false));
        assert_eq!(i2c.write(0xC1), I2cByte::Pointer);
        assert_eq!(i2c.write(0x55), I2cByte::Data(0x41));
        i2c.move_to(0x42);
        assert!(i2c.start(true, true));
        assert_eq!(i2c.read(), Some(0x42));
        i2c.release();
        assert_eq!((i2c.read(), i2c.write(0)), (None, I2cByte::Refused));
        i2c.stop();
        assert!(!i2c.is_active());
        assert!(!i2c.start(false, false));
        assert!(i2c.is_active());
    }
}
