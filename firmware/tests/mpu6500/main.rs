//! Register-level tests of the emulated MPU-6500 (RM-MPU-6500A-01 rev. 2.1): identity, reset
//! values, SIGNAL_PATH_RESET, the FIFO, and the accelerometer's own rate under every
//! FCHOICE_B / DLPF_CFG / ACCEL_FCHOICE_B setting (shared with the ICM-20602, which follows the
//! same tables).

#![allow(missing_docs)]

#[path = "../common/mod.rs"]
mod common;

mod accel_rate;
mod registers;
mod robustness;

use common::*;
use margemu_firmware::chip::{Mpu6xxx, Variant};
