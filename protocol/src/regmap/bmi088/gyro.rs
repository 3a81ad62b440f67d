//! The gyroscope die: addresses, bits, access rules, ranges and output rates (DS 5.4, 5.5;
//! AN 4.5 for INT_STATUS_1 bit 4 and the FIFO registers 0x0E, 0x1E, 0x34, 0x3D–0x3F).
//!
//! ```
//! use margemu_protocol::regmap::bmi088::gyro::{Bandwidth, GyroRange};
//! assert_eq!(GyroRange::from_reg(0x04), GyroRange::Dps125);
//! assert!((GyroRange::Dps2000.lsb_per_dps() - 16.384).abs() < 1e-6);
//! let bw = Bandwidth::from_reg(0x80); // reset value: bit 7 always reads 1
//! assert_eq!((bw.odr_hz(), bw.filter_hz(), bw.period_ns()), (2000, 532, 500_000));
//! ```

/// GYRO_CHIP_ID (DS 5.5.1).
pub const CHIP_ID: u8 = 0x0F;

/// The 7-bit I2C address with SDO2 at GND (0x69 with SDO2 at VDDIO; DS 6.2).
pub const I2C_ADDRESS: u8 = 0x68;

/// Frames the FIFO holds in FIFO mode (AN 4: 100; stream mode keeps 99).
pub const FIFO_FRAMES: usize = 100;

/// The rate data registers RATE_X_LSB..=RATE_Z_MSB: 6 bytes.
pub const DATA_LEN: usize = 6;

/// Register addresses (DS 5.4, AN 4.5.1).
pub mod reg {
    /// Chip identification, 0x0F.
    pub const CHIP_ID: u8 = 0x00;
    /// Rate X LSB; X MSB, Y and Z follow up to 0x07 (little-endian).
    pub const RATE_X_LSB: u8 = 0x02;
    /// Rate Z MSB: the last data register.
    pub const RATE_Z_MSB: u8 = 0x07;
    /// Interrupt status: bit 7 data_int (cleared 280–400 µs after it is set), bit 4 fifo_int.
    pub const INT_STAT_1: u8 = 0x0A;
    /// FIFO status: bit 7 overrun, bits 6:0 frame count.
    pub const FIFO_STATUS: u8 = 0x0E;
    /// Range: 0 ±2000, 1 ±1000, 2 ±500, 3 ±250, 4 ±125 °/s.
    pub const RANGE: u8 = 0x0F;
    /// Output rate and filter bandwidth, bits 3:0 (bit 7 always reads 1).
    pub const BANDWIDTH: u8 = 0x10;
    /// Power mode: 0x00 normal, 0x80 suspend, 0x20 deep suspend.
    pub const LPM1: u8 = 0x11;
    /// Soft reset (0xB6); write-only.
    pub const SOFTRESET: u8 = 0x14;
    /// Interrupt enables: bit 7 data_en, bit 6 fifo_en.
    pub const INT_CTRL: u8 = 0x15;
    /// INT3/INT4 electrical configuration: bits 3/1 open drain, 2/0 active high.
    pub const INT3_INT4_IO_CONF: u8 = 0x16;
    /// Interrupt mapping: bit 7 data to INT4, 5 FIFO to INT4, 2 FIFO to INT3, 0 data to INT3.
    pub const INT3_INT4_IO_MAP: u8 = 0x18;
    /// FIFO watermark interrupt: 0x88 enabled, 0x08 disabled.
    pub const FIFO_WM_ENABLE: u8 = 0x1E;
    /// External FIFO synchronisation: bit 5 enable, bit 4 source INT4.
    pub const FIFO_EXT_INT_S: u8 = 0x34;
    /// Self-test: bit 4 rate_ok, 2 bist_fail, 1 bist_rdy (read), 0 trig_bist (write).
    pub const SELF_TEST: u8 = 0x3C;
    /// FIFO configuration 0: bits 6:0 watermark level (frames), bit 7 tag; a write clears the
    /// FIFO.
    pub const FIFO_CONFIG_0: u8 = 0x3D;
    /// FIFO configuration 1: bits 7:6 mode (0x40 FIFO, 0x80 stream), bits 1:0 data select
    /// (0 XYZ, 1 X, 2 Y, 3 Z); a write clears the FIFO and the overrun flag.
    pub const FIFO_CONFIG_1: u8 = 0x3E;
    /// FIFO read port.
    pub const FIFO_DATA: u8 = 0x3F;
}

/// Bits and values (DS 5.5, AN 4.5).
pub mod bits {
    /// INT_STAT_1.data_int.
    pub const DATA_INT: u8 = 1 << 7;
    /// INT_STAT_1.fifo_int.
    pub const FIFO_INT: u8 = 1 << 4;
    /// FIFO_STATUS.fifo_overrun.
    pub const FIFO_OVERRUN: u8 = 1 << 7;
    /// FIFO_STATUS frame counter field.
    pub const FIFO_FRAME_COUNT: u8 = 0x7F;
    /// BANDWIDTH bit 7: read-only, always 1.
    pub const BANDWIDTH_FIXED: u8 = 1 << 7;
    /// LPM1: normal mode.
    pub const PM_NORMAL: u8 = 0x00;
    /// LPM1: suspend mode (registers kept, no data).
    pub const PM_SUSPEND: u8 = 0x80;
    /// LPM1: deep suspend mode (configuration lost, no data).
    pub const PM_DEEP_SUSPEND: u8 = 0x20;
    /// SOFTRESET: soft reset.
    pub const CMD_SOFT_RESET: u8 = 0xB6;
    /// INT_CTRL.data_en.
    pub const DATA_EN: u8 = 1 << 7;
    /// INT_CTRL.fifo_en.
    pub const FIFO_EN: u8 = 1 << 6;
    /// INT3_INT4_IO_MAP: data ready to INT3.
    pub const INT3_DATA: u8 = 1 << 0;
    /// INT3_INT4_IO_MAP: FIFO interrupt to INT3.
    pub const INT3_FIFO: u8 = 1 << 2;
    /// INT3_INT4_IO_MAP: FIFO interrupt to INT4.
    pub const INT4_FIFO: u8 = 1 << 5;
    /// INT3_INT4_IO_MAP: data ready to INT4.
    pub const INT4_DATA: u8 = 1 << 7;
    /// INT3_INT4_IO_CONF.int3_lvl: active high.
    pub const INT3_LVL: u8 = 1 << 0;
    /// INT3_INT4_IO_CONF.int3_od: open drain.
    pub const INT3_OD: u8 = 1 << 1;
    /// FIFO_WM_ENABLE bit 7: watermark interrupt on.
    pub const FIFO_WM_EN: u8 = 1 << 7;
    /// FIFO_CONFIG_1 mode field.
    pub const FIFO_MODE_MASK: u8 = 0xC0;
    /// FIFO_CONFIG_1: FIFO (stop-at-full) mode.
    pub const FIFO_MODE_FIFO: u8 = 0x40;
    /// FIFO_CONFIG_1: stream mode.
    pub const FIFO_MODE_STREAM: u8 = 0x80;
    /// FIFO_CONFIG_1 data select field.
    pub const FIFO_DATA_SELECT: u8 = 0x03;
    /// FIFO_CONFIG_0 watermark field.
    pub const FIFO_WATERMARK: u8 = 0x7F;
    /// SELF_TEST.rate_ok.
    pub const RATE_OK: u8 = 1 << 4;
    /// SELF_TEST.bist_rdy.
    pub const BIST_RDY: u8 = 1 << 1;
    /// SELF_TEST.trig_bist.
    pub const TRIG_BIST: u8 = 1 << 0;
}

/// `(reset value, writable bits)` of a listed gyroscope register.
pub(super) const fn spec(addr: u8) -> Option<(u8, u8)> {
    let s = match addr {
        reg::CHIP_ID => (CHIP_ID, 0),
        reg::RATE_X_LSB..=reg::RATE_Z_MSB => (0x00, 0),
        reg::INT_STAT_1 | reg::FIFO_STATUS => (0x00, 0),
        reg::RANGE => (0x00, 0xFF),
        reg::BANDWIDTH => (0x80, 0x7F),
        reg::LPM1 => (0x00, 0xFF),
        reg::SOFTRESET => (0x00, 0xFF), // write-only, reads 0
        reg::INT_CTRL => (0x00, 0xC0),
        reg::INT3_INT4_IO_CONF => (0x0F, 0x0F), // DS 5.4 register map (its bit table says 0)
        reg::INT3_INT4_IO_MAP => (0x00, 0xA5),
        reg::FIFO_WM_ENABLE => (0x08, 0xFF), // AN 4.5.6 (its overview says 0x00)
        reg::FIFO_EXT_INT_S => (0x00, 0x30),
        reg::SELF_TEST => (0x00, bits::TRIG_BIST), // a command: reads the test's status
        reg::FIFO_CONFIG_0 => (0x00, 0xFF),
        reg::FIFO_CONFIG_1 => (0x00, 0xC3),
        reg::FIFO_DATA => (0x00, 0),
        _ => return None,
    };
    Some(s)
}

/// Gyroscope range, GYRO_RANGE (DS 5.5.4). The register keeps all 8 bits; the range follows
/// bits 2:0 (Bosch's API mask), and the reserved codes 5–7 read as ±2000 °/s here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroRange {
    /// ±2000 °/s (code 0, the reset value), 16.384 LSB/(°/s).
    #[default]
    Dps2000,
    /// ±1000 °/s, 32.768 LSB/(°/s).
    Dps1000,
    /// ±500 °/s, 65.536 LSB/(°/s).
    Dps500,
    /// ±250 °/s, 131.072 LSB/(°/s).
    Dps250,
    /// ±125 °/s, 262.144 LSB/(°/s).
    Dps125,
}

impl GyroRange {
    /// Every range in code order.
    pub const ALL: [Self; 5] = [
        Self::Dps2000,
        Self::Dps1000,
        Self::Dps500,
        Self::Dps250,
        Self::Dps125,
    ];

    /// The range a GYRO_RANGE value selects.
    pub const fn from_reg(value: u8) -> Self {
        match value & 0x07 {
            1 => Self::Dps1000,
            2 => Self::Dps500,
            3 => Self::Dps250,
            4 => Self::Dps125,
            _ => Self::Dps2000,
        }
    }

    /// The GYRO_RANGE code.
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Full scale in °/s.
    pub const fn full_scale_dps(self) -> u16 {
        2000 >> self.bits()
    }

    /// Sensitivity, LSB per °/s: 32768 / full scale (DS 1.3, table 5).
    pub fn lsb_per_dps(self) -> f32 {
        32768.0 / f32::from(self.full_scale_dps())
    }
}

/// Output data rate and filter bandwidth, GYRO_BANDWIDTH bits 3:0 (DS 5.5.5). Codes 8–15 are
/// reserved and decode as their bits 2:0 here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bandwidth(u8);

impl Bandwidth {
    /// `(ODR Hz, filter Hz)` of codes 0–7.
    const TABLE: [(u16, u16); 8] = [
        (2000, 532),
        (2000, 230),
        (1000, 116),
        (400, 47),
        (200, 23),
        (100, 12),
        (200, 64),
        (100, 32),
    ];

    /// The setting a GYRO_BANDWIDTH value selects.
    pub const fn from_reg(value: u8) -> Self {
        Self(value & 0x07)
    }

    /// The gyro_bw code.
    pub const fn code(self) -> u8 {
        self.0
    }

    fn entry(self) -> (u16, u16) {
        Self::TABLE
            .get(usize::from(self.0))
            .copied()
            .unwrap_or((2000, 532))
    }

    /// Output data rate, Hz.
    pub fn odr_hz(self) -> u16 {
        self.entry().0
    }

    /// Filter bandwidth, Hz.
    pub fn filter_hz(self) -> u16 {
        self.entry().1
    }

    /// Sample period in ns (exact).
    pub fn period_ns(self) -> u64 {
        1_000_000_000 / u64::from(self.odr_hz().max(1))
    }

    /// The setting of output rate `hz` (within 1e-9 relative) with the widest filter: 2000 Hz
    /// (532 Hz filter, the reset value), 1000, 400, 200 (64 Hz) or 100 Hz (32 Hz); `None` for
    /// any other rate.
    pub fn widest_at_hz(hz: f64) -> Option<Self> {
        (0..8u8)
            .map(Self)
            .filter(|bw| (f64::from(bw.odr_hz()) - hz).abs() <= 1e-9 * hz)
            .max_by_key(|bw| bw.filter_hz())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges() {
        let want = [16.384, 32.768, 65.536, 131.072, 262.144];
        for (range, w) in GyroRange::ALL.into_iter().zip(want) {
            assert!((range.lsb_per_dps() - w).abs() < 1e-4, "{range:?}");
            assert_eq!(GyroRange::from_reg(range.bits()), range);
        }
        assert_eq!(GyroRange::from_reg(0x05), GyroRange::Dps2000); // reserved
        assert_eq!(GyroRange::Dps125.full_scale_dps(), 125);
    }

    #[test]
    fn bandwidths() {
        let periods: [u64; 8] = [
            500_000, 500_000, 1_000_000, 2_500_000, 5_000_000, 10_000_000, 5_000_000, 10_000_000,
        ];
        for (code, p) in (0u8..).zip(periods) {
            assert_eq!(
                Bandwidth::from_reg(0x80 | code).period_ns(),
                p,
                "code {code}"
            );
        }
        assert_eq!(Bandwidth::from_reg(0x87).filter_hz(), 32);
        assert_eq!(Bandwidth::from_reg(0x0A).code(), 2);
        let codes = [2000.0, 1000.0, 400.0, 200.0, 100.0].map(Bandwidth::widest_at_hz);
        assert_eq!(
            codes.map(|bw| bw.map(Bandwidth::code)),
            [0, 2, 3, 6, 7].map(Some)
        );
        assert_eq!(Bandwidth::widest_at_hz(800.0), None);
    }
}
