//! The 7×7 covariance of the EKF and the two operations on it: prediction and one scalar
//! measurement update.
//!
//! The matrix is symmetric, so only its upper triangle is stored: 28 entries, packed row by row
//! ([`Packed`], indexed through [`at`]). Each operation computes each of those entries once, so
//! the matrix is exactly symmetric by construction, and none forms a 7×7 product:
//!
//! * the prediction works on the blocks `P = [[X, Y], [Yᵀ, Z]]` (`X` 4×4 attitude, `Y` 4×3
//!   attitude–bias, `Z` 3×3 bias) of `Φ = [[A, B], [0, I]]`, whose lower rows are the identity;
//! * a measurement row is zero in the bias states, so `u = P hᵀ` reads only the first four rows,
//!   and the update is a rank-one correction of the 28 entries.

use crate::Real;

/// State dimension: quaternion (4) and gyroscope bias (3).
pub const N: usize = 7;

/// Entries of the packed upper triangle: `N·(N+1)/2`.
pub const PACKED: usize = N * (N + 1) / 2;

/// A symmetric 7×7 matrix, stored whole (what [`crate::Ekf::covariance`] returns).
pub type Cov<T> = [[T; N]; N];

/// The upper triangle of a symmetric 7×7 matrix, row by row: `(0,0), (0,1), …, (0,6), (1,1), …`.
pub type Packed<T> = [T; PACKED];

/// Packed position of entry `(i, j)` (either order), for `i, j < N`.
const INDEX: [[usize; N]; N] = {
    let mut t = [[0; N]; N];
    let mut i = 0;
    let mut k = 0;
    while i < N {
        let mut j = i;
        while j < N {
            t[i][j] = k;
            t[j][i] = k;
            k += 1;
            j += 1;
        }
        i += 1;
    }
    t
};

/// Packed position of entry `(i, j)` (either order). `i, j < N`; the callers' loops have
/// constant bounds, so the table lookup folds away.
#[inline(always)]
pub const fn at(i: usize, j: usize) -> usize {
    INDEX[i][j]
}

/// The packed upper triangle of `p` (assumed symmetric).
pub fn pack<T: Real>(p: &Cov<T>) -> Packed<T> {
    let mut out = [T::ZERO; PACKED];
    for i in 0..N {
        for j in i..N {
            out[at(i, j)] = p[i][j];
        }
    }
    out
}

/// The whole symmetric matrix of a packed triangle.
pub fn unpack<T: Real>(p: &Packed<T>) -> Cov<T> {
    let mut out = [[T::ZERO; N]; N];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = p[at(i, j)];
        }
    }
    out
}

/// `S·v` for the skew-symmetric `S = Ω(hw)`, `(hw)` = `s`: the part of `A·v = v + S·v`
/// beyond the identity (`q ⊗ (0, s) = Ω(s)·q`).
#[inline(always)]
fn omega<T: Real>(s: [T; 3], v: [T; 4]) -> [T; 4] {
    [
        -s[0] * v[1] - s[1] * v[2] - s[2] * v[3],
        s[0] * v[0] + s[2] * v[2] - s[1] * v[3],
        s[1] * v[0] - s[2] * v[1] + s[0] * v[3],
        s[2] * v[0] + s[1] * v[1] - s[0] * v[2],
    ]
}

/// `A·v = v + Ω(s)·v`.
#[inline(always)]
pub(crate) fn apply_a<T: Real>(s: [T; 3], v: [T; 4]) -> [T; 4] {
    let o = omega(s, v);
    [v[0] + o[0], v[1] + o[1], v[2] + o[2], v[3] + o[3]]
}

/// `B·v = −h·Ξ(q)·v = Ξ(c)·v` with `c = −h·q`: `vec`-free form of `c ⊗ (0, v)`.
#[inline(always)]
pub(crate) fn apply_b<T: Real>(c: [T; 4], v: [T; 3]) -> [T; 4] {
    [
        -c[1] * v[0] - c[2] * v[1] - c[3] * v[2],
        c[0] * v[0] - c[3] * v[1] + c[2] * v[2],
        c[3] * v[0] + c[0] * v[1] - c[1] * v[2],
        -c[2] * v[0] + c[1] * v[1] + c[0] * v[2],
    ]
}

/// `Φ·P·Φᵀ + Q` for `Φ = [[A, B], [0, I]]` with `A = I + Ω(s)` (`s = Tₛ/2·w`, `w` the
/// bias-corrected rate), `B = Ξ(c)` (`c = −Tₛ/2·q`) and `Q = diag(qq·I₄, qb·I₃)`.
///
/// On the blocks of `P`: `Y⁻ = A·Y + B·Z`, `X⁻ = G·Aᵀ + Y⁻·Bᵀ + qq·I` with `G = A·X + B·Yᵀ`,
/// `Z⁻ = Z + qb·I`. `A` and `B` are applied as the quaternion products they are (12
/// multiplications per vector), and of `X⁻` only the upper triangle is kept.
#[inline(always)]
pub fn predict<T: Real>(p: &mut Packed<T>, s: [T; 3], c: [T; 4], qq: T, qb: T) {
    let x = |i: usize, j: usize| p[at(i, j)];
    // Columns of Y (4-vectors) and of Z (3-vectors).
    let ycol: [[T; 4]; 3] = core::array::from_fn(|j| core::array::from_fn(|i| x(i, 4 + j)));
    let zcol: [[T; 3]; 3] = core::array::from_fn(|j| core::array::from_fn(|i| x(4 + i, 4 + j)));
    // Y⁻ column j = A·y_j + B·z_j.
    let ynew: [[T; 4]; 3] = core::array::from_fn(|j| {
        let (a, b) = (apply_a(s, ycol[j]), apply_b(c, zcol[j]));
        [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
    });
    // G column j = A·x_j + B·(row j of Y); X symmetric, so x_j is also row j.
    let g: [[T; 4]; 4] = core::array::from_fn(|j| {
        let xj = [x(0, j), x(1, j), x(2, j), x(3, j)];
        let yj = [x(j, 4), x(j, 5), x(j, 6)];
        let (a, b) = (apply_a(s, xj), apply_b(c, yj));
        [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
    });
    // Row i of X⁻ = A·(row i of G) + B·(row i of Y⁻).
    for i in 0..4 {
        let gi = [g[0][i], g[1][i], g[2][i], g[3][i]];
        let yi = [ynew[0][i], ynew[1][i], ynew[2][i]];
        let (a, b) = (apply_a(s, gi), apply_b(c, yi));
        for j in i..4 {
            p[at(i, j)] = a[j] + b[j];
        }
        p[at(i, i)] += qq;
        for (j, col) in ynew.iter().enumerate() {
            p[at(i, 4 + j)] = col[i];
        }
    }
    for i in 4..N {
        p[at(i, i)] += qb;
    }
}

/// One scalar measurement `y = h·x + v`, `h` nonzero only in the quaternion block (`h4`),
/// `var(v) = r`: updates `p` and returns the gain `k` (7), or `None` (and leaves `p` alone) when
/// the innovation variance `s = h·P·hᵀ + r` is not finite and positive.
///
/// With `u = P hᵀ` (the first four rows of `P` only) and `k = u / s`, the Joseph form
/// `P⁺ = (I − k h) P (I − k h)ᵀ + r k kᵀ` expands for any gain into
/// `P⁺ = P − (k uᵀ + u kᵀ) + s·k kᵀ = P − u kᵀ + k eᵀ`, `e = s·k − u`.
/// `e` is what the rounding of `k` leaves of `s·k − u` (zero in exact arithmetic), so the update
/// costs two multiply–adds per stored entry and still keeps the Joseph form's property that a
/// rounding error in `k` changes `P⁺` only to second order.
#[inline(always)]
pub fn scalar_update<T: Real>(p: &mut Packed<T>, h4: [T; 4], r: T) -> Option<[T; N]> {
    let u: [T; N] = core::array::from_fn(|j| {
        h4[0] * p[at(0, j)] + h4[1] * p[at(1, j)] + h4[2] * p[at(2, j)] + h4[3] * p[at(3, j)]
    });
    let s = h4[0] * u[0] + h4[1] * u[1] + h4[2] * u[2] + h4[3] * u[3] + r;
    if !(s.is_finite() && s > T::ZERO) {
        return None;
    }
    let inv = T::ONE / s;
    let k: [T; N] = core::array::from_fn(|j| u[j] * inv);
    let e: [T; N] = core::array::from_fn(|j| s * k[j] - u[j]);
    for i in 0..N {
        for j in i..N {
            let v = &mut p[at(i, j)];
            *v = (*v - u[i] * k[j]) + k[i] * e[j];
        }
    }
    Some(k)
}

/// Whether every entry is finite and every diagonal entry positive (a cheap guard; the tests
/// check positive definiteness itself).
#[inline(always)]
pub fn is_sane<T: Real>(p: &Packed<T>) -> bool {
    let mut sum = T::ZERO;
    for &v in p {
        sum += v;
    }
    let mut ok = true;
    for i in 0..N {
        ok &= p[at(i, i)] > T::ZERO;
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
    fn packing_round_trips() {
        let p = spd();
        assert_eq!(unpack(&pack(&p)), p);
        let mut seen = [false; PACKED];
        for i in 0..N {
            for j in i..N {
                assert!(!seen[at(i, j)]);
                seen[at(i, j)] = true;
                assert_eq!(at(i, j), at(j, i));
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn predict_is_phi_p_phi_transpose_plus_q() {
        let (s, c) = ([0.1, -0.3, 0.05], [0.02, -0.01, 0.03, 0.015]);
        // Φ from the products themselves: column k is Φ·e_k.
        let mut phi = [[0.0; N]; N];
        for k in 0..4 {
            let e: [f64; 4] = core::array::from_fn(|i| f64::from(u8::from(i == k)));
            let col = apply_a(s, e);
            for i in 0..4 {
                phi[i][k] = col[i];
            }
        }
        for k in 0..3 {
            let e: [f64; 3] = core::array::from_fn(|i| f64::from(u8::from(i == k)));
            let col = apply_b(c, e);
            for i in 0..4 {
                phi[i][4 + k] = col[i];
            }
        }
        for i in 4..N {
            phi[i][i] = 1.0;
        }
        // A = I + Ω(s) is skew-symmetric apart from the identity.
        for i in 0..4 {
            for j in 0..4 {
                let d = f64::from(u8::from(i == j));
                assert_eq!(phi[i][j] - d, -(phi[j][i] - d));
            }
        }
        let p = spd();
        let mut expect = matmul(&matmul(&phi, &p), &transpose(&phi));
        for (i, row) in expect.iter_mut().enumerate() {
            row[i] += if i < 4 { 1e-3 } else { 2e-4 };
        }
        let mut got = pack(&p);
        predict(&mut got, s, c, 1e-3, 2e-4);
        assert_close(&unpack(&got), &expect);
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
        let mut got = pack(&p);
        let k = scalar_update(&mut got, h4, r).unwrap();
        assert_close(&unpack(&got), &expect);
        for j in 0..N {
            assert!((k[j] - u[j] / s).abs() < 1e-15);
        }
        assert!(is_sane(&got));
        let before = got;
        assert_eq!(scalar_update(&mut got, [f64::NAN; 4], r), None);
        assert_eq!(got, before);
        let mut bad = got;
        bad[at(3, 3)] = -1.0;
        assert!(!is_sane(&bad));
        let mut bad = got;
        bad[at(2, 5)] = f64::INFINITY;
        assert!(!is_sane(&bad));
    }

    /// The rank-one form `P − u kᵀ + k eᵀ` is the Joseph expansion `P − (k uᵀ + u kᵀ) + s k kᵀ`
    /// for any gain, not only the optimal one.
    #[test]
    fn rank_one_form_is_the_joseph_expansion_for_any_gain() {
        let p = spd();
        let u = [0.3, -0.2, 0.7, 0.1, -0.4, 0.25, 0.05];
        let k = [0.11, 0.02, -0.3, 0.4, 0.07, -0.15, 0.2];
        let s = 1.7;
        let e: [f64; N] = core::array::from_fn(|j| s * k[j] - u[j]);
        for i in 0..N {
            for j in 0..N {
                let joseph = p[i][j] - (k[i] * u[j] + u[i] * k[j]) + s * k[i] * k[j];
                let ours = p[i][j] - u[i] * k[j] + k[i] * e[j];
                assert!((joseph - ours).abs() < 1e-15, "[{i}][{j}]");
            }
        }
    }
}
