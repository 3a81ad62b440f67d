//! The dropout fault in a register image: each chip's own "no valid sample" value written into
//! the data of the sensors that dropped out ([`super::ChipSettings::mark_invalid`]).
//!
//! Sensor bits are those of `margemu_model::fault::Sensor::bit`: bit 0 the accelerometer,
//! bit 1 the gyroscope, bit 2 the magnetometer. Per family:
//!
//! - **InvenSense 6xxx** (MPU-9250, MPU-6500, MPU-6000, ICM-20602): −32768 (0x8000) in the
//!   sensor's ACCEL_*OUT or GYRO_*OUT registers, the value the InvenSense parts use for a sample
//!   that is not valid (the same code the ICM-42688-P datasheet names). The MPU-9250's
//!   magnetometer is the AK8963's: a dropout sets ST2.HOFL, the AK8963's own "this measurement
//!   is not correct" flag (AK8963 datasheet §6.4.3.6 magnetic sensor overflow, §8.3.5 ST2),
//!   which drivers check before they use the data; the data registers keep the measurement.
//! - **ICM-42688-P**: −32768 in ACCEL_DATA / GYRO_DATA and −524288 in the 20-bit FIFO fields
//!   (DS-000347 §4.11 Sensor Data Registers, and the FIFO packet structure in §6: −32768 marks
//!   an invalid 16-bit sample, as the data registers of a sensor that is off read — TDK's
//!   forum thread "42688P sensor register data always 0x8000" shows the same — and the most
//!   negative 20-bit code an invalid 20-bit one; [`crate::regmap::icm42688p::convert::INVALID16`],
//!   `INVALID20`).
//! - **BMI270, BMI088**: their datasheets define an invalid code for the temperature only
//!   (BMI270 TEMPERATURE 0x8000, BMI088 TEMP_MSB 0x80); for accel and gyro data they define
//!   none (a driver sees missing data through the DRDY bits, which the chip computes). margemu
//!   writes −32768 (bytes 0x00, 0x80, LSB first), the format's most negative value, as the
//!   BMI270 does for its temperature: a convention, not a datasheet value.
//! - **QMC5883L**: −32768, the value its outputs saturate to on overflow (DS §9.2.2: OVL is set
//!   and each axis saturates at −32768 or 32767).
//! - **IST8310**: its datasheet defines no invalid code; −32768 likewise (a convention).
//! - **RM3100**: its datasheet defines no invalid code; the most negative 24-bit result,
//!   −8388608 (0x800000), likewise (a convention).

use super::{ChipModel, Conversion, Image};
use crate::regmap::icm42688p::convert::{INVALID16, INVALID20};
use crate::regmap::icm42688p::image::field as icm;
use crate::regmap::mpu6xxx::image::field as mpu;
use crate::regmap::{ak8963, bmi088, bmi270, mag_image, rm3100};
use core::ops::Range;
use margemu_model::fault::Sensor;

const ACC: u8 = Sensor::Acc.bit();
const GYR: u8 = Sensor::Gyr.bit();
const MAG: u8 = Sensor::Mag.bit();

/// Writes the invalid values of `sensors` into `image`, an image of `model` under `conversion`.
pub(super) fn mark(conversion: &Conversion, model: ChipModel, image: &mut Image, sensors: u8) {
    let bytes = image.as_mut_bytes();
    let be16 = INVALID16.to_be_bytes();
    let le16 = INVALID16.to_le_bytes();
    let each = |bytes: &mut [u8], on: bool, range: Range<usize>, code: &[u8]| {
        if let (true, Some(part)) = (on, bytes.get_mut(range)) {
            for chunk in part.chunks_exact_mut(code.len()) {
                chunk.copy_from_slice(code);
            }
        }
    };
    let (acc, gyr, mag) = (sensors & ACC != 0, sensors & GYR != 0, sensors & MAG != 0);
    match conversion {
        Conversion::Mpu6xxx(_) => {
            each(bytes, acc, mpu::ACCEL, &be16);
            each(bytes, gyr, mpu::GYRO, &be16);
            if mag && model.has_magnetometer() {
                if let Some(st2) = bytes.get_mut(mpu::ST2) {
                    *st2 |= ak8963::bits::ST2_HOFL;
                }
            }
        }
        Conversion::Icm42688p(_) => {
            let be20 = rm3100::data_bytes(INVALID20);
            each(bytes, acc, icm::ACCEL, &be16);
            each(bytes, gyr, icm::GYRO, &be16);
            each(bytes, acc, icm::ACCEL20, &be20);
            each(bytes, gyr, icm::GYRO20, &be20);
        }
        // Both Bosch images: ACC x, y, z then GYR/RATE x, y, z, LSB first.
        Conversion::Bmi270(_) => {
            each(bytes, acc, bmi270::image::field::ACCEL, &le16);
            each(bytes, gyr, bmi270::image::field::GYRO, &le16);
        }
        Conversion::Bmi088(_) => {
            each(bytes, acc, bmi088::image::field::ACCEL, &le16);
            each(bytes, gyr, bmi088::image::field::GYRO, &le16);
        }
        Conversion::Ist8310 | Conversion::Qmc5883l(_) => {
            each(bytes, mag, 0..mag_image::IMAGE_LEN, &le16)
        }
        Conversion::Rm3100(_) => each(
            bytes,
            mag,
            0..rm3100::IMAGE_LEN,
            &rm3100::data_bytes(-(1 << 23)),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::super::{ChipSettings, PhysicalSample};
    use super::*;

    fn image(model: ChipModel, sensors: u8) -> (Image, Image) {
        let settings = ChipSettings::power_on(model);
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.8],
            gyr: [0.1, -0.2, 0.3],
            mag: [20.0, -5.0, 40.0],
            temp_c: 25.0,
        };
        let clean = settings.image(&sample);
        (settings.faulted_image(&sample, sensors), clean)
    }

    /// `got` is `clean` with `range` filled with `code`.
    fn assert_marked(got: &Image, clean: &Image, range: Range<usize>, code: &[u8]) {
        let mut want = clean.as_bytes().to_vec();
        for chunk in want[range].chunks_exact_mut(code.len()) {
            chunk.copy_from_slice(code);
        }
        assert_eq!(got.as_bytes(), &want[..]);
    }

    #[test]
    fn each_family_marks_its_own_registers_only() {
        for model in [ChipModel::Bmi270, ChipModel::Bmi088] {
            let (got, clean) = image(model, GYR);
            assert_marked(&got, &clean, 6..12, &[0x00, 0x80]);
            let (got, clean) = image(model, ACC | MAG);
            assert_marked(&got, &clean, 0..6, &[0x00, 0x80]);
        }
        for model in [ChipModel::Ist8310, ChipModel::Qmc5883l] {
            let (got, clean) = image(model, MAG);
            assert_marked(&got, &clean, 0..6, &[0x00, 0x80]);
            let (got, clean) = image(model, ACC | GYR);
            assert_eq!(got, clean, "no accel or gyro to mark");
        }
        let (got, clean) = image(ChipModel::Rm3100, MAG);
        assert_marked(&got, &clean, 0..9, &[0x80, 0x00, 0x00]);
        for model in [ChipModel::Mpu6500, ChipModel::Mpu6000, ChipModel::Icm20602] {
            let (got, clean) = image(model, ACC | MAG);
            assert_marked(&got, &clean, 0..6, &[0x80, 0x00]);
        }
        let (got, clean) = image(ChipModel::Mpu9250, 0);
        assert_eq!(got, clean);
    }

    #[test]
    fn the_marked_values_decode_as_the_most_negative_code() {
        let (got, _) = image(ChipModel::Icm42688p, ACC | GYR);
        let r =
            crate::regmap::icm42688p::image::ImageRepr::parse(got.as_bytes().try_into().unwrap());
        assert_eq!((r.accel, r.gyro), ([INVALID16; 3], [INVALID16; 3]));
        assert_eq!((r.accel20, r.gyro20), ([INVALID20; 3], [INVALID20; 3]));
    }
}
