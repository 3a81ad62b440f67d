//! The accelerometer die: addresses, bits, access rules, ranges and output rates (DS 5.2, 5.3;
//! AN 3 for the FIFO registers 0x24–0x26 and 0x45–0x49).
//!
//! ```
//! use margemu_protocol::regmap::bmi088::accel::{reg, AccRange, Odr};
//! use margemu_protocol::regmap::bmi088::Die;
//! assert_eq!(Die::Accel.reset_value(reg::ACC_CONF), 0xA8); // normal filter, 100 Hz
//! assert_eq!(AccRange::from_reg(0x01), AccRange::G6);
//! assert_eq!(Odr::from_conf(0xAC).map(Odr::period_ns), Some(625_000)); // 1.6 kHz
//! assert_eq!(Odr::from_conf(0xA4), None); // reserved
//! ```

/// ACC_CHIP_ID (DS 5.3.1).
pub const CHIP_ID: u8 = 0x1E;

/// The 7-bit I2C address with SDO1 at GND (0x19 with SDO1 at VDDIO; DS 6.2).
pub const I2C_ADDRESS: u8 = 0x18;

/// FIFO size in bytes (AN 3).
pub const FIFO_SIZE: usize = 1024;

/// The data registers ACC_X_LSB..=ACC_Z_MSB: 6 bytes.
pub const DATA_LEN: usize = 6;

/// Register addresses (DS 5.2, AN 3.5.1).
pub mod reg {
    /// Chip identification, 0x1E.
    pub const CHIP_ID: u8 = 0x00;
    /// Error flags: bit 0 fatal_err, bits 4:2 error_code (1: invalid ACC_CONF).
    pub const ERR_REG: u8 = 0x02;
    /// Status: bit 7 acc_drdy (bit 4 reads 1 after reset, undocumented).
    pub const STATUS: u8 = 0x03;
    /// Accel X LSB; X MSB, Y and Z follow up to 0x17 (little-endian).
    pub const ACC_X_LSB: u8 = 0x12;
    /// Accel Z MSB: the last data register.
    pub const ACC_Z_MSB: u8 = 0x17;
    /// Sensor time bits 7:0; 15:8 and 23:16 follow at 0x19 and 0x1A.
    pub const SENSORTIME_0: u8 = 0x18;
    /// Sensor time bits 23:16.
    pub const SENSORTIME_2: u8 = 0x1A;
    /// Interrupt status: bit 7 acc_drdy, cleared by reading this register.
    pub const INT_STAT_1: u8 = 0x1D;
    /// Temperature bits 10:3 (0x80 marks an invalid value).
    pub const TEMP_MSB: u8 = 0x22;
    /// Temperature bits 2:0 in bits 7:5.
    pub const TEMP_LSB: u8 = 0x23;
    /// FIFO fill level in bytes, bits 7:0.
    pub const FIFO_LENGTH_0: u8 = 0x24;
    /// FIFO fill level in bytes, bits 13:8.
    pub const FIFO_LENGTH_1: u8 = 0x25;
    /// FIFO read port.
    pub const FIFO_DATA: u8 = 0x26;
    /// Accel configuration: bits 7:4 acc_bwp, 3:0 acc_odr.
    pub const ACC_CONF: u8 = 0x40;
    /// Accel range: bits 1:0.
    pub const ACC_RANGE: u8 = 0x41;
    /// FIFO down-sampling: bit 7 must be 1, bits 6:4 fifo_downs.
    pub const FIFO_DOWNS: u8 = 0x45;
    /// FIFO watermark, bits 7:0 (bytes).
    pub const FIFO_WTM_0: u8 = 0x46;
    /// FIFO watermark, bits 12:8.
    pub const FIFO_WTM_1: u8 = 0x47;
    /// FIFO configuration 0: bit 1 must be 1, bit 0 mode (1 FIFO / stop-at-full, 0 stream).
    pub const FIFO_CONFIG_0: u8 = 0x48;
    /// FIFO configuration 1: bit 6 acc_en, bit 4 must be 1, bits 3/2 INT1/INT2 tags.
    pub const FIFO_CONFIG_1: u8 = 0x49;
    /// INT1 pin configuration: bit 4 input, 3 output, 2 open drain, 1 active high.
    pub const INT1_IO_CONF: u8 = 0x53;
    /// INT2 pin configuration, as INT1_IO_CONF.
    pub const INT2_IO_CONF: u8 = 0x54;
    /// Interrupt mapping: bits 6/5/4 drdy/watermark/full to INT2, bits 2/1/0 to INT1.
    pub const INT1_INT2_MAP_DATA: u8 = 0x58;
    /// Self-test: 0x0D positive, 0x09 negative, 0x00 off.
    pub const ACC_SELF_TEST: u8 = 0x6D;
    /// Power configuration: 0x03 suspend, 0x00 active.
    pub const ACC_PWR_CONF: u8 = 0x7C;
    /// Power control: 0x04 accelerometer (and temperature sensor) on, 0x00 off.
    pub const ACC_PWR_CTRL: u8 = 0x7D;
    /// Soft reset (0xB6) and FIFO reset (0xB0); write-only.
    pub const ACC_SOFTRESET: u8 = 0x7E;
}

/// Bits and values (DS 5.3, AN 3).
pub mod bits {
    /// ACC_STATUS.acc_drdy and ACC_INT_STAT_1.acc_drdy.
    pub const DRDY: u8 = 1 << 7;
    /// ACC_ERR_REG.error_code = 1 (invalid ACC_CONF), in place.
    pub const ERROR_CODE_CONF: u8 = 1 << 2;
    /// ACC_PWR_CTRL: accelerometer on.
    pub const ACC_ENABLE: u8 = 0x04;
    /// ACC_PWR_CONF: active mode.
    pub const PWR_ACTIVE: u8 = 0x00;
    /// ACC_SOFTRESET: soft reset.
    pub const CMD_SOFT_RESET: u8 = 0xB6;
    /// ACC_SOFTRESET: FIFO reset.
    pub const CMD_FIFO_RESET: u8 = 0xB0;
    /// FIFO_CONFIG_0.mode: FIFO (stop-at-full) mode; clear for stream mode.
    pub const FIFO_MODE_STOP: u8 = 1 << 0;
    /// FIFO_CONFIG_1.acc_en.
    pub const FIFO_ACC_EN: u8 = 1 << 6;
    /// Header of an acceleration frame (bits 1:0: INT2/INT1 tags).
    pub const FIFO_HEADER_ACC: u8 = 0x84;
    /// Header of a skip frame (one payload byte: frames lost).
    pub const FIFO_HEADER_SKIP: u8 = 0x40;
    /// What each byte of an over-read returns (AN 3.2.6: "0x8000 is returned").
    pub const FIFO_OVERREAD: [u8; 2] = [0x80, 0x00];
    /// INT1_INT2_MAP_DATA: data ready to INT1.
    pub const INT1_DRDY: u8 = 1 << 2;
    /// INT1_INT2_MAP_DATA: FIFO watermark to INT1.
    pub const INT1_FWM: u8 = 1 << 1;
    /// INT1_INT2_MAP_DATA: FIFO full to INT1.
    pub const INT1_FFULL: u8 = 1 << 0;
    /// INTx_IO_CONF.intx_out: the pin is an output.
    pub const INT_OUT: u8 = 1 << 3;
    /// INTx_IO_CONF.intx_od: open drain.
    pub const INT_OD: u8 = 1 << 2;
    /// INTx_IO_CONF.intx_lvl: active high.
    pub const INT_LVL: u8 = 1 << 1;
}

/// `(reset value, writable bits)` of a listed accelerometer register.
pub(super) const fn spec(addr: u8) -> Option<(u8, u8)> {
    let s = match addr {
        reg::CHIP_ID => (CHIP_ID, 0),
        reg::ERR_REG => (0x00, 0),
        reg::STATUS => (0x10, 0),
        reg::ACC_X_LSB..=reg::SENSORTIME_2 => (0x00, 0),
        reg::INT_STAT_1 => (0x00, 0),
        reg::TEMP_MSB | reg::TEMP_LSB => (0x00, 0),
        reg::FIFO_LENGTH_0 | reg::FIFO_LENGTH_1 | reg::FIFO_DATA => (0x00, 0),
        reg::ACC_CONF => (0xA8, 0xFF),
        reg::ACC_RANGE => (0x01, 0x03),
        reg::FIFO_DOWNS => (0x80, 0xF0),
        reg::FIFO_WTM_0 => (0x00, 0xFF),
        reg::FIFO_WTM_1 => (0x02, 0x1F),
        reg::FIFO_CONFIG_0 => (0x02, 0x03),
        reg::FIFO_CONFIG_1 => (0x10, 0x7F),
        reg::INT1_IO_CONF | reg::INT2_IO_CONF => (0x00, 0x1E),
        reg::INT1_INT2_MAP_DATA => (0x00, 0x77),
        reg::ACC_SELF_TEST => (0x00, 0xFF),
        reg::ACC_PWR_CONF => (0x03, 0xFF),
        reg::ACC_PWR_CTRL => (0x00, 0xFF),
        reg::ACC_SOFTRESET => (0x00, 0xFF), // write-only, reads 0
        _ => return None,
    };
    Some(s)
}

/// Accelerometer range, ACC_RANGE bits 1:0 (DS 5.3.9).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccRange {
    /// ±3 g (code 0).
    G3,
    /// ±6 g (code 1, the reset value).
    #[default]
    G6,
    /// ±12 g (code 2).
    G12,
    /// ±24 g (code 3).
    G24,
}

impl AccRange {
    /// Every range in code order.
    pub const ALL: [Self; 4] = [Self::G3, Self::G6, Self::G12, Self::G24];

    /// The range an ACC_RANGE value selects.
    pub const fn from_reg(value: u8) -> Self {
        match value & 0x03 {
            0 => Self::G3,
            1 => Self::G6,
            2 => Self::G12,
            _ => Self::G24,
        }
    }

    /// The ACC_RANGE code.
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Sensitivity, LSB per g, from DS 5.3.4: mg = raw / 32768 · 1000 · 2^(code + 1) · 1.5,
    /// so 32768 / (1.5 · 2^(code + 1)): 10922.67, 5461.33, 2730.67, 1365.33 (the DS table rounds
    /// these to 10920, 5460, 2730, 1365).
    pub fn lsb_per_g(self) -> f32 {
        32768.0 / (1.5 * f32::from(2u8 << self.bits()))
    }

    /// Full scale in g.
    pub const fn full_scale_g(self) -> u8 {
        3 << self.bits()
    }
}

/// An output data rate, ACC_CONF bits 3:0 (DS 5.3.8): 12.5 Hz · 2^(code − 5), codes 5 (12.5 Hz)
/// to 12 (1600 Hz).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Odr(u8);

impl Odr {
    /// 100 Hz, the reset value.
    pub const HZ100: Self = Self(0x08);
    /// 1600 Hz, the fastest.
    pub const HZ1600: Self = Self(0x0C);

    /// The rate an ACC_CONF value selects; `None` for the reserved codes 0–4 and 13–15.
    pub const fn from_conf(value: u8) -> Option<Self> {
        match value & 0x0F {
            code @ 0x05..=0x0C => Some(Self(code)),
            _ => None,
        }
    }

    /// The acc_odr code.
    pub const fn code(self) -> u8 {
        self.0
    }

    /// Sample period in ns (exact: 80 ms / 2^(code − 5)).
    pub const fn period_ns(self) -> u64 {
        80_000_000 >> (self.0.saturating_sub(5))
    }

    /// The rate, Hz.
    pub fn hz(self) -> f64 {
        1e9 / self.period_ns() as f64
    }

    /// The fastest rate at or below `hz` (within 1e-9 relative); `None` below 12.5 Hz.
    pub fn at_most_hz(hz: f64) -> Option<Self> {
        (0x05..=0x0C)
            .rev()
            .map(Self)
            .find(|odr| odr.hz() <= hz * (1.0 + 1e-9))
    }
}

/// Whether an ACC_CONF value is valid: acc_bwp 0x8–0xA (OSR4, OSR2, normal) and a listed ODR.
/// An invalid value sets ACC_ERR_REG.error_code = 1 (DS 5.3.2).
pub const fn conf_is_valid(value: u8) -> bool {
    matches!(value >> 4, 0x8..=0xA) && Odr::from_conf(value).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sensitivities_follow_the_ds_formula() {
        let want = [10922.667, 5461.333, 2730.667, 1365.333];
        for (range, w) in AccRange::ALL.into_iter().zip(want) {
            assert!((range.lsb_per_g() - w).abs() < 1e-2, "{range:?}");
            assert_eq!(AccRange::from_reg(range.bits()), range);
        }
        assert_eq!(AccRange::G24.full_scale_g(), 24);
    }

    #[test]
    fn odr_periods_and_validity() {
        assert_eq!(Odr::from_conf(0x05).map(Odr::period_ns), Some(80_000_000));
        assert_eq!(Odr::HZ100.period_ns(), 10_000_000);
        assert_eq!(Odr::HZ1600.period_ns(), 625_000);
        assert_eq!(Odr::from_conf(0x0D), None);
        assert_eq!(Odr::at_most_hz(2000.0), Some(Odr::HZ1600));
        assert_eq!(Odr::at_most_hz(1000.0).map(Odr::code), Some(0x0B)); // 800 Hz
        assert_eq!(Odr::at_most_hz(400.0).map(Odr::hz), Some(400.0));
        assert_eq!(Odr::at_most_hz(12.5).map(Odr::code), Some(0x05));
        assert_eq!(Odr::at_most_hz(12.0), None);
        assert!(conf_is_valid(0xA8) && conf_is_valid(0x8C) && conf_is_valid(0x95));
        assert!(!conf_is_valid(0xB8) && !conf_is_valid(0x78) && !conf_is_valid(0xA0));
    }
}
