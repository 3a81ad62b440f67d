//! Physical values ↔ BMI270 register values, shared by the emulated chip and the host.
//!
//! Conversions scale, round to the nearest integer (halves away from zero) and saturate through
//! the 6xxx family's [`round_saturate`]; NaN converts to 0. Register values are little-endian
//! (DS: 5.2 register description of DATA_8..19, TEMPERATURE_0/1, SENSORTIME_0..2):
//! - accel and gyro, i16 at the configured range ([`AccRange`], [`GyrRange`]);
//! - temperature, i16 at 1/512 K per LSB, 0 = 23 °C; 0x8000 (−32768) marks an invalid value,
//!   so conversion saturates one code above it;
//! - sensor time, a 24-bit counter at 39.0625 µs per LSB that wraps.
//!
//! ```
//! use margemu_protocol::regmap::bmi270::convert::*;
//! use margemu_protocol::regmap::bmi270::{AccRange, GyrRange};
//! assert_eq!(accel_to_raw(9.80665, AccRange::G8), 4096);
//! assert_eq!(gyro_to_raw(core::f32::consts::PI / 180.0, GyrRange::Dps2000), 16); // 16.4
//! assert_eq!(temp_to_raw(24.0), 512);
//! assert_eq!(temp_to_raw(-500.0), -32767);
//! assert_eq!(sensortime(1_000_000_000), 25_600);
//! ```

use super::{AccRange, GyrRange};
use crate::regmap::mpu6xxx::convert::round_saturate;

pub use crate::regmap::mpu6xxx::convert::STANDARD_GRAVITY;

/// Temperature sensitivity, LSB/K.
pub const TEMP_LSB_PER_K: f32 = 512.0;
/// Temperature at which TEMPERATURE reads 0, °C.
pub const TEMP_OFFSET_C: f32 = 23.0;
/// The TEMPERATURE value of an invalid (not yet measured) temperature.
pub const TEMP_INVALID: i16 = i16::MIN;
/// Sensor time resolution, ns per LSB (39.0625 µs = 78125 / 2 ns).
pub const SENSORTIME_NS_PER_LSB: f64 = 39_062.5;
/// Sensor time wraps after 2^24 counts.
pub const SENSORTIME_MASK: u32 = 0x00FF_FFFF;

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
pub fn gyro_to_raw(w: f32, range: GyrRange) -> i16 {
    let lsb_per_radps = (DEG_PER_RAD * f64::from(range.lsb_per_dps())) as f32;
    round_saturate(w * lsb_per_radps, i16::MIN, i16::MAX)
}

/// TEMPERATURE of a die temperature `t` (°C), never the invalid code.
pub fn temp_to_raw(t: f32) -> i16 {
    round_saturate((t - TEMP_OFFSET_C) * TEMP_LSB_PER_K, -32767, i16::MAX)
}

/// The specific force (m/s²) of accel data `raw`.
pub fn accel_from_raw(raw: i16, range: AccRange) -> f32 {
    f32::from(raw) * (STANDARD_GRAVITY / range.lsb_per_g())
}

/// The angular rate (rad/s) of gyro data `raw`.
pub fn gyro_from_raw(raw: i16, range: GyrRange) -> f32 {
    (f64::from(raw) / f64::from(range.lsb_per_dps()) / DEG_PER_RAD) as f32
}

/// The die temperature (°C) of TEMPERATURE `raw`; `None` for the invalid code 0x8000.
pub fn temp_from_raw(raw: i16) -> Option<f32> {
    (raw != TEMP_INVALID).then(|| f32::from(raw) / TEMP_LSB_PER_K + TEMP_OFFSET_C)
}

/// SENSORTIME (24 bits) at chip time `now_ns` since power-on.
pub fn sensortime(now_ns: u64) -> u32 {
    // 39.0625 µs = 78125 / 2 ns; u64 ns covers centuries, so the product cannot overflow in use.
    ((now_ns.saturating_mul(2) / 78_125) & u64::from(SENSORTIME_MASK)) as u32
}

/// The three little-endian bytes of a SENSORTIME value.
pub fn sensortime_bytes(ticks: u32) -> [u8; 3] {
    let [b0, b1, b2, _] = ticks.to_le_bytes();
    [b0, b1, b2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accel_at_every_range() {
        for range in AccRange::ALL {
            let one_g = accel_to_raw(STANDARD_GRAVITY, range);
            assert_eq!(f32::from(one_g), range.lsb_per_g());
            assert_eq!(accel_to_raw(-STANDARD_GRAVITY, range), -one_g);
            assert!((accel_from_raw(one_g, range) - STANDARD_GRAVITY).abs() < 1e-4);
        }
        assert_eq!(accel_to_raw(1000.0, AccRange::G16), i16::MAX); // clipped
        assert_eq!(accel_to_raw(-1000.0, AccRange::G16), i16::MIN);
        assert_eq!(accel_to_raw(f32::NAN, AccRange::G2), 0);
    }

    #[test]
    fn gyro_at_every_range() {
        let dps100 = 100.0_f32.to_radians();
        let expected = [1640, 3280, 6560, 13120, 26240];
        for (range, want) in GyrRange::ALL.into_iter().zip(expected) {
            assert_eq!(gyro_to_raw(dps100, range), want, "{range:?}");
            assert!((gyro_from_raw(want, range) - dps100).abs() < 1e-5);
        }
        assert_eq!(gyro_to_raw(100.0, GyrRange::Dps125), i16::MAX);
    }

    #[test]
    fn temperature_encoding() {
        assert_eq!(temp_to_raw(23.0), 0);
        assert_eq!(temp_to_raw(22.0), -512);
        assert_eq!(temp_to_raw(200.0), i16::MAX);
        assert_eq!(temp_to_raw(-200.0), -32767); // never 0x8000
        assert_eq!(temp_from_raw(TEMP_INVALID), None);
        assert_eq!(temp_from_raw(1024), Some(25.0));
    }

    #[test]
    fn sensortime_counts_and_wraps() {
        assert_eq!(sensortime(0), 0);
        assert_eq!(sensortime(39_062), 0);
        assert_eq!(sensortime(39_063), 1);
        assert_eq!(sensortime(78_125), 2);
        let wrap_ns = (1u64 << 24) * 78_125 / 2; // 655.36 s
        assert_eq!(sensortime(wrap_ns), 0);
        assert_eq!(sensortime(wrap_ns - 30_000), SENSORTIME_MASK);
        assert_eq!(sensortime_bytes(0x0A0B0C), [0x0C, 0x0B, 0x0A]);
    }
}
