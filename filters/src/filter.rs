//! The interface every filter implements, its input sample, its counters and the helpers that run
//! a filter over recorded samples.
//!
//! A filter takes one [`Imu`] sample and the time step `dt` (s) since the previous one, and keeps
//! a unit quaternion (Hamilton, scalar first, body to world). `update` accepts any input and never
//! panics or produces a NaN: an unusable accelerometer or magnetometer vector (zero, NaN or
//! infinite) skips that correction, an unusable `dt` (≤ 0 or not finite) or gyroscope skips the
//! whole update, and a step whose result would not be finite is discarded. Each case is counted
//! in [`Diagnostics`].
//!
//! ```
//! use margemu_filters::{run, AttitudeFilter, Ecf, EcfConfig, Imu};
//! let mut ecf = Ecf::<f64>::new(&EcfConfig::default())?;
//! let level = Imu { gyro: [0.0; 3], acc: [0.0, 0.0, 9.80665], mag: [0.5, 0.0, -0.83] };
//! let mut out = [[0.0; 4]; 200];
//! assert_eq!(run(&mut ecf, &[level; 200], 0.005, &mut out), 200);
//! assert!(margemu_filters::quat::geodesic_angle(out[199], [1.0, 0.0, 0.0, 0.0]) < 1e-9);
//! ecf.update(&Imu { acc: [f64::NAN; 3], ..level }, 0.005);
//! assert_eq!(ecf.diagnostics().skipped_accel, 1);
//! # Ok::<(), margemu_filters::Error>(())
//! ```

use crate::quat::{euler_zyx, Quat, Vec3};
use crate::Real;

/// One MARG sample in body axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Imu<T> {
    /// Angular rate (rad/s).
    pub gyro: [T; 3],
    /// Specific force (m/s²): `(0, 0, +9.80665)` level at rest. Only its direction is used.
    pub acc: [T; 3],
    /// Magnetic field, any unit. Only its direction is used.
    pub mag: [T; 3],
}

/// What a filter did with its inputs since it was built (a `reset` keeps the counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Diagnostics {
    /// Updates that changed the state: propagations, and the sample that initialized the
    /// attitude (`Initial::FirstSample`).
    pub updates: u64,
    /// Updates skipped whole because `dt` was ≤ 0 or not finite or the gyroscope was not finite.
    pub skipped_updates: u64,
    /// Accelerometer corrections skipped: the vector was zero, NaN or infinite.
    pub skipped_accel: u64,
    /// Magnetometer corrections skipped: the vector was zero, NaN or infinite.
    pub skipped_mag: u64,
    /// Steps (or, in the EKF, single measurement updates) whose result was not finite or, in the
    /// EKF, whose covariance lost a positive diagonal; the state before them was kept.
    pub rejected: u64,
}

/// An attitude filter: gyroscope propagation corrected by the accelerometer and magnetometer.
///
/// Object safe, so a caller can hold several filters as `&mut dyn AttitudeFilter<f64>`.
pub trait AttitudeFilter<T: Real> {
    /// Takes one sample, `dt` seconds after the previous one. Never panics, never yields NaN.
    fn update(&mut self, imu: &Imu<T>, dt: T);
    /// The attitude estimate: unit, Hamilton, scalar first, body to world.
    fn quaternion(&self) -> Quat<T>;
    /// Restarts the filter at attitude `q` (normalized; a zero or non-finite `q` restarts at the
    /// identity). Integrator, bias and covariance return to their initial values.
    fn reset(&mut self, q: Quat<T>);
    /// What the filter did with its inputs.
    fn diagnostics(&self) -> Diagnostics;
    /// The attitude as ZYX Euler angles `[roll, pitch, yaw]` (rad).
    fn euler(&self) -> Vec3<T> {
        euler_zyx(self.quaternion())
    }
}

/// Runs `filter` over `samples` taken every `dt` seconds and writes the attitude after each
/// sample to `out`. Returns the number written: the shorter of the two slices.
pub fn run<T: Real, F: AttitudeFilter<T> + ?Sized>(
    filter: &mut F,
    samples: &[Imu<T>],
    dt: T,
    out: &mut [Quat<T>],
) -> usize {
    let n = samples.len().min(out.len());
    for (imu, q) in samples[..n].iter().zip(&mut out[..n]) {
        filter.update(imu, dt);
        *q = filter.quaternion();
    }
    n
}

/// Runs `filter` over `samples` latched at `t_ns` (nanoseconds, as in `CONVENTIONS.md`) and writes
/// the attitude after each sample to `out`. Sample `k > 0` gets `dt = (t_k − t_{k−1})·10⁻⁹`;
/// sample 0 gets the first interval `t_1 − t_0` (it initializes the filter). Non-increasing
/// stamps give `dt = 0`, which the filter skips and counts. Returns the number written: the
/// shortest of the three slices.
pub fn run_stamped<T: Real, F: AttitudeFilter<T> + ?Sized>(
    filter: &mut F,
    t_ns: &[u64],
    samples: &[Imu<T>],
    out: &mut [Quat<T>],
) -> usize {
    let n = samples.len().min(out.len()).min(t_ns.len());
    for k in 0..n {
        let (a, b) = if k == 0 { (0, 1) } else { (k - 1, k) };
        let step_ns = match (t_ns.get(a), t_ns.get(b)) {
            (Some(&ta), Some(&tb)) => tb.saturating_sub(ta),
            _ => 0,
        };
        filter.update(&samples[k], T::from_f64(step_ns as f64 * 1e-9));
        out[k] = filter.quaternion();
    }
    n
}
