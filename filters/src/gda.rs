//! Gradient-descent attitude filter (Madgwick et al. 2011), the paper's eq. 25.
//!
//! ```text
//! f_k   = [Â(q̂_k) − A_k ; Ĥ(q̂_k) − H_k]            (unit vectors, 6 rows)
//! ∇f_k  = J_kᵀ f_k
//! q̂_k+1 = normalize(q̂_k + Tₛ·(½ q̂_k ⊗ (0, Ω_k) − β·∇f_k / ‖∇f_k‖))
//! ```
//!
//! **Normalization.** The paper prints `β·∇f/‖f‖`; Madgwick's original (and the ROS and MATLAB
//! implementations the paper cites) divide by `‖∇f‖`. The default here is Madgwick's
//! ([`GdaNormalization::Gradient`]): the step is then a unit direction, so `β` is exactly the
//! rate (per second, in quaternion norm) at which the correction moves `q̂`, and
//! `β ≈ √(3/4)·ω̃` relates it to the gyroscope error `ω̃` as in Madgwick's report.
//! The printed form is available as [`GdaNormalization::Residual`]. It is scale-free too
//! (`∇f` is linear in `f`), but its step length `‖Jᵀ f‖/‖f‖` depends on the direction of the
//! error: for a small tilt error seen by one vector the correction turns the estimate at `4β`
//! rad/s instead of `2β`, and in general at `4β·|e|/‖f‖`, between about `1.5β` and `5.7β` for the
//! default reference field. Both step at a constant rate however small the error, so around a
//! static truth the estimate dithers within about one step: `2β·Tₛ` rad (Gradient), up to
//! `4√2·β·Tₛ` (Residual). `tests/gda.rs` pins the rates and the dither of both.
//!
//! **Gradient in closed form.** Writing each residual with the homogeneous quadratic form
//! `Â(q) = q* ⊗ r ⊗ q` (equal to Madgwick's polynomials on the unit sphere) gives, for unit `q`,
//!
//! ```text
//! ∇f = 2·q ⊗ (σ, −e),   σ = ½‖f‖² = Σ (1 − Â·A),   e = A × Â + H × Ĥ
//! ```
//!
//! where `e` is the ECF's error vector (eq. 24). So one quaternion product replaces the 6×4
//! Jacobian for any reference vectors, and the update is `q̂ ⊗ (−β'σ, ½Ω + β'e)` with
//! `β' = β/‖(σ, e)‖` (Gradient) or `2β/‖f‖` (Residual). A missing vector drops its rows.
//! The magnetic reference is the configured world field (not Madgwick's in-filter
//! `b = (√(hx²+hy²), 0, hz)` compensation), as eq. 25 writes it.
//!
//! **Madgwick's original MARG update** ([`GdaNormalization::Xio`]; Madgwick, "An efficient
//! orientation filter for inertial and inertial/magnetic sensor arrays", x-io report, 2010,
//! eqs. 43–46, written here from the report's equations): the step is normalised by `‖∇f‖` as
//! in [`GdaNormalization::Gradient`], and the magnetic reference is not the configured one but
//! is rebuilt at every update from the measurement, the *magnetic distortion compensation* of
//! the report's section 3.4: `h = q̂ ⊗ m ⊗ q̂*` (the unit field measurement in the world), then
//! `b = (√(hx² + hy²), 0, hz)`. Against eq. 25 of the paper (which compares with a fixed
//! world field `H`), what differs:
//! - the reference's inclination follows the measurement, so a field whose dip differs from
//!   the configured one (or drifts) does not pull the tilt, and a magnetic disturbance that
//!   changes the dip affects only heading;
//! - the reference has no horizontal direction of its own: heading is taken from magnetic
//!   north along world +x whatever the configured field's declination (the configured field
//!   only sets the first-sample TRIAD start);
//! - no gyroscope bias compensation (the report's `ζ` term of eqs. 47–48 is left out, as in
//!   its published MARG update).
//!
//! Default `β = 0.1` (Madgwick's published default; the paper's "initial" column came from
//! heuristics).
//!
//! ```
//! use margemu_filters::{AttitudeFilter, Gda, GdaConfig, Imu};
//! let mut gda = Gda::<f32>::new(&GdaConfig::default())?;
//! let level = Imu { gyro: [0.0; 3], acc: [0.0, 0.0, 9.81], mag: [0.5, 0.0, -0.83] };
//! gda.update(&level, 0.005);
//! assert!((gda.quaternion()[0] - 1.0).abs() < 1e-6);
//! # Ok::<(), margemu_filters::Error>(())
//! ```

use crate::filter::{AttitudeFilter, Diagnostics, Imu};
use crate::init::{parameter, Initial, Shared, DEFAULT_MAG_REFERENCE};
use crate::quat::{
    axpy, body_to_world, cross, dot3, mul, normalize, scale, up_in_body, world_to_body, Quat, Vec3,
};
use crate::{Error, Real};

/// What the gradient step of eq. 25 is divided by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GdaNormalization {
    /// `β·∇f/‖∇f‖`, Madgwick's original (default).
    #[default]
    Gradient,
    /// `β·∇f/‖f‖`, as the paper prints eq. 25.
    Residual,
    /// Madgwick's original MARG update (x-io report, 2010): `β·∇f/‖∇f‖` with the magnetic
    /// reference rebuilt from each measurement, `b = (√(hx²+hy²), 0, hz)` (see the module docs).
    Xio,
}

/// Parameters of the [`Gda`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GdaConfig {
    /// Learning rate `β` (1/s, quaternion norm per second), `>= 0`. Default 0.1.
    pub beta: f64,
    /// What the step is divided by. Default: `‖∇f‖` (Madgwick).
    pub normalization: GdaNormalization,
    /// World-frame magnetic reference (any length, not vertical). Default `(0.5, 0, −0.83)`.
    pub mag_reference: [f64; 3],
    /// Where the filter starts. Default: from the first sample.
    pub initial: Initial,
}

impl Default for GdaConfig {
    fn default() -> Self {
        Self {
            beta: 0.1,
            normalization: GdaNormalization::Gradient,
            mag_reference: DEFAULT_MAG_REFERENCE,
            initial: Initial::FirstSample,
        }
    }
}

/// The gradient-descent filter of eq. 25.
#[derive(Clone, Debug)]
pub struct Gda<T> {
    s: Shared<T>,
    beta: T,
    normalization: GdaNormalization,
}

/// `(σ, e)` of the module docs for unit `q` and unit measurements.
#[inline(always)]
fn residual_terms<T: Real>(
    q: Quat<T>,
    acc: Option<Vec3<T>>,
    mag: Option<Vec3<T>>,
    mag_ref: Vec3<T>,
) -> (T, Vec3<T>) {
    let mut sigma = T::ZERO;
    let mut e = [T::ZERO; 3];
    let mut add = |measured: Vec3<T>, predicted: Vec3<T>| {
        let d = axpy(predicted, -T::ONE, measured);
        sigma += T::HALF * dot3(d, d);
        e = axpy(e, T::ONE, cross(measured, predicted));
    };
    if let Some(a) = acc {
        add(a, up_in_body(q));
    }
    if let Some(h) = mag {
        add(h, world_to_body(q, mag_ref));
    }
    (sigma, e)
}

/// `∇f = Jᵀf` of eq. 25 at the unit quaternion `q`, for the accelerometer and magnetometer
/// readings `acc`, `mag` (normalized here; an unusable one drops its rows) and the world field
/// `mag_reference` (unit).
pub fn objective_gradient<T: Real>(
    q: Quat<T>,
    acc: Vec3<T>,
    mag: Vec3<T>,
    mag_reference: Vec3<T>,
) -> Quat<T> {
    let (sigma, e) = residual_terms(q, normalize(acc), normalize(mag), mag_reference);
    scale(mul(q, [sigma, -e[0], -e[1], -e[2]]), T::TWO)
}

impl<T: Real> Gda<T> {
    /// A filter with the parameters of `cfg`, checked.
    pub fn new(cfg: &GdaConfig) -> Result<Self, Error> {
        Ok(Self {
            s: Shared::new(cfg.mag_reference, cfg.initial)?,
            beta: parameter(cfg.beta, "beta", false)?,
            normalization: cfg.normalization,
        })
    }
}

impl<T: Real> AttitudeFilter<T> for Gda<T> {
    fn update(&mut self, imu: &Imu<T>, dt: T) {
        let Some(step) = self.s.begin(imu, dt) else {
            return;
        };
        let q = self.s.q;
        let mag_ref = match (self.normalization, step.mag) {
            (GdaNormalization::Xio, Some(m)) => {
                let h = body_to_world(q, m);
                [(h[0] * h[0] + h[1] * h[1]).sqrt(), T::ZERO, h[2]]
            }
            _ => self.s.mag_ref,
        };
        let (sigma, e) = residual_terms(q, step.acc, step.mag, mag_ref);
        let norm = match self.normalization {
            GdaNormalization::Gradient | GdaNormalization::Xio => {
                (sigma * sigma + e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
            }
            GdaNormalization::Residual => (T::TWO * sigma).sqrt() * T::HALF,
        };
        // β' of the module docs; no correction at an exact optimum (0/0).
        let gain = if norm > T::ZERO {
            self.beta / norm
        } else {
            T::ZERO
        };
        let p = [
            -gain * sigma,
            T::HALF * step.gyro[0] + gain * e[0],
            T::HALF * step.gyro[1] + gain * e[1],
            T::HALF * step.gyro[2] + gain * e[2],
        ];
        let d = mul(q, p);
        self.s.commit(axpy(q, step.dt, d));
    }

    fn quaternion(&self) -> Quat<T> {
        self.s.q
    }

    fn reset(&mut self, q: Quat<T>) {
        self.s.reset(q);
    }

    fn diagnostics(&self) -> Diagnostics {
        self.s.diag
    }
}
