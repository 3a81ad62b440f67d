//! The BMI088 *register image* of one sample: what the host computes and the link carries
//! (source mode (a)), and what the firmware computes from a physical sample (mode (b)).
//!
//! Layout (14 bytes), a verbatim copy of the registers a sample fills on both dies, each in
//! its own register order (DS 5.3.4 ACC data, 5.5.2 RATE data, 5.3.7 TEMP):
//!
//! | bytes  | die, registers            | content                                                  |
//! |--------|---------------------------|----------------------------------------------------------|
//! | 0..6   | accel 0x12..=0x17         | ACC_X/Y/Z, LSB first, at the configured ACC_RANGE        |
//! | 6..12  | gyro 0x02..=0x07          | RATE_X/Y/Z, LSB first, at the configured GYRO_RANGE      |
//! | 12..14 | accel 0x22, 0x23          | TEMP_MSB (bits 10:3), TEMP_LSB (bits 2:0 in bits 7:5)    |
//!
//! Nothing else is needed to latch one sample exactly: the FIFO frames of both dies carry the
//! same 16-bit values as the data registers (AN 3.2.1, 4.2), and SENSORTIME comes from the
//! accelerometer die's own clock. The image always holds both sensors and the temperature;
//! the chip decides what a latch takes (the gyro every served sample, the accel at its own ODR,
//! the temperature every 1.28 s, nothing of a die that is off: see
//! `margemu_firmware::chip::bmi088`).
//!
//! ```
//! use margemu_protocol::regmap::bmi088::image::{ImageConfig, ImageRepr, IMAGE_LEN};
//! let dps = core::f32::consts::PI / 180.0;
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0, 0.0, dps], 24.0, &ImageConfig::NOMINAL);
//! let bytes = repr.emit();
//! assert_eq!(bytes.len(), IMAGE_LEN);
//! assert_eq!(&bytes[4..6], &[0x55, 0x15]); // +1 g on z at ±6 g: 5461, LSB first
//! assert_eq!(&bytes[10..12], &[0x10, 0x00]); // 1 °/s at ±2000 °/s: 16
//! assert_eq!(&bytes[12..14], &[0x01, 0x00]); // 24 °C: 8 (0.125 K per LSB)
//! assert_eq!(ImageRepr::parse(&bytes), repr);
//! ```

use super::accel::{AccRange, DATA_LEN};
use super::convert::{accel_to_raw, gyro_to_raw, temp_bytes, temp_to_raw};
use super::gyro::GyroRange;

/// Length of a register image in bytes: accel and gyro data, temperature.
pub const IMAGE_LEN: usize = 2 * DATA_LEN + 2;

/// Byte ranges of the image's fields.
pub mod field {
    use core::ops::Range;
    /// ACC_X..=ACC_Z (accel die 0x12..=0x17).
    pub const ACCEL: Range<usize> = 0..6;
    /// RATE_X..=RATE_Z (gyro die 0x02..=0x07).
    pub const GYRO: Range<usize> = 6..12;
    /// TEMP_MSB, TEMP_LSB (accel die 0x22, 0x23).
    pub const TEMP: Range<usize> = 12..14;
}

/// The register settings a conversion depends on. `Default` is [`ImageConfig::NOMINAL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageConfig {
    /// ACC_RANGE (accel die).
    pub acc_range: AccRange,
    /// GYRO_RANGE (gyro die).
    pub gyr_range: GyroRange,
}

impl ImageConfig {
    /// The power-on settings: ±6 g, ±2000 °/s.
    pub const NOMINAL: Self = Self {
        acc_range: AccRange::G6,
        gyr_range: GyroRange::Dps2000,
    };
}

/// One sample's register values, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageRepr {
    /// ACC_X, Y, Z.
    pub accel: [i16; 3],
    /// RATE_X, Y, Z.
    pub gyro: [i16; 3],
    /// The 11-bit temperature value (−1024, TEMP_MSB 0x80, marks an invalid value and is never
    /// converted to).
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

    /// Decodes an image (every byte pattern is valid; TEMP_LSB bits 4:0 are ignored).
    pub fn parse(bytes: &[u8; IMAGE_LEN]) -> Self {
        let le16 = |at: usize| i16::from_le_bytes([bytes[at], bytes[at + 1]]);
        let [msb, lsb] = [bytes[field::TEMP.start], bytes[field::TEMP.start + 1]];
        // Bits 10:3 from TEMP_MSB, 2:0 from TEMP_LSB bits 7:5, sign-extended from bit 10.
        let u11 = (u16::from(msb) << 3) | (u16::from(lsb) >> 5);
        Self {
            accel: core::array::from_fn(|i| le16(field::ACCEL.start + 2 * i)),
            gyro: core::array::from_fn(|i| le16(field::GYRO.start + 2 * i)),
            temp: ((u11 << 5) as i16) >> 5,
        }
    }

    /// Encodes the image.
    pub fn emit(&self) -> [u8; IMAGE_LEN] {
        let mut out = [0u8; IMAGE_LEN];
        let data = self.accel.iter().chain(&self.gyro);
        for (pair, v) in out.chunks_exact_mut(2).zip(data) {
            pair.copy_from_slice(&v.to_le_bytes());
        }
        let [msb, lsb] = temp_bytes(self.temp);
        out[field::TEMP.start] = msb;
        out[field::TEMP.start + 1] = lsb;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regmap::bmi088::convert::temp_from_bytes;

    #[test]
    fn layout_byte_by_byte() {
        let repr = ImageRepr {
            accel: [0x0102, -2, 0x7FFF],
            gyro: [0x1122, 0x3344, -0x5566],
            temp: -1023,
        };
        let bytes = repr.emit();
        assert_eq!(
            bytes,
            [
                0x02, 0x01, 0xFE, 0xFF, 0xFF, 0x7F, // accel
                0x22, 0x11, 0x44, 0x33, 0x9A, 0xAA, // gyro
                0x80, 0x20, // temperature: 0x401 (11 bits) = -1023
            ]
        );
        assert_eq!(ImageRepr::parse(&bytes), repr);
        assert_eq!(ImageRepr::parse(&[0xFF; IMAGE_LEN]).temp, -1);
        assert_eq!(ImageRepr::parse(&[0x7F; IMAGE_LEN]).temp, 1019);
    }

    #[test]
    fn from_physical_uses_the_ranges_and_the_ds_temperature() {
        let cfg = ImageConfig {
            acc_range: AccRange::G3,
            gyr_range: GyroRange::Dps125,
        };
        let dps = core::f32::consts::PI / 180.0;
        let r = ImageRepr::from_physical([9.80665, 0.0, -9.80665], [dps, 0.0, 0.0], 85.0, &cfg);
        assert_eq!(r.accel, [10923, 0, -10923]);
        assert_eq!(r.gyro, [262, 0, 0]);
        let bytes = r.emit();
        assert_eq!(temp_from_bytes([bytes[12], bytes[13]]), Some(85.0));
        let cold = ImageRepr::from_physical([0.0; 3], [0.0; 3], -500.0, &ImageConfig::NOMINAL);
        assert_eq!(cold.temp, -1023, "never the invalid code");
    }
}
