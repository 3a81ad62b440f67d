//! Named world frames at the edges (CONVENTIONS "Named world frames"): a recording's vectors and
//! quaternions in NWU, ENU or NED, converted once, as they are read, into margemu's own frames,
//! and back as estimates are written.
//!
//! | frame | world axes | body axes assumed | converted on reading |
//! |---|---|---|---|
//! | `nwu` (default) | x north, y west, z up | margemu's (z up at rest: the accelerometer reads `+g` on z) | nothing |
//! | `enu` | x east, y north, z up | margemu's | world vectors `(x, y, z) → (y, −x, z)`; quaternions `q → W ⊗ q`, `W` a −90° turn about z |
//! | `ned` | x north, y east, z down | FRD (x forward, y right, z down: the accelerometer reads `−g` on z at rest) | world vectors and body vectors (accelerometer, gyroscope, magnetometer) `(x, y, z) → (x, −y, −z)`; quaternions `q → W ⊗ q ⊗ W⁻¹`, `W` a half turn about x |
//!
//! What is converted: the IMU columns (body vectors, `ned` only), the reference and estimate
//! quaternions (body to world), the magnetic reference given with `--mag-reference` (a world
//! vector), and, when writing, the estimates (back into the named frame, their Euler angles
//! taken in it). Scores that compare two attitudes in one frame (geodesic, heading, inclination)
//! do not depend on the frame; the Euler angles of `errors.csv` and the figures are margemu's
//! (NWU, ZYX).

use nalgebra::{Quaternion, UnitQuaternion};
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

fn unit(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]))
}

fn coords(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

impl Frame {
    /// `W`: this frame's world axes to NWU.
    fn world(self) -> UnitQuaternion<f64> {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        match self {
            Self::Nwu => UnitQuaternion::identity(),
            Self::Enu => unit([h, 0.0, 0.0, -h]),
            Self::Ned => unit([0.0, 1.0, 0.0, 0.0]),
        }
    }

    /// `B`: this frame's body axes to margemu's.
    fn body(self) -> UnitQuaternion<f64> {
        match self {
            Self::Ned => unit([0.0, 1.0, 0.0, 0.0]),
            _ => UnitQuaternion::identity(),
        }
    }

    /// A world vector in this frame, in NWU.
    pub fn world_in(self, v: [f64; 3]) -> [f64; 3] {
        let r = self.world() * nalgebra::Vector3::from(v);
        [r.x, r.y, r.z]
    }

    /// A body vector (accelerometer, gyroscope, magnetometer) in this frame's body axes, in
    /// margemu's.
    pub fn body_in(self, v: [f64; 3]) -> [f64; 3] {
        let r = self.body() * nalgebra::Vector3::from(v);
        [r.x, r.y, r.z]
    }

    /// A body-to-world quaternion `[w, x, y, z]` of this frame, in margemu's (`W ⊗ q ⊗ B⁻¹`);
    /// its norm is kept.
    pub fn quat_in(self, q: [f64; 4]) -> [f64; 4] {
        if self == Self::Nwu {
            return q;
        }
        let p = self.world().quaternion()
            * Quaternion::new(q[0], q[1], q[2], q[3])
            * self.body().inverse().quaternion();
        [p.w, p.i, p.j, p.k]
    }

    /// A body-to-world quaternion of margemu's, in this frame (`W⁻¹ ⊗ q ⊗ B`).
    pub fn quat_out(self, q: [f64; 4]) -> [f64; 4] {
        if self == Self::Nwu {
            return q;
        }
        coords(&(self.world().inverse() * unit(q) * self.body()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_convert_axes_as_documented_and_round_trip() {
        assert_eq!(
            Frame::Enu.world_in([1.0, 0.0, 0.0]).map(f64::round),
            [0.0, -1.0, 0.0]
        );
        assert_eq!(
            Frame::Enu.world_in([0.0, 1.0, 0.0]).map(f64::round),
            [1.0, 0.0, 0.0]
        );
        assert_eq!(Frame::Ned.world_in([1.0, 2.0, 3.0]), [1.0, -2.0, -3.0]);
        assert_eq!(Frame::Ned.body_in([0.0, 0.0, -9.8]), [0.0, 0.0, 9.8]);
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
            let in_frame = unit(q) * nalgebra::Vector3::from(v);
            let in_nwu = unit(frame.quat_in(q)) * nalgebra::Vector3::from(frame.body_in(v));
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
}
