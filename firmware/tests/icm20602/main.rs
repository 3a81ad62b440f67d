//! Register-level tests of the emulated ICM-20602 (DS-000176 rev. 1.0): identity and reset
//! values, the registers it lacks (no auxiliary I2C master, no EXT_SENS_DATA, no DMP) and adds
//! (I2C_IF, FIFO_WM_TH, SELF_TEST_*_GYRO at 0x50), its FIFO, and PX4's 8 kHz FIFO reader
//! (`common::fc::px4_icm20602`) with its duplicated-accel check.

#![allow(missing_docs)]

#[path = "../common/mod.rs"]
mod common;

mod fifo;
mod px4;
mod registers;

use common::*;
use margemu_firmware::chip::{Mpu6xxx, Variant};

/// A fresh ICM-20602, woken with CLKSEL 1 as PX4 does.
pub fn awake() -> Mpu6xxx {
    let mut c = chip(Variant::Icm20602);
    spi_write(&mut c, 0x6B, &[0x01]);
    c
}
