//! The MPU-9250 + AK8963 *register image*: what one sample puts into the data registers, as the
//! host sends it in source mode (a) and as the firmware computes it from a physical sample.
//!
//! The link carries it as an opaque `[u8; IMAGE_LEN]`. Layout (22 bytes), each part a verbatim
//! copy of the registers it fills, so neither side reorders bytes:
//!
//! | bytes  | registers                | content                                               |
//! |--------|--------------------------|-------------------------------------------------------|
//! | 0..6   | MPU 0x3B..=0x40          | ACCEL_XOUT_H/L, Y, Z — big-endian two's complement    |
//! | 6..8   | MPU 0x41..=0x42          | TEMP_OUT_H/L                                          |
//! | 8..14  | MPU 0x43..=0x48          | GYRO_XOUT_H/L, Y, Z                                   |
//! | 14     | AK8963 0x02 ST1          | 0x01 (DRDY, as after a measurement); ignored on input |
//! | 15..21 | AK8963 0x03..=0x08       | HXL, HXH, HYL, HYH, HZL, HZH — little-endian, AK axes |
//! | 21     | AK8963 0x09 ST2          | HOFL (bit 3) and BITM (bit 4) of this measurement     |
//!
//! The magnetometer part is the measurement the AK8963 *would* store if it measured now; the
//! chip takes it only when its own 8/100 Hz schedule (or a single measurement) completes, and
//! computes DRDY/DOR itself.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr, IMAGE_LEN};
//! let cfg = ImageConfig::default(); // ±2 g, ±250 °/s, 14-bit, ASA 128
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 21.0, [0.6, 0.0, 0.0], &cfg);
//! let bytes = repr.emit();
//! assert_eq!(bytes.len(), IMAGE_LEN);
//! assert_eq!(&bytes[4..6], &[0x40, 0x00]); // +1 g on z at ±2 g: 16384
//! assert_eq!(&bytes[15..21], &[0, 0, 1, 0, 0, 0]); // MPU x → AK y
//! assert_eq!(ImageRepr::parse(&bytes), repr);
//! ```

use core::ops::Range;

use super::convert::{
    accel_to_raw_with_offset, gyro_to_raw_with_offset, mag_axes_to_mpu, mag_from_raw,
    mag_measurement, STANDARD_GRAVITY,
};
use super::variant::TempScale;
use super::{AccelFs, GyroFs};
use crate::regmap::ak8963::{self, MagBits};

/// Length of a register image in bytes (a part with the AK8963).
pub const IMAGE_LEN: usize = 22;

/// Length of the image of a part without magnetometer (MPU-6000, MPU-6500, ICM-20602): the
/// first [`field::SENSORS`] bytes alone.
pub const SENSORS_LEN: usize = 14;

/// Byte ranges of the image's fields.
pub mod field {
    use core::ops::Range;
    /// ACCEL_XOUT_H..=ACCEL_ZOUT_L.
    pub const ACCEL: Range<usize> = 0..6;
    /// TEMP_OUT_H..=TEMP_OUT_L.
    pub const TEMP: Range<usize> = 6..8;
    /// GYRO_XOUT_H..=GYRO_ZOUT_L.
    pub const GYRO: Range<usize> = 8..14;
    /// The MPU-9250 part, registers 0x3B..=0x48 in order.
    pub const SENSORS: Range<usize> = 0..14;
    /// AK8963 ST1.
    pub const ST1: usize = 14;
    /// AK8963 HXL..=HZH.
    pub const MAG: Range<usize> = 15..21;
    /// AK8963 ST2.
    pub const ST2: usize = 21;
}

/// The register settings a conversion depends on. `Default` is [`ImageConfig::NOMINAL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageConfig {
    /// ACCEL_CONFIG full scale.
    pub accel_fs: AccelFs,
    /// GYRO_CONFIG full scale.
    pub gyro_fs: GyroFs,
    /// AK8963 CNTL1.BIT.
    pub mag_bits: MagBits,
    /// AK8963 fuse ROM ASAX, ASAY, ASAZ.
    pub asa: [u8; 3],
    /// Gyro user offsets XG/YG/ZG_OFFSET_H:L (X/Y/Z_OFFS_USR).
    pub gyro_offset: [i16; 3],
    /// How far XA/YA/ZA_OFFSET_H:L were moved from the factory trim (16-bit register units).
    pub accel_offset: [i16; 3],
    /// The part's temperature sensor scale.
    pub temp: TempScale,
}

impl ImageConfig {
    /// Settings after power-on with nominal fuse ROM values (ASA = 128, factor 1).
    pub const NOMINAL: Self = Self {
        accel_fs: AccelFs::G2,
        gyro_fs: GyroFs::Dps250,
        mag_bits: MagBits::Bits14,
        asa: [128; 3],
        gyro_offset: [0; 3],
        accel_offset: [0; 3],
        temp: TempScale::Mpu6500,
    };
}

impl Default for ImageConfig {
    fn default() -> Self {
        Self::NOMINAL
    }
}

/// One sample's register values, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ImageRepr {
    /// ACCEL_XOUT, ACCEL_YOUT, ACCEL_ZOUT.
    pub accel: [i16; 3],
    /// TEMP_OUT.
    pub temp: i16,
    /// GYRO_XOUT, GYRO_YOUT, GYRO_ZOUT.
    pub gyro: [i16; 3],
    /// AK8963 HX, HY, HZ (AK8963 axes).
    pub mag: [i16; 3],
    /// AK8963 ST2.HOFL.
    pub mag_overflow: bool,
    /// AK8963 ST2.BITM (16-bit output).
    pub mag_16bit: bool,
}

impl ImageRepr {
    /// Converts a physical sample in the MPU-9250's accel/gyro axes: specific force `acc` (m/s²),
    /// angular rate `gyr` (rad/s), die temperature `temp_c` (°C) and magnetic field `mag_ut` (µT;
    /// the AK8963 axis swap is applied here).
    pub fn from_physical(
        acc: [f32; 3],
        gyr: [f32; 3],
        temp_c: f32,
        mag_ut: [f32; 3],
        cfg: &ImageConfig,
    ) -> Self {
        let (mag, mag_overflow) = mag_measurement(mag_ut, cfg.asa, cfg.mag_bits);
        Self {
            accel: core::array::from_fn(|i| {
                accel_to_raw_with_offset(acc[i], cfg.accel_fs, cfg.accel_offset[i])
            }),
            temp: cfg.temp.to_raw(temp_c),
            gyro: core::array::from_fn(|i| {
                gyro_to_raw_with_offset(gyr[i], cfg.gyro_fs, cfg.gyro_offset[i])
            }),
            mag,
            mag_overflow,
            mag_16bit: cfg.mag_bits == MagBits::Bits16,
        }
    }

    /// Decodes an image (every byte pattern is valid).
    pub fn parse(bytes: &[u8; IMAGE_LEN]) -> Self {
        let be = |r: Range<usize>| -> [i16; 3] {
            core::array::from_fn(|i| {
                i16::from_be_bytes([bytes[r.start + 2 * i], bytes[r.start + 2 * i + 1]])
            })
        };
        let st2 = bytes[field::ST2];
        Self {
            accel: be(field::ACCEL),
            temp: i16::from_be_bytes([bytes[field::TEMP.start], bytes[field::TEMP.start + 1]]),
            gyro: be(field::GYRO),
            mag: core::array::from_fn(|i| {
                i16::from_le_bytes([
                    bytes[field::MAG.start + 2 * i],
                    bytes[field::MAG.start + 2 * i + 1],
                ])
            }),
            mag_overflow: st2 & ak8963::bits::ST2_HOFL != 0,
            mag_16bit: st2 & ak8963::bits::ST2_BITM != 0,
        }
    }

    /// Encodes the image.
    pub fn emit(&self) -> [u8; IMAGE_LEN] {
        let mut out = [0u8; IMAGE_LEN];
        self.emit_sensors(&mut out[field::SENSORS]);
        out[field::ST1] = ak8963::bits::ST1_DRDY;
        for (i, v) in self.mag.iter().enumerate() {
            out[field::MAG.start + 2 * i..][..2].copy_from_slice(&v.to_le_bytes());
        }
        out[field::ST2] = self.st2();
        out
    }

    /// Writes the 14 bytes of registers 0x3B..=0x48 to `out[..14]` (does nothing if shorter).
    pub fn emit_sensors(&self, out: &mut [u8]) {
        let Some(out) = out.get_mut(..14) else { return };
        for (i, v) in self.accel.iter().enumerate() {
            out[2 * i..][..2].copy_from_slice(&v.to_be_bytes());
        }
        out[6..8].copy_from_slice(&self.temp.to_be_bytes());
        for (i, v) in self.gyro.iter().enumerate() {
            out[8 + 2 * i..][..2].copy_from_slice(&v.to_be_bytes());
        }
    }

    /// The AK8963 data registers HXL..=HZH of this measurement.
    pub fn mag_bytes(&self) -> [u8; 6] {
        let [x, y, z] = self.mag.map(i16::to_le_bytes);
        [x[0], x[1], y[0], y[1], z[0], z[1]]
    }

    /// AK8963 ST2 of this measurement (HOFL, BITM).
    pub fn st2(&self) -> u8 {
        let mut st2 = 0;
        if self.mag_overflow {
            st2 |= ak8963::bits::ST2_HOFL;
        }
        if self.mag_16bit {
            st2 |= ak8963::bits::ST2_BITM;
        }
        st2
    }
}

/// One image decoded back to physical units (the inverse of [`ImageRepr::from_physical`] to
/// within one LSB; what the chip clipped stays clipped).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Physical {
    /// Specific force (m/s²), MPU axes.
    pub acc: [f64; 3],
    /// Angular rate (rad/s), MPU axes.
    pub gyr: [f64; 3],
    /// Die temperature (°C).
    pub temp_c: f64,
    /// Magnetic field (µT), back in the MPU's accel/gyro axes.
    pub mag_ut: [f64; 3],
}

impl ImageRepr {
    /// The physical values these register values stand for under `cfg`: accel and gyro user
    /// offsets removed, the AK8963's sensitivity adjustment (ASA) applied and its axes mapped
    /// back to the MPU's (`x = y_ak, y = x_ak, z = −z_ak`).
    pub fn to_physical(&self, cfg: &ImageConfig) -> Physical {
        let lsb_per_g = f64::from(cfg.accel_fs.lsb_per_g());
        let lsb_per_radps = f64::from(cfg.gyro_fs.lsb_per_dps()) * 180.0 / core::f64::consts::PI;
        let gyro_offset_lsb =
            |i: usize| f64::from(cfg.gyro_offset[i]) * 4.0 / f64::from(1u8 << cfg.gyro_fs.bits());
        Physical {
            acc: core::array::from_fn(|i| {
                let offset = f64::from(cfg.accel_offset[i] & !1) * lsb_per_g / 2048.0;
                (f64::from(self.accel[i]) - offset) / lsb_per_g * f64::from(STANDARD_GRAVITY)
            }),
            gyr: core::array::from_fn(|i| {
                (f64::from(self.gyro[i]) - gyro_offset_lsb(i)) / lsb_per_radps
            }),
            temp_c: cfg.temp.from_raw(self.temp),
            mag_ut: mag_axes_to_mpu(self.mag_ut_sensor_axes(cfg)),
        }
    }

    /// The magnetic field of these register values in µT in the AK8963's own axes, its
    /// sensitivity adjustment (ASA of `cfg`) applied: what a driver reads before it turns the
    /// field into the accel/gyro axes ([`to_physical`](Self::to_physical) does that turn).
    pub fn mag_ut_sensor_axes(&self, cfg: &ImageConfig) -> [f64; 3] {
        core::array::from_fn(|i| mag_from_raw(self.mag[i], cfg.asa[i], cfg.mag_bits))
    }

    /// Decodes one FIFO record of the MARG layout ([`fifo`](super::fifo)): the sensor bytes,
    /// then slave 0's seven AK8963 bytes HXL..=HZH, ST2 (ST1 is not in the record; it reads
    /// as DRDY, as in an image). Every byte pattern is valid.
    pub fn parse_marg_record(record: &[u8; super::fifo::MARG_RECORD_LEN]) -> Self {
        let mut image = [0u8; IMAGE_LEN];
        image[field::SENSORS].copy_from_slice(&record[field::SENSORS]);
        image[field::ST1] = ak8963::bits::ST1_DRDY;
        image[field::MAG.start..=field::ST2].copy_from_slice(&record[field::SENSORS.end..]);
        Self::parse(&image)
    }

    /// Decodes the first [`SENSORS_LEN`] bytes and, when present, the AK8963 block of an image
    /// of either length (a shorter slice is zero-padded).
    pub fn parse_slice(bytes: &[u8]) -> Self {
        let mut full = [0u8; IMAGE_LEN];
        let n = bytes.len().min(IMAGE_LEN);
        full[..n].copy_from_slice(&bytes[..n]);
        Self::parse(&full)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_byte_by_byte() {
        let repr = ImageRepr {
            accel: [0x0102, -2, 0x7FFF],
            temp: -32768,
            gyro: [0x1122, 0x3344, -0x5566],
            mag: [0x0102, -1, 0x7FF8],
            mag_overflow: true,
            mag_16bit: true,
        };
        let bytes = repr.emit();
        assert_eq!(
            bytes,
            [
                0x01, 0x02, 0xFF, 0xFE, 0x7F, 0xFF, // accel
                0x80, 0x00, // temp
                0x11, 0x22, 0x33, 0x44, 0xAA, 0x9A, // gyro
                0x01, // ST1
                0x02, 0x01, 0xFF, 0xFF, 0xF8, 0x7F, // HXL..HZH
                0x18, // ST2: HOFL | BITM
            ]
        );
        assert_eq!(ImageRepr::parse(&bytes), repr);
    }

    #[test]
    fn parse_accepts_any_bytes() {
        let repr = ImageRepr::parse(&[0xFF; IMAGE_LEN]);
        assert_eq!(repr.accel, [-1; 3]);
        assert!(repr.mag_overflow && repr.mag_16bit);
        assert_eq!(ImageRepr::parse(&[0; IMAGE_LEN]), ImageRepr::default());
    }

    #[test]
    fn from_physical_uses_every_setting() {
        let cfg = ImageConfig {
            accel_fs: AccelFs::G16,
            gyro_fs: GyroFs::Dps2000,
            mag_bits: MagBits::Bits16,
            ..ImageConfig::NOMINAL
        };
        let one_dps = core::f32::consts::PI / 180.0;
        let r = ImageRepr::from_physical(
            [9.80665, -9.80665, 0.0],
            [10.0 * one_dps, 0.0, -10.0 * one_dps],
            22.0,
            [15.0, 30.0, 45.0],
            &cfg,
        );
        assert_eq!(r.accel, [2048, -2048, 0]);
        assert_eq!(r.gyro, [164, 0, -164]);
        assert_eq!(r.temp, 334);
        assert_eq!(r.mag, [200, 100, -300]);
        assert!(r.mag_16bit && !r.mag_overflow);
        assert_eq!(r.st2(), 0x10);
    }
}
