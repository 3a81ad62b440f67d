//! Full scales and output data rates (DS: gyroscope and accelerometer
//! specifications; register descriptions of GYRO_CONFIG0 and ACCEL_CONFIG0).

/// Accelerometer full scale, ACCEL_CONFIG0.ACCEL_FS_SEL (bits 7:5; codes 4–7 reserved, read as
/// ±2 g here).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelFs {
    /// ±16 g (code 0, the reset value), 2048 LSB/g.
    #[default]
    G16,
    /// ±8 g, 4096 LSB/g.
    G8,
    /// ±4 g, 8192 LSB/g.
    G4,
    /// ±2 g, 16384 LSB/g.
    G2,
}

impl AccelFs {
    /// Every full scale in code order.
    pub const ALL: [Self; 4] = [Self::G16, Self::G8, Self::G4, Self::G2];

    /// The full scale selected by an ACCEL_CONFIG0 value.
    pub const fn from_accel_config0(value: u8) -> Self {
        match value >> 5 {
            0 => Self::G16,
            1 => Self::G8,
            2 => Self::G4,
            _ => Self::G2,
        }
    }

    /// The ACCEL_FS_SEL code (bits 7:5 hold `code << 5`).
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Sensitivity, LSB per g.
    pub const fn lsb_per_g(self) -> f32 {
        match self {
            Self::G16 => 2048.0,
            Self::G8 => 4096.0,
            Self::G4 => 8192.0,
            Self::G2 => 16384.0,
        }
    }

    /// The range, ± g (2, 4, 8 or 16).
    pub fn range_g(self) -> f64 {
        32768.0 / f64::from(self.lsb_per_g())
    }
}

/// Gyroscope full scale, GYRO_CONFIG0.GYRO_FS_SEL (bits 7:5).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroFs {
    /// ±2000 °/s (code 0, the reset value), 16.4 LSB/(°/s).
    #[default]
    Dps2000,
    /// ±1000 °/s, 32.8.
    Dps1000,
    /// ±500 °/s, 65.5.
    Dps500,
    /// ±250 °/s, 131.
    Dps250,
    /// ±125 °/s, 262.
    Dps125,
    /// ±62.5 °/s, 524.3.
    Dps62_5,
    /// ±31.25 °/s, 1048.6.
    Dps31_25,
    /// ±15.625 °/s, 2097.2.
    Dps15_625,
}

impl GyroFs {
    /// Every full scale in code order.
    pub const ALL: [Self; 8] = [
        Self::Dps2000,
        Self::Dps1000,
        Self::Dps500,
        Self::Dps250,
        Self::Dps125,
        Self::Dps62_5,
        Self::Dps31_25,
        Self::Dps15_625,
    ];

    /// The full scale selected by a GYRO_CONFIG0 value.
    pub const fn from_gyro_config0(value: u8) -> Self {
        Self::ALL[(value >> 5) as usize & 0x07]
    }

    /// The GYRO_FS_SEL code (bits 7:5 hold `code << 5`).
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// Sensitivity, LSB per °/s (DS: gyroscope specifications).
    pub const fn lsb_per_dps(self) -> f32 {
        match self {
            Self::Dps2000 => 16.4,
            Self::Dps1000 => 32.8,
            Self::Dps500 => 65.5,
            Self::Dps250 => 131.0,
            Self::Dps125 => 262.0,
            Self::Dps62_5 => 524.3,
            Self::Dps31_25 => 1048.6,
            Self::Dps15_625 => 2097.2,
        }
    }

    /// The range, ± °/s: 2000 / 2^GYRO_FS_SEL (2000 down to 15.625).
    pub fn range_dps(self) -> f64 {
        2000.0 / f64::from(1u16 << self.bits())
    }
}

/// Output data rate, GYRO_CONFIG0.GYRO_ODR / ACCEL_CONFIG0.ACCEL_ODR (bits 3:0). Codes 0 and
/// (for the gyro) 12–14 are reserved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Odr {
    /// 32 kHz (code 1).
    Hz32k,
    /// 16 kHz (2).
    Hz16k,
    /// 8 kHz (3).
    Hz8k,
    /// 4 kHz (4).
    Hz4k,
    /// 2 kHz (5).
    Hz2k,
    /// 1 kHz (6, the reset value).
    Hz1k,
    /// 200 Hz (7).
    Hz200,
    /// 100 Hz (8).
    Hz100,
    /// 50 Hz (9).
    Hz50,
    /// 25 Hz (10).
    Hz25,
    /// 12.5 Hz (11).
    Hz12_5,
    /// 6.25 Hz (12, accelerometer only: low-power rates).
    Hz6_25,
    /// 3.125 Hz (13, accelerometer only).
    Hz3_125,
    /// 1.5625 Hz (14, accelerometer only).
    Hz1_5625,
    /// 500 Hz (15).
    Hz500,
}

impl Odr {
    /// The rate of an ODR code (bits 3:0 of `config0`), accelerometer codes included; `None`
    /// for the reserved code 0.
    pub const fn from_config0(config0: u8) -> Option<Self> {
        Some(match config0 & 0x0F {
            1 => Self::Hz32k,
            2 => Self::Hz16k,
            3 => Self::Hz8k,
            4 => Self::Hz4k,
            5 => Self::Hz2k,
            6 => Self::Hz1k,
            7 => Self::Hz200,
            8 => Self::Hz100,
            9 => Self::Hz50,
            10 => Self::Hz25,
            11 => Self::Hz12_5,
            12 => Self::Hz6_25,
            13 => Self::Hz3_125,
            14 => Self::Hz1_5625,
            15 => Self::Hz500,
            _ => return None,
        })
    }

    /// The rate of a GYRO_CONFIG0 value: as [`Odr::from_config0`] without the accel-only codes.
    pub const fn from_gyro_config0(config0: u8) -> Option<Self> {
        match Self::from_config0(config0) {
            Some(Self::Hz6_25 | Self::Hz3_125 | Self::Hz1_5625) => None,
            odr => odr,
        }
    }

    /// The gyro ODR of `hz` (within 1e-9 relative), if the gyro has one.
    pub fn gyro_of_hz(hz: f64) -> Option<Self> {
        (0..16u8)
            .filter_map(Self::from_gyro_config0)
            .find(|odr| (1e9 / odr.period_ns() as f64 - hz).abs() <= 1e-9 * hz)
    }

    /// The 4-bit ODR code.
    pub const fn bits(self) -> u8 {
        match self {
            Self::Hz32k => 1,
            Self::Hz16k => 2,
            Self::Hz8k => 3,
            Self::Hz4k => 4,
            Self::Hz2k => 5,
            Self::Hz1k => 6,
            Self::Hz200 => 7,
            Self::Hz100 => 8,
            Self::Hz50 => 9,
            Self::Hz25 => 10,
            Self::Hz12_5 => 11,
            Self::Hz6_25 => 12,
            Self::Hz3_125 => 13,
            Self::Hz1_5625 => 14,
            Self::Hz500 => 15,
        }
    }

    /// Nanoseconds between samples (exact for every code).
    pub const fn period_ns(self) -> u64 {
        match self {
            Self::Hz32k => 31_250,
            Self::Hz16k => 62_500,
            Self::Hz8k => 125_000,
            Self::Hz4k => 250_000,
            Self::Hz2k => 500_000,
            Self::Hz1k => 1_000_000,
            Self::Hz200 => 5_000_000,
            Self::Hz100 => 10_000_000,
            Self::Hz50 => 20_000_000,
            Self::Hz25 => 40_000_000,
            Self::Hz12_5 => 80_000_000,
            Self::Hz6_25 => 160_000_000,
            Self::Hz3_125 => 320_000_000,
            Self::Hz1_5625 => 640_000_000,
            Self::Hz500 => 2_000_000,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip() {
        for code in 0..16u8 {
            match Odr::from_config0(code) {
                Some(odr) => assert_eq!(odr.bits(), code),
                None => assert_eq!(code, 0),
            }
        }
        assert_eq!(Odr::from_gyro_config0(0x0C), None);
        assert_eq!(Odr::from_gyro_config0(0x0F), Some(Odr::Hz500));
        for fs in AccelFs::ALL {
            assert_eq!(AccelFs::from_accel_config0(fs.bits() << 5 | 0x06), fs);
        }
        for fs in GyroFs::ALL {
            assert_eq!(GyroFs::from_gyro_config0(fs.bits() << 5 | 0x06), fs);
        }
        assert_eq!(AccelFs::from_accel_config0(0xE0), AccelFs::G2);
    }
}
