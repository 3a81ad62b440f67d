//! Register-level tests of the emulated QMC5883L, driven through [`I2cTarget`] with ArduPilot's
//! register sequence (`AP_Compass_QMC5883L.cpp`, re-described here from reading the driver, not
//! copied) and a driver that polls DRDY, as the Rust `qmc5883l` crate does.

#![allow(missing_docs)]

mod fc_ardupilot;
mod random_sequences;

#[path = "../common/transactions.rs"]
mod transactions;

pub use transactions::*;

use margemu_firmware::chip::{Chip, I2cTarget, Qmc5883l};

pub const MS: u64 = 1_000_000;
pub const ADDRESS: u8 = 0x0D;

/// The device loop: moves the chip's clock to `now_ns` without a new sample (the held field).
pub fn tick(mag: &mut Qmc5883l, now_ns: u64) {
    Chip::advance(mag, now_ns);
}

/// One register write over I2C, every byte acknowledged.
pub fn write_reg(mag: &mut impl I2cTarget, reg: u8, value: u8) {
    assert_eq!(i2c_write(mag, ADDRESS, &[reg, value]), [true; 3]);
}

/// A burst read over I2C from `reg`.
pub fn read_regs(mag: &mut impl I2cTarget, reg: u8, n: usize) -> Vec<u8> {
    i2c_read(mag, ADDRESS, reg, n).expect("address acknowledged")
}

/// A field sequence (µT, chip axes) sweeping every axis through both signs, inside ±8 G.
pub fn samples(n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let a = i as f32 * 0.41;
            [
                700.0 * a.sin(),
                -650.0 * a.cos(),
                60.0 * (0.5 * a).sin() - 45.0,
            ]
        })
        .collect()
}

/// Decodes 6 little-endian data bytes to µT at the 8 G range (30 LSB/µT).
pub fn decode_8g(bytes: &[u8]) -> [f32; 3] {
    core::array::from_fn(|i| f32::from(i16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]])) / 30.0)
}

/// Whether `got` is within one LSB (1/30 µT at 8 G) of `want` on every axis.
pub fn within_one_lsb(got: [f32; 3], want: [f32; 3]) -> bool {
    got.iter()
        .zip(want)
        .all(|(g, w)| (g - w).abs() <= 1.0 / 30.0 + 1e-3)
}
