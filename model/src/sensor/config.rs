//! Plain configuration structs of the sensor model, in SI units, every term optional.
//!
//! Each struct derives `Default` with every term `None`, which is the ideal sensor; a scene names
//! only the terms it wants. Values are `f64` (as a TOML scene parses them); the constructors
//! validate them and round the per-sample coefficients to `f32` once.
//!
//! ```
//! use margemu_model::sensor::{MargConfig, SensorErrors};
//! // The paper's section 3.2 noise, nothing else.
//! let mut cfg = MargConfig::default();
//! cfg.gyro.errors.noise_density = Some([0.0224; 3]);
//! cfg.accel.errors.noise_density = Some([0.0224; 3]);
//! cfg.mag.errors.noise_density = Some([0.0022; 3]);
//! assert_eq!(cfg.mag.errors.bias, None);
//! assert_eq!(SensorErrors::default(), SensorErrors::default());
//! ```

use crate::vec3::Mat3d;

/// The error terms shared by the three sensors; `unit` is rad/s (gyroscope), m/s² (accelerometer)
/// or the scene's magnetic unit (magnetometer). Vectors and matrices are in sensor axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorErrors {
    /// Scale-factor error matrix ΔS of eq. 18 (dimensionless); the sensor applies `I + ΔS`.
    pub scale_factor: Option<Mat3d>,
    /// Misalignment matrix M of eq. 18 (dimensionless, identity when aligned), applied before
    /// the scale factor: `(I + ΔS)·M`.
    pub misalignment: Option<Mat3d>,
    /// Constant bias (ω̄, a₀ or h₀ of eq. 18), unit.
    pub bias: Option<[f64; 3]>,
    /// White-noise density, unit/√Hz; the per-sample deviation is `density·√rate`.
    pub noise_density: Option<[f64; 3]>,
    /// Bias instability (first-order Gauss–Markov).
    pub bias_instability: Option<BiasInstability>,
    /// Rate random walk coefficient K, unit/√s (Allan deviation `K·√(τ/3)`).
    pub rate_random_walk: Option<[f64; 3]>,
    /// Temperature-dependent bias.
    pub temperature_bias: Option<TemperatureBias>,
    /// Resolution: the output is rounded to a multiple of this step, unit (> 0).
    pub resolution: Option<[f64; 3]>,
    /// Range: the output is clipped to `[-range, +range]`, unit (> 0).
    pub range: Option<[f64; 3]>,
}

/// Bias instability as a first-order Gauss–Markov process (see [`crate::noise`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BiasInstability {
    /// IEEE Std 952 bias-instability coefficient B per axis, unit; the Allan floor is `0.664·B`.
    pub coefficient: [f64; 3],
    /// Correlation time of the process, s (> 0); the floor shows around τ = 1.89 × this.
    pub correlation_time_s: f64,
}

/// A bias linear in temperature: `coefficient · (T − reference_c)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TemperatureBias {
    /// Bias per degree, unit/°C.
    pub coefficient: [f64; 3],
    /// Temperature at which the term is zero, °C.
    pub reference_c: f64,
}

/// The gyroscope: eq. 18's Ω, plus g-sensitivity.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GyroConfig {
    /// The shared error terms, unit rad/s.
    pub errors: SensorErrors,
    /// g-sensitivity matrix G, (rad/s)/(m/s²): adds `G·f` (f the specific force at the sensor,
    /// in sensor axes) after scale and misalignment.
    pub g_sensitivity: Option<Mat3d>,
}

/// The accelerometer: eq. 18's A, plus the lever arm.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AccelConfig {
    /// The shared error terms, unit m/s².
    pub errors: SensorErrors,
    /// Sensor position r relative to the rotation centre, m, body axes: the sensed specific
    /// force becomes `f + ω̇×r + ω×(ω×r)`.
    pub lever_arm_m: Option<[f64; 3]>,
}

/// The magnetometer: eq. 18's H with soft and hard iron.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MagConfig {
    /// The shared error terms, unit of the scene's field.
    pub errors: SensorErrors,
    /// Soft-iron matrix B_si (identity = none).
    pub soft_iron: Option<Mat3d>,
    /// Hard-iron vector b_hi, scene unit.
    pub hard_iron: Option<[f64; 3]>,
}

/// The three sensors of the MARG unit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MargConfig {
    /// Gyroscope terms.
    pub gyro: GyroConfig,
    /// Accelerometer terms.
    pub accel: AccelConfig,
    /// Magnetometer terms.
    pub mag: MagConfig,
}

impl SensorErrors {
    /// Whether no term is configured (the sensor is ideal).
    pub fn is_ideal(&self) -> bool {
        *self == Self::default()
    }
}
