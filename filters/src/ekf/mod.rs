//! Quaternion extended Kalman filter with gyroscope-bias states, the paper's eq. 26.
//!
//! State `x = (q, b)`: the attitude quaternion (4, additive, as eq. 26 writes it) and the
//! gyroscope bias `b` (3, rad/s), with a 7×7 covariance `P`.
//!
//! **Predict.** `q⁻ = normalize(q + Tₛ/2 · q ⊗ (0, Ω − b))`, `b⁻ = b`,
//! `P⁻ = Φ P Φᵀ + Q` with `Φ = [[A, B], [0, I]]`, `A = I + Tₛ/2·Ω(Ω − b)`, `B = −Tₛ/2·Ξ(q)`
//! (`q ⊗ (0, ω) = Ω(ω)·q = Ξ(q)·ω`) and
//! `Q = diag(Tₛ·σ_g²/4 · I₄, Tₛ·σ_b² · I₃)`: `σ_g` is the gyroscope noise density and `σ_b` the
//! bias random walk, so `Q` follows `Tₛ` and the tuning does not depend on the rate. White gyro
//! noise moves `q` by `Tₛ/2·Ξ(q)·δω`, whose covariance is `Tₛσ_g²/4 · (I − q qᵀ)`; the filter
//! adds the same variance along `q` too, so `P` stays positive definite in the one direction that
//! no process noise would reach (renormalization removes whatever the state gains there).
//!
//! **Update.** The measurements are the unit accelerometer and magnetometer directions,
//! `h(q) = q* ⊗ r ⊗ q` for the world up axis and the unit magnetic reference `r`. Its Jacobian
//! is `H = 2·vec-rows of L(q* ⊗ r)` (left multiplication), zero for the bias. `R` is diagonal
//! (`σ_a²`, `σ_m²` per axis, dimensionless: per-sample standard deviations of the unit vectors),
//! so the six rows are processed one at a time: scalar innovation variance, no matrix inverse.
//! All six are linearized at `x⁻`, and each innovation subtracts what the earlier rows already
//! corrected (`y_i = z_i − h_i(x⁻) − H_i·δx`), so the result equals the batch update of eq. 26.
//! Each row's covariance update is `P − u kᵀ` (`u = P hᵀ`, `k = u / s`), the Joseph form at
//! this gain; then `q = normalize(q⁻ + δq)`, `b = b⁻ + δb`.
//!
//! **Cost.** The structure does the work ([`covariance`]): `P` is kept as its packed upper
//! triangle (28 entries); the prediction works on the blocks of `P` and applies `A` and `B` as
//! the quaternion products they are (`A·v = v + Ω(Tₛ/2·w)·v`, `B·v = Ξ(−Tₛ/2·q)·v`, twelve
//! multiplications per vector), since the lower rows of `Φ` are the identity; each measurement
//! row is zero in the bias states, so `P hᵀ` reads four rows; and the three rows of one vector
//! write `P` once, as a rank-three update of the 28 entries, each row's `u` being corrected for
//! the earlier rows instead of read from an updated `P` ([`covariance::vector_update`], equal in
//! exact arithmetic to three scalar updates). The same filter written the plain way (whole
//! matrix, `[A B]·P·[A B]ᵀ`, full Joseph expansion per row) is kept in
//! `tests/common/ekf_reference.rs`; `tests/ekf_reference.rs` checks that both give the same
//! estimates and covariance, and `docs/filters.md` (*Cost*) has the timings.
//!
//! **Guards.** A missing vector skips its three rows. A row whose innovation variance is not
//! positive and finite is skipped; a step that would leave a non-finite state or a covariance
//! with a non-positive or non-finite diagonal is undone whole. Each counts as `rejected`.
//!
//! **Defaults** (ours; the paper's "initial" column came from heuristics): `σ_g = 0.0224`
//! (rad/s)/√Hz (the case study's gyroscope), `σ_b = 1e-4` (rad/s)/√s, `σ_a = σ_m = 0.5`, initial
//! standard deviations 0.1 per quaternion component and 0.05 rad/s for the bias. The sensor noise
//! of the unit vectors is only 0.03 per sample in the case study (200 Hz), but there external
//! accelerations of several g and magnetic bursts of several field magnitudes dominate the
//! residuals: with `σ_a = σ_m = 0.05` the bias states absorb them and run off to 2 rad/s in
//! `tests/long_run.rs`'s scene (attitude error 1.2 rad rms), with 0.5 they stay below 0.11 rad/s
//! (0.28 rad rms).
//!
//! ```
//! use margemu_filters::{AttitudeFilter, Ekf, EkfConfig, Imu};
//! use margemu_filters::quat::{from_euler_zyx, geodesic_angle, world_to_body};
//! let truth = from_euler_zyx([0.5f64, 0.2, -2.5]);
//! let bias = [0.02, -0.01, 0.03];
//! // Noise-free vectors: trust them, and let the bias move fast.
//! let cfg = EkfConfig { accel_noise: 0.05, mag_noise: 0.05, gyro_bias_walk: 1e-2, ..EkfConfig::default() };
//! let mut ekf = Ekf::new(&cfg)?;
//! let imu = Imu {
//!     gyro: bias,
//!     acc: world_to_body(truth, [0.0, 0.0, 9.80665]),
//!     mag: world_to_body(truth, [0.5, 0.0, -0.83]),
//! };
//! for _ in 0..12_000 {
//!     ekf.update(&imu, 0.005);
//! }
//! assert!(geodesic_angle(ekf.quaternion(), truth) < 1e-6);
//! assert!((0..3).all(|i| (ekf.bias()[i] - bias[i]).abs() < 1e-6));
//! # Ok::<(), margemu_filters::Error>(())
//! ```

pub mod covariance;

use crate::filter::{AttitudeFilter, Diagnostics, Imu};
use crate::init::{parameter, Initial, Shared, DEFAULT_MAG_REFERENCE};
use crate::quat::{axpy, cross, integrate, normalize, scale, Quat, Vec3};
use crate::{Error, Real};
use covariance::{is_sane, predict, unpack, vector_update, Cov, Packed, N, PACKED};

/// Parameters of the [`Ekf`]: the paper's four noise statistics, the initial uncertainty, the
/// reference field and the start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EkfConfig {
    /// Gyroscope white-noise density `σ_g`, (rad/s)/√Hz, `> 0`. Default 0.0224.
    pub gyro_noise: f64,
    /// Gyroscope bias random walk `σ_b`, (rad/s)/√s, `> 0`. Default 1e-4.
    pub gyro_bias_walk: f64,
    /// Per-axis standard deviation of the unit accelerometer direction per sample, `> 0`.
    /// Default 0.5.
    pub accel_noise: f64,
    /// Per-axis standard deviation of the unit magnetometer direction per sample, `> 0`.
    /// Default 0.5.
    pub mag_noise: f64,
    /// Initial standard deviation of each quaternion component, `> 0`. Default 0.1.
    pub initial_attitude_std: f64,
    /// Initial standard deviation of each bias component (rad/s), `> 0`. Default 0.05.
    pub initial_bias_std: f64,
    /// World-frame magnetic reference (any length, not vertical). Default `(0.5, 0, −0.83)`.
    pub mag_reference: [f64; 3],
    /// Where the filter starts. Default: from the first sample.
    pub initial: Initial,
}

impl Default for EkfConfig {
    fn default() -> Self {
        Self {
            gyro_noise: 0.0224,
            gyro_bias_walk: 1e-4,
            accel_noise: 0.5,
            mag_noise: 0.5,
            initial_attitude_std: 0.1,
            initial_bias_std: 0.05,
            mag_reference: DEFAULT_MAG_REFERENCE,
            initial: Initial::FirstSample,
        }
    }
}

/// The quaternion EKF of eq. 26.
#[derive(Clone, Debug)]
pub struct Ekf<T> {
    s: Shared<T>,
    bias: Vec3<T>,
    /// The covariance, packed upper triangle.
    p: Packed<T>,
    p0: Packed<T>,
    /// `σ_g²/4` and `σ_b²`: times `Tₛ`, the diagonal of `Q`.
    q_att: T,
    q_bias: T,
    r_acc: T,
    r_mag: T,
}

/// The measurement `h(q) = vec(q* ⊗ r ⊗ q)` of the world vector `r` and its Jacobian rows
/// `∂h/∂q = 2·vec-rows of L(q* ⊗ r)`.
#[inline(always)]
fn observe<T: Real>(q: Quat<T>, r: Vec3<T>) -> (Vec3<T>, [[T; 4]; 3]) {
    let (w, v) = (q[0], [q[1], q[2], q[3]]);
    // p = q* ⊗ (0, r) = (v·r, w·r − v × r); h = vec(p ⊗ q) = p₀·v + w·p_v + p_v × v.
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

/// The blocks of `Φ = [[A, B], [0, I]]` for `q⁻ = q + h·q ⊗ (0, g − b)` at the bias-corrected
/// rate `w = g − b` and `h = Tₛ/2`: `A = I + h·Ω(w)`, `B = −h·Ξ(q)`, as matrices (the filter
/// applies them as products; the tests check both).
#[cfg(test)]
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

/// `diag(a, a, a, a, b, b, b)`, packed.
fn diagonal<T: Real>(a: T, b: T) -> Packed<T> {
    let mut p = [T::ZERO; PACKED];
    for i in 0..N {
        p[covariance::at(i, i)] = if i < 4 { a } else { b };
    }
    p
}

impl<T: Real> Ekf<T> {
    /// A filter with the parameters of `cfg`, checked.
    pub fn new(cfg: &EkfConfig) -> Result<Self, Error> {
        // A standard deviation, checked, then its square, checked in T.
        let square = |v: f64, what| {
            let std = parameter::<f64>(v, what, true)?;
            parameter::<T>(std * std, what, true)
        };
        let p0 = diagonal(
            square(cfg.initial_attitude_std, "initial_attitude_std")?,
            square(cfg.initial_bias_std, "initial_bias_std")?,
        );
        Ok(Self {
            s: Shared::new(cfg.mag_reference, cfg.initial)?,
            bias: [T::ZERO; 3],
            p: p0,
            p0,
            q_att: square(cfg.gyro_noise, "gyro_noise")? * T::HALF * T::HALF,
            q_bias: square(cfg.gyro_bias_walk, "gyro_bias_walk")?,
            r_acc: square(cfg.accel_noise, "accel_noise")?,
            r_mag: square(cfg.mag_noise, "mag_noise")?,
        })
    }

    /// The gyroscope bias estimate (rad/s), subtracted from the gyroscope before propagation.
    pub fn bias(&self) -> Vec3<T> {
        self.bias
    }

    /// The state covariance, order `(qw, qx, qy, qz, bx, by, bz)`; exactly symmetric.
    pub fn covariance(&self) -> Cov<T> {
        unpack(&self.p)
    }

    /// Corrects `q` (unit) and `dx` with the three rows of one reference vector `r` (world,
    /// unit) measured as `z` (body, unit), each of variance `var`. Rows whose update is refused
    /// are counted.
    #[inline(always)]
    fn correct(&mut self, q: Quat<T>, r: Vec3<T>, z: Vec3<T>, var: T, dx: &mut [T; N]) {
        let (predicted, rows) = observe(q, r);
        // The gains do not depend on the innovations: all three first, then the state.
        let gains = vector_update(&mut self.p, &rows, var);
        for (i, (h, gain)) in rows.into_iter().zip(gains).enumerate() {
            let y =
                z[i] - predicted[i] - (h[0] * dx[0] + h[1] * dx[1] + h[2] * dx[2] + h[3] * dx[3]);
            match gain {
                Some(k) => {
                    for j in 0..N {
                        dx[j] += k[j] * y;
                    }
                }
                None => self.s.diag.rejected += 1,
            }
        }
    }
}

impl<T: Real> AttitudeFilter<T> for Ekf<T> {
    fn update(&mut self, imu: &Imu<T>, dt: T) {
        let Some(step) = self.s.begin(imu, dt) else {
            return;
        };
        let (q, p_old) = (self.s.q, self.p);
        let w = axpy(step.gyro, -T::ONE, self.bias);
        let h = T::HALF * step.dt;
        predict(
            &mut self.p,
            scale(w, h),
            scale(q, -h),
            self.q_att * step.dt,
            self.q_bias * step.dt,
        );
        let Some(q_pred) = normalize(integrate(q, w, step.dt)) else {
            self.p = p_old;
            self.s.diag.rejected += 1;
            return;
        };
        let mut dx = [T::ZERO; N];
        if let Some(acc) = step.acc {
            let up = [T::ZERO, T::ZERO, T::ONE];
            self.correct(q_pred, up, acc, self.r_acc, &mut dx);
        }
        if let Some(mag) = step.mag {
            self.correct(q_pred, self.s.mag_ref, mag, self.r_mag, &mut dx);
        }
        let bias = axpy(self.bias, T::ONE, [dx[4], dx[5], dx[6]]);
        let q_new = normalize(axpy(q_pred, T::ONE, [dx[0], dx[1], dx[2], dx[3]]));
        match q_new {
            Some(q_new) if is_sane(&self.p) && bias.iter().all(|c| c.is_finite()) => {
                self.s.q = q_new;
                self.bias = bias;
            }
            _ => {
                self.p = p_old;
                self.s.diag.rejected += 1;
            }
        }
    }

    fn quaternion(&self) -> Quat<T> {
        self.s.q
    }

    fn reset(&mut self, q: Quat<T>) {
        self.s.reset(q);
        self.bias = [T::ZERO; 3];
        self.p = self.p0;
    }

    fn diagnostics(&self) -> Diagnostics {
        self.s.diag
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quat::{from_euler_zyx, mul, world_to_body};

    /// `vec(q* ⊗ r ⊗ q)` for any (not unit) `q`: the homogeneous quadratic form.
    fn h(q: Quat<f64>, r: Vec3<f64>) -> Vec3<f64> {
        let p = mul(mul([q[0], -q[1], -q[2], -q[3]], [0.0, r[0], r[1], r[2]]), q);
        [p[1], p[2], p[3]]
    }

    #[test]
    fn invalid_parameters_are_refused() {
        let bad = |cfg: EkfConfig| Ekf::<f32>::new(&cfg).unwrap_err();
        let d = EkfConfig::default();
        let what = |what| Error::NonPositiveParameter { what };
        assert_eq!(
            bad(EkfConfig {
                accel_noise: -0.5,
                ..d
            }),
            what("accel_noise")
        );
        assert_eq!(
            bad(EkfConfig {
                gyro_bias_walk: 0.0,
                ..d
            }),
            what("gyro_bias_walk")
        );
        // Its square is below f32's range.
        assert_eq!(
            bad(EkfConfig {
                mag_noise: 1e-30,
                ..d
            }),
            what("mag_noise")
        );
        assert_eq!(
            bad(EkfConfig {
                gyro_noise: 1e30,
                ..d
            }),
            Error::ParameterTooLarge { what: "gyro_noise" }
        );
        assert_eq!(
            bad(EkfConfig {
                initial_bias_std: f64::NAN,
                ..d
            }),
            Error::NonFiniteParameter {
                what: "initial_bias_std"
            }
        );
        assert_eq!(
            bad(EkfConfig {
                mag_reference: [0.0, 0.0, -1.0],
                ..d
            }),
            Error::VerticalMagneticReference
        );
        assert_eq!(
            bad(EkfConfig {
                mag_reference: [0.0; 3],
                ..d
            }),
            Error::ZeroMagneticReference
        );
        assert_eq!(
            bad(EkfConfig {
                initial: Initial::Attitude([0.0; 4]),
                ..d
            }),
            Error::ZeroInitialAttitude
        );
        assert!(Ekf::<f64>::new(&EkfConfig {
            mag_noise: 1e-30,
            ..d
        })
        .is_ok());
    }

    #[test]
    // Matrices indexed the way the formulas write them.
    #[allow(clippy::needless_range_loop)]
    fn transition_matrix_matches_finite_differences() {
        let (q, g, bias, h) = (
            from_euler_zyx([0.4f64, -1.1, 2.9]),
            [3.0, -20.0, 45.0],
            [0.1, 0.2, -0.3],
            0.0025,
        );
        let step = |x: [f64; 7]| {
            let w = [0, 1, 2].map(|i| g[i] - x[4 + i]);
            integrate([x[0], x[1], x[2], x[3]], w, 2.0 * h)
        };
        let w = [0, 1, 2].map(|i| g[i] - bias[i]);
        let (a, b) = transition(q, w, h);
        // The products the filter applies are these matrices.
        for k in 0..4 {
            let e: [f64; 4] = core::array::from_fn(|i| f64::from(u8::from(i == k)));
            let col = covariance::apply_a([h * w[0], h * w[1], h * w[2]], e);
            assert!(
                (0..4).all(|i| (col[i] - a[i][k]).abs() < 1e-15),
                "A col {k}"
            );
        }
        for k in 0..3 {
            let e: [f64; 3] = core::array::from_fn(|i| f64::from(u8::from(i == k)));
            let col = covariance::apply_b(q.map(|c| -h * c), e);
            assert!(
                (0..4).all(|i| (col[i] - b[i][k]).abs() < 1e-15),
                "B col {k}"
            );
        }
        let x = [q[0], q[1], q[2], q[3], bias[0], bias[1], bias[2]];
        for k in 0..7 {
            let (mut up, mut down) = (x, x);
            up[k] += 1e-6;
            down[k] -= 1e-6;
            let (fu, fd) = (step(up), step(down));
            for i in 0..4 {
                let d = (fu[i] - fd[i]) / 2e-6;
                let phi = if k < 4 { a[i][k] } else { b[i][k - 4] };
                assert!((phi - d).abs() < 1e-9, "row {i} col {k}: {phi} vs {d}");
            }
        }
    }

    #[test]
    fn measurement_and_jacobian_match_finite_differences() {
        let r = [0.3, -0.5, 0.81];
        for e in [[0.1, 0.2, 0.3], [3.0, -1.2, -2.0], [-0.4, 1.5, 3.1]] {
            let q = from_euler_zyx::<f64>(e);
            let (predicted, rows) = observe(q, r);
            let expect = world_to_body(q, r);
            for i in 0..3 {
                assert!((predicted[i] - expect[i]).abs() < 1e-15);
            }
            let eps = 1e-6;
            for k in 0..4 {
                let (mut up, mut down) = (q, q);
                up[k] += eps;
                down[k] -= eps;
                let (hu, hd) = (h(up, r), h(down, r));
                for i in 0..3 {
                    let fd = (hu[i] - hd[i]) / (2.0 * eps);
                    assert!((rows[i][k] - fd).abs() < 1e-9, "{e:?} row {i} col {k}");
                }
            }
        }
    }
}
