//! Physical values ↔ ICM-42688-P register values, shared by the emulated chip and the host.
//!
//! Every conversion scales, rounds to the nearest integer (halves away from zero) and
//! saturates, through [`round_saturate`] / [`round_saturate_i32`] of the 6xxx family; NaN
//! converts to 0. Sensitivities (DS: sensor specifications, 4.13 Digital-Output Temperature
//! Sensor, FIFO packet structure):
//! - 16-bit accel and gyro at the configured full scale ([`AccelFs`], [`GyroFs`]);
//! - TEMP_DATA, 16 bits: °C = raw / 132.48 + 25;
//! - FIFO temperature, 8 bits (packets 1–3): °C = raw / 2.07 + 25. 132.48 / 2.07 = 64, so the
//!   8-bit value is the 16-bit one divided by 64 (rounded, saturated to i8): [`fifo_temp8`];
//! - 20-bit FIFO data (packet 4), fixed at ±16 g and ±2000 °/s whatever the configured full
//!   scale: accel carries 18 meaningful bits at 8192 LSB/g with the 2 low bits 0, gyro 19 bits
//!   at 131 LSB/(°/s) with the low bit 0 (DS: FIFO packet structure; PX4 `ICM42688P.cpp` decodes them the
//!   same way). The most negative 20-bit code, −524288, marks an invalid sample, so conversion
//!   saturates one code above it.
//!
//! ```
//! use margemu_protocol::regmap::icm42688p::convert::*;
//! use margemu_protocol::regmap::icm42688p::{AccelFs, GyroFs};
//! assert_eq!(accel_to_raw(9.80665, AccelFs::G16), 2048);
//! assert_eq!(accel_to_raw20(9.80665), 32768); // 8192 · 4
//! assert_eq!(gyro_to_raw20(core::f32::consts::PI / 180.0), 262); // 131 · 2
//! assert_eq!(temp_to_raw(26.0), 132);
//! assert_eq!(fifo_temp8(132), 2);
//! ```

use super::{AccelFs, GyroFs};
use crate::regmap::mpu6xxx::convert::{round_saturate, round_saturate_i32};

pub use crate::regmap::mpu6xxx::convert::STANDARD_GRAVITY;

/// TEMP_DATA sensitivity, LSB/°C.
pub const TEMP_LSB_PER_C: f32 = 132.48;
/// FIFO 8-bit temperature sensitivity, LSB/°C.
pub const FIFO_TEMP_LSB_PER_C: f32 = 2.07;
/// Temperature at which both temperature values read 0, °C.
pub const TEMP_OFFSET_C: f32 = 25.0;
/// Accel sensitivity of the 18 meaningful bits of 20-bit FIFO data, LSB/g.
pub const ACCEL_HIRES_LSB_PER_G: f32 = 8192.0;
/// Gyro sensitivity of the 19 meaningful bits of 20-bit FIFO data, LSB/(°/s).
pub const GYRO_HIRES_LSB_PER_DPS: f32 = 131.0;
/// The value of an invalid (sensor off) 16-bit sample.
pub const INVALID16: i16 = i16::MIN;
/// The value of an invalid 20-bit sample.
pub const INVALID20: i32 = -(1 << 19);

const DEG_PER_RAD: f64 = 180.0 / core::f64::consts::PI;

fn lsb_per_radps(lsb_per_dps: f32) -> f32 {
    (DEG_PER_RAD * lsb_per_dps as f64) as f32
}

/// ACCEL_DATA of a specific force `a` (m/s²).
pub fn accel_to_raw(a: f32, fs: AccelFs) -> i16 {
    round_saturate(a * (fs.lsb_per_g() / STANDARD_GRAVITY), i16::MIN, i16::MAX)
}

/// GYRO_DATA of an angular rate `w` (rad/s).
pub fn gyro_to_raw(w: f32, fs: GyroFs) -> i16 {
    round_saturate(w * lsb_per_radps(fs.lsb_per_dps()), i16::MIN, i16::MAX)
}

/// TEMP_DATA of a die temperature `t` (°C).
pub fn temp_to_raw(t: f32) -> i16 {
    round_saturate((t - TEMP_OFFSET_C) * TEMP_LSB_PER_C, i16::MIN, i16::MAX)
}

/// The FIFO's 8-bit temperature of a TEMP_DATA value: `raw / 64`, rounded, saturated to i8.
pub fn fifo_temp8(raw16: i16) -> i8 {
    round_saturate(f32::from(raw16) / 64.0, -128, 127) as i8
}

/// 20-bit FIFO accel value (2 low bits 0) of a specific force `a` (m/s²).
pub fn accel_to_raw20(a: f32) -> i32 {
    let lsb = a * (ACCEL_HIRES_LSB_PER_G / STANDARD_GRAVITY);
    round_saturate_i32(lsb, -(1 << 17) + 1, (1 << 17) - 1) * 4
}

/// 20-bit FIFO gyro value (low bit 0) of an angular rate `w` (rad/s).
pub fn gyro_to_raw20(w: f32) -> i32 {
    let lsb = w * lsb_per_radps(GYRO_HIRES_LSB_PER_DPS);
    round_saturate_i32(lsb, -(1 << 18) + 1, (1 << 18) - 1) * 2
}

/// Specific force (m/s²) of an ACCEL_DATA value.
pub fn accel_from_raw(raw: i16, fs: AccelFs) -> f32 {
    f32::from(raw) * (STANDARD_GRAVITY / fs.lsb_per_g())
}

/// Angular rate (rad/s) of a GYRO_DATA value.
pub fn gyro_from_raw(raw: i16, fs: GyroFs) -> f32 {
    f32::from(raw) / lsb_per_radps(fs.lsb_per_dps())
}

/// Die temperature (°C) of a TEMP_DATA value.
pub fn temp_from_raw(raw: i16) -> f32 {
    f32::from(raw) / TEMP_LSB_PER_C + TEMP_OFFSET_C
}

/// Die temperature (°C) of a FIFO 8-bit temperature.
pub fn temp_from_fifo8(raw: i8) -> f32 {
    f32::from(raw) / FIFO_TEMP_LSB_PER_C + TEMP_OFFSET_C
}

/// Specific force (m/s²) of a 20-bit FIFO accel value.
pub fn accel_from_raw20(raw: i32) -> f32 {
    (raw as f32 / 4.0) * (STANDARD_GRAVITY / ACCEL_HIRES_LSB_PER_G)
}

/// Angular rate (rad/s) of a 20-bit FIFO gyro value.
pub fn gyro_from_raw20(raw: i32) -> f32 {
    (raw as f32 / 2.0) / lsb_per_radps(GYRO_HIRES_LSB_PER_DPS)
}

/// `raw` (20 bits, two's complement in bits 19:0) sign-extended to i32.
pub const fn sign_extend20(raw: u32) -> i32 {
    ((raw << 12) as i32) >> 12
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f32 = STANDARD_GRAVITY;
    const DPS: f32 = core::f32::consts::PI / 180.0;

    #[test]
    fn sixteen_bit_at_each_full_scale() {
        for (fs, lsb) in AccelFs::ALL.into_iter().zip([2048, 4096, 8192, 16384]) {
            assert_eq!(accel_to_raw(G, fs), lsb);
            assert_eq!(accel_to_raw(-G, fs), -lsb);
        }
        assert_eq!(accel_to_raw(-16.0 * G, AccelFs::G16), -32768);
        assert_eq!(accel_to_raw(f32::NAN, AccelFs::G2), 0);
        let expected = [164, 328, 655, 1310, 2620, 5243, 10486, 20972];
        for (fs, lsb) in GyroFs::ALL.into_iter().zip(expected) {
            assert_eq!(gyro_to_raw(10.0 * DPS, fs), lsb, "{fs:?}");
        }
        assert_eq!(gyro_to_raw(100.0 * DPS, GyroFs::Dps15_625), 32767);
    }

    #[test]
    fn temperatures() {
        assert_eq!(temp_to_raw(25.0), 0);
        assert_eq!(temp_to_raw(35.0), 1325); // 1324.8
        assert_eq!(temp_to_raw(-40.0), -8611); // −8611.2
        assert_eq!(fifo_temp8(1325), 21); // 20.70
        assert_eq!(fifo_temp8(-32), -1); // −0.5 rounds away from zero
        assert_eq!(fifo_temp8(-8611), -128); // −134.5 saturates
        assert_eq!(fifo_temp8(i16::MAX), 127);
        assert!((temp_from_fifo8(21) - 35.145).abs() < 1e-3);
        assert!((temp_from_raw(1325) - 35.0015).abs() < 1e-3);
    }

    #[test]
    fn twenty_bit_scaling_and_limits() {
        assert_eq!(accel_to_raw20(G), 32768);
        assert_eq!(accel_to_raw20(-G / 8192.0), -4);
        assert_eq!(accel_to_raw20(1e9), 524284);
        assert_eq!(accel_to_raw20(-1e9), -524284, "never the invalid code");
        assert_eq!(gyro_to_raw20(2000.0 * DPS), 524000);
        assert_eq!(gyro_to_raw20(-1e9), -524286);
        assert_eq!(gyro_to_raw20(f32::NAN), 0);
        assert_eq!(sign_extend20(0x80000), INVALID20);
        assert_eq!(sign_extend20(0xFFFFC), -4);
        assert_eq!(sign_extend20(0x7FFFF), 524287);
        assert!((accel_from_raw20(32768) - G).abs() < 1e-6);
        assert!((gyro_from_raw20(262) - DPS).abs() < 1e-7);
        assert!((gyro_from_raw(164, GyroFs::Dps2000) - 10.0 * DPS).abs() < 1e-6);
        assert!((accel_from_raw(-2048, AccelFs::G16) + G).abs() < 1e-6);
    }
}
