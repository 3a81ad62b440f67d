//! The MARG sensor model of eq. 18, per axis, with the error terms real parts show.
//!
//! ```text
//! Ω = (I + ΔS_Ω)·M_Ω·ω + G·f + ω̄ + c_Ω(T−T₀) + b_GM + b_RW + μ        gyroscope
//! A = (I + ΔS_A)·M_A·(f + ω̇×r + ω×(ω×r)) + a₀ + c_A(T−T₀) + … + ν     accelerometer
//! H = (I + ΔS_H)·M_H·(B_si·h + b_hi) + h₀ + c_H(T−T₀) + … + ε          magnetometer
//! ```
//! then each axis rounded to its resolution and clipped to its range. `f` is the specific force
//! (`α + g` of eq. 18 in our sign convention: it reads `(0, 0, +9.80665)` level at rest). Every
//! term is off unless configured ([`MargConfig`]); a configuration without any term takes the
//! ideal path, which copies the input and costs nothing else.
//!
//! # Numerics
//! The firmware (Cortex-M4F: hardware `f32`, software `f64`) runs this very code and must produce
//! the same bits as the host. So the per-sample path is `f32` only, with a fixed order of
//! operations and no fused multiply-add; the coefficients are computed once in `f64` at
//! construction (products of matrices, `density·√rate`, `exp(−1/(fs·T))`) and rounded to `f32`.
//! Input and output are `f32` ([`Truth`], [`Sample`]): the host rounds its `f64` truth to `f32`
//! once, the same values it would send to the firmware. `f32` resolves 6·10⁻⁸ of full scale,
//! far below any MEMS noise floor.
//!
//! # Non-finite input
//! NaN in a component gives NaN in the output axes it reaches, for that sample only: the noise
//! states never absorb input values, so the next finite sample is exact again (also with a range
//! configured: clipping keeps NaN, and the chip model decides which code a NaN becomes). ±∞ and
//! anything beyond ±10¹⁵ is limited to ±10¹⁵ first, so with a range it saturates like any other
//! out-of-range value. Without any term configured, the output is the input, bit for bit.
//!
//! ```
//! use margemu_model::sensor::{Marg, MargConfig, Truth};
//! let mut cfg = MargConfig::default();
//! cfg.accel.errors.bias = Some([0.5, 0.0, 0.0]);
//! cfg.accel.errors.range = Some([20.0; 3]);
//! let mut marg = Marg::new(&cfg, 200.0, 42)?;
//! let truth = Truth { specific_force: [0.0, 0.0, 9.80665], ..Truth::default() };
//! assert_eq!(marg.sample(&truth).acc, [0.5, 0.0, 9.80665]);
//! let shaken = Truth { specific_force: [1e30, f32::NEG_INFINITY, 3.0], ..truth };
//! assert_eq!(marg.sample(&shaken).acc, [20.0, -20.0, 3.0]);
//! # Ok::<(), margemu_model::Error>(())
//! ```

mod config;
#[cfg(feature = "serde")]
mod config_serde;
mod triad;

pub use config::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, MargConfig, SensorErrors, SensorTable,
    TemperatureBias,
};
pub use triad::INPUT_LIMIT;

use crate::error::{each3, finite, finite3x3, Error};
use crate::vec3::{add, clamp, cross, mat_vec, Mat3, Vec3};
use triad::{mat_f32, vec_f32, Kind, Triad};

/// True kinematics at the sensor, body axes, SI units, one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Truth {
    /// Body angular rate ω, rad/s.
    pub angular_rate: Vec3,
    /// Specific force f at the rotation centre, m/s² (`(0, 0, +9.80665)` level at rest).
    pub specific_force: Vec3,
    /// Magnetic field in body axes, scene unit (add the perturbation here).
    pub magnetic_field: Vec3,
    /// Angular acceleration ω̇, rad/s² (used by the lever arm only).
    pub angular_acceleration: Vec3,
    /// Sensor temperature, °C; `None` means the reference temperature of each term.
    pub temperature_c: Option<f32>,
}

/// One output sample of the three sensors, in their units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Accelerometer, m/s².
    pub acc: Vec3,
    /// Gyroscope, rad/s.
    pub gyr: Vec3,
    /// Magnetometer, scene unit.
    pub mag: Vec3,
}

/// `v` finite and rounded to `f32` (refused if a component is NaN, infinite or overflows).
pub(crate) fn vec_f32_checked(v: [f64; 3], what: &'static str) -> Result<Vec3, Error> {
    vec_f32(each3(v, what, finite)?, what)
}

fn check_rate(rate_hz: f64) -> Result<f64, Error> {
    if rate_hz.is_finite() && rate_hz > 0.0 {
        Ok(rate_hz)
    } else {
        Err(Error::InvalidRate)
    }
}

/// The gyroscope model.
#[derive(Clone, Debug)]
pub struct Gyro {
    triad: Triad,
    g_sensitivity: Option<Mat3>,
}

impl Gyro {
    /// The gyroscope of `cfg` at `rate_hz` with the scene seed `seed`.
    pub fn new(cfg: &GyroConfig, rate_hz: f64, seed: u64) -> Result<Self, Error> {
        let rate = check_rate(rate_hz)?;
        let g = cfg
            .g_sensitivity
            .map(|g| finite3x3(g, "gyro.g_sensitivity"))
            .transpose()?;
        Ok(Self {
            triad: Triad::new(Kind::Gyro, &cfg.errors, None, None, rate, seed)?,
            g_sensitivity: g.map(|g| mat_f32(&g, "gyro.g_sensitivity")).transpose()?,
        })
    }

    /// One sample from the true rate ω (rad/s) and the specific force at the sensor (m/s², used
    /// only by the g-sensitivity).
    #[inline]
    pub fn sample(
        &mut self,
        angular_rate: Vec3,
        specific_force: Vec3,
        temperature_c: Option<f32>,
    ) -> Vec3 {
        let extra = self
            .g_sensitivity
            .as_ref()
            .map(|g| mat_vec(g, clamp(specific_force, INPUT_LIMIT)));
        self.triad.apply(angular_rate, extra, temperature_c)
    }

    /// Whether no term is configured.
    pub fn is_ideal(&self) -> bool {
        self.triad.is_ideal() && self.g_sensitivity.is_none()
    }
}

/// The accelerometer model.
#[derive(Clone, Debug)]
pub struct Accel {
    triad: Triad,
    lever_arm: Option<Vec3>,
}

impl Accel {
    /// The accelerometer of `cfg` at `rate_hz` with the scene seed `seed`.
    pub fn new(cfg: &AccelConfig, rate_hz: f64, seed: u64) -> Result<Self, Error> {
        let rate = check_rate(rate_hz)?;
        let r = cfg
            .lever_arm_m
            .map(|r| each3(r, "accel.lever_arm_m", finite))
            .transpose()?;
        Ok(Self {
            triad: Triad::new(Kind::Accel, &cfg.errors, None, None, rate, seed)?,
            lever_arm: r.map(|r| vec_f32(r, "accel.lever_arm_m")).transpose()?,
        })
    }

    /// The specific force at the sensor: `f + ω̇×r + ω×(ω×r)` with the lever arm r (or `f`),
    /// inputs limited to ±[`INPUT_LIMIT`].
    #[inline]
    pub fn specific_force_at_sensor(&self, truth: &Truth) -> Vec3 {
        let f = clamp(truth.specific_force, INPUT_LIMIT);
        match self.lever_arm {
            None => f,
            Some(r) => {
                let w = clamp(truth.angular_rate, INPUT_LIMIT);
                let dw = clamp(truth.angular_acceleration, INPUT_LIMIT);
                add(f, add(cross(dw, r), cross(w, cross(w, r))))
            }
        }
    }

    /// One sample from the specific force at the sensor (see [`Self::specific_force_at_sensor`]).
    #[inline]
    pub fn sample(&mut self, specific_force_at_sensor: Vec3, temperature_c: Option<f32>) -> Vec3 {
        self.triad
            .apply(specific_force_at_sensor, None, temperature_c)
    }

    /// Whether no term is configured.
    pub fn is_ideal(&self) -> bool {
        self.triad.is_ideal() && self.lever_arm.is_none()
    }
}

/// The magnetometer model.
#[derive(Clone, Debug)]
pub struct Mag {
    triad: Triad,
}

impl Mag {
    /// The magnetometer of `cfg` at `rate_hz` with the scene seed `seed`.
    pub fn new(cfg: &MagConfig, rate_hz: f64, seed: u64) -> Result<Self, Error> {
        let rate = check_rate(rate_hz)?;
        Ok(Self {
            triad: Triad::new(
                Kind::Mag,
                &cfg.errors,
                cfg.soft_iron,
                cfg.hard_iron,
                rate,
                seed,
            )?,
        })
    }

    /// One sample from the field h in body axes (perturbation included).
    #[inline]
    pub fn sample(&mut self, field: Vec3, temperature_c: Option<f32>) -> Vec3 {
        self.triad.apply(field, None, temperature_c)
    }

    /// Whether no term is configured.
    pub fn is_ideal(&self) -> bool {
        self.triad.is_ideal()
    }
}

/// The three sensors at one output rate.
#[derive(Clone, Debug)]
pub struct Marg {
    gyro: Gyro,
    accel: Accel,
    mag: Mag,
    ideal: bool,
}

impl Marg {
    /// The MARG unit of `cfg` at `rate_hz` (all three sensors) with the scene seed `seed`.
    pub fn new(cfg: &MargConfig, rate_hz: f64, seed: u64) -> Result<Self, Error> {
        let gyro = Gyro::new(&cfg.gyro, rate_hz, seed)?;
        let accel = Accel::new(&cfg.accel, rate_hz, seed)?;
        let mag = Mag::new(&cfg.mag, rate_hz, seed)?;
        let ideal = gyro.is_ideal() && accel.is_ideal() && mag.is_ideal();
        Ok(Self {
            gyro,
            accel,
            mag,
            ideal,
        })
    }

    /// Whether no term of any sensor is configured (the fast path).
    pub fn is_ideal(&self) -> bool {
        self.ideal
    }

    /// One sample of all three sensors. Never panics; see the module docs for non-finite input.
    #[inline]
    pub fn sample(&mut self, truth: &Truth) -> Sample {
        if self.ideal {
            return Sample {
                acc: truth.specific_force,
                gyr: truth.angular_rate,
                mag: truth.magnetic_field,
            };
        }
        let t = truth.temperature_c;
        let f = self.accel.specific_force_at_sensor(truth);
        Sample {
            acc: self.accel.sample(f, t),
            gyr: self.gyro.sample(truth.angular_rate, f, t),
            mag: self.mag.sample(truth.magnetic_field, t),
        }
    }

    /// One sample with the accelerometer's specific force at the sensor and the gyroscope's
    /// rate given: what a sampling chain ([`crate::chain`]) made of the truth's. The field, the
    /// temperature and (for the g-sensitivity) nothing else come from `truth`.
    #[inline]
    pub fn sample_chained(
        &mut self,
        truth: &Truth,
        specific_force_at_sensor: Vec3,
        angular_rate: Vec3,
    ) -> Sample {
        if self.ideal {
            return Sample {
                acc: specific_force_at_sensor,
                gyr: angular_rate,
                mag: truth.magnetic_field,
            };
        }
        let t = truth.temperature_c;
        let f = specific_force_at_sensor;
        Sample {
            acc: self.accel.sample(f, t),
            gyr: self.gyro.sample(angular_rate, f, t),
            mag: self.mag.sample(truth.magnetic_field, t),
        }
    }

    /// The gyroscope.
    pub fn gyro(&self) -> &Gyro {
        &self.gyro
    }

    /// The accelerometer.
    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    /// The magnetometer.
    pub fn mag(&self) -> &Mag {
        &self.mag
    }
}
