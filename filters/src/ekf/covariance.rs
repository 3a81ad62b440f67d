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
///
/// Row-oriented, so that the inner loops run along rows: `M = [A B]·P` (the first four rows of
/// `Φ·P`) as sums of scaled rows of `P`, then the attitude block `M·[A B]ᵀ` as sums of scaled rows
/// of `[A B]ᵀ`, mirrored from its upper triangle.
#[inline(always)]
pub fn predict<T: Real>(p: &mut Cov<T>, a: &[[T; 4]; 4], b: &[[T; 3]; 4], qq: T, qb: T) {
    let mut m = [[T::ZERO; N]; 4];
    for (mi, (ai, bi)) in m.iter_mut().zip(a.iter().zip(b)) {
        for j in 0..N {
            mi[j] = ai[0] * p[0][j]
                + ai[1] * p[1][j]
                + ai[2] * p[2][j]
                + ai[3] * p[3][j]
                + bi[0] * p[4][j]
                + bi[1] * p[5][j]
                + bi[2] * p[6][j];
        }
    }
    // Columns of [A B] as rows: at[k][j] = A[j][k], bt[k][j] = B[j][k].
    let mut at = [[T::ZERO; 4]; 4];
    let mut bt = [[T::ZERO; 4]; 3];
    for j in 0..4 {
        for k in 0..4 {
            at[k][j] = a[j][k];
        }
        for k in 0..3 {
            bt[k][j] = b[j][k];
        }
    }
    for (i, mi) in m.iter().enumerate() {
        let mut row = [T::ZERO; 4];
        for j in 0..4 {
            row[j] = mi[0] * at[0][j]
                + mi[1] * at[1][j]
                + mi[2] * at[2][j]
                + mi[3] * at[3][j]
                + mi[4] * bt[0][j]
                + mi[5] * bt[1][j]
                + mi[6] * bt[2][j];
        }
        for j in i..4 {
            p[i][j] = row[j];
            p[j][i] = row[j];
        }
        for j in 4..N {
            p[i][j] = mi[j];
            p[j][i] = mi[j];
        }
    }
    for (i, row) in p.iter_mut().enumerate() {
        row[i] += if i < 4 { qq } else { qb };
    }
}

/// One scalar measurement `y = h·x + v`, `h` nonzero only in the quaternion block (`h4`),
/// `var(v) = r`: updates `p` in Joseph form and returns the gain `k` (7), or `None` (and leaves
/// `p` alone) when the innovation variance `s = h·P·hᵀ + r` is not finite and positive.
///
/// Joseph form `P⁺ = (I − k h) P (I − k h)ᵀ + r k kᵀ`, expanded for a rank-one `k h` into
/// `P⁺ = P − (k uᵀ + u kᵀ) + s·k kᵀ` with `u = P hᵀ`. The expansion is exact for any gain, so it
/// keeps the Joseph form's property that a rounding error in `k` changes `P⁺` only to second
/// order; it costs O(n²) instead of two matrix products. Each entry is computed as
/// `(P_ij − (k_i u_j + u_i k_j)) + s·(k_i k_j)`, whose rounding is the same for `ij` and `ji`, so
/// the full square stays exactly symmetric.
#[inline(always)]
pub fn scalar_update<T: Real>(p: &mut Cov<T>, h4: [T; 4], r: T) -> Option<[T; N]> {
    // u = P hᵀ = Σ_k h_k·(row k of P), P symmetric.
    let mut u = [T::ZERO; N];
    for j in 0..N {
        u[j] = h4[0] * p[0][j] + h4[1] * p[1][j] + h4[2] * p[2][j] + h4[3] * p[3][j];
    }
    let s = h4[0] * u[0] + h4[1] * u[1] + h4[2] * u[2] + h4[3] * u[3] + r;
    if !(s.is_finite() && s > T::ZERO) {
        return None;
    }
    let k = crate::quat::scale(u, T::ONE / s);
    for (i, row) in p.iter_mut().enumerate() {
        let (ki, ui) = (k[i], u[i]);
        for j in 0..N {
            row[j] = (row[j] - (ki * u[j] + ui * k[j])) + s * (ki * k[j]);
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
// The reference computations index matrices the way the formulas write them.
#[allow(clippy::needless_range_loop)]
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
                l[i][j] = if i == j {
                    0.5 + i as f64 * 0.1
                } else {
                    0.05 * (i + 2 * j) as f64 - 0.2
                };
            }
        }
        matmul(&l, &transpose(&l))
    }

    fn assert_close(x: &Cov<f64>, y: &Cov<f64>) {
        for i in 0..N {
            for j in 0..N {
                assert!(
                    (x[i][j] - y[i][j]).abs() < 1e-13,
                    "[{i}][{j}] {} {}",
                    x[i][j],
                    y[i][j]
                );
                assert_eq!(x[i][j], x[j][i]);
            }
        }
    }

    #[test]
    fn predict_is_phi_p_phi_transpose_plus_q() {
        let a = [
            [1.0, -0.1, 0.2, 0.05],
            [0.1, 1.0, -0.3, 0.2],
            [-0.2, 0.3, 1.0, 0.1],
            [0.0, -0.2, -0.1, 1.0],
        ];
        let b = [
            [0.01, -0.02, 0.03],
            [0.04, 0.0, -0.01],
            [-0.02, 0.03, 0.01],
            [0.0, 0.05, -0.04],
        ];
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
