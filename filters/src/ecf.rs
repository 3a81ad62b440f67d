//! Explicit complementary filter (Mahony et al. 2008), the paper's eq. 24.
//!
//! ```text
//! e_k   = A_k × Â(q̂_k) + H_k × Ĥ(q̂_k)
//! Ω̂_k   = Ω_k + Kp·e_k + Ki·Σᵢ₌₁ᵏ eᵢ·Tₛ
//! q̂_k+1 = normalize(q̂_k + Tₛ/2 · q̂_k ⊗ (0, Ω̂_k))
//! ```
//!
//! `A_k`, `H_k` are the measured accelerometer and magnetometer directions (unit vectors), `Â`,
//! `Ĥ` the world references (up, and the magnetic reference) seen through the estimate. For a
//! small error the cross products point along the rotation that carries the estimate onto the
//! truth, so `Kp` (rad/s per unit error) sets the correction bandwidth and `Ki` (rad/s²) the
//! integral action, which estimates a constant gyroscope bias. A missing vector drops its term;
//! the integral keeps its value while both are missing. `Tₛ` is the `dt` of each update.
//!
//! Defaults: `Kp = 0.5`, `Ki = 0`, those of Mahony's reference implementation (the paper's
//! "initial" column came from heuristics it does not list).
//!
//! ```
//! use margemu_filters::{AttitudeFilter, Ecf, EcfConfig, Imu, Initial};
//! use margemu_filters::quat::{from_euler_zyx, geodesic_angle, world_to_body};
//! let truth = from_euler_zyx([0.3f64, -0.2, 0.5]);
//! let identity = Initial::Attitude([1.0, 0.0, 0.0, 0.0]);
//! let cfg = EcfConfig { kp: 5.0, initial: identity, ..EcfConfig::default() };
//! let mut ecf = Ecf::new(&cfg)?;
//! let imu = Imu {
//!     gyro: [0.0; 3],
//!     acc: world_to_body(truth, [0.0, 0.0, 9.80665]),
//!     mag: world_to_body(truth, [0.5, 0.0, -0.83]),
//! };
//! for _ in 0..20_000 {
//!     ecf.update(&imu, 0.005);
//! }
//! assert!(geodesic_angle(ecf.quaternion(), truth) < 1e-9);
//! # Ok::<(), margemu_filters::Error>(())
//! ```

use crate::filter::{AttitudeFilter, Diagnostics, Imu};
use crate::init::{parameter, Initial, Shared, DEFAULT_MAG_REFERENCE};
use crate::quat::{axpy, cross, integrate, up_in_body, world_to_body, Quat, Vec3};
use crate::{Error, Real};

/// Parameters of the [`Ecf`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EcfConfig {
    /// Proportional gain `Kp` (rad/s per unit vector error), `>= 0`. Default 0.5.
    pub kp: f64,
    /// Integral gain `Ki` (rad/s² per unit vector error), `>= 0`. Default 0.
    pub ki: f64,
    /// World-frame magnetic reference (any length, not vertical). Default `(0.5, 0, −0.83)`.
    pub mag_reference: [f64; 3],
    /// Where the filter starts. Default: from the first sample.
    pub initial: Initial,
}

impl Default for EcfConfig {
    fn default() -> Self {
        Self {
            kp: 0.5,
            ki: 0.0,
            mag_reference: DEFAULT_MAG_REFERENCE,
            initial: Initial::FirstSample,
        }
    }
}

/// The explicit complementary filter of eq. 24.
#[derive(Clone, Debug)]
pub struct Ecf<T> {
    s: Shared<T>,
    kp: T,
    ki: T,
    /// `Σ eᵢ·Tₛ`.
    integral: Vec3<T>,
}

impl<T: Real> Ecf<T> {
    /// A filter with the parameters of `cfg`, checked.
    pub fn new(cfg: &EcfConfig) -> Result<Self, Error> {
        Ok(Self {
            s: Shared::new(cfg.mag_reference, cfg.initial)?,
            kp: parameter(cfg.kp, "kp", false)?,
            ki: parameter(cfg.ki, "ki", false)?,
            integral: [T::ZERO; 3],
        })
    }

    /// The integral `Σ eᵢ·Tₛ`; `Ki` times it is the filter's estimate of minus the gyro bias.
    pub fn integral(&self) -> Vec3<T> {
        self.integral
    }
}

impl<T: Real> AttitudeFilter<T> for Ecf<T> {
    fn update(&mut self, imu: &Imu<T>, dt: T) {
        let Some(step) = self.s.begin(imu, dt) else {
            return;
        };
        let q = self.s.q;
        let mut e = [T::ZERO; 3];
        if let Some(a) = step.acc {
            e = cross(a, up_in_body(q));
        }
        if let Some(h) = step.mag {
            e = axpy(e, T::ONE, cross(h, world_to_body(q, self.s.mag_ref)));
        }
        let integral = axpy(self.integral, step.dt, e);
        let omega = axpy(axpy(step.gyro, self.kp, e), self.ki, integral);
        let finite = integral.iter().all(|c| c.is_finite());
        if finite && self.s.commit(integrate(q, omega, step.dt)) {
            self.integral = integral;
        } else if !finite {
            self.s.diag.rejected += 1;
        }
    }

    fn quaternion(&self) -> Quat<T> {
        self.s.q
    }

    fn reset(&mut self, q: Quat<T>) {
        self.s.reset(q);
        self.integral = [T::ZERO; 3];
    }

    fn diagnostics(&self) -> Diagnostics {
        self.s.diag
    }
}
