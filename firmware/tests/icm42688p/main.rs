//! Register-level tests of the emulated ICM-42688-P, driven through the bus-target traits with
//! byte literals, one file per behaviour, plus the register sequences of three flight-controller
//! drivers (`fc_*.rs`, on the reusable harness in `fc.rs`).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned:
//! `spi(&mut chip, &[0x80 | 0x75, 0x00]) == [0x00, 0x47]`.

#![allow(missing_docs)]

mod bus;
mod data;
mod fc;
mod fc_ardupilot;
mod fc_betaflight;
mod fc_px4;
mod fifo;
mod interrupts;
mod random_sequences;
mod resets;

use margemu_firmware::chip::{I2cTarget, Icm42688p, PhysicalSample, SpiTarget};

pub const MS: u64 = 1_000_000;
pub const US: u64 = 1_000;
pub const G: f32 = 9.80665;

/// A fresh ICM-42688-P.
pub fn chip() -> Icm42688p {
    Icm42688p::new()
}

/// A chip with gyro and accel in low-noise mode (PWR_MGMT0 = 0x0F), everything else at reset.
pub fn running() -> Icm42688p {
    let mut c = chip();
    spi_write(&mut c, 0x4E, &[0x0F]);
    c
}

/// One SPI transaction: MOSI bytes in, MISO bytes out, aligned byte for byte.
pub fn spi(chip: &mut impl SpiTarget, mosi: &[u8]) -> Vec<u8> {
    let mut miso = vec![chip.select()];
    for (i, &byte) in mosi.iter().enumerate() {
        let next = chip.exchange(byte);
        if i + 1 < mosi.len() {
            miso.push(next);
        }
    }
    chip.deselect();
    miso.truncate(mosi.len());
    miso
}

/// Reads `n` registers from `addr` over SPI.
pub fn spi_read(chip: &mut impl SpiTarget, addr: u8, n: usize) -> Vec<u8> {
    let mut mosi = vec![0x80 | addr];
    mosi.resize(n + 1, 0x00);
    spi(chip, &mosi)[1..].to_vec()
}

/// Writes `values` from `addr` on over SPI.
pub fn spi_write(chip: &mut impl SpiTarget, addr: u8, values: &[u8]) {
    let mut mosi = vec![addr];
    mosi.extend_from_slice(values);
    assert_eq!(
        spi(chip, &mosi),
        vec![0; mosi.len()],
        "MISO is 0x00 during writes"
    );
}

/// Selects a register bank (REG_BANK_SEL 0x76).
pub fn bank(chip: &mut impl SpiTarget, bank: u8) {
    spi_write(chip, 0x76, &[bank]);
}

/// An I2C write transaction; returns the ACK of the address and each byte.
pub fn i2c_write(chip: &mut impl I2cTarget, address: u8, bytes: &[u8]) -> Vec<bool> {
    let mut acks = vec![chip.start(address, false)];
    acks.extend(bytes.iter().map(|&b| chip.write(b)));
    chip.stop();
    acks
}

/// Register read over I2C: pointer, repeated START, `n` bytes, STOP; `None` without ACK.
pub fn i2c_read(chip: &mut impl I2cTarget, address: u8, reg: u8, n: usize) -> Option<Vec<u8>> {
    if !chip.start(address, false) {
        chip.stop();
        return None;
    }
    chip.write(reg);
    assert!(chip.start(address, true), "repeated START");
    let bytes = (0..n).map(|_| chip.read()).collect();
    chip.stop();
    Some(bytes)
}

/// A sample whose register values at ±16 g / ±2000 °/s are small integers: accel x = `n` LSB,
/// y = −2n, z = 1 g (2048); gyro x = n (at 16.4 LSB/(°/s)), y = 3, z = −n; 25 °C.
pub fn sample(n: i16) -> PhysicalSample {
    let n = f32::from(n);
    let dps = core::f32::consts::PI / 180.0;
    PhysicalSample {
        acc: [n * G / 2048.0, -2.0 * n * G / 2048.0, G],
        gyr: [n / 16.4 * dps, 3.0 / 16.4 * dps, -n / 16.4 * dps],
        mag: [0.0; 3],
        temp_c: 25.0,
    }
}
