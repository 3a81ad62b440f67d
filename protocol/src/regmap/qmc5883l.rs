//! The QST QMC5883L 3-axis magnetometer: register addresses, bits, identity values, CONF1 fields
//! (mode, output rate, range, over-sampling), CONF2 (soft reset, pointer roll-over) and the
//! µT → register conversion.
//!
//! Sources: the QST QMC5883L datasheet ("DS" below: register map 00H–0DH, STATUS bits DRDY,
//! OVL, DOR, reset by reading any data register; ranges ±2 G and ±8 G at 12000 and 3000 LSB/G;
//! ODR 10/50/100/200 Hz; SET/RESET period 0x01 recommended; ROL_PNT rolls the pointer over
//! 00H–06H), and what the drivers rely on: ArduPilot `libraries/AP_Compass/AP_Compass_QMC5883L.cpp`
//! (reads 0x00 once, requires 0x0C = 0x01 and 0x0D = 0xFF, writes 0x0B = 0x01, 0x20 = 0x40,
//! 0x21 = 0x01, CONF1 = continuous, 100 Hz, OSR 512, 8 G; every 10 ms reads STATUS and reads the
//! 6 data bytes only if bit 2 is set) and the Rust `qmc5883l` crate (register and bit names).
//! Nothing is copied from them.
//!
//! The datasheet PDF was not at hand when this module was written: the DS facts above are as
//! recalled and as driver headers (the Rust `qmc5883l` crate and other open-source QMC5883L
//! drivers) name them (STATUS bit 0 DRDY, bit 1 OVL, bit 2 DOR), to be checked against the PDF.
//!
//! Not from the datasheet (stated where used): where the output clips (full scale, ±24000 LSB
//! in both ranges) and when the first continuous measurement completes.
//!
//! ```
//! use margemu_protocol::regmap::qmc5883l::{measurement, reg, Odr, Range, CHIP_ID_VALUE};
//! assert_eq!((reg::CHIP_ID, CHIP_ID_VALUE), (0x0D, 0xFF));
//! assert_eq!(Odr::from_conf1(0x19), Odr::Hz100);
//! assert_eq!(Range::from_conf1(0x19), Range::Gauss8);
//! // 50 µT = 0.5 G at 3000 LSB/G.
//! assert_eq!(measurement([50.0, 0.0, -400.0], Range::Gauss8), ([1500, 0, -12000], false));
//! ```

use super::mpu6xxx::convert::round_saturate;

/// The QMC5883L's 7-bit I2C address.
pub const I2C_ADDRESS: u8 = 0x0D;

/// Bytes of one register image: the data registers ([`super::mag_image`], at the range the
/// image was computed for).
pub const IMAGE_LEN: usize = super::mag_image::IMAGE_LEN;

/// The value of the chip ID register 0x0D (DS register map).
pub const CHIP_ID_VALUE: u8 = 0xFF;

/// The value of the reserved register 0x0C, which ArduPilot requires.
pub const REG_0C_VALUE: u8 = 0x01;

/// Register addresses (DS register map).
pub mod reg {
    /// X low byte (little endian).
    pub const XOUT_L: u8 = 0x00;
    /// Z high byte.
    pub const ZOUT_H: u8 = 0x05;
    /// Status: DRDY, OVL, DOR.
    pub const STATUS: u8 = 0x06;
    /// Temperature low byte.
    pub const TOUT_L: u8 = 0x07;
    /// Temperature high byte.
    pub const TOUT_H: u8 = 0x08;
    /// Control 1: OSR, RNG, ODR, MODE.
    pub const CONF1: u8 = 0x09;
    /// Control 2: SOFT_RST, ROL_PNT, INT_ENB.
    pub const CONF2: u8 = 0x0A;
    /// SET/RESET period (FBR).
    pub const PERIOD: u8 = 0x0B;
    /// Reserved, reads 0x01.
    pub const RESERVED_0C: u8 = 0x0C;
    /// Chip ID, 0xFF.
    pub const CHIP_ID: u8 = 0x0D;
    /// Undocumented register ArduPilot writes 0x40 to (stored, read back).
    pub const UNDOC_20: u8 = 0x20;
    /// Undocumented register ArduPilot writes 0x01 to (stored, read back).
    pub const UNDOC_21: u8 = 0x21;
}

/// Bits.
pub mod bits {
    /// STATUS: data ready.
    pub const STATUS_DRDY: u8 = 1 << 0;
    /// STATUS: overflow (an axis outside the range).
    pub const STATUS_OVL: u8 = 1 << 1;
    /// STATUS: data skipped (a measurement overwrote unread data).
    pub const STATUS_DOR: u8 = 1 << 2;
    /// CONF1: mode field (00 standby, 01 continuous).
    pub const CONF1_MODE: u8 = 0x03;
    /// CONF1: output data rate field.
    pub const CONF1_ODR: u8 = 0x0C;
    /// CONF1: range field.
    pub const CONF1_RNG: u8 = 0x30;
    /// CONF1: over-sampling ratio field.
    pub const CONF1_OSR: u8 = 0xC0;
    /// CONF2: interrupt pin disabled (INT_ENB).
    pub const CONF2_INT_ENB: u8 = 1 << 0;
    /// CONF2: pointer roll-over over 00H–06H.
    pub const CONF2_ROL_PNT: u8 = 1 << 6;
    /// CONF2: soft reset (every register to its default).
    pub const CONF2_SOFT_RST: u8 = 1 << 7;
}

/// Operating mode (CONF1 bits 1:0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// 00: standby.
    #[default]
    Standby,
    /// 01: continuous measurement at the ODR.
    Continuous,
    /// 10, 11: reserved, no measurement.
    Reserved,
}

impl Mode {
    /// The mode selected by a CONF1 value.
    pub const fn from_conf1(value: u8) -> Self {
        match value & bits::CONF1_MODE {
            0 => Self::Standby,
            1 => Self::Continuous,
            _ => Self::Reserved,
        }
    }
}

/// Output data rate (CONF1 bits 3:2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Odr {
    /// 00: 10 Hz.
    #[default]
    Hz10,
    /// 01: 50 Hz.
    Hz50,
    /// 10: 100 Hz.
    Hz100,
    /// 11: 200 Hz.
    Hz200,
}

impl Odr {
    /// The rate selected by a CONF1 value.
    pub const fn from_conf1(value: u8) -> Self {
        match (value & bits::CONF1_ODR) >> 2 {
            0 => Self::Hz10,
            1 => Self::Hz50,
            2 => Self::Hz100,
            _ => Self::Hz200,
        }
    }

    /// Nanoseconds between measurements.
    pub const fn period_ns(self) -> u64 {
        match self {
            Self::Hz10 => 100_000_000,
            Self::Hz50 => 20_000_000,
            Self::Hz100 => 10_000_000,
            Self::Hz200 => 5_000_000,
        }
    }
}

/// Field range (CONF1 bits 5:4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Range {
    /// 00: ±2 G, 12000 LSB/G.
    #[default]
    Gauss2,
    /// 01 (and the reserved 1x codes): ±8 G, 3000 LSB/G.
    Gauss8,
}

impl Range {
    /// The range selected by a CONF1 value.
    pub const fn from_conf1(value: u8) -> Self {
        if value & bits::CONF1_RNG == 0 {
            Self::Gauss2
        } else {
            Self::Gauss8
        }
    }

    /// The CONF1 RNG field's bits for this range (00 and 01).
    pub const fn conf1_bits(self) -> u8 {
        match self {
            Self::Gauss2 => 0x00,
            Self::Gauss8 => 0x10,
        }
    }

    /// Sensitivity in LSB per µT (1 G = 100 µT): 120 and 30.
    pub const fn lsb_per_ut(self) -> f32 {
        match self {
            Self::Gauss2 => 120.0,
            Self::Gauss8 => 30.0,
        }
    }
}

/// Largest magnitude of the data registers: full scale, 2 G × 12000 = 8 G × 3000 = 24000 LSB.
/// Assumption: the datasheet gives the range, not where the output clips.
pub const MAX_RAW: i16 = 24_000;

/// The data registers for a field in µT in the chip's axes at `range`, and whether any axis
/// clipped at [`MAX_RAW`] (STATUS.OVL). NaN reads 0.
pub fn measurement(field_ut: [f32; 3], range: Range) -> ([i16; 3], bool) {
    let mut raw = [0i16; 3];
    for (out, b) in raw.iter_mut().zip(field_ut) {
        *out = round_saturate(b * range.lsb_per_ut(), -MAX_RAW, MAX_RAW);
    }
    (raw, overflows(raw))
}

/// Whether raw data registers report an overflow (STATUS.OVL): an axis at full scale.
pub fn overflows(raw: [i16; 3]) -> bool {
    raw.iter()
        .any(|v| v.unsigned_abs() >= MAX_RAW.unsigned_abs())
}

/// The field in µT (chip axes) raw data registers stand for at `range`.
pub fn field_ut(raw: [i16; 3], range: Range) -> [f64; 3] {
    raw.map(|v| f64::from(v) / f64::from(range.lsb_per_ut()))
}

/// The next register after `addr` in a burst: with CONF2.ROL_PNT set, 0x06 rolls over to 0x00;
/// otherwise (and outside 00H–06H) the address increments.
pub const fn next_address(addr: u8, roll_over: bool) -> u8 {
    if roll_over && addr == reg::STATUS {
        reg::XOUT_L
    } else {
        addr.wrapping_add(1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conf1_fields() {
        assert_eq!(Mode::from_conf1(0x00), Mode::Standby);
        assert_eq!(Mode::from_conf1(0xFD), Mode::Continuous);
        assert_eq!(Mode::from_conf1(0x02), Mode::Reserved);
        assert_eq!(Odr::from_conf1(0x00).period_ns(), 100_000_000);
        assert_eq!(Odr::from_conf1(0x04).period_ns(), 20_000_000);
        assert_eq!(Odr::from_conf1(0x0C).period_ns(), 5_000_000);
        assert_eq!(Range::from_conf1(0xCF), Range::Gauss2);
        assert_eq!(Range::from_conf1(0x20), Range::Gauss8);
    }

    #[test]
    fn conversion_rounds_and_clips() {
        assert_eq!(
            measurement([0.5, -0.01, 0.0], Range::Gauss2),
            ([60, -1, 0], false)
        );
        assert_eq!(
            measurement([200.0, -1000.0, f32::NAN], Range::Gauss2),
            ([24000, -24000, 0], true)
        );
        assert!(!measurement([799.0, 0.0, 0.0], Range::Gauss8).1);
    }

    #[test]
    fn pointer_roll_over() {
        assert_eq!(next_address(0x06, true), 0x00);
        assert_eq!(next_address(0x06, false), 0x07);
        assert_eq!(next_address(0x0D, true), 0x0E);
    }
}
