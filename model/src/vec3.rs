//! Three-vectors and 3×3 matrices as plain arrays, with a fixed order of operations.
//!
//! The per-sample path works on `[f32; 3]` and `[[f32; 3]; 3]` (row-major). Every function spells
//! its arithmetic out term by term and left to right, so that the result does not depend on the
//! compiler: `mat_vec(m, v)[i] = (m[i][0]·v[0] + m[i][1]·v[1]) + m[i][2]·v[2]`, never fused. The
//! `f64` helpers serve the one-off precomputation of coefficients at construction.
//!
//! ```
//! use margemu_model::vec3::{cross, mat_vec};
//! assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
//! let m = [[1.0, 2.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]];
//! assert_eq!(mat_vec(&m, [1.0, 1.0, 2.0]), [3.0, 1.0, 1.0]);
//! ```

/// A three-vector in single precision.
pub type Vec3 = [f32; 3];
/// A row-major 3×3 matrix in single precision.
pub type Mat3 = [[f32; 3]; 3];
/// A row-major 3×3 matrix in double precision (configuration and precomputation).
pub type Mat3d = [[f64; 3]; 3];

/// The 3×3 identity in double precision.
pub const IDENTITY: Mat3d = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// `m · v`, each row summed left to right.
#[inline(always)]
pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// `a + b`.
#[inline(always)]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a × b`.
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Each component limited to `[-limit, limit]`; NaN stays NaN.
#[inline(always)]
pub fn clamp(v: Vec3, limit: f32) -> Vec3 {
    [
        v[0].clamp(-limit, limit),
        v[1].clamp(-limit, limit),
        v[2].clamp(-limit, limit),
    ]
}

/// `a · b` in double precision, each entry summed left to right.
pub fn mat_mul_f64(a: &Mat3d, b: &Mat3d) -> Mat3d {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            *entry = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
        }
    }
    out
}

/// `m · v` in double precision.
pub fn mat_vec_f64(m: &Mat3d, v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// `I + d` in double precision.
pub fn identity_plus(d: &Mat3d) -> Mat3d {
    let mut out = *d;
    for (i, row) in out.iter_mut().enumerate() {
        row[i] += 1.0;
    }
    out
}

/// Rounds a double-precision matrix to single precision (round to nearest).
pub fn to_f32(m: &Mat3d) -> Mat3 {
    m.map(|row| row.map(|x| x as f32))
}

/// Rounds a double-precision vector to single precision (round to nearest).
pub fn vec_to_f32(v: [f64; 3]) -> Vec3 {
    v.map(|x| x as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_follow_the_textbook_definitions() {
        let a = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 10.0]];
        let b = [[0.5, 0.0, 1.0], [0.0, 2.0, 0.0], [1.0, 0.0, 0.25]];
        assert_eq!(
            mat_mul_f64(&a, &b),
            [[3.5, 4.0, 1.75], [8.0, 10.0, 5.5], [13.5, 16.0, 9.5]]
        );
        assert_eq!(mat_vec_f64(&a, [1.0, 0.0, -1.0]), [-2.0, -2.0, -3.0]);
        assert_eq!(identity_plus(&[[0.5; 3]; 3])[1], [0.5, 1.5, 0.5]);
        assert_eq!(cross([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]);
        let c = clamp([f32::INFINITY, -1e30, f32::NAN], 2.0);
        assert_eq!([c[0], c[1]], [2.0, -2.0]);
        assert!(c[2].is_nan());
    }
}
