//! Register-level tests of the emulated ICM-42688-P, driven through the bus-target traits with
//! byte literals, one file per behaviour, plus the register sequences of three flight-controller
//! drivers (`fc_*.rs`, on the reusable harness in `fc.rs`).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned:
//! `spi(&mut chip, &[0x80 | 0x75, 0x00]) == [0x00, 0x47]`.

#![allow(missing_docs)]

mod afsr;
mod bus;
mod data;
mod faults;
mod fc;
mod fc_ardupilot;
mod fc_betaflight;
mod fc_decoding;
mod fc_px4;
mod fifo;
mod interrupts;
mod random_sequences;
mod resets;

#[path = "../common/random_ops.rs"]
mod random_ops;
#[path = "../common/transactions.rs"]
mod transactions;

pub use fc::sample;
pub use transactions::*;

use margemu_firmware::chip::{I2cTarget, Icm42688p, PhysicalSample, SpiTarget};

pub const MS: u64 = 1_000_000;
pub const US: u64 = 1_000;

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

/// Selects a register bank (REG_BANK_SEL 0x76).
pub fn bank(chip: &mut impl SpiTarget, bank: u8) {
    spi_write(chip, 0x76, &[bank]);
}
