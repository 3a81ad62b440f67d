//! From the driver's readings to one body frame in SI units, as a flight controller's sensor
//! layer does it.
//!
//! The `mpu9250` crate (0.25) returns, whatever its docs say (see `tests/driver_mpu9250.rs`):
//! the accelerometer in m/s² (on its own `G = 9.807`), the gyroscope in rad/s, and the
//! magnetometer in **milligauss**, ASA-adjusted, in the **AK8963's own axes**. The body frame is
//! the MPU-9250's accel/gyro frame (the chip is mounted with the plate's axes), so the
//! magnetometer is turned into it with a [`MagAlignment`], the equivalent of a flight
//! controller's "mag alignment" setting. In the MPU-9250 package the AK8963's x is the
//! accelerometer's y, its y the accelerometer's x, and its z points the other way (datasheet
//! PS-MPU-9250A section 9.1), so the alignment of this board is [`MagAlignment::MPU9250`]:
//! body = (ak_y, ak_x, −ak_z).
//!
//! The driver's own scale constants stay as they are (its gyro is 550–977 ppm off the
//! datasheet's sensitivity, its accelerometer 36 ppm): a flight controller built on this crate
//! sees exactly these values.

use std::fmt;
use std::str::FromStr;

/// One axis of the body frame as a sensor axis and a sign.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SignedAxis {
    /// The sensor axis (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// Whether its sign flips.
    pub negate: bool,
}

/// Where each body axis comes from in the magnetometer's reading (a signed permutation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MagAlignment(pub [SignedAxis; 3]);

const fn axis(axis: usize, negate: bool) -> SignedAxis {
    SignedAxis { axis, negate }
}

impl MagAlignment {
    /// The AK8963 inside an MPU-9250: body = (ak_y, ak_x, −ak_z).
    pub const MPU9250: Self = Self([axis(1, false), axis(0, false), axis(2, true)]);
    /// No turn: the sensor's axes taken as the body's (wrong for an MPU-9250; a test uses it to
    /// show the error a flight controller makes without the alignment).
    pub const IDENTITY: Self = Self([axis(0, false), axis(1, false), axis(2, false)]);

    /// `v` (sensor axes) in body axes.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        self.0
            .map(|a| if a.negate { -v[a.axis] } else { v[a.axis] })
    }
}

impl Default for MagAlignment {
    fn default() -> Self {
        Self::MPU9250
    }
}

/// `y,x,-z` (body x, y, z from the sensor's axes).
impl fmt::Display for MagAlignment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<String> = self
            .0
            .iter()
            .map(|a| {
                format!(
                    "{}{}",
                    if a.negate { "-" } else { "" },
                    ["x", "y", "z"][a.axis]
                )
            })
            .collect();
        f.write_str(&names.join(","))
    }
}

/// Parses `y,x,-z`: three signed axis names, each sensor axis once.
impl FromStr for MagAlignment {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}`: expected three signed axes such as `y,x,-z`, each axis once");
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(bad());
        }
        let mut out = [axis(0, false); 3];
        let mut seen = [false; 3];
        for (slot, part) in out.iter_mut().zip(&parts) {
            let (negate, name) = match part.strip_prefix('-') {
                Some(rest) => (true, rest),
                None => (false, part.strip_prefix('+').unwrap_or(part)),
            };
            let i = ["x", "y", "z"]
                .iter()
                .position(|n| *n == name)
                .ok_or_else(bad)?;
            if std::mem::replace(&mut seen[i], true) {
                return Err(bad());
            }
            *slot = axis(i, negate);
        }
        Ok(Self(out))
    }
}

/// One MARG sample in body axes and SI units (the field in µT).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodySample {
    /// Angular rate, rad/s.
    pub gyro: [f64; 3],
    /// Specific force, m/s².
    pub acc: [f64; 3],
    /// Magnetic field, µT.
    pub mag_ut: [f64; 3],
}

/// The driver's readings (its units, see the module docs) in body axes and SI units.
pub fn to_body(
    accel: [f32; 3],
    gyro: [f32; 3],
    mag_mgauss: [f32; 3],
    alignment: &MagAlignment,
) -> BodySample {
    let wide = |v: [f32; 3]| v.map(f64::from);
    BodySample {
        gyro: wide(gyro),
        acc: wide(accel),
        // 1 µT = 10 mG.
        mag_ut: alignment.apply(wide(mag_mgauss).map(|m| m * 0.1)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_protocol::regmap::mpu6xxx::convert::mag_axes_from_mpu;

    #[test]
    fn mpu9250_alignment_undoes_the_chips_axis_swap() {
        let body = [3.0f32, -5.0, 7.0];
        let ak = mag_axes_from_mpu(body);
        let back = MagAlignment::MPU9250.apply(ak.map(f64::from));
        assert_eq!(back, body.map(f64::from));
        assert_ne!(MagAlignment::IDENTITY.apply(ak.map(f64::from)), back);
    }

    #[test]
    fn alignments_parse_and_print() {
        assert_eq!("y,x,-z".parse::<MagAlignment>(), Ok(MagAlignment::MPU9250));
        assert_eq!(
            " x, +y ,z".parse::<MagAlignment>(),
            Ok(MagAlignment::IDENTITY)
        );
        assert_eq!(MagAlignment::MPU9250.to_string(), "y,x,-z");
        for bad in ["x,y", "x,x,z", "x,y,w", "x,y,--z", ""] {
            assert!(bad.parse::<MagAlignment>().is_err(), "{bad}");
        }
    }

    #[test]
    fn milligauss_become_microtesla_in_body_axes() {
        let s = to_body(
            [0.0, 0.0, 9.8],
            [0.1, 0.2, 0.3],
            [100.0, 200.0, 300.0],
            &MagAlignment::MPU9250,
        );
        assert_eq!(s.mag_ut, [20.0, 10.0, -30.0]);
        assert_eq!(s.acc[2], f64::from(9.8f32));
    }
}
