//! From the frames and units devices report in to margemu's conventions (`CONVENTIONS.md`: world
//! z up, body x forward and z up, ZYX Euler `R = Rz(yaw) Ry(pitch) Rx(roll)`, Hamilton
//! quaternions scalar first, body to world; SI units).
//!
//! - **MAVLink** reports NED world and FRD body axes. Both frames turn by 180° about x: world
//!   (north, west, up), body (forward, left, up). Hence `R' = Rx(π) R Rx(π)ᵀ`: roll stays, pitch
//!   and yaw change sign, `q = (w, x, y, z) → (w, x, −y, −z)`, and a body vector
//!   `(x, y, z) → (x, −y, −z)` ([`from_ned`]). The map is its own inverse, so
//!   [`mavlink_out`](super::mavlink_out) uses it the other way.
//! - **MSP** (Betaflight, INAV) already works in body axes forward, left, up with the world's z
//!   up: roll is positive right wing down, pitch positive **nose down** (Betaflight's GPS rescue
//!   says "positive pitch setpoint means nose down"; INAV's multicopter position controller turns
//!   a forward acceleration into a positive pitch), and yaw is the compass heading, clockwise from
//!   north. Hence roll and pitch stay and `yaw = −heading` ([`from_msp`]). ArduPilot's MSP
//!   telemetry sends its own NED pitch (nose up positive) instead; margemu follows Betaflight.
//!
//! North is world x in both cases.

use margemu_sim::truth::canonical_euler;
use nalgebra::{Quaternion, UnitQuaternion};

/// Standard gravity, m/s² (MAVLink's milli-g).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// An attitude in margemu's conventions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attitude {
    /// Canonical ZYX Euler angles (rad): roll, yaw in (−π, π], pitch in [−π/2, π/2].
    pub euler: [f64; 3],
    /// Unit quaternion `(w, x, y, z)`, body to world.
    pub quaternion: [f64; 4],
}

impl Attitude {
    /// From ZYX Euler angles (rad); the quaternion is computed from them.
    pub fn from_euler(roll: f64, pitch: f64, yaw: f64) -> Self {
        let q = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        Self {
            euler: canonical_euler(roll, pitch, yaw),
            quaternion: [q.w, q.i, q.j, q.k],
        }
    }

    /// From a quaternion `(w, x, y, z)`, normalized here; the Euler angles are computed from it.
    /// A quaternion that has no direction ([`normalize`](margemu_sim::quat::normalize):
    /// zero, near zero, not finite) gives NaN throughout, which evaluation skips and counts.
    pub fn from_quaternion(q: [f64; 4]) -> Self {
        if margemu_sim::quat::normalize(q).is_none() {
            return Self {
                euler: [f64::NAN; 3],
                quaternion: [f64::NAN; 4],
            };
        }
        let [w, x, y, z] = q;
        let norm = libm::sqrt(w * w + x * x + y * y + z * z);
        let q = [w / norm, x / norm, y / norm, z / norm];
        let unit = UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]));
        let (roll, pitch, yaw) = unit.euler_angles();
        Self {
            euler: [roll, pitch, yaw],
            quaternion: q,
        }
    }
}

/// A NED/FRD vector, quaternion or Euler triple in margemu's frames (and back: the map is an
/// involution); the one map, [`margemu_sim::frame::ned`].
pub use margemu_sim::frame::ned as from_ned;

/// MSP (Betaflight/INAV) attitude in margemu's conventions.
pub mod from_msp {
    use super::Attitude;

    /// `MSP_ATTITUDE` fields: roll and pitch in 0.1°, yaw as the heading in whole degrees.
    pub fn attitude(roll_decideg: i16, pitch_decideg: i16, heading_deg: i16) -> Attitude {
        let rad = |deg: f64| deg.to_radians();
        Attitude::from_euler(
            rad(f64::from(roll_decideg) / 10.0),
            rad(f64::from(pitch_decideg) / 10.0),
            rad(-f64::from(heading_deg)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use margemu_sim::truth::geodesic_angle;

    /// The world direction of a body axis.
    fn axis(q: [f64; 4], body: [f64; 3]) -> [f64; 3] {
        let u = UnitQuaternion::new_unchecked(Quaternion::new(q[0], q[1], q[2], q[3]));
        let v = u * nalgebra::Vector3::from(body);
        [v.x, v.y, v.z]
    }

    #[test]
    fn a_quaternion_without_direction_is_nan_not_a_rotation() {
        for q in [
            [1e-30, 1e-30, 0.0, 0.0],
            [0.0; 4],
            [f64::NAN, 0.0, 0.0, 1.0],
        ] {
            let a = Attitude::from_quaternion(q);
            assert!(
                a.quaternion.iter().chain(&a.euler).all(|v| v.is_nan()),
                "{q:?}: {a:?}"
            );
        }
        let a = Attitude::from_quaternion([0.0, 2.0, 0.0, 0.0]);
        assert_eq!(a.quaternion, [0.0, 1.0, 0.0, 0.0]);
    }

    #[test]
    fn euler_and_quaternion_agree_with_the_truth_convention() {
        // R = Rz(yaw) Ry(pitch) Rx(roll), as truth.rs builds its quaternion from half angles.
        let (roll, pitch, yaw) = (0.3_f64, -0.4_f64, 2.5_f64);
        let a = Attitude::from_euler(roll, pitch, yaw);
        let (sp, cp) = (0.5 * roll).sin_cos();
        let (st, ct) = (0.5 * pitch).sin_cos();
        let (ss, cs) = (0.5 * yaw).sin_cos();
        let truth = [
            cp * ct * cs + sp * st * ss,
            sp * ct * cs - cp * st * ss,
            cp * st * cs + sp * ct * ss,
            cp * ct * ss - sp * st * cs,
        ];
        assert!(geodesic_angle(&a.quaternion, &truth) < 1e-15);
        let back = Attitude::from_quaternion(a.quaternion);
        for (x, y) in back.euler.iter().zip([roll, pitch, yaw]) {
            assert_relative_eq!(*x, y, epsilon = 1e-12);
        }
    }

    #[test]
    fn ned_pitch_up_and_east_heading_in_margemu_axes() {
        // MAVLink: nose 10° up, heading east (NED yaw +90°).
        let e = from_ned::euler([0.0, 10f64.to_radians(), 90f64.to_radians()]);
        let a = Attitude::from_euler(e[0], e[1], e[2]);
        let nose = axis(a.quaternion, [1.0, 0.0, 0.0]);
        assert!(nose[2] > 0.17, "nose up: {nose:?}");
        // East is −y in (north, west, up).
        assert!(nose[1] < -0.98, "heading east: {nose:?}");
        // The same attitude as a NED quaternion goes through the quaternion map.
        let q_ned = UnitQuaternion::from_euler_angles(0.0, 10f64.to_radians(), 90f64.to_radians());
        let q = from_ned::quaternion([q_ned.w, q_ned.i, q_ned.j, q_ned.k]);
        assert!(geodesic_angle(&q, &a.quaternion) < 1e-15);
    }

    #[test]
    fn betaflight_msp_signs() {
        // Right wing 20° down, nose 10° down, heading 90° (east).
        let a = from_msp::attitude(200, 100, 90);
        let nose = axis(a.quaternion, [1.0, 0.0, 0.0]);
        let right_wing = axis(a.quaternion, [0.0, -1.0, 0.0]);
        assert!(nose[2] < -0.17, "nose down: {nose:?}");
        assert!(nose[1] < -0.98, "heading east: {nose:?}");
        assert!(right_wing[2] < -0.3, "right wing down: {right_wing:?}");
        assert_relative_eq!(a.euler[2], -std::f64::consts::FRAC_PI_2, epsilon = 1e-15);
    }
}
