//! The BMI270 *register image* of one sample: what the host computes and the link carries
//! (source mode (a)), and what the firmware computes from a physical sample (mode (b)).
//!
//! Layout (14 bytes), a verbatim copy of the registers a sample fills, in their own
//! little-endian order (DS: 5.2 DATA_8..19, TEMPERATURE_0/1):
//!
//! | bytes  | registers    | content                                                        |
//! |--------|--------------|----------------------------------------------------------------|
//! | 0..6   | 0x0C..=0x11  | ACC_X/Y/Z, LSB first, at the configured ACC_RANGE              |
//! | 6..12  | 0x12..=0x17  | GYR_X/Y/Z, LSB first, at the configured GYR_RANGE              |
//! | 12..14 | 0x22..=0x23  | TEMPERATURE, LSB first, 1/512 K per LSB, 0 = 23 °C             |
//!
//! Nothing else is needed to latch a sample exactly: the FIFO frames carry the same 16-bit
//! values as the data registers (DS: 4.7 FIFO, frame formats; filtered data, the only kind
//! emulated), and SENSORTIME comes from the chip's own clock. The image always holds both
//! sensors and the temperature; the chip decides which of them a latch takes (the accel at its
//! own ODR, the temperature every 10 ms, nothing before the configuration upload: see
//! `margemu_firmware::chip::bmi270`).
//!
//! ```
//! use margemu_protocol::regmap::bmi270::image::{ImageConfig, ImageRepr, IMAGE_LEN};
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 24.0, &ImageConfig::NOMINAL);
//! let bytes = repr.emit();
//! assert_eq!(bytes.len(), IMAGE_LEN);
//! assert_eq!(&bytes[4..6], &[0x00, 0x10]); // +1 g on z at ±8 g: 4096, LSB first
//! assert_eq!(&bytes[12..14], &[0x00, 0x02]); // 24 °C: 512
//! assert_eq!(ImageRepr::parse(&bytes), repr);
//! ```

use super::convert::{accel_to_raw, gyro_to_raw, temp_to_raw};
use super::{AccRange, GyrRange, DATA_LEN};

/// Length of a register image in bytes.
pub const IMAGE_LEN: usize = DATA_LEN + 2;

/// Byte ranges of the image's fields.
pub mod field {
    use core::ops::Range;
    /// ACC_X..=ACC_Z (0x0C..=0x11).
    pub const ACCEL: Range<usize> = 0..6;
    /// GYR_X..=GYR_Z (0x12..=0x17).
    pub const GYRO: Range<usize> = 6..12;
    /// The data registers 0x0C..=0x17 in order.
    pub const DATA: Range<usize> = 0..12;
    /// TEMPERATURE_0..=TEMPERATURE_1 (0x22..=0x23).
    pub const TEMP: Range<usize> = 12..14;
}

/// The register settings a conversion depends on. `Default` is [`ImageConfig::NOMINAL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageConfig {
    /// ACC_RANGE.
    pub acc_range: AccRange,
    /// GYR_RANGE.
    pub gyr_range: GyrRange,
}

impl ImageConfig {
    /// The power-on settings: ±8 g, ±2000 °/s.
    pub const NOMINAL: Self = Self {
        acc_range: AccRange::G8,
        gyr_range: GyrRange::Dps2000,
    };
}

/// One sample's register values, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageRepr {
    /// ACC_X, Y, Z.
    pub accel: [i16; 3],
    /// GYR_X, Y, Z.
    pub gyro: [i16; 3],
    /// TEMPERATURE (−32768, 0x8000, marks an invalid value and is never converted to).
    pub temp: i16,
}

impl ImageRepr {
    /// Converts a physical sample in the chip's axes: specific force `acc` (m/s²), angular rate
    /// `gyr` (rad/s), die temperature `temp_c` (°C).
    pub fn from_physical(acc: [f32; 3], gyr: [f32; 3], temp_c: f32, cfg: &ImageConfig) -> Self {
        Self {
            accel: acc.map(|a| accel_to_raw(a, cfg.acc_range)),
            gyro: gyr.map(|w| gyro_to_raw(w, cfg.gyr_range)),
            temp: temp_to_raw(temp_c),
        }
    }

    /// Decodes an image (every byte pattern is valid).
    pub fn parse(bytes: &[u8; IMAGE_LEN]) -> Self {
        let le16 = |at: usize| i16::from_le_bytes([bytes[at], bytes[at + 1]]);
        Self {
            accel: core::array::from_fn(|i| le16(field::ACCEL.start + 2 * i)),
            gyro: core::array::from_fn(|i| le16(field::GYRO.start + 2 * i)),
            temp: le16(field::TEMP.start),
        }
    }

    /// Encodes the image.
    pub fn emit(&self) -> [u8; IMAGE_LEN] {
        let mut out = [0u8; IMAGE_LEN];
        let values = self.accel.iter().chain(&self.gyro).chain([&self.temp]);
        for (pair, v) in out.chunks_exact_mut(2).zip(values) {
            pair.copy_from_slice(&v.to_le_bytes());
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
            accel: [0x0102, -2, 0x7FFF],
            gyro: [0x1122, 0x3344, -0x5566],
            temp: -32767,
        };
        let bytes = repr.emit();
        assert_eq!(
            bytes,
            [
                0x02, 0x01, 0xFE, 0xFF, 0xFF, 0x7F, // accel
                0x22, 0x11, 0x44, 0x33, 0x9A, 0xAA, // gyro
                0x01, 0x80, // temperature
            ]
        );
        assert_eq!(ImageRepr::parse(&bytes), repr);
        assert_eq!(ImageRepr::parse(&[0xFF; IMAGE_LEN]).temp, -1);
    }

    #[test]
    fn from_physical_uses_the_ranges() {
        let cfg = ImageConfig {
            acc_range: AccRange::G2,
            gyr_range: GyrRange::Dps125,
        };
        let dps = core::f32::consts::PI / 180.0;
        let r = ImageRepr::from_physical([9.80665, 0.0, -9.80665], [dps, 0.0, 0.0], 22.0, &cfg);
        assert_eq!(r.accel, [16384, 0, -16384]);
        assert_eq!(r.gyro, [262, 0, 0]);
        assert_eq!(r.temp, -512);
        let at_rest = ImageRepr::from_physical([0.0; 3], [0.0; 3], -500.0, &ImageConfig::NOMINAL);
        assert_eq!(at_rest.temp, -32767, "never the invalid code");
    }
}
