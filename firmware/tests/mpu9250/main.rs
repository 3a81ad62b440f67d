//! Register-level tests of the emulated MPU-9250 + AK8963, driven through the bus-target traits
//! with byte literals, one file per behaviour of issue 4 item 1.
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned:
//! `spi(&mut chip, &[0x80 | 0x75, 0x00]) == [0x00, 0x71]`.

#![allow(missing_docs)]

mod accel_rate;
mod aux_master;
mod bus_i2c;
mod bus_spi;
mod data;
mod faults;
mod fifo;
mod interrupts;
mod magnetometer;
mod random_sequences;
mod resets;
mod write_log;

/// The 6xxx helpers (bench, flight-controller sequences, accel-rate helpers), by path.
#[path = "../common/mod.rs"]
mod common;
#[path = "../common/random_ops.rs"]
mod random_ops;
use common::transactions;
pub use common::transactions::*;

use margemu_firmware::chip::{Config, I2cTarget, Mpu6xxx, PhysicalSample, SpiTarget};

pub const MS: u64 = 1_000_000;

/// A fresh MPU-9250 with nominal fuse ROM values (ASA 128: adjustment factor 1).
pub fn chip() -> Mpu6xxx {
    Mpu6xxx::with_config(Config {
        asa: [128; 3],
        ..Config::default()
    })
}

/// The physical sample at rest, level, 25 °C, with a field of (20, 0, −40) µT.
pub fn at_rest() -> PhysicalSample {
    PhysicalSample {
        acc: [0.0, 0.0, 9.80665],
        gyr: [0.0; 3],
        mag: [20.0, 0.0, -40.0],
        temp_c: 25.0,
    }
}

/// Every MPU-9250 register as the bus would read it, without side effects.
pub fn registers(chip: &Mpu6xxx) -> Vec<u8> {
    (0..0x80).map(|a| chip.peek(a)).collect()
}
