//! Register-level tests of the emulated BMI088's two dies, driven through their SPI (and I2C)
//! front ends with byte literals, one file per behaviour, plus PX4's register sequences
//! (`px4.rs`).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned;
//! an accelerometer read has one dummy byte after the address byte
//! (`spi(&mut accel, &[0x80, 0x00, 0x00]) == [0x00, 0x00, 0x1E]`), a gyroscope read none.

#![allow(missing_docs)]

mod boundary;
mod bus;
mod data;
mod faults;
mod fifo;
mod px4;

#[path = "../common/transactions.rs"]
mod transactions;

pub use transactions::*;

use margemu_firmware::chip::bmi088::{Bmi088Accel, Bmi088Gyro};
use margemu_firmware::chip::{PhysicalSample, SpiTarget};

pub const MS: u64 = 1_000_000;
pub const G: f32 = 9.80665;

/// An accelerometer die switched to SPI by a dummy read, as every driver begins.
pub fn spi_accel() -> Bmi088Accel {
    let mut c = Bmi088Accel::new();
    dummy_read(&mut c);
    c
}

/// An accelerometer die in SPI mode, switched on (ACC_PWR_CONF active, ACC_PWR_CTRL on).
pub fn running_accel() -> Bmi088Accel {
    let mut c = spi_accel();
    spi_write(&mut c, 0x7C, &[0x00]);
    spi_write(&mut c, 0x7D, &[0x04]);
    c
}

/// The drivers' dummy read of ACC_CHIP_ID: one chip-select edge.
pub fn dummy_read(chip: &mut impl SpiTarget) {
    spi(chip, &[0x80, 0x00]);
}

/// Reads `n` accelerometer registers from `addr`, dropping the dummy byte (which must be 0x00).
pub fn aread(chip: &mut (impl SpiTarget + ?Sized), addr: u8, n: usize) -> Vec<u8> {
    let bytes = spi_read(chip, addr, n + 1);
    assert_eq!(bytes.first(), Some(&0x00), "dummy byte");
    bytes[1..].to_vec()
}

/// Reads one accelerometer register.
pub fn aread1(chip: &mut (impl SpiTarget + ?Sized), addr: u8) -> u8 {
    aread(chip, addr, 1)[0]
}

/// Reads one gyroscope register.
pub fn gread1(chip: &mut Bmi088Gyro, addr: u8) -> u8 {
    spi_read(chip, addr, 1)[0]
}

/// Little-endian i16 words of `bytes`.
pub fn words(bytes: &[u8]) -> Vec<i16> {
    bytes
        .chunks(2)
        .map(|w| i16::from_le_bytes([w[0], w[1]]))
        .collect()
}

/// A sample with accel in g and rates in °/s.
pub fn sample(acc_g: [f32; 3], gyr_dps: [f32; 3], temp_c: f32) -> PhysicalSample {
    PhysicalSample {
        acc: acc_g.map(|a| a * G),
        gyr: gyr_dps.map(f32::to_radians),
        temp_c,
        ..Default::default()
    }
}

/// Sample number `k` of a test stream: distinct on every axis, within ±3 g and ±125 °/s.
pub fn numbered(k: u32) -> PhysicalSample {
    let u = (k % 200) as f32 / 100.0 - 1.0; // −1 ..< 1
    sample(
        [u * 2.5, -u * 1.5, 1.0 + 0.5 * u],
        [u * 120.0, 60.0 - u * 50.0, -u * 7.0],
        30.0,
    )
}

/// Checks `got` against `physical · lsb_per_unit` within one LSB (saturating like the chip).
pub fn assert_within_1_lsb(got: i16, physical: f64, lsb_per_unit: f64, what: &str) {
    let want = (physical * lsb_per_unit).clamp(-32768.0, 32767.0);
    assert!(
        (f64::from(got) - want).abs() <= 1.0,
        "{what}: read {got}, expected {want:.2}"
    );
}

/// Accel sensitivity typed from DS 5.3.4's formula, independently of the crate's own.
pub fn acc_lsb_per_g(code: u8) -> f64 {
    32768.0 / (1.5 * f64::from(1u32 << (code + 1)))
}

/// Gyro sensitivity typed from DS table 5, independently of the crate's own.
pub fn gyr_lsb_per_dps(code: u8) -> f64 {
    [16.384, 32.768, 65.536, 131.072, 262.144][usize::from(code)]
}
