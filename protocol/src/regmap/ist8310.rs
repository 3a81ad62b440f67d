//! The iSentek IST8310 3-axis magnetometer: register addresses, bits, reset values, operating
//! modes, averaging, measurement timing and the µT → register conversion.
//!
//! Sources: the iSentek IST8310 datasheet ("DS" below: register map, 0.3 µT/LSB, dynamic range
//! ±1600 µT on x and y and ±2500 µT on z, AVGCNTL "average by 16 times (ODRmax = 166 Hz)"), and
//! what the drivers rely on: ArduPilot `libraries/AP_Compass/AP_Compass_IST8310.cpp` (probe WAI,
//! SRST until CNTL2 bit 0 reads 0, AVGCNTL = 0x24, PDCNTL = 0xC0, then single measurements every
//! 10 ms, 6 data bytes from 0x03, values outside the range discarded) and PX4
//! `src/drivers/magnetometer/isentek/ist8310/` (`iSentek_IST8310_registers.hpp`, `IST8310.cpp`:
//! reads 7 bytes from STAT1 and requires STAT1.DRDY, waits at least 6 ms for a measurement with
//! 16 times averaging, re-reads its configured registers). Nothing is copied from them.
//!
//! The datasheet PDF was not at hand when this module was written: the DS facts above are as
//! the drivers and PX4's register header (which quotes DS field descriptions) give them, to be
//! checked against the PDF.
//!
//! Not from the datasheet (stated where used): the reset values of AVGCNTL and PDCNTL and the
//! measurement time for averaging other than 16 times.
//!
//! ```
//! use margemu_protocol::regmap::ist8310::{measurement, reg, Average, Mode, WAI_VALUE};
//! assert_eq!(WAI_VALUE, 0x10);
//! assert_eq!(reg::AVGCNTL, 0x41);
//! assert_eq!(Mode::from_cntl1(0x01), Mode::Single);
//! assert_eq!(Average::from_avgcntl(0x24), [Average::X16, Average::X16]);
//! assert_eq!(measurement([30.0, -0.3, 3000.0]), ([100, -1, 8333], true));
//! ```

use super::mpu6xxx::convert::round_saturate;

/// The IST8310's 7-bit I2C address as the drivers use it by default.
pub const I2C_ADDRESS: u8 = 0x0E;

/// Every 7-bit address the CAD0/CAD1 straps give, the default first (ArduPilot probes all four
/// for external compasses).
pub const I2C_ADDRESSES: [u8; 4] = [0x0E, 0x0C, 0x0D, 0x0F];

/// Bytes of one register image: the data registers ([`super::mag_image`]).
pub const IMAGE_LEN: usize = super::mag_image::IMAGE_LEN;

/// The value of WAI (DS register map; ArduPilot and PX4 probe it).
pub const WAI_VALUE: u8 = 0x10;

/// Register addresses (DS register map).
pub mod reg {
    /// Who Am I, 0x10.
    pub const WAI: u8 = 0x00;
    /// Status 1: DRDY, DOR.
    pub const STAT1: u8 = 0x02;
    /// X low byte (little endian).
    pub const DATAXL: u8 = 0x03;
    /// Z high byte.
    pub const DATAZH: u8 = 0x08;
    /// Status 2: INT.
    pub const STAT2: u8 = 0x09;
    /// Control 1: MODE.
    pub const CNTL1: u8 = 0x0A;
    /// Control 2: SRST, DRP, DREN.
    pub const CNTL2: u8 = 0x0B;
    /// Self-test: SELF_TEST.
    pub const STR: u8 = 0x0C;
    /// Control 3 (PX4's output-resolution bits; stored, not acted on).
    pub const CNTL3: u8 = 0x0D;
    /// Temperature low byte.
    pub const TEMPL: u8 = 0x1C;
    /// Temperature high byte.
    pub const TEMPH: u8 = 0x1D;
    /// Temperature compensation control.
    pub const TCCNTL: u8 = 0x40;
    /// Average control: y (5:3), x and z (2:0).
    pub const AVGCNTL: u8 = 0x41;
    /// Pulse duration control (7:6; 11 = normal, "please use this setting").
    pub const PDCNTL: u8 = 0x42;
}

/// Bits.
pub mod bits {
    /// STAT1: data ready.
    pub const STAT1_DRDY: u8 = 1 << 0;
    /// STAT1: data overrun (a measurement overwrote data that was never read).
    pub const STAT1_DOR: u8 = 1 << 1;
    /// CNTL1: mode field.
    pub const CNTL1_MODE: u8 = 0x0F;
    /// CNTL2: soft reset, the same routine as power-on reset; clears itself.
    pub const CNTL2_SRST: u8 = 1 << 0;
    /// CNTL2: DRDY pin polarity.
    pub const CNTL2_DRP: u8 = 1 << 2;
    /// CNTL2: DRDY pin enable.
    pub const CNTL2_DREN: u8 = 1 << 3;
    /// STR: self-test.
    pub const STR_SELF_TEST: u8 = 1 << 6;
    /// CNTL3: x, y, z 16-bit output bits (PX4).
    pub const CNTL3_XYZ_16BIT: u8 = 0x70;
    /// AVGCNTL: y averaging field.
    pub const AVGCNTL_Y: u8 = 0x38;
    /// AVGCNTL: x and z averaging field.
    pub const AVGCNTL_XZ: u8 = 0x07;
    /// AVGCNTL: both fields.
    pub const AVGCNTL_MASK: u8 = AVGCNTL_Y | AVGCNTL_XZ;
    /// PDCNTL: pulse duration field.
    pub const PDCNTL_PD: u8 = 0xC0;
}

/// Reset (power-on and SRST) values of the read/write registers.
pub mod reset {
    /// CNTL1: stand-by.
    pub const CNTL1: u8 = 0x00;
    /// CNTL2: DRDY pin disabled, SRST clear.
    pub const CNTL2: u8 = 0x00;
    /// AVGCNTL: no averaging. Assumption (both drivers overwrite it).
    pub const AVGCNTL: u8 = 0x00;
    /// PDCNTL: assumption (both drivers write 0xC0, "normal").
    pub const PDCNTL: u8 = 0x00;
}

/// Operating mode (CNTL1 bits 3:0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// 0000: stand-by.
    #[default]
    StandBy,
    /// 0001: one measurement, then stand-by (CNTL1 returns to 0).
    Single,
    /// Any other value: reserved, no measurement.
    Reserved,
}

impl Mode {
    /// The mode selected by a CNTL1 value.
    pub const fn from_cntl1(value: u8) -> Self {
        match value & bits::CNTL1_MODE {
            0x0 => Self::StandBy,
            0x1 => Self::Single,
            _ => Self::Reserved,
        }
    }
}

/// Number of internal samples averaged per output (one AVGCNTL field).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, PartialOrd, Ord)]
pub enum Average {
    /// 000: no averaging.
    #[default]
    X1,
    /// 001: 2 times.
    X2,
    /// 010: 4 times.
    X4,
    /// 011: 8 times.
    X8,
    /// 100 (and the reserved codes above it): 16 times.
    X16,
}

impl Average {
    /// The averaging of one 3-bit field.
    pub const fn from_field(field: u8) -> Self {
        match field & 0x07 {
            0 => Self::X1,
            1 => Self::X2,
            2 => Self::X4,
            3 => Self::X8,
            _ => Self::X16,
        }
    }

    /// `[y, xz]` averaging selected by an AVGCNTL value.
    pub const fn from_avgcntl(value: u8) -> [Self; 2] {
        [Self::from_field(value >> 3), Self::from_field(value)]
    }

    /// How many samples are averaged.
    pub const fn times(self) -> u32 {
        match self {
            Self::X1 => 1,
            Self::X2 => 2,
            Self::X4 => 4,
            Self::X8 => 8,
            Self::X16 => 16,
        }
    }
}

/// Measurement time with 16 times averaging: 1 / 166 Hz, rounded up to 6.1 ms (DS: "ODRmax =
/// 166 Hz"; PX4 waits "at least 6 ms").
pub const MEASUREMENT_16X_NS: u64 = 6_100_000;

/// Shortest measurement time (no averaging). Assumption: the datasheet gives only the 16-times
/// figure; shorter averaging shortens the measurement down to this floor.
pub const MEASUREMENT_MIN_NS: u64 = 1_000_000;

/// Time from CNTL1 = single to STAT1.DRDY for an AVGCNTL value: scaled by the larger of the two
/// averaging counts from [`MEASUREMENT_16X_NS`], never below [`MEASUREMENT_MIN_NS`].
pub const fn measurement_ns(avgcntl: u8) -> u64 {
    let [y, xz] = Average::from_avgcntl(avgcntl);
    let times = if y.times() > xz.times() {
        y.times()
    } else {
        xz.times()
    };
    let t = MEASUREMENT_16X_NS * times as u64 / 16;
    if t < MEASUREMENT_MIN_NS {
        MEASUREMENT_MIN_NS
    } else {
        t
    }
}

/// Sensitivity in µT per LSB (DS: 0.3).
pub const UT_PER_LSB: f32 = 0.3;

/// Dynamic range in µT of x, y and z (DS: ±1600, ±1600, ±2500).
pub const RANGE_UT: [f32; 3] = [1600.0, 1600.0, 2500.0];

/// The largest magnitude the data registers hold on x, y, z: the range in LSB (5333, 5333,
/// 8333), so ArduPilot's plausibility check (`|raw| ≤ range / 0.3 + 1`) passes clipped data.
pub const MAX_RAW: [i16; 3] = [5333, 5333, 8333];

/// The data registers for a field in µT in the chip's axes, and whether any axis clipped at
/// [`MAX_RAW`]. NaN reads 0.
pub fn measurement(field_ut: [f32; 3]) -> ([i16; 3], bool) {
    let mut raw = [0i16; 3];
    let mut clipped = false;
    for ((out, b), max) in raw.iter_mut().zip(field_ut).zip(MAX_RAW) {
        *out = round_saturate(b / UT_PER_LSB, -max, max);
        clipped |= out.unsigned_abs() >= max.unsigned_abs();
    }
    (raw, clipped)
}

/// The data registers DATAXL..=DATAZH of raw values (little endian): the chip's image.
pub fn data_bytes(raw: [i16; 3]) -> [u8; 6] {
    super::mag_image::emit(raw)
}

/// The field in µT (chip axes) raw data registers stand for.
pub fn field_ut(raw: [i16; 3]) -> [f64; 3] {
    raw.map(|v| f64::from(v) * f64::from(UT_PER_LSB))
}

/// The next register after `addr` in a burst: the address increments (the drivers' bursts
/// stay within 0x02..=0x08).
pub const fn next_address(addr: u8) -> u8 {
    addr.wrapping_add(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_and_averaging() {
        assert_eq!(Mode::from_cntl1(0x00), Mode::StandBy);
        assert_eq!(Mode::from_cntl1(0xF1), Mode::Single);
        assert_eq!(Mode::from_cntl1(0x03), Mode::Reserved);
        assert_eq!(Average::from_avgcntl(0x09), [Average::X2, Average::X2]);
        assert_eq!(Average::from_avgcntl(0x3F), [Average::X16, Average::X16]);
    }

    #[test]
    fn measurement_time_follows_the_larger_averaging() {
        assert_eq!(measurement_ns(0x24), 6_100_000);
        assert_eq!(measurement_ns(0x04), 6_100_000);
        assert_eq!(measurement_ns(0x18), 3_050_000);
        assert_eq!(measurement_ns(0x00), 1_000_000);
    }

    #[test]
    fn conversion_rounds_and_clips_per_axis() {
        assert_eq!(measurement([0.15, -0.15, 0.14]), ([1, -1, 0], false));
        assert_eq!(
            measurement([1599.9, -1600.0, 2499.0]).0,
            [5333, -5333, 8330]
        );
        assert_eq!(measurement([-2000.0, 0.0, f32::NAN]), ([-5333, 0, 0], true));
        assert_eq!(
            data_bytes([0x0102, -2, 0x7F00]),
            [0x02, 0x01, 0xFE, 0xFF, 0x00, 0x7F]
        );
    }
}
