//! Ranges and output data rates (DS: 1 specification, sensitivities; register description of
//! ACC_CONF, ACC_RANGE, GYR_CONF and GYR_RANGE).

/// Accelerometer range, ACC_RANGE bits 1:0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccRange {
    /// ±2 g (code 0), 16384 LSB/g.
    G2,
    /// ±4 g (code 1), 8192 LSB/g.
    G4,
    /// ±8 g (code 2, the reset value), 4096 LSB/g.
    #[default]
    G8,
    /// ±16 g (code 3), 2048 LSB/g.
    G16,
}

impl AccRange {
    /// Every range in code order.
    pub const ALL: [Self; 4] = [Self::G2, Self::G4, Self::G8, Self::G16];

    /// The range an ACC_RANGE value selects.
    pub const fn from_reg(value: u8) -> Self {
        match value & 0x03 {
            0 => Self::G2,
            1 => Self::G4,
            2 => Self::G8,
            _ => Self::G16,
        }
    }

    /// The ACC_RANGE code.
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Sensitivity, LSB per g.
    pub const fn lsb_per_g(self) -> f32 {
        match self {
            Self::G2 => 16384.0,
            Self::G4 => 8192.0,
            Self::G8 => 4096.0,
            Self::G16 => 2048.0,
        }
    }

    /// The range, ± g.
    pub const fn range_g(self) -> f64 {
        match self {
            Self::G2 => 2.0,
            Self::G4 => 4.0,
            Self::G8 => 8.0,
            Self::G16 => 16.0,
        }
    }
}

/// Gyroscope range, GYR_RANGE bits 2:0 (codes 5–7 are reserved; read as ±125 °/s here).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyrRange {
    /// ±2000 °/s (code 0, the reset value), 16.4 LSB/(°/s).
    #[default]
    Dps2000,
    /// ±1000 °/s, 32.8 LSB/(°/s).
    Dps1000,
    /// ±500 °/s, 65.6 LSB/(°/s).
    Dps500,
    /// ±250 °/s, 131.2 LSB/(°/s).
    Dps250,
    /// ±125 °/s, 262.4 LSB/(°/s).
    Dps125,
}

impl GyrRange {
    /// Every range in code order.
    pub const ALL: [Self; 5] = [
        Self::Dps2000,
        Self::Dps1000,
        Self::Dps500,
        Self::Dps250,
        Self::Dps125,
    ];

    /// The range a GYR_RANGE value selects (the OIS bit 3 does not change the data registers).
    pub const fn from_reg(value: u8) -> Self {
        match value & 0x07 {
            0 => Self::Dps2000,
            1 => Self::Dps1000,
            2 => Self::Dps500,
            3 => Self::Dps250,
            _ => Self::Dps125,
        }
    }

    /// The GYR_RANGE code.
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Sensitivity, LSB per °/s (DS: 1 specification, typical sensitivity).
    pub const fn lsb_per_dps(self) -> f32 {
        match self {
            Self::Dps2000 => 16.4,
            Self::Dps1000 => 32.8,
            Self::Dps500 => 65.6,
            Self::Dps250 => 131.2,
            Self::Dps125 => 262.4,
        }
    }

    /// The range, ± °/s.
    pub const fn range_dps(self) -> f64 {
        match self {
            Self::Dps2000 => 2000.0,
            Self::Dps1000 => 1000.0,
            Self::Dps500 => 500.0,
            Self::Dps250 => 250.0,
            Self::Dps125 => 125.0,
        }
    }
}

/// An output data rate, the ODR field (bits 3:0) of ACC_CONF or GYR_CONF: 100 Hz · 2^(code − 8),
/// from 0.78125 Hz (code 1) to 3200 Hz (code 13; the accelerometer stops at 1600 Hz, code 12).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Odr(u8);

impl Odr {
    /// 25 Hz, the slowest gyro rate.
    pub const HZ25: Self = Self(0x06);
    /// 100 Hz (the accel reset value).
    pub const HZ100: Self = Self(0x08);
    /// 200 Hz (the gyro reset value).
    pub const HZ200: Self = Self(0x09);
    /// 800 Hz.
    pub const HZ800: Self = Self(0x0B);
    /// 1600 Hz, the fastest accel rate.
    pub const HZ1600: Self = Self(0x0C);
    /// 3200 Hz, the fastest gyro rate.
    pub const HZ3200: Self = Self(0x0D);

    /// The rate an ACC_CONF or GYR_CONF value selects; `None` for the reserved codes 0 and 14–15.
    pub const fn from_conf(value: u8) -> Option<Self> {
        match value & 0x0F {
            code @ 0x01..=0x0D => Some(Self(code)),
            _ => None,
        }
    }

    /// The gyro rate of `hz` (within 1e-9 relative): codes 6 (25 Hz) to 13 (3.2 kHz), the
    /// GYR_CONF codes of the Bosch sensor API (`BMI2_GYR_ODR_25HZ` ..= `BMI2_GYR_ODR_3200HZ`).
    /// The datasheet's key features name 6.4 kHz for the gyroscope: that is its pre-filtered
    /// data in the FIFO (FIFO_DOWNS gyr_fifo_filt_data = 0), not a GYR_CONF rate.
    pub fn gyro_of_hz(hz: f64) -> Option<Self> {
        Self::of_hz(hz, 0x06..=0x0D)
    }

    /// The accel rate of `hz`: codes 1 (0.78 Hz) to 12 (1.6 kHz).
    pub fn accel_of_hz(hz: f64) -> Option<Self> {
        Self::of_hz(hz, 0x01..=0x0C)
    }

    fn of_hz(hz: f64, codes: core::ops::RangeInclusive<u8>) -> Option<Self> {
        codes
            .map(Self)
            .find(|odr| (odr.hz() - hz).abs() <= 1e-9 * hz)
    }

    /// The rate in Hz.
    pub fn hz(self) -> f64 {
        1e9 / self.period_ns() as f64
    }

    /// The ODR code.
    pub const fn code(self) -> u8 {
        self.0
    }

    /// Sample period in ns (exact: 10 ms · 2^(8 − code)).
    pub const fn period_ns(self) -> u64 {
        if self.0 <= 8 {
            10_000_000 << (8 - self.0)
        } else {
            10_000_000 >> (self.0 - 8)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odr_periods() {
        assert_eq!(
            Odr::from_conf(0x01).map(Odr::period_ns),
            Some(1_280_000_000)
        );
        assert_eq!(Odr::HZ100.period_ns(), 10_000_000);
        assert_eq!(Odr::HZ800.period_ns(), 1_250_000);
        assert_eq!(Odr::HZ1600.period_ns(), 625_000);
        assert_eq!(Odr::HZ3200.period_ns(), 312_500);
        assert_eq!(Odr::from_conf(0x00), None);
        assert_eq!(Odr::from_conf(0x0E), None);
    }

    #[test]
    fn rates_by_hz() {
        assert_eq!(Odr::gyro_of_hz(3200.0), Some(Odr::HZ3200));
        assert_eq!(Odr::gyro_of_hz(25.0), Some(Odr::HZ25));
        assert_eq!(Odr::gyro_of_hz(12.5), None); // accel only
        assert_eq!(Odr::gyro_of_hz(6400.0), None); // pre-filtered FIFO data only
        assert_eq!(Odr::accel_of_hz(1600.0), Some(Odr::HZ1600));
        assert_eq!(Odr::accel_of_hz(3200.0), None);
        assert_eq!(Odr::accel_of_hz(0.78125).map(Odr::code), Some(1));
        assert_eq!(Odr::gyro_of_hz(1000.0), None);
        assert_eq!(AccRange::G4.range_g(), 4.0);
        assert_eq!(GyrRange::Dps125.range_dps(), 125.0);
    }

    #[test]
    fn range_codes_round_trip() {
        for r in AccRange::ALL {
            assert_eq!(AccRange::from_reg(r.bits()), r);
        }
        for r in GyrRange::ALL {
            assert_eq!(GyrRange::from_reg(r.bits()), r);
            assert_eq!(GyrRange::from_reg(r.bits() | 0x08), r); // OIS range bit
        }
        assert_eq!(AccRange::default(), AccRange::G8);
    }
}
