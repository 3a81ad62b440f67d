//! The 7×7 covariance of the EKF and the two operations on it: prediction, and the update by
//! the three measurement rows of one reference vector.
//!
//! The matrix is symmetric, so only its upper triangle is stored: 28 entries, packed row by row
//! ([`Packed`], indexed through [`at`]). Each operation computes each of those entries once, so
//! the matrix is exactly symmetric by construction, and none forms a 7×7 product:
//!
//! * the prediction works on the blocks `P = [[X, Y], [Yᵀ, Z]]` (`X` 4×4 attitude, `Y` 4×3
//!   attitude–bias, `Z` 3×3 bias) of `Φ = [[A, B], [0, I]]`, whose lower rows are the identity;
//! * a measurement row is zero in the bias states, so `u = P hᵀ` reads only the first four rows,
//!   and the three rows of one vector write `P` once, as a rank-three correction of the 28
//!   entries.

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

/// `Ω(s)·v = v ⊗ (0, s)` (`Ω` as in the module docs of the EKF), skew-symmetric in its 4×4
/// form: the part of `A·v = v + Ω(s)·v` beyond the identity, with `s = Tₛ/2·w`.
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

/// `B·v = −h·Ξ(q)·v = Ξ(c)·v = c ⊗ (0, v)` with `c = −h·q`.
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
    // Y⁻ column j = A·y_j + B·z_j (y_j, z_j the columns of Y and Z).
    let mut ynew = [[T::ZERO; 4]; 3];
    for (j, col) in ynew.iter_mut().enumerate() {
        let yj = [x(0, 4 + j), x(1, 4 + j), x(2, 4 + j), x(3, 4 + j)];
        let zj = [x(4, 4 + j), x(5, 4 + j), x(6, 4 + j)];
        let (a, b) = (apply_a(s, yj), apply_b(c, zj));
        *col = [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]];
    }
    // G column j = A·x_j + B·(row j of Y); X symmetric, so x_j is also row j.
    let mut g = [[T::ZERO; 4]; 4];
    for (j, col) in g.iter_mut().enumerate() {
        let xj = [x(0, j), x(1, j), x(2, j), x(3, j)];
        let yj = [x(j, 4), x(j, 5), x(j, 6)];
        let (a, b) = (apply_a(s, xj), apply_b(c, yj));
        *col = [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]];
    }
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

/// The three scalar measurements `yᵢ = hᵢ·x + vᵢ` of one reference vector, processed one after
/// the other, `hᵢ` nonzero only in the quaternion block (`h[i]`), `var(vᵢ) = r`: updates `p`
/// and returns the gain `kᵢ` of each row (7), or `None` for a row whose innovation variance
/// `sᵢ = hᵢ·P·hᵢᵀ + r` (with `P` as the earlier rows left it) is not finite and positive; such
/// a row leaves `P` alone.
///
/// One scalar update is `P⁺ = P − u kᵀ` with `u = P hᵀ`, `s = h·u + r`, `k = u / s` (the
/// Joseph form `(I − k h) P (I − k h)ᵀ + r k kᵀ` at this gain). Processing the rows in turn
/// needs each row's `uᵢ` from the `P` the earlier rows left, and that is
/// `uᵢ = P hᵢᵀ − Σⱼ₍<ᵢ₎ kⱼ·(hᵢ·uⱼ)` with the `P` before the vector, since
/// `(P − uⱼ kⱼᵀ)·hᵢᵀ = P hᵢᵀ − uⱼ (kⱼ·hᵢ) = P hᵢᵀ − kⱼ (hᵢ·uⱼ)` (`kⱼ` is a multiple of `uⱼ`).
/// So the rows cost three products `P hᵢᵀ` (four rows of `P` each: `h` is zero in the bias
/// states) and a few 7-vector corrections, and `P` is written once, as the rank-three update
/// `P − Σᵢ uᵢ kᵢᵀ` of its 28 stored entries. The result equals the three scalar updates in
/// exact arithmetic.
#[inline(always)]
pub fn vector_update<T: Real>(p: &mut Packed<T>, h: &[[T; 4]; 3], r: T) -> [Option<[T; N]>; 3] {
    let mut u = [[T::ZERO; N]; 3];
    let mut k = [[T::ZERO; N]; 3];
    let mut ok = [false; 3];
    for i in 0..3 {
        let hi = h[i];
        let mut ui = [T::ZERO; N];
        for (j, v) in ui.iter_mut().enumerate() {
            *v = hi[0] * p[at(0, j)]
                + hi[1] * p[at(1, j)]
                + hi[2] * p[at(2, j)]
                + hi[3] * p[at(3, j)];
        }
        for j in 0..i {
            if ok[j] {
                let uj = u[j];
                let c = hi[0] * uj[0] + hi[1] * uj[1] + hi[2] * uj[2] + hi[3] * uj[3];
                for (v, kj) in ui.iter_mut().zip(k[j]) {
                    *v -= kj * c;
                }
            }
        }
        let s = hi[0] * ui[0] + hi[1] * ui[1] + hi[2] * ui[2] + hi[3] * ui[3] + r;
        if s.is_finite() && s > T::ZERO {
            let inv = T::ONE / s;
            for (kv, &uv) in k[i].iter_mut().zip(&ui) {
                *kv = uv * inv;
            }
            u[i] = ui;
            ok[i] = true;
        }
    }
    // Rows refused have u = k = 0 and drop out.
    for a in 0..N {
        for b in a..N {
            p[at(a, b)] -= (u[0][a] * k[0][b] + u[1][a] * k[1][b]) + u[2][a] * k[2][b];
        }
    }
    [0, 1, 2].map(|i| if ok[i] { Some(k[i]) } else { None })
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

    /// Three textbook scalar Kalman updates `P − u uᵀ / s`, one after the other; `None` for a
    /// row refused.
    fn sequential(p: &Cov<f64>, h: &[[f64; 4]; 3], r: f64) -> (Cov<f64>, [Option<[f64; N]>; 3]) {
        let mut p = *p;
        let mut gains = [None; 3];
        for (i, h4) in h.iter().enumerate() {
            let hh = [h4[0], h4[1], h4[2], h4[3], 0.0, 0.0, 0.0];
            let u: [f64; N] = core::array::from_fn(|j| (0..N).map(|k| p[j][k] * hh[k]).sum());
            let s: f64 = (0..N).map(|k| hh[k] * u[k]).sum::<f64>() + r;
            if !(s.is_finite() && s > 0.0) {
                continue;
            }
            for a in 0..N {
                for b in 0..N {
                    p[a][b] -= u[a] * u[b] / s;
                }
            }
            gains[i] = Some(u.map(|v| v / s));
        }
        (p, gains)
    }

    #[test]
    fn vector_update_is_three_kalman_updates() {
        let p = spd();
        let rows = [
            [0.3, -1.2, 0.5, 2.0],
            [1.1, 0.4, -0.7, 0.2],
            [-0.5, 0.9, 1.3, -0.6],
        ];
        let mut nan_row = rows;
        nan_row[1] = [f64::NAN; 4];
        for h in [rows, nan_row] {
            let (expect, gains) = sequential(&p, &h, 0.01);
            let mut got = pack(&p);
            let k = vector_update(&mut got, &h, 0.01);
            assert_close(&unpack(&got), &expect);
            for i in 0..3 {
                assert_eq!(k[i].is_some(), gains[i].is_some(), "row {i}");
                if let (Some(k), Some(g)) = (k[i], gains[i]) {
                    assert!((0..N).all(|j| (k[j] - g[j]).abs() < 1e-14), "row {i}");
                }
            }
            assert!(is_sane(&got));
        }
        let mut got = pack(&p);
        assert_eq!(
            vector_update(&mut got, &[[f64::NAN; 4]; 3], 0.01),
            [None; 3]
        );
        assert_eq!(got, pack(&p));
        let mut bad = got;
        bad[at(3, 3)] = -1.0;
        assert!(!is_sane(&bad));
        let mut bad = got;
        bad[at(2, 5)] = f64::INFINITY;
        assert!(!is_sane(&bad));
    }
}
