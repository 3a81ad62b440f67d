//! Physical values → register values: the one place where this happens, shared by the emulated
//! chip (firmware) and the host (which predicts what a driver reads).
//!
//! Inputs are SI (m/s², rad/s, °C) or µT for the magnetic field, in the MPU-9250's accel/gyro
//! axes. Every conversion scales, rounds to the nearest integer (halves away from zero) and
//! saturates at the register's range; it never wraps. NaN converts to 0 (a value silicon
//! cannot produce, so the choice only has to be fixed and documented); ±∞ saturate.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::convert::{accel_to_raw, gyro_to_raw, temp_to_raw, STANDARD_GRAVITY};
//! use margemu_protocol::regmap::mpu6xxx::{AccelFs, GyroFs};
//! assert_eq!(accel_to_raw(STANDARD_GRAVITY, AccelFs::G2), 16384);
//! assert_eq!(accel_to_raw(-1e30, AccelFs::G2), -32768);
//! assert_eq!(gyro_to_raw(core::f32::consts::PI, GyroFs::Dps2000), 2952); // 180 °/s · 16.4
//! assert_eq!(temp_to_raw(21.0), 0);
//! ```

use super::{AccelFs, GyroFs};
use crate::regmap::ak8963::{MagBits, OVERFLOW_SUM_UT, SELF_TEST_14BIT};

/// Standard gravity (m/s²) used for 1 g.
pub const STANDARD_GRAVITY: f32 = 9.80665;

/// Temperature sensitivity, LSB/°C (PS section 3).
pub const TEMP_LSB_PER_C: f32 = 333.87;

/// Temperature at which TEMP_OUT reads 0 (RoomTemp_Offset, RM section 4.23), °C.
pub const TEMP_OFFSET_C: f32 = 21.0;

const DEG_PER_RAD: f64 = 180.0 / core::f64::consts::PI;

/// `x` rounded to the nearest integer (halves away from zero), clamped to `[lo, hi]`; NaN → 0.
pub fn round_saturate(x: f32, lo: i16, hi: i16) -> i16 {
    round_saturate_i32(x, i32::from(lo), i32::from(hi)) as i16
}

/// [`round_saturate`] for registers wider than 16 bits (the ICM-42688-P's 18/19-bit FIFO data).
/// Exact for bounds within ±2^24, where every integer is an `f32`; wider bounds are narrowed to
/// that range.
pub fn round_saturate_i32(x: f32, lo: i32, hi: i32) -> i32 {
    const EXACT: i32 = 1 << 24;
    let (a, b) = (lo.clamp(-EXACT, EXACT), hi.clamp(-EXACT, EXACT));
    let (lo, hi) = (a.min(b), a.max(b)); // never panics, whatever the caller passes
    if x.is_nan() {
        return 0;
    }
    // Clamp first, so the float → int cast below is exact and far from i32's limits.
    let x = x.clamp((lo - 1) as f32, (hi + 1) as f32);
    let truncated = x as i32; // toward zero; exact here
    let fraction = x - truncated as f32; // exact for |x| < 2^24
    let rounded = if fraction >= 0.5 {
        truncated + 1
    } else if fraction <= -0.5 {
        truncated - 1
    } else {
        truncated
    };
    rounded.clamp(lo, hi)
}

/// Accelerometer register value (ACCEL_xOUT) of a specific force `a` in m/s².
pub fn accel_to_raw(a: f32, fs: AccelFs) -> i16 {
    accel_to_raw_with_offset(a, fs, 0)
}

/// Accelerometer register value with a user offset: `offset` is how far the XA/YA/ZA_OFFS
/// register pair was moved from its factory trim, as a 16-bit register value (units of
/// 1/2048 g, bit 0 reserved and ignored: 0.98 mg steps; RM section 4.39). The offset is added
/// to the sensor value before rounding and saturation, as the silicon does.
pub fn accel_to_raw_with_offset(a: f32, fs: AccelFs, offset: i16) -> i16 {
    let lsb_per_mps2 = fs.lsb_per_g() / STANDARD_GRAVITY;
    let offset_lsb = f32::from(offset & !1) * (fs.lsb_per_g() / 2048.0);
    round_saturate(a * lsb_per_mps2 + offset_lsb, i16::MIN, i16::MAX)
}

/// Gyroscope register value (GYRO_xOUT) of an angular rate `w` in rad/s.
pub fn gyro_to_raw(w: f32, fs: GyroFs) -> i16 {
    gyro_to_raw_with_offset(w, fs, 0)
}

/// Gyroscope register value with the user offset `offs_usr` (XG/YG/ZG_OFFSET_H:L) added before
/// rounding and saturation: `offs_usr · 4 / 2^FS_SEL` LSB (RM section 4.3).
pub fn gyro_to_raw_with_offset(w: f32, fs: GyroFs, offs_usr: i16) -> i16 {
    let lsb_per_radps = (DEG_PER_RAD * fs.lsb_per_dps() as f64) as f32;
    let offset_lsb = f32::from(offs_usr) * 4.0 / f32::from(1u8 << fs.bits());
    round_saturate(w * lsb_per_radps + offset_lsb, i16::MIN, i16::MAX)
}

/// TEMP_OUT of a die temperature `t` in °C: `(t − 21) · 333.87`.
pub fn temp_to_raw(t: f32) -> i16 {
    round_saturate((t - TEMP_OFFSET_C) * TEMP_LSB_PER_C, i16::MIN, i16::MAX)
}

/// The sensitivity adjustment factor of a fuse-ROM ASA value: `(ASA − 128) / 256 + 1`
/// (DS section 8.3.11). A driver multiplies the register value by it.
pub fn asa_factor(asa: u8) -> f32 {
    (f32::from(asa) - 128.0) / 256.0 + 1.0
}

/// AK8963 register value (HX, HY or HZ) of a field component `b` in µT along that AK8963 axis.
/// The part's own sensitivity differs from nominal by the factor its ASA value records, so the
/// register holds `b / (sensitivity · asa_factor)`: a driver that applies the datasheet's
/// adjustment recovers `b` to within one LSB. Clips at ±8190 (14-bit) or ±32760 (16-bit).
pub fn mag_to_raw(b: f32, asa: u8, bits: MagBits) -> i16 {
    let lsb = b / (bits.ut_per_lsb() * asa_factor(asa));
    round_saturate(lsb, -bits.max_raw(), bits.max_raw())
}

/// The field in the AK8963's own axes from the field in the MPU-9250 accel/gyro axes: the
/// magnetometer die is mounted with x and y swapped and z reversed (PS section 9.1, figure
/// "Orientation of Axes of Sensitivity"): `x_ak = y_mpu`, `y_ak = x_mpu`, `z_ak = −z_mpu`. The
/// one statement of that mounting: [`mag_axes_to_mpu`] is its inverse.
pub fn mag_axes_from_mpu<T: Copy + core::ops::Neg<Output = T>>(b: [T; 3]) -> [T; 3] {
    let [x, y, z] = b;
    [y, x, -z]
}

/// The field in the MPU-9250 accel/gyro axes from the field in the AK8963's own axes: the
/// inverse of [`mag_axes_from_mpu`] (`x_mpu = y_ak`, `y_mpu = x_ak`, `z_mpu = −z_ak`).
///
/// ```
/// use margemu_protocol::regmap::mpu6xxx::convert::{mag_axes_from_mpu, mag_axes_to_mpu};
/// let b = [3.0f32, -5.0, 7.0];
/// assert_eq!(mag_axes_to_mpu(mag_axes_from_mpu(b)), b);
/// ```
pub fn mag_axes_to_mpu<T: Copy + core::ops::Neg<Output = T>>(b: [T; 3]) -> [T; 3] {
    // The swap and the sign flip undo themselves.
    mag_axes_from_mpu(b)
}

/// A field component in µT along its AK8963 axis from the register value `raw` (HX, HY or HZ),
/// with the sensitivity adjustment of `asa` applied: the inverse of [`mag_to_raw`] to within
/// one LSB.
pub fn mag_from_raw(raw: i16, asa: u8, bits: MagBits) -> f64 {
    f64::from(raw) * f64::from(bits.ut_per_lsb()) * f64::from(asa_factor(asa))
}

/// A measurement as the AK8963 stores it: the three data register values (AK8963 axes) and
/// whether ST2.HOFL is set. `field_mpu_axes` is in µT in the MPU-9250's accel/gyro axes.
///
/// HOFL is set when `|x| + |y| + |z| ≥ 4912 µT` (DS section 6.4.3.6) or a component clipped;
/// the data registers then hold the clipped values (the datasheet calls them "not correct").
pub fn mag_measurement(field_mpu_axes: [f32; 3], asa: [u8; 3], bits: MagBits) -> ([i16; 3], bool) {
    let b = mag_axes_from_mpu(field_mpu_axes);
    let mut raw = [0i16; 3];
    let mut clipped = false;
    for i in 0..3 {
        raw[i] = mag_to_raw(b[i], asa[i], bits);
        clipped |= raw[i].unsigned_abs() >= bits.max_raw().unsigned_abs();
    }
    let sum = b[0].abs() + b[1].abs() + b[2].abs();
    let overflow = sum >= OVERFLOW_SUM_UT || sum.is_nan() || clipped;
    (raw, overflow)
}

/// The data register values of a self-test measurement: the internal field
/// [`SELF_TEST_14BIT`] (scaled by 4 at 16-bit output), divided
/// by the ASA factor so that the adjusted values land where the datasheet expects them.
pub fn mag_self_test(asa: [u8; 3], bits: MagBits) -> [i16; 3] {
    let scale = match bits {
        MagBits::Bits14 => 1.0,
        MagBits::Bits16 => 4.0,
    };
    let mut raw = [0i16; 3];
    for i in 0..3 {
        let adjusted = f32::from(SELF_TEST_14BIT[i]) * scale;
        raw[i] = round_saturate(
            adjusted / asa_factor(asa[i]),
            -bits.max_raw(),
            bits.max_raw(),
        );
    }
    raw
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: f32 = STANDARD_GRAVITY;

    #[test]
    fn rounding_is_to_nearest_halves_away_from_zero() {
        assert_eq!(round_saturate(0.49999997, -10, 10), 0);
        assert_eq!(round_saturate(0.5, -10, 10), 1);
        assert_eq!(round_saturate(-0.5, -10, 10), -1);
        assert_eq!(round_saturate(-0.49999997, -10, 10), 0);
        assert_eq!(round_saturate(2.5, -10, 10), 3);
        assert_eq!(round_saturate(-2.4, -10, 10), -2);
        assert_eq!(round_saturate(32766.5, i16::MIN, i16::MAX), 32767);
    }

    #[test]
    fn saturation_and_nan() {
        for x in [1e30, f32::INFINITY, 32767.6, 40000.0] {
            assert_eq!(round_saturate(x, i16::MIN, i16::MAX), 32767);
            assert_eq!(round_saturate(-x, i16::MIN, i16::MAX), -32768);
        }
        assert_eq!(round_saturate(f32::NAN, i16::MIN, i16::MAX), 0);
        assert_eq!(round_saturate(-f32::NAN, -5, 5), 0);
        assert_eq!(accel_to_raw(f32::NAN, AccelFs::G16), 0);
        assert_eq!(gyro_to_raw(f32::INFINITY, GyroFs::Dps250), 32767);
        assert_eq!(temp_to_raw(-1e30), -32768);
        assert_eq!(mag_to_raw(1e30, 128, MagBits::Bits14), 8190);
        assert_eq!(mag_to_raw(-1e30, 128, MagBits::Bits16), -32760);
    }

    #[test]
    fn accel_lsb_at_each_full_scale() {
        let expected = [16384, 8192, 4096, 2048];
        for (fs, lsb) in AccelFs::ALL.into_iter().zip(expected) {
            assert_eq!(accel_to_raw(G, fs), lsb);
            assert_eq!(accel_to_raw(-G, fs), -lsb);
            assert_eq!(accel_to_raw(0.0, fs), 0);
        }
        // Full scale: +2 g is one LSB past +32767, −2 g is exactly −32768.
        assert_eq!(accel_to_raw(2.0 * G, AccelFs::G2), 32767);
        assert_eq!(accel_to_raw(-2.0 * G, AccelFs::G2), -32768);
        assert_eq!(accel_to_raw(16.0 * G, AccelFs::G16), 32767);
        assert_eq!(accel_to_raw(-16.0 * G, AccelFs::G16), -32768);
        // Half an LSB at ±16 g is 1/4096 g.
        assert_eq!(accel_to_raw(G * 1.4 / 2048.0, AccelFs::G16), 1);
        assert_eq!(accel_to_raw(G * 1.6 / 2048.0, AccelFs::G16), 2);
    }

    #[test]
    fn gyro_lsb_at_each_full_scale() {
        let one_dps = core::f32::consts::PI / 180.0;
        let expected = [262, 131, 66, 33]; // 2 °/s: 65.6 and 32.8 LSB round to nearest
        for (fs, lsb) in GyroFs::ALL.into_iter().zip(expected) {
            assert_eq!(gyro_to_raw(2.0 * one_dps, fs), lsb, "{fs:?}");
            assert_eq!(gyro_to_raw(-2.0 * one_dps, fs), -lsb, "{fs:?}");
        }
        assert_eq!(gyro_to_raw(100.0 * one_dps, GyroFs::Dps250), 13100);
        assert_eq!(gyro_to_raw(100.0 * one_dps, GyroFs::Dps500), 6550);
        assert_eq!(gyro_to_raw(100.0 * one_dps, GyroFs::Dps1000), 3280);
        assert_eq!(gyro_to_raw(100.0 * one_dps, GyroFs::Dps2000), 1640);
        assert_eq!(gyro_to_raw(300.0 * one_dps, GyroFs::Dps250), 32767);
        assert_eq!(gyro_to_raw(-2100.0 * one_dps, GyroFs::Dps2000), -32768);
    }

    #[test]
    fn user_offsets() {
        // X_OFFS_USR = 1 adds 4 LSB at ±250 °/s, 0.5 LSB at ±2000 °/s.
        assert_eq!(gyro_to_raw_with_offset(0.0, GyroFs::Dps250, 1), 4);
        assert_eq!(gyro_to_raw_with_offset(0.0, GyroFs::Dps500, -3), -6);
        assert_eq!(gyro_to_raw_with_offset(0.0, GyroFs::Dps2000, 2), 1);
        assert_eq!(
            gyro_to_raw_with_offset(0.0, GyroFs::Dps250, i16::MAX),
            32767
        );
        // One 0.98 mg step (16-bit value 2) is 16 LSB at ±2 g, 2 LSB at ±16 g; bit 0 ignored.
        assert_eq!(accel_to_raw_with_offset(0.0, AccelFs::G2, 2), 16);
        assert_eq!(accel_to_raw_with_offset(0.0, AccelFs::G2, 3), 16);
        assert_eq!(accel_to_raw_with_offset(G, AccelFs::G16, -2), 2046);
        assert_eq!(accel_to_raw_with_offset(-2.0 * G, AccelFs::G2, -2), -32768);
    }

    #[test]
    fn temperature() {
        assert_eq!(temp_to_raw(21.0), 0);
        assert_eq!(temp_to_raw(22.0), 334); // 333.87
        assert_eq!(temp_to_raw(20.0), -334);
        assert_eq!(temp_to_raw(31.0), 3339); // 3338.7
        assert_eq!(temp_to_raw(85.0), 21368); // 21367.68
        assert_eq!(temp_to_raw(-40.0), -20366); // −20366.07
    }

    #[test]
    fn magnetometer_lsb_and_asa() {
        // ASA 128: factor 1.
        assert_eq!(mag_to_raw(0.6, 128, MagBits::Bits14), 1);
        assert_eq!(mag_to_raw(0.15, 128, MagBits::Bits16), 1);
        assert_eq!(mag_to_raw(48.0, 128, MagBits::Bits16), 320);
        assert_eq!(mag_to_raw(48.0, 128, MagBits::Bits14), 80);
        // ASA 0xB0 (176): factor 1.1875, a driver multiplies back.
        let raw = mag_to_raw(48.0, 0xB0, MagBits::Bits16);
        assert_eq!(raw, 269); // 320 / 1.1875 = 269.47
        let recovered = f32::from(raw) * asa_factor(0xB0) * 0.15;
        assert!((recovered - 48.0).abs() <= 0.15 * asa_factor(0xB0));
        // Range limits.
        assert_eq!(mag_to_raw(4912.0, 128, MagBits::Bits14), 8187);
        assert_eq!(mag_to_raw(6000.0, 128, MagBits::Bits16), 32760);
    }

    #[test]
    fn magnetometer_axes_and_overflow() {
        assert_eq!(mag_axes_from_mpu([1.0, 2.0, 3.0]), [2.0, 1.0, -3.0]);
        assert_eq!(
            mag_axes_to_mpu(mag_axes_from_mpu([1.0, 2.0, 3.0])),
            [1.0, 2.0, 3.0]
        );
        let (raw, hofl) = mag_measurement([15.0, 30.0, -45.0], [128; 3], MagBits::Bits16);
        assert_eq!(raw, [200, 100, 300]);
        assert!(!hofl);
        let (_, hofl) = mag_measurement([2000.0, 2000.0, 912.0], [128; 3], MagBits::Bits16);
        assert!(hofl, "|x|+|y|+|z| = 4912 µT overflows");
        let (_, hofl) = mag_measurement([2000.0, 2000.0, 911.0], [128; 3], MagBits::Bits16);
        assert!(!hofl);
        let (raw, hofl) = mag_measurement([f32::NAN, 0.0, 0.0], [128; 3], MagBits::Bits14);
        assert_eq!(raw, [0, 0, 0]);
        assert!(hofl);
    }

    #[test]
    fn self_test_field_passes_the_datasheet_criteria_after_adjustment() {
        for asa in [0u8, 128, 0xB0, 255] {
            for (bits, k) in [(MagBits::Bits14, 1.0), (MagBits::Bits16, 4.0)] {
                let raw = mag_self_test([asa; 3], bits);
                let adj: [f32; 3] = core::array::from_fn(|i| f32::from(raw[i]) * asa_factor(asa));
                assert!(
                    (-50.0 * k..=50.0 * k).contains(&adj[0]),
                    "{asa} {bits:?} {adj:?}"
                );
                assert!((-50.0 * k..=50.0 * k).contains(&adj[1]));
                assert!((-800.0 * k..=-200.0 * k).contains(&adj[2]));
            }
        }
    }
}
