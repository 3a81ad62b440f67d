//! How a filter starts, the world reference vectors, and the per-step bookkeeping all filters
//! share (input checks, counters, the first-sample initialization).
//!
//! World references (`CONVENTIONS.md`): gravity points down, so the accelerometer at rest reads
//! the world's up axis `(0, 0, 1)` in body axes; the magnetic reference is configurable, by default
//! the author's normalized field `(0.5, 0, −0.83)`. Both are used as unit vectors, and so are the
//! measurements.
//!
//! [`triad`] computes the attitude from one accelerometer and magnetometer sample:
//!
//! ```
//! use margemu_filters::init::triad;
//! use margemu_filters::quat::{from_euler_zyx, geodesic_angle, world_to_body};
//! let truth = from_euler_zyx([0.2f64, -1.4, 3.1]);
//! let m_ref = [0.5, 0.0, -0.83];
//! let acc = world_to_body(truth, [0.0, 0.0, 9.80665]);
//! let mag = world_to_body(truth, m_ref);
//! assert!(geodesic_angle(triad(acc, mag, m_ref).unwrap(), truth) < 1e-12);
//! ```

use crate::filter::{Diagnostics, Imu};
use crate::quat::{cross, from_euler_zyx, from_rotation_matrix, identity, normalize, Quat, Vec3};
use crate::{Error, Real};

/// The author's normalized magnetic reference field (world frame), before normalization.
pub const DEFAULT_MAG_REFERENCE: [f64; 3] = [0.5, 0.0, -0.83];

/// Where a filter starts.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Initial {
    /// From the first sample with a usable accelerometer, by [`triad`] (default). That sample
    /// only sets the attitude; filtering starts with the next one. Until then the estimate is
    /// the identity (and samples without a usable accelerometer are still filtered).
    #[default]
    FirstSample,
    /// From this quaternion (normalized by the constructor).
    Attitude([f64; 4]),
}

/// The attitude whose body axes see the world's up axis along `acc` and the world field
/// `mag_reference` in the plane of `acc` and `mag` (TRIAD, gravity first). With an unusable `mag`
/// (zero, not finite, or within 0.06° of `acc`) only the tilt is found, at zero yaw. `None` when
/// `acc` is zero or not finite, or `mag_reference` is vertical.
pub fn triad<T: Real>(acc: Vec3<T>, mag: Vec3<T>, mag_reference: Vec3<T>) -> Option<Quat<T>> {
    let b1 = normalize(acc)?;
    let up = [T::ZERO, T::ZERO, T::ONE];
    let b2 = normalize(mag).and_then(|h| {
        let c = cross(b1, h);
        let s2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        if s2 > T::from_f64(1e-6) {
            normalize(c)
        } else {
            None
        }
    });
    let Some(b2) = b2 else {
        // Tilt only: roll and pitch from the accelerometer, yaw zero.
        let roll = b1[1].atan2(b1[2]);
        let pitch = (-b1[0]).atan2((b1[1] * b1[1] + b1[2] * b1[2]).sqrt());
        return Some(from_euler_zyx([roll, pitch, T::ZERO]));
    };
    let t2 = normalize(cross(up, mag_reference))?;
    let (t1, t3, b3) = (up, cross(up, t2), cross(b1, b2));
    let (t, b) = ([t1, t2, t3], [b1, b2, b3]);
    // R = Σ tᵢ bᵢᵀ maps each body vector onto its world twin.
    let mut m = [[T::ZERO; 3]; 3];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, entry) in row.iter_mut().enumerate() {
            *entry = t[0][r] * b[0][c] + t[1][r] * b[1][c] + t[2][r] * b[2][c];
        }
    }
    Some(from_rotation_matrix(m))
}

/// `value` as `T`, checked: finite, in range, and `>= 0` (or `> 0` when `positive`).
pub(crate) fn parameter<T: Real>(
    value: f64,
    what: &'static str,
    positive: bool,
) -> Result<T, Error> {
    if !value.is_finite() {
        return Err(Error::NonFiniteParameter { what });
    }
    if positive && value <= 0.0 {
        return Err(Error::NonPositiveParameter { what });
    }
    if value < 0.0 {
        return Err(Error::NegativeParameter { what });
    }
    let v = T::from_f64(value);
    if !v.is_finite() {
        return Err(Error::ParameterTooLarge { what });
    }
    if positive && v <= T::ZERO {
        // Positive in f64 but below the smallest subnormal of T.
        return Err(Error::NonPositiveParameter { what });
    }
    Ok(v)
}

/// One step's checked inputs: `dt > 0` and the gyroscope finite; each vector unit or absent.
pub(crate) struct Step<T> {
    pub dt: T,
    pub gyro: Vec3<T>,
    pub acc: Option<Vec3<T>>,
    pub mag: Option<Vec3<T>>,
}

/// The state every filter has: attitude, magnetic reference, start mode and counters.
#[derive(Clone, Debug)]
pub(crate) struct Shared<T> {
    pub q: Quat<T>,
    /// Unit magnetic reference, world frame.
    pub mag_ref: Vec3<T>,
    /// Waiting for the first usable accelerometer sample ([`Initial::FirstSample`]).
    pub pending: bool,
    pub diag: Diagnostics,
}

impl<T: Real> Shared<T> {
    pub fn new(mag_reference: [f64; 3], initial: Initial) -> Result<Self, Error> {
        if mag_reference.iter().any(|c| !c.is_finite()) {
            return Err(Error::NonFiniteParameter {
                what: "mag_reference",
            });
        }
        let m = normalize(mag_reference).ok_or(Error::ZeroMagneticReference)?;
        if (m[0] * m[0] + m[1] * m[1]).sqrt() < 1e-3 {
            return Err(Error::VerticalMagneticReference);
        }
        let (q, pending) = match initial {
            Initial::FirstSample => (identity(), true),
            Initial::Attitude(q) => {
                if q.iter().any(|c| !c.is_finite()) {
                    return Err(Error::NonFiniteParameter { what: "initial" });
                }
                let q = normalize(q).ok_or(Error::ZeroInitialAttitude)?;
                (q.map(T::from_f64), false)
            }
        };
        Ok(Self {
            q,
            mag_ref: m.map(T::from_f64),
            pending,
            diag: Diagnostics::default(),
        })
    }

    /// Checks one sample and returns the step to take, or `None` when there is none: the update
    /// must be skipped (counted), or the sample initialized the attitude (pending start).
    #[inline(always)]
    pub fn begin(&mut self, imu: &Imu<T>, dt: T) -> Option<Step<T>> {
        let acc = normalize(imu.acc);
        let mag = normalize(imu.mag);
        if self.pending {
            if let Some(q) = acc.and_then(|a| triad(a, mag.unwrap_or([T::ZERO; 3]), self.mag_ref)) {
                // The initializing sample sets the attitude and nothing else.
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

    /// Takes `q` (normalized) as the new attitude; a `q` that cannot be normalized is counted as
    /// rejected and the attitude stays. Returns whether it was taken.
    #[inline(always)]
    pub fn commit(&mut self, q: Quat<T>) -> bool {
        match normalize(q) {
            Some(q) => {
                self.q = q;
                true
            }
            None => {
                self.diag.rejected += 1;
                false
            }
        }
    }

    /// Restarts at `q` (the identity when `q` cannot be normalized); no pending initialization.
    pub fn reset(&mut self, q: Quat<T>) {
        self.q = normalize(q).unwrap_or_else(identity);
        self.pending = false;
    }
}
