//! Named world frames and the one map between NED/FRD and margemu's axes (CONVENTIONS "Named
//! world frames"): a recording's vectors and quaternions in NWU, ENU or NED converted once, at
//! the edge, into margemu's own frames and back, and the NED map every MAVLink reader and writer
//! uses ([`ned`]).
//!
//! | frame | world axes | body axes assumed | converted on reading |
//! |---|---|---|---|
//! | `nwu` (default) | x north, y west, z up | margemu's (z up at rest: the accelerometer reads `+g` on z) | nothing |
//! | `enu` | x east, y north, z up | margemu's | world vectors `(x, y, z) → (y, −x, z)`; quaternions `q → W ⊗ q`, `W` a −90° turn about z |
//! | `ned` | x north, y east, z down | FRD (x forward, y right, z down: the accelerometer reads `−g` on z at rest) | world and body vectors `(x, y, z) → (x, −y, −z)`; quaternions `q → W ⊗ q ⊗ W⁻¹ = (w, x, −y, −z)`, `W` a half turn about x |
//!
//! The NED map is exact sign flips and its own inverse; the ENU map multiplies by `1/√2` once.
//! Scores that compare two attitudes in one frame (geodesic, heading, inclination) do not
//! depend on the frame.
//!
//! ```
//! use margemu_sim::frame::{ned, Frame};
//! assert_eq!(Frame::Ned.body_in([0.0, 0.0, -9.8]), [0.0, 0.0, 9.8]);
//! assert_eq!(Frame::Ned.quat_in([0.5, 0.1, 0.2, 0.3]), ned::quaternion([0.5, 0.1, 0.2, 0.3]));
//! assert_eq!(Frame::Enu.world_in([1.0, 0.0, 0.0]), [0.0, -1.0, 0.0]); // east is −y in NWU
//! assert_eq!("NED".parse::<Frame>(), Ok(Frame::Ned));
//! ```

use std::fmt;
use std::str::FromStr;

/// A named world frame (and the body axes it implies; see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Frame {
    /// margemu's own: x north, y west, z up.
    #[default]
    Nwu,
    /// x east, y north, z up.
    Enu,
    /// x north, y east, z down; body FRD.
    Ned,
}

impl FromStr for Frame {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "nwu" => Ok(Self::Nwu),
            "enu" => Ok(Self::Enu),
            "ned" => Ok(Self::Ned),
            _ => Err(format!("unknown frame `{s}` (nwu, enu or ned)")),
        }
    }
}

impl fmt::Display for Frame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Nwu => "nwu",
            Self::Enu => "enu",
            Self::Ned => "ned",
        })
    }
}

/// NED world and FRD body axes to margemu's (world north, west, up; body forward, left, up),
/// and back: both frames turn by 180° about x, so the map is an involution. MAVLink's readers
/// and writers and the recordings' `--frame ned` all use it.
pub mod ned {
    use crate::truth::wrap_angle;

    /// Body or world vector: `(x, y, z) → (x, −y, −z)`.
    pub fn vector(v: [f64; 3]) -> [f64; 3] {
        [v[0], -v[1], -v[2]]
    }

    /// Body-to-world quaternion: `(w, x, y, z) → (w, x, −y, −z)`.
    pub fn quaternion(q: [f64; 4]) -> [f64; 4] {
        [q[0], q[1], -q[2], -q[3]]
    }

    /// ZYX Euler angles: `(roll, pitch, yaw) → (roll, −pitch, −yaw)`, yaw wrapped to (−π, π].
    pub fn euler(e: [f64; 3]) -> [f64; 3] {
        [e[0], -e[1], wrap_angle(-e[2])]
    }
}

/// `(a, 0, 0, c) ⊗ q`: a turn about z applied on the left.
fn about_z(a: f64, c: f64, q: [f64; 4]) -> [f64; 4] {
    let [w, x, y, z] = q;
    [a * w - c * z, a * x - c * y, a * y + c * x, a * z + c * w]
}

impl Frame {
    /// A world vector in this frame, in NWU.
    pub fn world_in(self, v: [f64; 3]) -> [f64; 3] {
        match self {
            Self::Nwu => v,
            Self::Enu => [v[1], -v[0], v[2]],
            Self::Ned => ned::vector(v),
        }
    }

    /// A body vector (accelerometer, gyroscope, magnetometer) in this frame's body axes, in
    /// margemu's.
    pub fn body_in(self, v: [f64; 3]) -> [f64; 3] {
        match self {
            Self::Ned => ned::vector(v),
            Self::Nwu | Self::Enu => v,
        }
    }

    /// A body-to-world quaternion `[w, x, y, z]` of this frame, in margemu's (`W ⊗ q ⊗ B⁻¹`);
    /// its norm is kept.
    pub fn quat_in(self, q: [f64; 4]) -> [f64; 4] {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        match self {
            Self::Nwu => q,
            Self::Enu => about_z(h, -h, q),
            Self::Ned => ned::quaternion(q),
        }
    }

    /// A body-to-world quaternion of margemu's, in this frame (`W⁻¹ ⊗ q ⊗ B`).
    pub fn quat_out(self, q: [f64; 4]) -> [f64; 4] {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        match self {
            Self::Nwu => q,
            Self::Enu => about_z(h, h, q),
            Self::Ned => ned::quaternion(q),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Quaternion, UnitQuaternion, Vector3};

    fn unit(q: [f64; 4]) -> UnitQuaternion<f64> {
        UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]))
    }

    #[test]
    fn frames_convert_axes_as_documented_and_round_trip() {
        assert_eq!(Frame::Enu.world_in([0.0, 1.0, 0.0]), [1.0, 0.0, 0.0]);
        assert_eq!(Frame::Ned.world_in([1.0, 2.0, 3.0]), [1.0, -2.0, -3.0]);
        assert_eq!(Frame::Enu.body_in([1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
        let q = [0.8, 0.2, -0.3, 0.47];
        let n = (q.iter().map(|x| x * x).sum::<f64>()).sqrt();
        let q = q.map(|x| x / n);
        for frame in [Frame::Nwu, Frame::Enu, Frame::Ned] {
            let back = frame.quat_out(frame.quat_in(q));
            let dot: f64 = back.iter().zip(q).map(|(a, b)| a * b).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-12, "{frame}");
            // A body vector seen in the world agrees in both frames.
            let v = [0.3, -0.5, 0.8];
            let in_frame = unit(q) * Vector3::from(v);
            let in_nwu = unit(frame.quat_in(q)) * Vector3::from(frame.body_in(v));
            let expected = frame.world_in([in_frame.x, in_frame.y, in_frame.z]);
            for i in 0..3 {
                assert!((in_nwu[i] - expected[i]).abs() < 1e-12, "{frame}");
            }
        }
        assert!("xyz"
            .parse::<Frame>()
            .unwrap_err()
            .contains("nwu, enu or ned"));
    }

    #[test]
    fn the_enu_turn_is_minus_90_degrees_about_z() {
        let w = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -std::f64::consts::FRAC_PI_2);
        let q = UnitQuaternion::from_quaternion(Quaternion::new(0.8, 0.2, -0.3, 0.47));
        let p = w * q;
        let ours = Frame::Enu.quat_in([q.w, q.i, q.j, q.k]);
        for (a, b) in ours.iter().zip([p.w, p.i, p.j, p.k]) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    #[test]
    fn the_ned_map_is_an_involution() {
        let e = [0.1, -0.2, -3.0];
        let twice = ned::euler(ned::euler(e));
        for (x, y) in twice.iter().zip(e) {
            assert!((x - y).abs() < 1e-15);
        }
        let q = [0.5, 0.1, 0.2, 0.3];
        assert_eq!(ned::quaternion(ned::quaternion(q)), q);
        assert_eq!(ned::vector(ned::vector([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0]);
    }
}
