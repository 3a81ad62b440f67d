//! Register-level tests of the emulated IST8310, driven through [`I2cTarget`] with the register
//! sequences of two flight-controller drivers: ArduPilot `AP_Compass_IST8310.cpp`
//! (`fc_ardupilot.rs`) and PX4 `src/drivers/magnetometer/isentek/ist8310/` (`fc_px4.rs`). The
//! sequences are re-described here from reading those drivers, not copied.

#![allow(missing_docs)]

mod fc_ardupilot;
mod fc_px4;
mod random_sequences;

#[path = "../common/transactions.rs"]
mod transactions;

pub use transactions::*;

use margemu_firmware::chip::{Chip, I2cTarget, Ist8310};

pub const MS: u64 = 1_000_000;
pub const ADDRESS: u8 = 0x0E;

/// The device loop: moves the chip's clock to `now_ns` without a new sample (the held field).
pub fn tick(mag: &mut Ist8310, now_ns: u64) {
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

/// A field sequence (µT, chip axes) sweeping every axis through both signs, inside the range.
pub fn samples(n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let a = i as f32 * 0.37;
            [
                1500.0 * a.sin(),
                -1400.0 * a.cos(),
                2400.0 * (0.5 * a).sin() + 0.1,
            ]
        })
        .collect()
}

/// Decodes 6 little-endian data bytes to µT at 0.3 µT/LSB.
pub fn decode(bytes: &[u8]) -> [f32; 3] {
    core::array::from_fn(|i| f32::from(i16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]])) * 0.3)
}

/// Whether `got` is within one LSB (0.3 µT) of `want` on every axis.
pub fn within_one_lsb(got: [f32; 3], want: [f32; 3]) -> bool {
    got.iter()
        .zip(want)
        .all(|(g, w)| (g - w).abs() <= 0.3 + 1e-3)
}
