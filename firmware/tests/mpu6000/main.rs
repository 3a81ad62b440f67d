//! Register-level tests of the emulated MPU-6000 (RM-MPU-6000A-00 rev. 4.2, PS-MPU-6000A-00
//! rev. 3.4), driven through the bus-target traits with byte literals, and the Betaflight and
//! ArduPilot register sequences against it (`common::fc`).

#![allow(missing_docs)]

#[path = "../common/mod.rs"]
mod common;

mod accel_rate;
mod faults;
mod fc_sequences;
mod fifo;
mod identity;
mod registers;

use common::*;
use margemu_firmware::chip::{Mpu6xxx, Variant};

/// A fresh MPU-6000, woken with the PLL clock (PWR_MGMT_1 = 0x03) as every driver does.
pub fn awake() -> Mpu6xxx {
    let mut c = chip(Variant::Mpu6000);
    spi_write(&mut c, 0x6B, &[0x03]);
    c
}
