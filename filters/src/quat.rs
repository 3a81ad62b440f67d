//! Quaternions and three-vectors as plain arrays, in the conventions of `CONVENTIONS.md`.
//!
//! Quaternions are Hamilton, scalar first `[w, x, y, z]`, unit, body to world
//! (`v_w = q ⊗ v_b ⊗ q*`). Euler angles are ZYX intrinsic, `R_wb = Rz(ψ)·Ry(θ)·Rx(φ)`, returned as
//! `[roll φ, pitch θ, yaw ψ]` with roll and yaw in (−π, π] and pitch in [−π/2, π/2]. `q` and `−q`
//! are the same attitude: [`geodesic_angle`] and [`euler_zyx`] give the same result for both.
//!
//! ```
//! use margemu_filters::quat::{euler_zyx, from_euler_zyx, geodesic_angle, world_to_body};
//! let q = from_euler_zyx([0.1f64, -0.4, 3.0]);
//! let e = euler_zyx(q);
//! assert!((e[0] - 0.1).abs() < 1e-12 && (e[1] + 0.4).abs() < 1e-12 && (e[2] - 3.0).abs() < 1e-12);
//! assert!(geodesic_angle(q, q.map(|c| -c)) < 1e-12);
//! // Level, at rest: the accelerometer reads the world's up axis in body axes.
//! let up = world_to_body([1.0f64, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
//! assert_eq!(up, [0.0, 0.0, 1.0]);
//! ```

use crate::Real;

/// A quaternion `[w, x, y, z]`.
pub type Quat<T> = [T; 4];
/// A three-vector.
pub type Vec3<T> = [T; 3];

/// The identity rotation.
pub fn identity<T: Real>() -> Quat<T> {
    [T::ONE, T::ZERO, T::ZERO, T::ZERO]
}

/// Hamilton product `a ⊗ b`.
#[inline(always)]
pub fn mul<T: Real>(a: Quat<T>, b: Quat<T>) -> Quat<T> {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// `q ⊗ (0, v)`: the product with a pure quaternion, `Ξ(q)·v`.
#[inline(always)]
pub fn mul_pure<T: Real>(q: Quat<T>, v: Vec3<T>) -> Quat<T> {
    [
        -q[1] * v[0] - q[2] * v[1] - q[3] * v[2],
        q[0] * v[0] + q[2] * v[2] - q[3] * v[1],
        q[0] * v[1] + q[3] * v[0] - q[1] * v[2],
        q[0] * v[2] + q[1] * v[1] - q[2] * v[0],
    ]
}

/// `a + s·b`, element by element (also `a + b` with `s = 1`).
#[inline(always)]
pub fn axpy<T: Real, const N: usize>(a: [T; N], s: T, b: [T; N]) -> [T; N] {
    let mut out = a;
    for i in 0..N {
        out[i] = a[i] + s * b[i];
    }
    out
}

/// `s·v`.
#[inline(always)]
pub fn scale<T: Real, const N: usize>(v: [T; N], s: T) -> [T; N] {
    let mut out = v;
    for c in &mut out {
        *c *= s;
    }
    out
}

/// `a · b`.
#[inline(always)]
pub fn dot3<T: Real>(a: Vec3<T>, b: Vec3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline(always)]
pub fn cross<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `v / |v|`, or `None` when `v` is zero or has a NaN or infinite component.
///
/// Never overflows or underflows: vectors whose squared norm leaves the normal range of `T`
/// (components near `T::MAX` or subnormal) are scaled by their largest component first.
#[inline(always)]
pub fn normalize<T: Real, const N: usize>(v: [T; N]) -> Option<[T; N]> {
    let mut n2 = T::ZERO;
    for c in v {
        n2 += c * c;
    }
    if n2.is_finite() && n2 >= T::MIN_POSITIVE {
        Some(scale(v, T::ONE / n2.sqrt()))
    } else {
        normalize_scaled(v)
    }
}

/// The slow path of [`normalize`]: divide by the largest magnitude, then normalize.
#[cold]
fn normalize_scaled<T: Real, const N: usize>(v: [T; N]) -> Option<[T; N]> {
    let mut m = T::ZERO;
    for c in v {
        if !c.is_finite() {
            return None;
        }
        if c.abs() > m {
            m = c.abs();
        }
    }
    if m == T::ZERO {
        return None;
    }
    let scaled = v.map(|c| c / m);
    let mut n2 = T::ZERO;
    for c in scaled {
        n2 += c * c;
    }
    let inv = T::ONE / n2.sqrt();
    Some(scaled.map(|c| c * inv))
}

/// `Rᵀ·r`: a world vector `r` in body axes, for the unit body-to-world quaternion `q`.
#[inline(always)]
pub fn world_to_body<T: Real>(q: Quat<T>, r: Vec3<T>) -> Vec3<T> {
    // v = r − w·t + u × t with t = 2·(u × r), u the vector part (rotation by q*).
    let u = [q[1], q[2], q[3]];
    let t = scale(cross(u, r), T::TWO);
    let ut = cross(u, t);
    [
        r[0] - q[0] * t[0] + ut[0],
        r[1] - q[0] * t[1] + ut[1],
        r[2] - q[0] * t[2] + ut[2],
    ]
}

/// `R·v`: a body vector in world axes.
#[inline(always)]
pub fn body_to_world<T: Real>(q: Quat<T>, v: Vec3<T>) -> Vec3<T> {
    world_to_body([q[0], -q[1], -q[2], -q[3]], v)
}

/// The world's up axis `(0, 0, 1)` in body axes: the third row of `R`.
#[inline(always)]
pub fn up_in_body<T: Real>(q: Quat<T>) -> Vec3<T> {
    let [w, x, y, z] = q;
    [
        T::TWO * (x * z - w * y),
        T::TWO * (y * z + w * x),
        T::ONE - T::TWO * (x * x + y * y),
    ]
}

/// One first-order step of `q̇ = ½ q ⊗ (0, ω)` (the paper's eq. 24–26): `q + dt/2 · q ⊗ (0, ω)`,
/// not normalized.
#[inline(always)]
pub fn integrate<T: Real>(q: Quat<T>, omega: Vec3<T>, dt: T) -> Quat<T> {
    axpy(q, T::HALF * dt, mul_pure(q, omega))
}

/// The angle (rad, in [0, π]) of the rotation between two attitudes; `q` and `−q` are equal.
///
/// `2·atan2(|vec(a* ⊗ b)|, |w(a* ⊗ b)|)`, equal to `2·acos|⟨a, b⟩|` for unit quaternions and
/// accurate for tiny angles too, where the `acos` form loses half its digits.
pub fn geodesic_angle<T: Real>(a: Quat<T>, b: Quat<T>) -> T {
    let d = mul([a[0], -a[1], -a[2], -a[3]], b);
    let v = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    T::TWO * v.atan2(d[0].abs())
}

/// ZYX Euler angles `[roll, pitch, yaw]` of a unit quaternion (see the module docs for ranges).
///
/// Pitch is `atan2(−R₂₀, √(R₂₁² + R₂₂²))`, accurate up to ±90°, where `asin` is not.
pub fn euler_zyx<T: Real>(q: Quat<T>) -> Vec3<T> {
    let [w, x, y, z] = q;
    let r20 = T::TWO * (x * z - w * y);
    let r21 = T::TWO * (y * z + w * x);
    let r22 = T::ONE - T::TWO * (x * x + y * y);
    let r10 = T::TWO * (x * y + w * z);
    let r00 = T::ONE - T::TWO * (y * y + z * z);
    [
        wrap_angle(r21.atan2(r22)),
        (-r20).atan2((r21 * r21 + r22 * r22).sqrt()),
        wrap_angle(r10.atan2(r00)),
    ]
}

/// The unit quaternion of ZYX Euler angles `[roll, pitch, yaw]`, with `w ≥ 0`.
pub fn from_euler_zyx<T: Real>(e: Vec3<T>) -> Quat<T> {
    let (sr, cr) = ((T::HALF * e[0]).sin(), (T::HALF * e[0]).cos());
    let (sp, cp) = ((T::HALF * e[1]).sin(), (T::HALF * e[1]).cos());
    let (sy, cy) = ((T::HALF * e[2]).sin(), (T::HALF * e[2]).cos());
    let q = [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ];
    canonical(q)
}

/// The same attitude with `w ≥ 0`.
pub fn canonical<T: Real>(q: Quat<T>) -> Quat<T> {
    if q[0] < T::ZERO {
        q.map(|c| -c)
    } else {
        q
    }
}

/// The unit quaternion (`w ≥ 0`) of a rotation matrix `m` (row-major, body to world), by
/// Shepperd's method: the largest of `w, x, y, z` is taken from the diagonal, the rest from the
/// off-diagonal sums, so no division is by a small number. `m` must be a rotation.
pub fn from_rotation_matrix<T: Real>(m: [[T; 3]; 3]) -> Quat<T> {
    let quarter = T::HALF * T::HALF;
    let trace = m[0][0] + m[1][1] + m[2][2];
    let q = if trace >= m[0][0] && trace >= m[1][1] && trace >= m[2][2] {
        let s = (T::ONE + trace).sqrt() * T::TWO;
        [
            quarter * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] >= m[1][1] && m[0][0] >= m[2][2] {
        let s = (T::ONE + m[0][0] - m[1][1] - m[2][2]).sqrt() * T::TWO;
        [
            (m[2][1] - m[1][2]) / s,
            quarter * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] >= m[2][2] {
        let s = (T::ONE + m[1][1] - m[0][0] - m[2][2]).sqrt() * T::TWO;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            quarter * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (T::ONE + m[2][2] - m[0][0] - m[1][1]).sqrt() * T::TWO;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            quarter * s,
        ]
    };
    canonical(normalize(q).unwrap_or_else(identity))
}

/// An angle wrapped into (−π, π] (the paper's eq. 27 errors).
pub fn wrap_angle<T: Real>(a: T) -> T {
    let tau = T::TWO * T::PI;
    let mut w = a - tau * ((a + T::PI) / tau).floor();
    if w <= -T::PI {
        w += tau;
    }
    if w > T::PI {
        w -= tau;
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_agree_with_the_matrix_of_zyx_euler_angles() {
        let (r, p, y) = (0.3f64, -0.7, 2.5);
        let q = from_euler_zyx([r, p, y]);
        let (sr, cr, sp, cp, sy, cy) = (r.sin(), r.cos(), p.sin(), p.cos(), y.sin(), y.cos());
        // R = Rz(y)·Ry(p)·Rx(r), column 0 is R·e_x.
        let col0 = [cy * cp, sy * cp, -sp];
        let got = body_to_world(q, [1.0, 0.0, 0.0]);
        for i in 0..3 {
            assert!((got[i] - col0[i]).abs() < 1e-15, "{got:?} {col0:?}");
        }
        let up = up_in_body(q);
        let up2 = world_to_body(q, [0.0, 0.0, 1.0]);
        let row2 = [-sp, cp * sr, cp * cr];
        for i in 0..3 {
            assert!((up[i] - row2[i]).abs() < 1e-15 && (up2[i] - row2[i]).abs() < 1e-15);
        }
    }

    #[test]
    fn normalize_handles_extreme_and_degenerate_vectors() {
        assert_eq!(normalize([3.0f32, 4.0, 0.0]), Some([0.6, 0.8, 0.0]));
        assert_eq!(normalize([f32::MAX, 0.0, 0.0]), Some([1.0, 0.0, 0.0]));
        assert_eq!(normalize([1e-45f32, 0.0, 0.0]), Some([1.0, 0.0, 0.0]));
        let n = normalize([f32::MAX, f32::MAX, 0.0]).unwrap();
        assert!((n[0] - core::f32::consts::FRAC_1_SQRT_2).abs() < 1e-7);
        assert_eq!(normalize([0.0f64; 3]), None);
        assert_eq!(normalize([f64::NAN, 1.0, 0.0]), None);
        assert_eq!(normalize([f64::INFINITY, 1.0, 0.0]), None);
    }

    #[test]
    fn matrix_round_trip_in_every_branch() {
        for e in [
            [0.1, 0.2, 0.3],
            [3.0, 0.1, 0.2],
            [0.1, 0.2, 3.0],
            [3.0, 0.1, -3.0],
            [1.6, 1.5, -1.2],
        ] {
            let q = from_euler_zyx::<f64>(e);
            let cols =
                [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|v| body_to_world(q, v));
            let m = [0, 1, 2].map(|r| [cols[0][r], cols[1][r], cols[2][r]]);
            assert!(geodesic_angle(q, from_rotation_matrix(m)) < 1e-14, "{e:?}");
        }
    }

    #[test]
    fn wrap_angle_lands_in_the_half_open_interval() {
        let pi = core::f64::consts::PI;
        assert_eq!(wrap_angle(pi), pi);
        assert_eq!(wrap_angle(-pi), pi);
        assert!((wrap_angle(3.0 * pi + 0.5) - (-pi + 0.5)).abs() < 1e-12);
        assert!((wrap_angle(-0.25f64) + 0.25).abs() < 1e-15);
    }
}
