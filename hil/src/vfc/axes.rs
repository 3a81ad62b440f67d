//! The body frame, and how a magnetometer's axes map into it, as a flight controller's sensor
//! layer does it.
//!
//! The body frame is the accel/gyro frame of the chip (the chip is mounted with the plate's
//! axes). A magnetometer with axes of its own is turned into it with a [`MagAlignment`], the
//! equivalent of a flight controller's "mag alignment" setting. The default,
//! [`MagAlignment::mpu9250`], is not a copy of the AK8963's mounting: it is read off the chip
//! module's own mapping ([`mag_axes_to_mpu`]), the one place that fact lives. Other alignments
//! (parsed from `y,x,-z`-style text) show what a wrong setting costs.

use margemu_protocol::regmap::mpu6xxx::convert::mag_axes_to_mpu;
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
    /// The AK8963 inside an MPU-9250, as the chip module maps it ([`mag_axes_to_mpu`]): each
    /// body axis is where that mapping sends one AK8963 axis.
    pub fn mpu9250() -> Self {
        let mut out = [axis(0, false); 3];
        for i in 0..3 {
            let mut unit = [0i8; 3];
            unit[i] = 1;
            let body = mag_axes_to_mpu(unit);
            if let Some(j) = body.iter().position(|&v| v != 0) {
                out[j] = axis(i, body[j] < 0);
            }
        }
        Self(out)
    }
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
    /// [`MagAlignment::mpu9250`].
    fn default() -> Self {
        Self::mpu9250()
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

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_protocol::regmap::mpu6xxx::convert::mag_axes_from_mpu;

    #[test]
    fn mpu9250_alignment_undoes_the_chips_axis_swap() {
        let body = [3.0f32, -5.0, 7.0];
        let ak = mag_axes_from_mpu(body);
        let back = MagAlignment::mpu9250().apply(ak.map(f64::from));
        assert_eq!(back, body.map(f64::from));
        assert_ne!(MagAlignment::IDENTITY.apply(ak.map(f64::from)), back);
    }

    #[test]
    fn alignments_parse_and_print() {
        assert_eq!(
            "y,x,-z".parse::<MagAlignment>(),
            Ok(MagAlignment::mpu9250())
        );
        assert_eq!(
            " x, +y ,z".parse::<MagAlignment>(),
            Ok(MagAlignment::IDENTITY)
        );
        assert_eq!(MagAlignment::mpu9250().to_string(), "y,x,-z");
        for bad in ["x,y", "x,x,z", "x,y,w", "x,y,--z", ""] {
            assert!(bad.parse::<MagAlignment>().is_err(), "{bad}");
        }
    }
}
