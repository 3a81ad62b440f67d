//! The ICM-42688-P *register image* of one sample: what the host computes and the link carries
//! (source mode (a)), and what the firmware computes from a physical sample (mode (b)).
//!
//! Layout (32 bytes), each 16-bit part a verbatim copy of the registers it fills in the
//! power-on (big-endian) byte order; the chip applies INTF_CONFIG0.SENSOR_DATA_ENDIAN itself:
//!
//! | bytes  | registers (bank 0) | content                                                     |
//! |--------|--------------------|-------------------------------------------------------------|
//! | 0..2   | 0x1D..=0x1E        | TEMP_DATA1/0 — big-endian two's complement                  |
//! | 2..8   | 0x1F..=0x24        | ACCEL_DATA_X1/X0, Y, Z at the configured full scale         |
//! | 8..14  | 0x25..=0x2A        | GYRO_DATA_X1/X0, Y, Z at the configured full scale          |
//! | 14..23 | FIFO packet 4      | 20-bit accel x, y, z, 3 bytes each, big-endian, sign-extended |
//! | 23..32 | FIFO packet 4      | 20-bit gyro x, y, z, same                                   |
//!
//! The 20-bit values are those of [`convert::accel_to_raw20`] / [`convert::gyro_to_raw20`]
//! (fixed ±16 g / ±2000 °/s, low bits 0). [`ImageRepr::parse`] accepts every byte pattern: of
//! each 3-byte field it keeps bits 19:0, sign-extended.
//!
//! ```
//! use margemu_protocol::regmap::icm42688p::image::{ImageConfig, ImageRepr, IMAGE_LEN};
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 25.0, &ImageConfig::NOMINAL);
//! let bytes = repr.emit();
//! assert_eq!(bytes.len(), IMAGE_LEN);
//! assert_eq!(&bytes[6..8], &[0x08, 0x00]); // +1 g on z at ±16 g: 2048
//! assert_eq!(&bytes[20..23], &[0x00, 0x80, 0x00]); // 20-bit: 32768
//! assert_eq!(ImageRepr::parse(&bytes), repr);
//! ```
//!
//! [`convert::accel_to_raw20`]: super::convert::accel_to_raw20
//! [`convert::gyro_to_raw20`]: super::convert::gyro_to_raw20

use super::convert::{accel_to_raw, accel_to_raw20, gyro_to_raw, gyro_to_raw20, temp_to_raw};
use super::{AccelFs, GyroFs, DATA_LEN};

/// Length of a register image in bytes.
pub const IMAGE_LEN: usize = 32;

/// Byte ranges of the image's fields.
pub mod field {
    use core::ops::Range;
    /// TEMP_DATA1..=TEMP_DATA0.
    pub const TEMP: Range<usize> = 0..2;
    /// ACCEL_DATA_X1..=ACCEL_DATA_Z0.
    pub const ACCEL: Range<usize> = 2..8;
    /// GYRO_DATA_X1..=GYRO_DATA_Z0.
    pub const GYRO: Range<usize> = 8..14;
    /// The data registers 0x1D..=0x2A in order.
    pub const REGISTERS: Range<usize> = 0..14;
    /// 20-bit accel x, y, z.
    pub const ACCEL20: Range<usize> = 14..23;
    /// 20-bit gyro x, y, z.
    pub const GYRO20: Range<usize> = 23..32;
}

/// The register settings a conversion depends on. `Default` is [`ImageConfig::NOMINAL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageConfig {
    /// ACCEL_CONFIG0 full scale.
    pub accel_fs: AccelFs,
    /// GYRO_CONFIG0 full scale.
    pub gyro_fs: GyroFs,
}

impl ImageConfig {
    /// The power-on settings: ±16 g, ±2000 °/s.
    pub const NOMINAL: Self = Self {
        accel_fs: AccelFs::G16,
        gyro_fs: GyroFs::Dps2000,
    };
}

/// One sample's register values, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageRepr {
    /// TEMP_DATA.
    pub temp: i16,
    /// ACCEL_DATA_X, Y, Z.
    pub accel: [i16; 3],
    /// GYRO_DATA_X, Y, Z.
    pub gyro: [i16; 3],
    /// 20-bit FIFO accel x, y, z.
    pub accel20: [i32; 3],
    /// 20-bit FIFO gyro x, y, z.
    pub gyro20: [i32; 3],
}

impl ImageRepr {
    /// Converts a physical sample in the chip's axes: specific force `acc` (m/s²), angular rate
    /// `gyr` (rad/s), die temperature `temp_c` (°C).
    pub fn from_physical(acc: [f32; 3], gyr: [f32; 3], temp_c: f32, cfg: &ImageConfig) -> Self {
        Self {
            temp: temp_to_raw(temp_c),
            accel: acc.map(|a| accel_to_raw(a, cfg.accel_fs)),
            gyro: gyr.map(|w| gyro_to_raw(w, cfg.gyro_fs)),
            accel20: acc.map(accel_to_raw20),
            gyro20: gyr.map(gyro_to_raw20),
        }
    }

    /// Decodes an image (every byte pattern is valid).
    pub fn parse(bytes: &[u8; IMAGE_LEN]) -> Self {
        let be16 = |at: usize| i16::from_be_bytes([bytes[at], bytes[at + 1]]);
        let be20 = |at: usize| {
            let raw = u32::from_be_bytes([0, bytes[at], bytes[at + 1], bytes[at + 2]]);
            super::convert::sign_extend20(raw & 0xF_FFFF)
        };
        Self {
            temp: be16(field::TEMP.start),
            accel: core::array::from_fn(|i| be16(field::ACCEL.start + 2 * i)),
            gyro: core::array::from_fn(|i| be16(field::GYRO.start + 2 * i)),
            accel20: core::array::from_fn(|i| be20(field::ACCEL20.start + 3 * i)),
            gyro20: core::array::from_fn(|i| be20(field::GYRO20.start + 3 * i)),
        }
    }

    /// Encodes the image.
    pub fn emit(&self) -> [u8; IMAGE_LEN] {
        let mut out = [0u8; IMAGE_LEN];
        out[field::REGISTERS].copy_from_slice(&self.registers());
        let values = self.accel20.iter().chain(self.gyro20.iter());
        for (chunk, v) in out[field::ACCEL20.start..].chunks_exact_mut(3).zip(values) {
            let [_, a, b, c] = v.to_be_bytes();
            chunk.copy_from_slice(&[a, b, c]);
        }
        out
    }

    /// The 14 bytes of registers 0x1D..=0x2A in big-endian order.
    pub fn registers(&self) -> [u8; DATA_LEN] {
        let mut out = [0u8; DATA_LEN];
        let values = [self.temp].into_iter().chain(self.accel).chain(self.gyro);
        for (pair, v) in out.chunks_exact_mut(2).zip(values) {
            pair.copy_from_slice(&v.to_be_bytes());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_byte_by_byte() {
        let repr = ImageRepr {
            temp: -32768,
            accel: [0x0102, -2, 0x7FFF],
            gyro: [0x1122, 0x3344, -0x5566],
            accel20: [4, -4, -524288],
            gyro20: [0x7FFFE, -2, 0x12344],
        };
        let bytes = repr.emit();
        assert_eq!(
            bytes,
            [
                0x80, 0x00, // temp
                0x01, 0x02, 0xFF, 0xFE, 0x7F, 0xFF, // accel
                0x11, 0x22, 0x33, 0x44, 0xAA, 0x9A, // gyro
                0x00, 0x00, 0x04, 0xFF, 0xFF, 0xFC, 0xF8, 0x00, 0x00, // accel20
                0x07, 0xFF, 0xFE, 0xFF, 0xFF, 0xFE, 0x01, 0x23, 0x44, // gyro20
            ]
        );
        assert_eq!(ImageRepr::parse(&bytes), repr);
    }

    #[test]
    fn parse_accepts_any_bytes() {
        let repr = ImageRepr::parse(&[0xFF; IMAGE_LEN]);
        assert_eq!(
            (repr.temp, repr.accel20, repr.gyro20),
            (-1, [-1; 3], [-1; 3])
        );
        let mut bytes = [0u8; IMAGE_LEN];
        bytes[14] = 0x70; // bits 23:20 are not part of the value
        assert_eq!(ImageRepr::parse(&bytes), ImageRepr::default());
    }

    #[test]
    fn from_physical_uses_the_full_scales() {
        let cfg = ImageConfig {
            accel_fs: AccelFs::G2,
            gyro_fs: GyroFs::Dps250,
        };
        let dps = core::f32::consts::PI / 180.0;
        let r = ImageRepr::from_physical([9.80665, 0.0, -9.80665], [dps, 0.0, 0.0], 26.0, &cfg);
        assert_eq!(r.accel, [16384, 0, -16384]);
        assert_eq!(r.gyro, [131, 0, 0]);
        assert_eq!(r.temp, 132);
        assert_eq!(r.accel20, [32768, 0, -32768]);
        assert_eq!(r.gyro20, [262, 0, 0]);
    }
}
