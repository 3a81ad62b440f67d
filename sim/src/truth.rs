//! Ground truth of the plate at one instant, from the joint coordinates and their derivatives.
//!
//! Frames and conventions are those of `CONVENTIONS.md`: world z up, gravity `(0, 0, −g)`,
//! attitude `R_wb = Rz(ψ) Ry(θ) Rx(φ)` from the revolute joints, Hamilton quaternions scalar
//! first, body-to-world. The sensor sits at the plate origin, so:
//!
//! - body rate `ω_b = [φ̇ − ψ̇ sθ, θ̇ cφ + ψ̇ cθ sφ, −θ̇ sφ + ψ̇ cθ cφ]` and its time derivative;
//! - specific force `f_b = R_wbᵀ (a_w − g_w)` (level at rest: `(0, 0, +g)`);
//! - external acceleration `a_w = (ẍ, ÿ, z̈)` and `R_wbᵀ a_w`;
//! - magnetic field `R_wbᵀ m_w` from the scene's reference field.
//!
//! Euler angles are reported canonically: roll and yaw in (−π, π], pitch in [−π/2, π/2]. Joint
//! angles beyond that (pitch past ±90°) are folded with the identity
//! `(φ, θ, ψ) ≡ (φ + π, π − θ, ψ + π)`, which is exact and needs no trigonometry. The
//! quaternion comes from the half angles of the joints, so it is continuous in time whenever
//! the joints are, gimbal lock included.
//!
//! Trigonometry uses `libm` (three `sincos` of half angles per sample; full angles by the
//! double-angle identities) so the numbers are the same on every machine.

use crate::bench::JointSample;
use core::f64::consts::{FRAC_PI_2, PI, TAU};
use margemu_model::time::Nanos;
use nalgebra::{Matrix3, Vector3};

/// Ground truth at one output instant (SI units; field in the scene's unit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Truth {
    /// Latch instant.
    pub t_ns: Nanos,
    /// Plate position in the world frame (m).
    pub position: [f64; 3],
    /// Plate velocity in the world frame (m/s).
    pub velocity: [f64; 3],
    /// Canonical roll, pitch, yaw (rad).
    pub euler: [f64; 3],
    /// Attitude quaternion `(w, x, y, z)`, body to world.
    pub quaternion: [f64; 4],
    /// Body angular rate (rad/s).
    pub body_rate: [f64; 3],
    /// Specific force in the body frame (m/s²).
    pub specific_force: [f64; 3],
    /// External acceleration in the world frame (m/s²).
    pub accel_world: [f64; 3],
    /// External acceleration in the body frame (m/s²).
    pub accel_body: [f64; 3],
    /// Body angular acceleration (rad/s²).
    pub angular_accel: [f64; 3],
    /// Magnetic field in the body frame.
    pub field_body: [f64; 3],
}

impl Truth {
    /// Every value after the time stamp, in the order of the `truth.csv` columns
    /// ([`crate::output::TRUTH_COLUMNS`] after `t_ns`).
    pub fn columns(&self) -> [f64; 31] {
        let [x, y, z] = self.position;
        let [roll, pitch, yaw] = self.euler;
        let [qw, qx, qy, qz] = self.quaternion;
        let [wx, wy, wz] = self.body_rate;
        let [fx, fy, fz] = self.specific_force;
        let [vx, vy, vz] = self.velocity;
        let [awx, awy, awz] = self.accel_world;
        let [abx, aby, abz] = self.accel_body;
        let [dwx, dwy, dwz] = self.angular_accel;
        let [mx, my, mz] = self.field_body;
        [
            x, y, z, roll, pitch, yaw, qw, qx, qy, qz, wx, wy, wz, fx, fy, fz, vx, vy, vz, awx,
            awy, awz, abx, aby, abz, dwx, dwy, dwz, mx, my, mz,
        ]
    }
}

/// Turns joint samples into ground truth for one scene's field and gravity.
#[derive(Clone, Copy, Debug)]
pub struct TruthModel {
    field_world: Vector3<f64>,
    gravity: f64,
}

impl TruthModel {
    /// A model for the world-frame field `field_world` and gravity `gravity` (m/s²).
    pub fn new(field_world: [f64; 3], gravity: f64) -> Self {
        Self {
            field_world: Vector3::from(field_world),
            gravity,
        }
    }

    /// Ground truth at `t_ns` for the joint sample `s`.
    pub fn compute(&self, t_ns: Nanos, s: &JointSample) -> Truth {
        let [x, y, z, phi, theta, psi] = s.q;
        let (sp2, cp2) = libm::sincos(0.5 * phi);
        let (st2, ct2) = libm::sincos(0.5 * theta);
        let (ss2, cs2) = libm::sincos(0.5 * psi);
        let quaternion = [
            cp2 * ct2 * cs2 + sp2 * st2 * ss2,
            sp2 * ct2 * cs2 - cp2 * st2 * ss2,
            cp2 * st2 * cs2 + sp2 * ct2 * ss2,
            cp2 * ct2 * ss2 - sp2 * st2 * cs2,
        ];
        let (sp, cp) = (2.0 * sp2 * cp2, cp2 * cp2 - sp2 * sp2);
        let (st, ct) = (2.0 * st2 * ct2, ct2 * ct2 - st2 * st2);
        let (ss, cs) = (2.0 * ss2 * cs2, cs2 * cs2 - ss2 * ss2);
        let r = Matrix3::new(
            cs * ct,
            cs * st * sp - ss * cp,
            cs * st * cp + ss * sp,
            ss * ct,
            ss * st * sp + cs * cp,
            ss * st * cp - cs * sp,
            -st,
            ct * sp,
            ct * cp,
        );
        let [dphi, dtheta, dpsi] = [s.qd[3], s.qd[4], s.qd[5]];
        let [ddphi, ddtheta, ddpsi] = [s.qdd[3], s.qdd[4], s.qdd[5]];
        let body_rate = [
            dphi - dpsi * st,
            dtheta * cp + dpsi * ct * sp,
            -dtheta * sp + dpsi * ct * cp,
        ];
        let angular_accel = [
            ddphi - ddpsi * st - dpsi * dtheta * ct,
            ddtheta * cp - dtheta * dphi * sp + ddpsi * ct * sp - dpsi * dtheta * st * sp
                + dpsi * dphi * ct * cp,
            -ddtheta * sp - dtheta * dphi * cp + ddpsi * ct * cp
                - dpsi * dtheta * st * cp
                - dpsi * dphi * ct * sp,
        ];
        let accel_world = Vector3::new(s.qdd[0], s.qdd[1], s.qdd[2]);
        let specific = accel_world + Vector3::new(0.0, 0.0, self.gravity);
        Truth {
            t_ns,
            position: [x, y, z],
            velocity: [s.qd[0], s.qd[1], s.qd[2]],
            euler: canonical_euler(phi, theta, psi),
            quaternion,
            body_rate,
            specific_force: r.tr_mul(&specific).into(),
            accel_world: accel_world.into(),
            accel_body: r.tr_mul(&accel_world).into(),
            angular_accel,
            field_body: r.tr_mul(&self.field_world).into(),
        }
    }
}

/// Wraps an angle into (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    // Inside (−3, 3) the quotient below lies in (0.02, 0.98), its floor is +0 and `a − 0` is
    // `a` itself (a zero keeps its sign): the common case skips the division and the floor.
    if a.abs() < 3.0 {
        return a;
    }
    let w = a - TAU * libm::floor((a + PI) / TAU);
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}

/// The canonical ZYX Euler triple of the same attitude: pitch in [−π/2, π/2], others wrapped.
pub fn canonical_euler(phi: f64, theta: f64, psi: f64) -> [f64; 3] {
    let theta = wrap_angle(theta);
    if theta > FRAC_PI_2 {
        [wrap_angle(phi + PI), PI - theta, wrap_angle(psi + PI)]
    } else if theta < -FRAC_PI_2 {
        [wrap_angle(phi + PI), -PI - theta, wrap_angle(psi + PI)]
    } else {
        [wrap_angle(phi), theta, wrap_angle(psi)]
    }
}

/// Geodesic angle between two attitudes (rad, in [0, π]); `q` and `−q` are the same attitude.
///
/// Computed as `2·atan2(|vec(q₁* ⊗ q₂)|, |w(q₁* ⊗ q₂)|)`, accurate for tiny angles where
/// `2·acos|⟨q₁, q₂⟩|` loses half its digits.
pub fn geodesic_angle(q1: &[f64; 4], q2: &[f64; 4]) -> f64 {
    let [w1, x1, y1, z1] = *q1;
    let [w2, x2, y2, z2] = *q2;
    // Product of the conjugate of q1 with q2.
    let w = w1 * w2 + x1 * x2 + y1 * y2 + z1 * z2;
    let x = w1 * x2 - x1 * w2 - y1 * z2 + z1 * y2;
    let y = w1 * y2 + x1 * z2 - y1 * w2 - z1 * x2;
    let z = w1 * z2 - x1 * y2 + y1 * x2 - z1 * w2;
    2.0 * libm::atan2(libm::sqrt(x * x + y * y + z * z), w.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The wrap without its shortcut.
    fn wrap_by_floor(a: f64) -> f64 {
        let w = a - TAU * libm::floor((a + PI) / TAU);
        if w <= -PI {
            w + TAU
        } else {
            w
        }
    }

    #[test]
    fn the_wrap_shortcut_gives_the_floor_formula_bit_for_bit() {
        let edges = [0.0, -0.0, 3.0, -3.0, PI, -PI, 1e-310, -1e-310, f64::NAN];
        let sweep = (-40_000..=40_000).map(|k| f64::from(k) * 1e-4);
        let near_three = (-2000..=2000).map(|k| 3.0 + f64::from(k) * f64::EPSILON);
        for a in edges.into_iter().chain(sweep).chain(near_three) {
            for a in [a, -a] {
                assert_eq!(wrap_angle(a).to_bits(), wrap_by_floor(a).to_bits(), "{a:e}");
            }
        }
    }

    /// `columns` follows the order `truth.csv` is written in.
    #[test]
    fn columns_follow_the_written_order() {
        let mut t = Truth::default();
        let mut next = 0.0;
        let mut fill = |v: &mut [f64]| {
            for x in v {
                next += 1.0;
                *x = next;
            }
        };
        fill(&mut t.position);
        fill(&mut t.euler);
        fill(&mut t.quaternion);
        fill(&mut t.body_rate);
        fill(&mut t.specific_force);
        fill(&mut t.velocity);
        fill(&mut t.accel_world);
        fill(&mut t.accel_body);
        fill(&mut t.angular_accel);
        fill(&mut t.field_body);
        let mut w = crate::output::TruthWriter::new(Vec::new()).unwrap();
        w.write(&t).unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        let row: Vec<f64> = text
            .lines()
            .nth(1)
            .unwrap()
            .split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(row, t.columns().to_vec());
    }
}
