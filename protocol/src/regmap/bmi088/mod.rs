//! The Bosch BMI088 inertial measurement unit: two dies in one package, each with its own
//! register map, chip select (SPI) or I2C address. [`accel`] is the accelerometer die (also
//! the temperature sensor and the sensor time), [`gyro`] the gyroscope die; [`convert`] turns
//! physical values into their register values; [`image`] is the 14-byte register image of one
//! sample the link carries; [`Die`] gives the access rules of either map.
//!
//! Sources ("DS" and "AN" below):
//! - datasheet BST-BMI088-DS001-14, revision 1.4 (September 2018): section 3 (quick start),
//!   4.1 (power modes), 4.2 (shadowing and bursts), 4.8 (soft reset), 5.2–5.5 (register maps and
//!   descriptions), 6.1 (SPI: the accelerometer's dummy byte and I2C → SPI switch), 6.2 (I2C
//!   addresses);
//! - application note "BMI08x FIFO usage", BST-BMI08x-AN002-01 (July 2018): every FIFO
//!   register of both dies (the datasheet only refers to it);
//! - where both are silent, Bosch's BMI08x sensor API (`bmi08_defs.h`: field masks of
//!   GYRO_RANGE 0x07, GYRO_BANDWIDTH 0x0F, gyro FIFO_CONFIG_0 tag bit 7 and FIFO_CONFIG_1
//!   data-select bits 1:0; `bmi08a.c`: a dummy read after each accelerometer soft reset).
//!
//! Where the documents disagree the choice is stated at the register: INT3_INT4_IO_CONF resets
//! to 0x0F (register map) although its bit table says 0; FIFO_WM_ENABLE resets to 0x08 (its
//! description) although the AN's overview says 0x00; an empty accelerometer FIFO reads
//! FIFO_LENGTH 0 (a 14-bit counter; the AN also says "an empty FIFO corresponds to 0x8000",
//! which the drivers mask away); ACC_PWR_CONF's "suspend" (DS 5.3.14) does not stop the
//! accelerometer: DS 3 and 4.1.1 make ACC_PWR_CTRL = 0x04 the switch to normal mode.
//!
//! Driver sequences these values serve were read (no code taken) in PX4
//! `src/drivers/imu/bosch/bmi088/` (`BMI088_Accelerometer.cpp`, `BMI088_Gyroscope.cpp`,
//! `Bosch_BMI088_*_Registers.hpp`), ArduPilot `AP_InertialSensor_BMI088.cpp` and the Rust
//! `bmi088` crate 0.2.1.
//!
//! ```
//! use margemu_protocol::regmap::bmi088::{accel, gyro, Die};
//! assert_eq!(Die::Accel.reset_value(accel::reg::CHIP_ID), 0x1E);
//! assert_eq!(Die::Gyro.reset_value(gyro::reg::CHIP_ID), 0x0F);
//! assert_eq!(Die::Accel.write_mask(accel::reg::ACC_RANGE), 0x03);
//! assert_eq!(Die::Gyro.reset_value(gyro::reg::BANDWIDTH), 0x80); // bit 7 reads 1
//! assert_eq!(accel::AccRange::from_reg(0x03), accel::AccRange::G24);
//! assert_eq!(gyro::Bandwidth::from_reg(0x82).odr_hz(), 1000);
//! ```

pub mod accel;
pub mod convert;
pub mod gyro;
pub mod image;

/// Which die of the package a register belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Die {
    /// The accelerometer (CSB1, I2C 0x18/0x19).
    Accel,
    /// The gyroscope (CSB2, I2C 0x68/0x69).
    Gyro,
}

impl Die {
    /// `(reset value, writable bits)` of a listed register; `None` for reserved addresses.
    const fn spec(self, addr: u8) -> Option<(u8, u8)> {
        match self {
            Self::Accel => accel::spec(addr),
            Self::Gyro => gyro::spec(addr),
        }
    }

    /// Whether the DS or the AN lists `addr`.
    pub const fn is_defined(self, addr: u8) -> bool {
        self.spec(addr).is_some()
    }

    /// The power-on (and soft-reset) value of `addr`; 0 for reserved addresses.
    pub const fn reset_value(self, addr: u8) -> u8 {
        match self.spec(addr) {
            Some((value, _)) => value,
            None => 0,
        }
    }

    /// The bits of `addr` a write stores; 0 for read-only and reserved registers.
    pub const fn write_mask(self, addr: u8) -> u8 {
        match self.spec(addr) {
            Some((_, mask)) => mask,
            None => 0,
        }
    }

    /// Whether `addr` is listed and read-only.
    pub const fn is_read_only(self, addr: u8) -> bool {
        matches!(self.spec(addr), Some((_, 0)))
    }

    /// The register a burst moves to after `addr`: the next one, wrapping at 0x7F, except on
    /// the die's FIFO_DATA port, which stays (AN 3.5.3, 4.5.10).
    pub const fn next_address(self, addr: u8) -> u8 {
        let port = match self {
            Self::Accel => accel::reg::FIFO_DATA,
            Self::Gyro => gyro::reg::FIFO_DATA,
        };
        if addr == port {
            addr
        } else {
            addr.wrapping_add(1) & 0x7F
        }
    }

    /// The CHIP_ID value at register 0x00.
    pub const fn chip_id(self) -> u8 {
        match self {
            Self::Accel => accel::CHIP_ID,
            Self::Gyro => gyro::CHIP_ID,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reserved_read_only_and_ports() {
        assert!(!Die::Accel.is_defined(0x01));
        assert!(Die::Accel.is_read_only(accel::reg::CHIP_ID));
        assert!(!Die::Accel.is_read_only(0x01));
        assert_eq!(Die::Gyro.write_mask(0x13), 0); // reserved (ArduPilot writes 0 there)
        assert_eq!(Die::Accel.next_address(0x26), 0x26);
        assert_eq!(Die::Accel.next_address(0x25), 0x26);
        assert_eq!(Die::Gyro.next_address(0x3F), 0x3F);
        assert_eq!(Die::Gyro.next_address(0x07), 0x08);
        assert_eq!(Die::Gyro.next_address(0x7F), 0x00);
        assert_eq!((Die::Accel.chip_id(), Die::Gyro.chip_id()), (0x1E, 0x0F));
    }
}
