//! Register-level tests of the emulated BMI270, driven through its SPI front end with byte
//! literals, one file per behaviour, plus the sequences of the ArduPilot, Betaflight and `bmi2`
//! drivers (`drivers.rs`).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned;
//! a BMI270 read has one dummy byte after the address byte:
//! `spi(&mut chip, &[0x80, 0x00, 0x00]) == [0x00, 0x00, 0x24]`.

#![allow(missing_docs)]

mod boundary;
mod bus;
mod data;
mod drivers;
mod faults;
mod fc;
mod fifo;
mod i2c;
mod interrupts;
mod rates;
mod upload;

#[path = "../common/transactions.rs"]
mod transactions;

pub use transactions::*;

use margemu_firmware::chip::bmi270::Bmi270;
use margemu_firmware::chip::SpiTarget;

pub const MS: u64 = 1_000_000;

/// A BMI270 just powered on (still in I2C mode).
pub fn chip() -> Bmi270 {
    Bmi270::new()
}

/// A chip switched to SPI by a dummy read, as every driver begins.
pub fn spi_chip() -> Bmi270 {
    let mut c = chip();
    dummy_read(&mut c);
    c
}

/// A chip in SPI mode with the 328-byte configuration file uploaded: INTERNAL_STATUS init_ok,
/// the sensors run once PWR_CTRL enables them.
pub fn ready_chip() -> Bmi270 {
    let mut c = spi_chip();
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01, "init_ok");
    c
}

/// The drivers' dummy read of CHIP_ID: one chip-select edge.
pub fn dummy_read(chip: &mut impl SpiTarget) {
    spi(chip, &[0x80, 0x00]);
}

/// Reads `n` registers from `addr`, dropping the dummy byte (which must be 0x00).
pub fn read(chip: &mut impl SpiTarget, addr: u8, n: usize) -> Vec<u8> {
    let bytes = spi_read(chip, addr, n + 1);
    assert_eq!(bytes.first(), Some(&0x00), "dummy byte");
    bytes[1..].to_vec()
}

/// Reads one register.
pub fn read1(chip: &mut impl SpiTarget, addr: u8) -> u8 {
    read(chip, addr, 1)[0]
}

/// A stand-in configuration file of `len` bytes (its content does not matter to the chip).
pub fn config_file(len: usize) -> Vec<u8> {
    (0..len).map(|i| (i * 7 + 3) as u8).collect()
}

/// The upload every flight firmware does: PWR_CONF 0, INIT_CTRL 0, one burst, INIT_CTRL 1.
pub fn upload(chip: &mut impl SpiTarget, file: &[u8]) {
    spi_write(chip, 0x7C, &[0x00]);
    spi_write(chip, 0x59, &[0x00]);
    spi_write(chip, 0x5E, file);
    spi_write(chip, 0x59, &[0x01]);
}
