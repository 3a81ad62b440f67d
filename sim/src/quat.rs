//! Attitude arithmetic on plain `[w, x, y, z]` arrays (Hamilton, scalar first, body to world),
//! done by `nalgebra`'s `UnitQuaternion`: normalisation, ZYX Euler angles, interpolation and
//! the geodesic angle (wrapping angles is `truth::wrap_angle`). Every function treats `q` and `−q`
//! as the same attitude.

use crate::truth::geodesic_angle;
use nalgebra::{Quaternion, UnitQuaternion};

/// A unit quaternion `[w, x, y, z]`.
pub type Quat = [f64; 4];

/// Norm below which a quaternion carries no attitude: its direction would be rounding noise
/// (`(1e-30, 1e-30, 0, 0)` is no 90° roll).
pub const MIN_NORM: f64 = 1e-6;

/// `q` scaled to unit norm, or `None` when its norm is below [`MIN_NORM`] or it is not finite.
pub fn normalize(q: Quat) -> Option<UnitQuaternion<f64>> {
    let raw = Quaternion::new(q[0], q[1], q[2], q[3]);
    let norm = raw.norm();
    (norm.is_finite() && norm >= MIN_NORM).then(|| UnitQuaternion::new_unchecked(raw / norm))
}

/// ZYX Euler angles `[roll, pitch, yaw]` of `q` (`R = Rz(ψ) Ry(θ) Rx(φ)`).
pub fn euler(q: &UnitQuaternion<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = q.euler_angles();
    [roll, pitch, yaw]
}

/// The attitude of ZYX Euler angles `[roll, pitch, yaw]`.
pub fn from_euler(e: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_euler_angles(e[0], e[1], e[2])
}

/// `a⁻¹ b` as `(w, x, y, z)`, written out: the hot path of scoring and alignment, which
/// nalgebra's generic code makes slow in debug builds.
fn relative(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> [f64; 4] {
    let (a, b) = (a.quaternion(), b.quaternion());
    let (aw, ax, ay, az) = (a.w, -a.i, -a.j, -a.k);
    [
        aw * b.w - ax * b.i - ay * b.j - az * b.k,
        aw * b.i + ax * b.w + ay * b.k - az * b.j,
        aw * b.j - ax * b.k + ay * b.w + az * b.i,
        aw * b.k + ax * b.j - ay * b.i + az * b.w,
    ]
}

/// The rotation angle between two attitudes in [0, π] (`truth::geodesic_angle`: `2·atan2(‖v‖,
/// |w|)` of `a⁻¹ b`, precise for small angles; `q` and `−q` the same).
pub fn geodesic(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> f64 {
    let wxyz = |q: &UnitQuaternion<f64>| [q.w, q.i, q.j, q.k];
    geodesic_angle(&wxyz(a), &wxyz(b))
}

/// The attitude a fraction `s` ∈ [0, 1] of the way from `a` to `b` along the shorter arc
/// (spherical linear interpolation as `a · (a⁻¹ b)^s`, its angle from `atan2`, so it stays
/// exact for the tiny steps between neighbouring samples).
pub fn interpolate(
    a: &UnitQuaternion<f64>,
    b: &UnitQuaternion<f64>,
    s: f64,
) -> UnitQuaternion<f64> {
    let [w, x, y, z] = relative(a, b);
    let sign = if w < 0.0 { -1.0 } else { 1.0 };
    let n = (x * x + y * y + z * z).sqrt();
    if n == 0.0 {
        return *a;
    }
    let half = s * n.atan2(w * sign);
    let k = sign * half.sin() / n;
    let step = Quaternion::new(half.cos(), x * k, y * k, z * k);
    UnitQuaternion::new_normalize(a.quaternion() * step)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::truth::wrap_angle as wrap;
    use core::f64::consts::PI;

    #[test]
    fn wrap_maps_into_the_half_open_interval() {
        assert_eq!(wrap(PI), PI);
        assert_eq!(wrap(-PI), PI);
        assert!((wrap(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap(-0.1 - 4.0 * PI) + 0.1).abs() < 1e-12);
    }

    #[test]
    fn geodesic_ignores_the_sign_and_is_precise_when_small() {
        let a = from_euler([0.1, -0.2, 3.0]);
        let b = from_euler([0.1, -0.2, 3.0 + 1e-9]);
        let minus_b = UnitQuaternion::new_unchecked(-b.into_inner());
        assert!((geodesic(&a, &b) - 1e-9).abs() < 1e-15);
        assert!((geodesic(&a, &minus_b) - 1e-9).abs() < 1e-15);
        let mid = interpolate(&a, &minus_b, 0.5);
        assert!((geodesic(&a, &mid) - 0.5e-9).abs() < 1e-15);
    }

    #[test]
    fn interpolation_and_geodesic_agree_with_nalgebra() {
        let a = from_euler([0.4, -1.1, 2.9]);
        let b = from_euler([-0.3, 0.2, -2.8]);
        let minus_b = UnitQuaternion::new_unchecked(-b.into_inner());
        for s in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let ours = interpolate(&a, &minus_b, s);
            let theirs = a.slerp(&b, s);
            assert!(geodesic(&ours, &theirs) < 1e-12, "{s}");
        }
        assert!((geodesic(&a, &b) - a.angle_to(&b)).abs() < 1e-12);
    }

    #[test]
    fn normalize_refuses_what_has_no_direction() {
        for q in [
            [0.0; 4],
            [1e-30, 1e-30, 0.0, 0.0],
            [f64::NAN, 0.0, 0.0, 1.0],
            [f64::INFINITY, 0.0, 0.0, 0.0],
        ] {
            assert!(normalize(q).is_none(), "{q:?}");
        }
        let u = normalize([0.0, 2.0, 0.0, 0.0]).unwrap();
        assert_eq!([u.w, u.i, u.j, u.k], [0.0, 1.0, 0.0, 0.0]);
        assert!(normalize([1e-3, 0.0, 0.0, 0.0]).is_some());
    }

    #[test]
    fn euler_round_trips() {
        let e = [0.3, -1.2, -2.9];
        let back = euler(&from_euler(e));
        for i in 0..3 {
            assert!((back[i] - e[i]).abs() < 1e-12, "{back:?}");
        }
    }
}
