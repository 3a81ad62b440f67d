//! The AK8963 magnetometer die of the MPU-9250: register addresses, bits, operating modes,
//! output resolution, measurement timing and self-test field (AKM AK8963 datasheet
//! MS1356-E-02, "DS" below; RM-MPU-9250A-00 section 5).
//!
//! ```
//! use margemu_protocol::regmap::ak8963::{reg, Mode, MagBits, WIA_VALUE};
//! assert_eq!(WIA_VALUE, 0x48);
//! assert_eq!(Mode::from_cntl1(0x16), Mode::Continuous2);
//! assert_eq!(MagBits::from_cntl1(0x16), MagBits::Bits16);
//! assert_eq!(reg::HXL, 0x03);
//! ```

/// The AK8963's 7-bit I2C address inside the MPU-9250 (CAD1 = CAD0 = 0).
pub const I2C_ADDRESS: u8 = 0x0C;

/// The fuse-ROM sensitivity adjustment values ASAX, ASAY, ASAZ of the emulated part (near 0xB0
/// like real parts, so a driver that ignores them is caught; DS section 8.3.11).
pub const EMULATED_ASA: [u8; 3] = [0xB0, 0xB2, 0xA7];

/// The value of WIA (DS section 8.3.1).
pub const WIA_VALUE: u8 = 0x48;

/// Register addresses (DS section 8.1).
pub mod reg {
    /// Device ID, 0x48.
    pub const WIA: u8 = 0x00;
    /// Device information (AKM internal).
    pub const INFO: u8 = 0x01;
    /// Status 1: DRDY, DOR.
    pub const ST1: u8 = 0x02;
    /// X low byte (little endian).
    pub const HXL: u8 = 0x03;
    /// Z high byte.
    pub const HZH: u8 = 0x08;
    /// Status 2: HOFL, BITM; reading it ends a data read.
    pub const ST2: u8 = 0x09;
    /// Control 1: BIT, MODE.
    pub const CNTL1: u8 = 0x0A;
    /// Control 2: SRST.
    pub const CNTL2: u8 = 0x0B;
    /// Self-test control: SELF.
    pub const ASTC: u8 = 0x0C;
    /// Test 1 ("do not access").
    pub const TS1: u8 = 0x0D;
    /// Test 2 ("do not access").
    pub const TS2: u8 = 0x0E;
    /// I2C disable.
    pub const I2CDIS: u8 = 0x0F;
    /// Fuse ROM X sensitivity adjustment.
    pub const ASAX: u8 = 0x10;
    /// Fuse ROM Y sensitivity adjustment.
    pub const ASAY: u8 = 0x11;
    /// Fuse ROM Z sensitivity adjustment.
    pub const ASAZ: u8 = 0x12;
}

/// Bits.
pub mod bits {
    /// ST1: data ready.
    pub const ST1_DRDY: u8 = 1 << 0;
    /// ST1: data overrun (a measurement was skipped).
    pub const ST1_DOR: u8 = 1 << 1;
    /// ST2: magnetic sensor overflow.
    pub const ST2_HOFL: u8 = 1 << 3;
    /// ST2: mirror of the output bit setting of the stored data.
    pub const ST2_BITM: u8 = 1 << 4;
    /// CNTL1: 16-bit output.
    pub const CNTL1_BIT: u8 = 1 << 4;
    /// CNTL1: mode field.
    pub const CNTL1_MODE: u8 = 0x0F;
    /// CNTL2: soft reset (self-clearing).
    pub const CNTL2_SRST: u8 = 1 << 0;
    /// ASTC: internal magnetic field for self-test.
    pub const ASTC_SELF: u8 = 1 << 6;
}

/// Operating mode (CNTL1.MODE, DS sections 6.4 and 8.3.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Mode {
    /// 0000: power-down.
    #[default]
    PowerDown,
    /// 0001: one measurement, then power-down.
    Single,
    /// 0010: continuous measurement at 8 Hz.
    Continuous1,
    /// 0110: continuous measurement at 100 Hz.
    Continuous2,
    /// 0100: measurement on the TRG pin (not wired in the MPU-9250 package).
    ExternalTrigger,
    /// 1000: one measurement of the internal self-test field, then power-down.
    SelfTest,
    /// 1111: the fuse ROM (ASAX..ASAZ) is readable.
    FuseRom,
    /// Any other MODE value: no measurement (the datasheet defines none).
    Undefined,
}

impl Mode {
    /// The mode selected by a CNTL1 value.
    pub const fn from_cntl1(value: u8) -> Self {
        match value & bits::CNTL1_MODE {
            0x0 => Self::PowerDown,
            0x1 => Self::Single,
            0x2 => Self::Continuous1,
            0x6 => Self::Continuous2,
            0x4 => Self::ExternalTrigger,
            0x8 => Self::SelfTest,
            0xF => Self::FuseRom,
            _ => Self::Undefined,
        }
    }

    /// Nanoseconds between measurements in the continuous modes (8 Hz, 100 Hz).
    pub const fn period_ns(self) -> Option<u64> {
        match self {
            Self::Continuous1 => Some(125_000_000),
            Self::Continuous2 => Some(10_000_000),
            _ => None,
        }
    }
}

/// Output resolution (CNTL1.BIT).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MagBits {
    /// 14-bit output, 0.6 µT/LSB, ±8190.
    #[default]
    Bits14,
    /// 16-bit output, 0.15 µT/LSB, ±32760.
    Bits16,
}

impl MagBits {
    /// The resolution selected by a CNTL1 value.
    pub const fn from_cntl1(value: u8) -> Self {
        if value & bits::CNTL1_BIT != 0 {
            Self::Bits16
        } else {
            Self::Bits14
        }
    }

    /// Sensitivity in µT per LSB (DS section 5: 0.6 and 0.15 typical).
    pub const fn ut_per_lsb(self) -> f32 {
        match self {
            Self::Bits14 => 0.6,
            Self::Bits16 => 0.15,
        }
    }

    /// The largest magnitude the data registers hold (DS table 8.3: 8190 and 32760).
    pub const fn max_raw(self) -> i16 {
        match self {
            Self::Bits14 => 8190,
            Self::Bits16 => 32760,
        }
    }
}

/// Time from the start of a measurement to data ready: the datasheet's typical single
/// measurement time of 7.2 ms (DS section 5, tSM). The emulation uses it for single,
/// self-test and the first continuous measurement.
pub const MEASUREMENT_NS: u64 = 7_200_000;

/// The magnetic sensor overflows when `|X| + |Y| + |Z|` reaches this many µT
/// (DS section 6.4.3.6); ST2.HOFL is then set.
pub const OVERFLOW_SUM_UT: f32 = 4912.0;

/// The self-test field the emulation reports, in LSB *after* sensitivity adjustment at 14-bit
/// output: inside the datasheet's pass band (DS self-test mode: X, Y in −50..=50,
/// Z in −800..=−200; 16-bit output is four times these).
pub const SELF_TEST_14BIT: [i16; 3] = [10, -15, -400];

/// The next register after `addr` in a burst: 0x00..=0x0C wraps to 0x00 and 0x10..=0x12 wraps
/// to 0x10 (DS section 7.2.3); anything else just increments.
pub const fn next_address(addr: u8) -> u8 {
    match addr {
        reg::ASTC => reg::WIA,
        reg::ASAZ => reg::ASAX,
        _ => addr.wrapping_add(1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes() {
        assert_eq!(Mode::from_cntl1(0x00), Mode::PowerDown);
        assert_eq!(Mode::from_cntl1(0x11), Mode::Single);
        assert_eq!(Mode::from_cntl1(0x02), Mode::Continuous1);
        assert_eq!(Mode::from_cntl1(0x04), Mode::ExternalTrigger);
        assert_eq!(Mode::from_cntl1(0x08), Mode::SelfTest);
        assert_eq!(Mode::from_cntl1(0x1F), Mode::FuseRom);
        assert_eq!(Mode::from_cntl1(0x03), Mode::Undefined);
        assert_eq!(Mode::Continuous1.period_ns(), Some(125_000_000));
        assert_eq!(Mode::Continuous2.period_ns(), Some(10_000_000));
        assert_eq!(Mode::Single.period_ns(), None);
    }

    #[test]
    fn burst_addresses_wrap_like_the_datasheet() {
        assert_eq!(next_address(0x03), 0x04);
        assert_eq!(next_address(0x0C), 0x00);
        assert_eq!(next_address(0x12), 0x10);
        assert_eq!(next_address(0xFF), 0x00);
    }
}
