//! The EKF's straightforward implementation, kept as the oracle of the optimized one
//! (`tests/ekf_reference.rs`) and as the "before" of the benchmark.
//!
//! The same filter as `margemu_filters::Ekf` (eq. 26, see `docs/filters.md`) written the plain
//! way: the whole 7×7 covariance, prediction as `[A B]·P` then `·[A B]ᵀ`, and a Joseph-form
//! scalar update of every entry for each of the six measurement rows. Only public items of the
//! crate are used; the start (`Initial`) and the input checks are copied from its `init` module.

#![allow(dead_code)]

use margemu_filters::init::triad;
use margemu_filters::quat::{axpy, cross, identity, integrate, normalize, scale, Quat, Vec3};
use margemu_filters::{AttitudeFilter, Diagnostics, EkfConfig, Imu, Initial, Real};

/// State dimension: quaternion (4) and gyroscope bias (3).
pub const N: usize = 7;

/// A symmetric 7×7 matrix, stored whole.
pub type Cov<T> = [[T; N]; N];

/// `Φ·P·Φᵀ + Q` for `Φ = [[A, B], [0, I]]` and `Q = diag(qq·I₄, qb·I₃)`.
#[inline(always)]
fn predict<T: Real>(p: &mut Cov<T>, a: &[[T; 4]; 4], b: &[[T; 3]; 4], qq: T, qb: T) {
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

/// Joseph-form scalar update `P⁺ = P − (k uᵀ + u kᵀ) + s·k kᵀ`, `u = P hᵀ`, `k = u / s`.
#[inline(always)]
fn scalar_update<T: Real>(p: &mut Cov<T>, h4: [T; 4], r: T) -> Option<[T; N]> {
    let mut u = [T::ZERO; N];
    for j in 0..N {
        u[j] = h4[0] * p[0][j] + h4[1] * p[1][j] + h4[2] * p[2][j] + h4[3] * p[3][j];
    }
    let s = h4[0] * u[0] + h4[1] * u[1] + h4[2] * u[2] + h4[3] * u[3] + r;
    if !(s.is_finite() && s > T::ZERO) {
        return None;
    }
    let k = scale(u, T::ONE / s);
    for (i, row) in p.iter_mut().enumerate() {
        let (ki, ui) = (k[i], u[i]);
        for j in 0..N {
            row[j] = (row[j] - (ki * u[j] + ui * k[j])) + s * (ki * k[j]);
        }
    }
    Some(k)
}

#[inline(always)]
fn is_sane<T: Real>(p: &Cov<T>) -> bool {
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

#[inline(always)]
fn observe<T: Real>(q: Quat<T>, r: Vec3<T>) -> (Vec3<T>, [[T; 4]; 3]) {
    let (w, v) = (q[0], [q[1], q[2], q[3]]);
    let p0 = v[0] * r[0] + v[1] * r[1] + v[2] * r[2];
    let vr = cross(v, r);
    let pv = axpy(scale(r, w), -T::ONE, vr);
    let predicted = axpy(axpy(scale(v, p0), w, pv), T::ONE, cross(pv, v));
    let rows = [
        [pv[0], p0, -pv[2], pv[1]],
        [pv[1], pv[2], p0, -pv[0]],
        [pv[2], -pv[1], pv[0], p0],
    ];
    (
        predicted,
        [
            scale(rows[0], T::TWO),
            scale(rows[1], T::TWO),
            scale(rows[2], T::TWO),
        ],
    )
}

#[inline(always)]
fn transition<T: Real>(q: Quat<T>, w: Vec3<T>, h: T) -> ([[T; 4]; 4], [[T; 3]; 4]) {
    let (hx, hy, hz) = (h * w[0], h * w[1], h * w[2]);
    let a = [
        [T::ONE, -hx, -hy, -hz],
        [hx, T::ONE, hz, -hy],
        [hy, -hz, T::ONE, hx],
        [hz, hy, -hx, T::ONE],
    ];
    let b = [
        [h * q[1], h * q[2], h * q[3]],
        [-h * q[0], h * q[3], -h * q[2]],
        [-h * q[3], -h * q[0], h * q[1]],
        [h * q[2], -h * q[1], -h * q[0]],
    ];
    (a, b)
}

fn diagonal<T: Real>(a: T, b: T) -> Cov<T> {
    let mut p = [[T::ZERO; N]; N];
    for (i, row) in p.iter_mut().enumerate() {
        row[i] = if i < 4 { a } else { b };
    }
    p
}

/// One step's checked inputs.
struct Step<T> {
    dt: T,
    gyro: Vec3<T>,
    acc: Option<Vec3<T>>,
    mag: Option<Vec3<T>>,
}

/// The reference EKF (valid configurations only: the oracle does not check them).
#[derive(Clone, Debug)]
pub struct ReferenceEkf<T> {
    q: Quat<T>,
    mag_ref: Vec3<T>,
    pending: bool,
    diag: Diagnostics,
    bias: Vec3<T>,
    p: Cov<T>,
    p0: Cov<T>,
    q_att: T,
    q_bias: T,
    r_acc: T,
    r_mag: T,
}

impl<T: Real> ReferenceEkf<T> {
    /// The filter of `cfg` (assumed valid).
    pub fn new(cfg: &EkfConfig) -> Self {
        let square = |v: f64| T::from_f64(v * v);
        let p0 = diagonal(
            square(cfg.initial_attitude_std),
            square(cfg.initial_bias_std),
        );
        let (q, pending) = match cfg.initial {
            Initial::FirstSample => (identity(), true),
            Initial::Attitude(q) => (normalize(q).unwrap().map(T::from_f64), false),
        };
        Self {
            q,
            mag_ref: normalize(cfg.mag_reference).unwrap().map(T::from_f64),
            pending,
            diag: Diagnostics::default(),
            bias: [T::ZERO; 3],
            p: p0,
            p0,
            q_att: square(cfg.gyro_noise) * T::HALF * T::HALF,
            q_bias: square(cfg.gyro_bias_walk),
            r_acc: square(cfg.accel_noise),
            r_mag: square(cfg.mag_noise),
        }
    }

    /// The gyroscope bias estimate.
    pub fn bias(&self) -> Vec3<T> {
        self.bias
    }

    /// The state covariance.
    pub fn covariance(&self) -> Cov<T> {
        self.p
    }

    fn begin(&mut self, imu: &Imu<T>, dt: T) -> Option<Step<T>> {
        let acc = normalize(imu.acc);
        let mag = normalize(imu.mag);
        if self.pending {
            if let Some(q) = acc.and_then(|a| triad(a, mag.unwrap_or([T::ZERO; 3]), self.mag_ref)) {
                self.q = q;
                self.pending = false;
                self.diag.updates += 1;
                self.diag.skipped_mag += u64::from(mag.is_none());
                return None;
            }
        }
        let gyro_ok = imu.gyro.iter().all(|c| c.is_finite());
        if !(dt.is_finite() && dt > T::ZERO && gyro_ok) {
            self.diag.skipped_updates += 1;
            return None;
        }
        self.diag.updates += 1;
        self.diag.skipped_accel += u64::from(acc.is_none());
        self.diag.skipped_mag += u64::from(mag.is_none());
        Some(Step {
            dt,
            gyro: imu.gyro,
            acc,
            mag,
        })
    }

    #[inline(always)]
    fn correct(&mut self, q: Quat<T>, r: Vec3<T>, z: Vec3<T>, var: T, dx: &mut [T; N]) {
        let (predicted, rows) = observe(q, r);
        for (i, h) in rows.into_iter().enumerate() {
            let y =
                z[i] - predicted[i] - (h[0] * dx[0] + h[1] * dx[1] + h[2] * dx[2] + h[3] * dx[3]);
            match scalar_update(&mut self.p, h, var) {
                Some(k) => {
                    for j in 0..N {
                        dx[j] += k[j] * y;
                    }
                }
                None => self.diag.rejected += 1,
            }
        }
    }
}

impl<T: Real> AttitudeFilter<T> for ReferenceEkf<T> {
    fn update(&mut self, imu: &Imu<T>, dt: T) {
        let Some(step) = self.begin(imu, dt) else {
            return;
        };
        let (q, p_old) = (self.q, self.p);
        let w = axpy(step.gyro, -T::ONE, self.bias);
        let h = T::HALF * step.dt;
        let (a, b) = transition(q, w, h);
        predict(
            &mut self.p,
            &a,
            &b,
            self.q_att * step.dt,
            self.q_bias * step.dt,
        );
        let Some(q_pred) = normalize(integrate(q, w, step.dt)) else {
            self.p = p_old;
            self.diag.rejected += 1;
            return;
        };
        let mut dx = [T::ZERO; N];
        if let Some(acc) = step.acc {
            let up = [T::ZERO, T::ZERO, T::ONE];
            self.correct(q_pred, up, acc, self.r_acc, &mut dx);
        }
        if let Some(mag) = step.mag {
            self.correct(q_pred, self.mag_ref, mag, self.r_mag, &mut dx);
        }
        let bias = axpy(self.bias, T::ONE, [dx[4], dx[5], dx[6]]);
        let q_new = normalize(axpy(q_pred, T::ONE, [dx[0], dx[1], dx[2], dx[3]]));
        match q_new {
            Some(q_new) if is_sane(&self.p) && bias.iter().all(|c| c.is_finite()) => {
                self.q = q_new;
                self.bias = bias;
            }
            _ => {
                self.p = p_old;
                self.diag.rejected += 1;
            }
        }
    }

    fn quaternion(&self) -> Quat<T> {
        self.q
    }

    fn reset(&mut self, q: Quat<T>) {
        self.q = normalize(q).unwrap_or_else(identity);
        self.pending = false;
        self.bias = [T::ZERO; 3];
        self.p = self.p0;
    }

    fn diagnostics(&self) -> Diagnostics {
        self.diag
    }
}
