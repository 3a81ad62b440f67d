//! The 7×7 covariance of the EKF and the two operations on it: prediction and one scalar
//! measurement update.
//!
//! The matrix is stored whole, row-major; every operation computes the upper triangle and mirrors
//! it, so it is exactly symmetric after each one.

use crate::Real;

/// State dimension: quaternion (4) and gyroscope bias (3).
pub const N: usize = 7;

/// A symmetric 7×7 matrix, stored whole.
pub type Cov<T> = [[T; N]; N];

/// `Φ·P·Φᵀ + Q` for `Φ = [[A, B], [0, I]]` (`A` 4×4, `B` 4×3) and `Q = diag(qq·I₄, qb·I₃)`.
#[inline(always)]
pub fn predict<T: Real>(p: &mut Cov<T>, a: &[[T; 4]; 4], b: &[[T; 3]; 4], qq: T, qb: T) {
    // M = [A B]·P, the first four rows of Φ·P.
    let mut m = [[T::ZERO; N]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            let mut acc = T::ZERO;
            for k in 0..4 {
                acc += a[i][k] * p[k][j];
            }
            for k in 0..3 {
                acc += b[i][k] * p[4 + k][j];
            }
            *entry = acc;
        }
    }
    // qq block: M·[A B]ᵀ (upper triangle), qb block: the last three columns of M.
    for i in 0..4 {
        for j in i..4 {
            let mut acc = T::ZERO;
            for k in 0..4 {
                acc += m[i][k] * a[j][k];
            }
            for k in 0..3 {
                acc += m[i][4 + k] * b[j][k];
            }
            p[i][j] = acc;
            p[j][i] = acc;
        }
        for j in 4..N {
            p[i][j] = m[i][j];
            p[j][i] = m[i][j];
        }
    }
    for i in 0..4 {
        p[i][i] += qq;
    }
    for i in 4..N {
        p[i][i] += qb;
    }
}

/// One scalar measurement `y = h·x + v`, `h` nonzero only in the quaternion block (`h4`),
/// `var(v) = r`: updates `p` in Joseph form and returns the gain `k` (7), or `None` (and leaves
/// `p` alone) when the innovation variance `s = h·P·hᵀ + r` is not finite and positive.
///
/// Joseph form `P⁺ = (I − k h) P (I − k h)ᵀ + r k kᵀ`, expanded for a rank-one `k h` into
/// `P⁺ = P − k uᵀ − u kᵀ + s k kᵀ` with `u = P hᵀ`. The expansion is exact for any gain, so it keeps
/// the Joseph form's property that a rounding error in `k` changes `P⁺` only to second order;
/// it costs O(n²) instead of two matrix products.
#[inline(always)]
pub fn scalar_update<T: Real>(p: &mut Cov<T>, h4: [T; 4], r: T) -> Option<[T; N]> {
    let mut u = [T::ZERO; N];
    for (j, uj) in u.iter_mut().enumerate() {
        *uj = p[j][0] * h4[0] + p[j][1] * h4[1] + p[j][2] * h4[2] + p[j][3] * h4[3];
    }
    let s = h4[0] * u[0] + h4[1] * u[1] + h4[2] * u[2] + h4[3] * u[3] + r;
    if !(s.is_finite() && s > T::ZERO) {
        return None;
    }
    let inv = T::ONE / s;
    let k = u.map(|uj| uj * inv);
    for i in 0..N {
        for j in i..N {
            let v = p[i][j] - k[i] * u[j] - u[i] * k[j] + s * k[i] * k[j];
            p[i][j] = v;
            p[j][i] = v;
        }
    }
    Some(k)
}

/// Whether every entry is finite and every diagonal entry positive (a cheap guard; the tests
/// check positive definiteness itself).
#[inline(always)]
pub fn is_sane<T: Real>(p: &Cov<T>) -> bool {
    let mut sum = T::ZERO;
    let mut ok = true;
    for (i, row) in p.iter().enumerate() {
        for &v in row {
            sum += v;
        }
        ok &= row[i] > T::ZERO;
    }
    ok && sum.is_finite()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matmul<const R: usize, const K: usize, const C: usize>(
        x: &[[f64; K]; R],
        y: &[[f64; C]; K],
    ) -> [[f64; C]; R] {
        let mut out = [[0.0; C]; R];
        for i in 0..R {
            for j in 0..C {
                out[i][j] = (0..K).map(|k| x[i][k] * y[k][j]).sum();
            }
        }
        out
    }

    fn transpose<const R: usize, const C: usize>(x: &[[f64; C]; R]) -> [[f64; R]; C] {
        let mut out = [[0.0; R]; C];
        for i in 0..R {
            for j in 0..C {
                out[j][i] = x[i][j];
            }
        }
        out
    }

    /// A symmetric positive definite test matrix.
    fn spd() -> Cov<f64> {
        let mut l = [[0.0; N]; N];
        for i in 0..N {
            for j in 0..=i {
                l[i][j] = if i == j { 0.5 + i as f64 * 0.1 } else { 0.05 * (i + 2 * j) as f64 - 0.2 };
            }
        }
        matmul(&l, &transpose(&l))
    }

    fn assert_close(x: &Cov<f64>, y: &Cov<f64>) {
        for i in 0..N {
            for j in 0..N {
                assert!((x[i][j] - y[i][j]).abs() < 1e-13, "[{i}][{j}] {} {}", x[i][j], y[i][j]);
                assert_eq!(x[i][j], x[j][i]);
            }
        }
    }

    #[test]
    fn predict_is_phi_p_phi_transpose_plus_q() {
        let a = [[1.0, -0.1, 0.2, 0.05], [0.1, 1.0, -0.3, 0.2], [-0.2, 0.3, 1.0, 0.1], [0.0, -0.2, -0.1, 1.0]];
        let b = [[0.01, -0.02, 0.03], [0.04, 0.0, -0.01], [-0.02, 0.03, 0.01], [0.0, 0.05, -0.04]];
        let mut phi = [[0.0; N]; N];
        for i in 0..4 {
            phi[i][..4].copy_from_slice(&a[i]);
            phi[i][4..].copy_from_slice(&b[i]);
        }
        for i in 4..N {
            phi[i][i] = 1.0;
        }
        let p = spd();
        let mut expect = matmul(&matmul(&phi, &p), &transpose(&phi));
        for (i, row) in expect.iter_mut().enumerate() {
            row[i] += if i < 4 { 1e-3 } else { 2e-4 };
        }
        let mut got = p;
        predict(&mut got, &a, &b, 1e-3, 2e-4);
        assert_close(&got, &expect);
    }

    #[test]
    fn scalar_update_is_the_kalman_update() {
        let p = spd();
        let h4 = [0.3, -1.2, 0.5, 2.0];
        let h = [h4[0], h4[1], h4[2], h4[3], 0.0, 0.0, 0.0];
        let r = 0.01;
        let u: [f64; N] = core::array::from_fn(|j| (0..N).map(|k| p[j][k] * h[k]).sum());
        let s: f64 = (0..N).map(|k| h[k] * u[k]).sum::<f64>() + r;
        let mut expect = p;
        for i in 0..N {
            for j in 0..N {
                expect[i][j] -= u[i] * u[j] / s;
            }
        }
        let mut got = p;
        let k = scalar_update(&mut got, h4, r).unwrap();
        assert_close(&got, &expect);
        for j in 0..N {
            assert!((k[j] - u[j] / s).abs() < 1e-15);
        }
        assert!(is_sane(&got));
        assert_eq!(scalar_update(&mut got, [f64::NAN; 4], r), None);
        let mut bad = got;
        bad[3][3] = -1.0;
        assert!(!is_sane(&bad));
    }
}
