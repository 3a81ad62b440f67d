//! The Bosch BMI088 (datasheet BST-BMI088-DS001-14, "DS"; FIFO application note
//! BST-BMI08x-AN002-01, "AN"; register maps in [`margemu_protocol::regmap::bmi088`]) as its two
//! dies, each a bus target of its own: a board with two chip selects wires [`Bmi088Accel`] to
//! CSB1 and [`Bmi088Gyro`] to CSB2 (both serve [`SpiTarget`](super::SpiTarget) and
//! [`I2cTarget`](super::I2cTarget): accel 0x18/0x19, gyro 0x68/0x69 by the SDO pins).
//!
//! **Samples.** Each die samples at its own output rate: the board calls `latch_at` once per
//! `sample_period_ns()` of that die (`None` while the die produces nothing) with the same
//! [`PhysicalSample`](super::PhysicalSample) stream, and `advance` to move the die's clock
//! between samples. A latch converts through the shared `regmap` conversions at the range
//! configured now; when a transaction is in progress the data registers swap when it ends, so a
//! burst reads one sample (DS 4.2). The MSB lock between separate single-byte transactions is
//! not modelled.
//!
//! **Accelerometer** ([`Bmi088Accel`]): the SPI front end the BMI270 has (I2C until a
//! chip-select rising edge, again after a soft reset; one dummy byte before read data), the
//! accelerometer off until ACC_PWR_CTRL = 0x04 (registers keep their last data while off),
//! sensor time, temperature every 1.28 s, the 1 KB FIFO with 0x84 frames, INT1/INT2.
//! **Gyroscope** ([`Bmi088Gyro`]): plain SPI (no dummy byte), normal/suspend/deep-suspend
//! modes, the 100-frame FIFO, the data-ready pulse, INT3/INT4. Each module says what it does not
//! emulate.
//!
//! **The served part** ([`Bmi088`], [`package`]): both dies as one [`Chip`](super::Chip) of
//! model [`ChipModel::Bmi088`](margemu_protocol::chip::ChipModel::Bmi088), the accelerometer on
//! the package's own chip select and the gyroscope on the next one
//! ([`Bmi088::die_spi_target`]), both on I2C; images latch the gyro at the served rate and
//! the accel at its own ODR. Register file 0 is the accelerometer, file 1 the gyroscope
//! (`boundary.rs`).
//!
//! **Faults** (`faults.rs`): the [`Chip`](super::Chip) fault hooks on both dies — power
//! cycles, wrong CHIP_IDs, FIFOs forced to overflow.
//!
//! Driver sequences read (no code taken): PX4 `src/drivers/imu/bosch/bmi088/`
//! (`BMI088_Accelerometer.cpp`, `BMI088_Gyroscope.cpp`), ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_BMI088.cpp`, the Rust `bmi088` crate 0.2.1 and
//! Bosch's BMI08x sensor API.
//!
//! ```
//! use margemu_firmware::chip::bmi088::{Bmi088Accel, Bmi088Gyro};
//! use margemu_firmware::chip::{PhysicalSample, SpiTarget};
//! let spi = |chip: &mut dyn SpiTarget, bytes: &[u8]| -> Vec<u8> {
//!     let mut miso = vec![chip.select()];
//!     for b in bytes {
//!         miso.push(chip.exchange(*b));
//!     }
//!     chip.deselect();
//!     miso.truncate(bytes.len());
//!     miso
//! };
//! let (mut accel, mut gyro) = (Bmi088Accel::new(), Bmi088Gyro::new());
//! assert_eq!(spi(&mut accel, &[0x80, 0, 0]), [0, 0, 0]); // I2C mode: nothing driven
//! assert_eq!(spi(&mut accel, &[0x80, 0, 0]), [0, 0, 0x1E]); // dummy byte, ACC_CHIP_ID
//! assert_eq!(spi(&mut gyro, &[0x80, 0]), [0, 0x0F]); // no dummy byte
//! spi(&mut accel, &[0x7D, 0x04]); // ACC_PWR_CTRL: on
//! let sample = PhysicalSample { acc: [0.0, 0.0, 9.80665], gyr: [0.0, 0.0, 1.0], ..Default::default() };
//! accel.latch_at(&sample, accel.sample_period_ns().unwrap());
//! gyro.latch_at(&sample, gyro.sample_period_ns().unwrap());
//! assert_eq!(spi(&mut accel, &[0x80 | 0x16, 0, 0, 0])[2..], [0x55, 0x15]); // 5461 (±6 g)
//! assert_eq!(spi(&mut gyro, &[0x80 | 0x06, 0, 0])[1..], [0xAB, 0x03]); // 939 (±2000 °/s)
//! ```

pub mod accel;
pub mod accel_fifo;
mod boundary;
mod faults;
pub mod gyro;
pub mod gyro_fifo;
mod i2c;
pub mod package;

pub use accel::Bmi088Accel;
pub use gyro::Bmi088Gyro;
pub use package::{Bmi088, Config};

use margemu_protocol::regmap::bmi088::Die;

/// Capacity of each die's register write log (entries of 4 bytes).
pub const WRITE_LOG_LEN: usize = 64;

/// One die's 128 registers as stored (what reads compute from them lives in the die).
#[derive(Clone, Debug, PartialEq, Eq)]
struct Regs([u8; 128]);

impl Regs {
    /// Every register at its power-on value.
    fn power_on(die: Die) -> Self {
        let mut regs = Self([0; 128]);
        regs.reset(die);
        regs
    }

    fn reset(&mut self, die: Die) {
        for (addr, value) in (0u8..).zip(self.0.iter_mut()) {
            *value = die.reset_value(addr);
        }
    }

    fn get(&self, addr: u8) -> u8 {
        self.0.get(usize::from(addr)).copied().unwrap_or(0)
    }

    fn set(&mut self, addr: u8, value: u8) {
        if let Some(r) = self.0.get_mut(usize::from(addr)) {
            *r = value;
        }
    }

    /// Stores `value` through the die's write mask.
    fn write_masked(&mut self, die: Die, addr: u8, value: u8) {
        let mask = die.write_mask(addr);
        self.set(addr, (self.get(addr) & !mask) | (value & mask));
    }
}

/// Little-endian `values` into `out` (extra bytes or values are dropped).
fn put_le(out: &mut [u8], values: [i16; 3]) {
    for (slot, byte) in out
        .iter_mut()
        .zip(values.iter().flat_map(|v| v.to_le_bytes()))
    {
        *slot = byte;
    }
}

/// An interrupt pin's electrical level (`true` = high): `asserted` shown at the active level
/// `active_high`.
fn pin_level(asserted: bool, active_high: bool) -> bool {
    asserted == active_high
}
