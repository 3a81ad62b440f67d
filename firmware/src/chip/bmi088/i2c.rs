//! The I2C target of either die (DS 6.2): a write sets the register pointer with its first byte
//! and writes the following bytes from there on; a read (after a repeated START) returns bytes
//! from the pointer, which moves along the die's burst order (FIFO_DATA stays). Addresses other
//! than the die's are not acknowledged; the accelerometer stops answering once a chip-select
//! edge has switched it to SPI (until the next reset).

use super::super::I2cTarget;
use super::{Bmi088Accel, Bmi088Gyro};

/// Where an I2C transaction to the die is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum I2cPort {
    /// No transaction addressed to this die.
    #[default]
    Idle,
    /// Addressed for writing; the next byte is the register pointer.
    Pointer,
    /// Writing data to the register at `.0`.
    Write(u8),
    /// Reading; the pointer is at `.0`.
    Read(u8),
}

/// What the I2C target needs of a die.
pub(super) trait I2cRegisters {
    fn port(&mut self) -> &mut I2cPort;
    /// The register pointer as a previous transaction left it.
    fn pointer(&self) -> u8;
    fn set_pointer(&mut self, addr: u8);
    fn answers(&self, address: u8) -> bool;
    /// A byte read from `addr`, with its side effects.
    fn read_now(&mut self, addr: u8) -> u8;
    fn write_now(&mut self, addr: u8, value: u8);
    fn next(&self, addr: u8) -> u8;
    /// The transaction ended.
    fn i2c_idle(&mut self);
}

fn start(die: &mut impl I2cRegisters, address: u8, read: bool) -> bool {
    if !die.answers(address) {
        // A repeated START to another target ends this die's part of the transaction.
        stop(die);
        return false;
    }
    let pointer = die.pointer();
    *die.port() = if read {
        I2cPort::Read(pointer)
    } else {
        I2cPort::Pointer
    };
    true
}

fn write(die: &mut impl I2cRegisters, byte: u8) -> bool {
    match *die.port() {
        I2cPort::Pointer => {
            die.set_pointer(byte & 0x7F);
            *die.port() = I2cPort::Write(byte & 0x7F);
            true
        }
        I2cPort::Write(addr) => {
            die.write_now(addr, byte);
            let next = die.next(addr);
            die.set_pointer(next);
            *die.port() = I2cPort::Write(next);
            true
        }
        I2cPort::Idle | I2cPort::Read(_) => false,
    }
}

fn read(die: &mut impl I2cRegisters) -> u8 {
    let I2cPort::Read(addr) = *die.port() else {
        return 0xFF; // not addressed: the bus floats high
    };
    let value = die.read_now(addr);
    let next = die.next(addr);
    die.set_pointer(next);
    *die.port() = I2cPort::Read(next);
    value
}

fn stop(die: &mut impl I2cRegisters) {
    if *die.port() != I2cPort::Idle {
        *die.port() = I2cPort::Idle;
        die.i2c_idle();
    }
}

macro_rules! i2c_target {
    ($die:ty) => {
        impl I2cTarget for $die {
            fn start(&mut self, address: u8, read: bool) -> bool {
                start(self, address, read)
            }
            fn write(&mut self, byte: u8) -> bool {
                write(self, byte)
            }
            fn read(&mut self) -> u8 {
                read(self)
            }
            fn stop(&mut self) {
                stop(self)
            }
        }
    };
}

i2c_target!(Bmi088Accel);
i2c_target!(Bmi088Gyro);
