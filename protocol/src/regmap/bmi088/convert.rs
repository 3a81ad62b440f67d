//! Physical values ↔ BMI088 register values, shared by the emulated dies and the host.
//!
//! Conversions scale, round to the nearest integer (halves away from zero) and saturate through
//! the 6xxx family's [`round_saturate`]; NaN converts to 0.
//! - accel (DS 5.3.4) and gyro (DS 5.5.2): i16, little-endian, at the configured range
//!   ([`AccRange::lsb_per_g`], [`GyroRange::lsb_per_dps`]);
//! - temperature (DS 5.3.7): 11-bit two's complement at 0.125 K per LSB, 0 = 23 °C, stored as
//!   TEMP_MSB (0x22) = bits 10:3 and TEMP_LSB (0x23) bits 7:5 = bits 2:0 ([`temp_bytes`]);
//!   −1024 (TEMP_MSB 0x80) marks an invalid value, so conversion saturates one code above it;
//! - sensor time (DS 5.3.5): the BMI270's 24-bit counter at 39.0625 µs per LSB
//!   ([`sensortime`]).
//!
//! ```
//! use margemu_protocol::regmap::bmi088::convert::*;
//! use margemu_protocol::regmap::bmi088::{accel::AccRange, gyro::GyroRange};
//! assert_eq!(accel_to_raw(9.80665, AccRange::G24), 1365); // 1365.33 LSB/g
//! assert_eq!(gyro_to_raw(core::f32::consts::PI / 180.0, GyroRange::Dps2000), 16); // 16.384
//! assert_eq!(temp_bytes(temp_to_raw(85.0)), [0x3E, 0x00]); // DS 5.3.7 table
//! assert_eq!(temp_bytes(temp_to_raw(-40.0)), [0xC1, 0x00]);
//! assert_eq!(temp_from_bytes([0x00, 0x60]), Some(23.375));
//! ```

use super::accel::AccRange;
use super::gyro::GyroRange;
use crate::regmap::mpu6xxx::convert::round_saturate;

pub use crate::regmap::bmi270::convert::{sensortime, sensortime_bytes, SENSORTIME_MASK};
pub use crate::regmap::mpu6xxx::convert::STANDARD_GRAVITY;

/// Temperature sensitivity, LSB/K.
pub const TEMP_LSB_PER_K: f32 = 8.0;
/// Temperature at which the 11-bit value is 0, °C.
pub const TEMP_OFFSET_C: f32 = 23.0;
/// The 11-bit value of an invalid temperature (TEMP_MSB = 0x80).
pub const TEMP_INVALID: i16 = -1024;
/// How often the temperature registers are updated, ns (DS 5.3.7: every 1.28 s).
pub const TEMP_UPDATE_NS: u64 = 1_280_000_000;

const DEG_PER_RAD: f64 = 180.0 / core::f64::consts::PI;

/// Accel data of a specific force `a` (m/s²).
pub fn accel_to_raw(a: f32, range: AccRange) -> i16 {
    round_saturate(
        a * (range.lsb_per_g() / STANDARD_GRAVITY),
        i16::MIN,
        i16::MAX,
    )
}

/// Gyro data of an angular rate `w` (rad/s).
pub fn gyro_to_raw(w: f32, range: GyroRange) -> i16 {
    let lsb_per_radps = (DEG_PER_RAD * f64::from(range.lsb_per_dps())) as f32;
    round_saturate(w * lsb_per_radps, i16::MIN, i16::MAX)
}

/// The 11-bit temperature value of a die temperature `t` (°C), never the invalid code.
pub fn temp_to_raw(t: f32) -> i16 {
    round_saturate((t - TEMP_OFFSET_C) * TEMP_LSB_PER_K, TEMP_INVALID + 1, 1023)
}

/// TEMP_MSB and TEMP_LSB of an 11-bit temperature value (bits above 10 are dropped).
pub fn temp_bytes(raw: i16) -> [u8; 2] {
    let u11 = (raw as u16) & 0x07FF;
    [(u11 >> 3) as u8, ((u11 & 0x07) << 5) as u8]
}

/// The die temperature (°C) of TEMP_MSB, TEMP_LSB, as DS 5.3.7 computes it; `None` for the
/// invalid code (TEMP_MSB 0x80, TEMP_LSB bits 7:5 clear).
pub fn temp_from_bytes([msb, lsb]: [u8; 2]) -> Option<f32> {
    let u11 = u16::from(msb) * 8 + u16::from(lsb) / 32;
    let int11 = if u11 > 1023 {
        i32::from(u11) - 2048
    } else {
        i32::from(u11)
    };
    (int11 != i32::from(TEMP_INVALID)).then(|| int11 as f32 / TEMP_LSB_PER_K + TEMP_OFFSET_C)
}

/// The specific force (m/s²) of accel data `raw`.
pub fn accel_from_raw(raw: i16, range: AccRange) -> f32 {
    f32::from(raw) * (STANDARD_GRAVITY / range.lsb_per_g())
}

/// The angular rate (rad/s) of gyro data `raw`.
pub fn gyro_from_raw(raw: i16, range: GyroRange) -> f32 {
    (f64::from(raw) / f64::from(range.lsb_per_dps()) / DEG_PER_RAD) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accel_at_every_range() {
        for range in AccRange::ALL {
            let one_g = accel_to_raw(STANDARD_GRAVITY, range);
            assert!(
                (f32::from(one_g) - range.lsb_per_g()).abs() <= 0.5,
                "{range:?}"
            );
            assert_eq!(accel_to_raw(-STANDARD_GRAVITY, range), -one_g);
            let back = accel_from_raw(one_g, range);
            assert!((back - STANDARD_GRAVITY).abs() < STANDARD_GRAVITY / range.lsb_per_g());
        }
        assert_eq!(
            accel_to_raw(30.0 * STANDARD_GRAVITY, AccRange::G24),
            i16::MAX
        );
        assert_eq!(
            accel_to_raw(-30.0 * STANDARD_GRAVITY, AccRange::G24),
            i16::MIN
        );
        assert_eq!(accel_to_raw(f32::NAN, AccRange::G3), 0);
    }

    #[test]
    fn gyro_at_every_range() {
        let dps100 = 100.0_f32.to_radians();
        let expected = [1638, 3277, 6554, 13107, 26214];
        for (range, want) in GyroRange::ALL.into_iter().zip(expected) {
            assert_eq!(gyro_to_raw(dps100, range), want, "{range:?}");
            let half_lsb = (0.5 / range.lsb_per_dps()).to_radians() + 1e-6;
            assert!((gyro_from_raw(want, range) - dps100).abs() < half_lsb);
        }
        assert_eq!(gyro_to_raw(100.0, GyroRange::Dps125), i16::MAX);
    }

    #[test]
    fn temperature_encoding() {
        for (t, bytes) in [
            (85.0, [0x3E, 0x00]),
            (23.375, [0x00, 0x60]),
            (23.25, [0x00, 0x40]),
            (23.125, [0x00, 0x20]),
            (23.0, [0x00, 0x00]),
            (-40.0, [0xC1, 0x00]),
        ] {
            assert_eq!(temp_bytes(temp_to_raw(t)), bytes, "{t} °C");
            assert_eq!(temp_from_bytes(bytes), Some(t));
        }
        assert_eq!(temp_to_raw(200.0), 1023);
        assert_eq!(temp_to_raw(-200.0), -1023); // never the invalid code
        assert_eq!(temp_from_bytes([0x80, 0x00]), None);
        assert_eq!(temp_from_bytes(temp_bytes(-1023)), Some(-104.875));
    }
}
