//! `[sensors.<gyro|accel|mag>]` and `[perturbation]`: the MARG error model (paper eq. 18 plus
//! the terms real parts show) and the magnetic perturbation generator (eq. 19–23).
//!
//! Every term is off unless the scene names it; a scene without `[sensors]` produces ideal
//! samples (the truth rounded to `f32`) at the cost of a copy, and one without
//! `[perturbation]` runs no generator at all. Units: gyro rad/s, accel m/s², mag the scene's
//! field unit; densities per √Hz, random walks per √s, times in s, temperatures in °C.

use super::error::Violation;
use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, MargConfig, SensorErrors, TemperatureBias,
};
use serde::Deserialize;

/// A 3×3 matrix, row by row.
pub type Matrix = [[f64; 3]; 3];

/// `[sensors]`: one table per sensor, and the temperature the sensors see.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SensorsSpec {
    /// Gyroscope (rad/s).
    pub gyro: SensorSpec,
    /// Accelerometer (m/s²).
    pub accel: SensorSpec,
    /// Magnetometer (scene field unit).
    pub mag: SensorSpec,
    /// `[start °C, slope °C/s]`: the temperature for temperature-dependent biases.
    pub temperature: Option<[f64; 2]>,
}

/// One sensor's error terms; each is off when absent.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SensorSpec {
    /// ΔS of eq. 18: scale-factor error matrix (0 = none).
    pub scale_factor: Option<Matrix>,
    /// M of eq. 18: misalignment matrix (identity = aligned).
    pub misalignment: Option<Matrix>,
    /// Constant bias.
    pub bias: Option<[f64; 3]>,
    /// White noise density (unit/√Hz): σ = density · √rate.
    pub noise_density: Option<[f64; 3]>,
    /// Bias instability: a first-order Gauss–Markov process.
    pub bias_instability: Option<BiasInstabilitySpec>,
    /// Rate random walk (unit/√s).
    pub rate_random_walk: Option<[f64; 3]>,
    /// Temperature-dependent bias: `coefficient · (T − reference)`.
    pub temperature_bias: Option<TemperatureBiasSpec>,
    /// Output resolution (quantization step).
    pub resolution: Option<[f64; 3]>,
    /// Output range: values clip at ±range.
    pub range: Option<[f64; 3]>,
    /// Gyro only: g-sensitivity matrix ((rad/s)/(m/s²)) applied to the specific force.
    pub g_sensitivity: Option<Matrix>,
    /// Accelerometer only: sensor position relative to the rotation centre (m, body axes).
    pub lever_arm: Option<[f64; 3]>,
    /// Magnetometer only: soft-iron matrix B_si of eq. 18.
    pub soft_iron: Option<Matrix>,
    /// Magnetometer only: hard-iron vector b_hi of eq. 18.
    pub hard_iron: Option<[f64; 3]>,
}

/// Bias instability parameters.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BiasInstabilitySpec {
    /// The Allan-deviation floor B (unit).
    pub coefficient: [f64; 3],
    /// Correlation time (s).
    pub correlation_time: f64,
}

/// Temperature-dependent bias parameters.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TemperatureBiasSpec {
    /// Bias per °C.
    pub coefficient: [f64; 3],
    /// Temperature of zero bias (°C).
    pub reference: f64,
}

/// How burst amplitudes are drawn.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Scaling {
    /// Peak drawn uniformly from `amplitude = [lo, hi]` (the paper's 0–4 nu).
    #[default]
    Uniform,
    /// The author's reference code: `1 + 4.5 · U(0, 1)`.
    Reference,
}

/// Where bursts act.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum PlacementSpec {
    /// Independent bursts on each axis (the reference code).
    #[default]
    PerAxis,
    /// One burst at a time along `direction` (body axes).
    Direction,
    /// One burst at a time along a random direction.
    RandomDirection,
}

/// `[perturbation]`: magnetic perturbation bursts added to the true field.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct PerturbationSpec {
    /// Burst length Δt (s).
    pub window: f64,
    /// Butterworth low-pass cutoff (Hz).
    pub cutoff: f64,
    /// How amplitudes are drawn.
    pub scaling: Scaling,
    /// Peak amplitude range (scene field unit), with `scaling = "uniform"`.
    pub amplitude: [f64; 2],
    /// Quiet time between bursts, drawn uniformly from `[lo, hi]` (s).
    pub gap: [f64; 2],
    /// Per axis, along a direction, or along a random direction.
    pub placement: PlacementSpec,
    /// The direction for `placement = "direction"`.
    pub direction: Option<[f64; 3]>,
}

impl Default for PerturbationSpec {
    fn default() -> Self {
        Self {
            window: 2.0,
            cutoff: 5.0,
            scaling: Scaling::Uniform,
            amplitude: [0.0, 4.0],
            gap: [1.0, 5.0],
            placement: PlacementSpec::PerAxis,
            direction: None,
        }
    }
}

impl SensorSpec {
    fn errors(&self) -> SensorErrors {
        SensorErrors {
            scale_factor: self.scale_factor,
            misalignment: self.misalignment,
            bias: self.bias,
            noise_density: self.noise_density,
            bias_instability: self.bias_instability.map(|b| BiasInstability {
                coefficient: b.coefficient,
                correlation_time_s: b.correlation_time,
            }),
            rate_random_walk: self.rate_random_walk,
            temperature_bias: self.temperature_bias.map(|t| TemperatureBias {
                coefficient: t.coefficient,
                reference_c: t.reference,
            }),
            resolution: self.resolution,
            range: self.range,
        }
    }

    /// The keys set that belong to another sensor, for `sensor` (`gyro`, `accel`, `mag`).
    pub(crate) fn foreign_keys(&self, sensor: &str) -> Option<&'static str> {
        let set = [
            ("g_sensitivity", self.g_sensitivity.is_some(), "gyro"),
            ("lever_arm", self.lever_arm.is_some(), "accel"),
            ("soft_iron", self.soft_iron.is_some(), "mag"),
            ("hard_iron", self.hard_iron.is_some(), "mag"),
        ];
        set.iter()
            .find(|(_, present, owner)| *present && *owner != sensor)
            .map(|(k, _, _)| *k)
    }
}

impl SensorsSpec {
    /// The model configuration.
    pub fn config(&self) -> MargConfig {
        MargConfig {
            gyro: GyroConfig {
                errors: self.gyro.errors(),
                g_sensitivity: self.gyro.g_sensitivity,
            },
            accel: AccelConfig {
                errors: self.accel.errors(),
                lever_arm_m: self.accel.lever_arm,
            },
            mag: MagConfig {
                errors: self.mag.errors(),
                soft_iron: self.mag.soft_iron,
                hard_iron: self.mag.hard_iron,
            },
        }
    }
}

impl PerturbationSpec {
    /// The model configuration (`direction` defaults to the zero vector, which the model
    /// refuses, when `placement = "direction"` names none).
    pub fn config(&self) -> PerturbationConfig {
        PerturbationConfig {
            window_s: self.window,
            cutoff_hz: self.cutoff,
            amplitude: match self.scaling {
                Scaling::Uniform => Amplitude::Uniform {
                    lo: self.amplitude[0],
                    hi: self.amplitude[1],
                },
                Scaling::Reference => Amplitude::Reference,
            },
            gap_s: self.gap,
            placement: match self.placement {
                PlacementSpec::PerAxis => Placement::PerAxis,
                PlacementSpec::Direction => {
                    Placement::Direction(self.direction.unwrap_or([0.0; 3]))
                }
                PlacementSpec::RandomDirection => Placement::RandomDirection,
            },
        }
    }
}

/// Finite sensor and perturbation values outside their plausible ranges (the model itself
/// refuses non-finite ones and those of the wrong sign, with its own messages).
pub(crate) fn check_ranges(spec: &super::SceneSpec) -> Result<(), Violation> {
    use super::ranges::{self, Plausible};
    let check = |xs: &[f64], at: &[&str], range: Plausible| -> Result<(), Violation> {
        for (i, &x) in xs.iter().enumerate() {
            if x.is_finite() {
                range.check(x, at).map_err(|v| v.index(i))?;
            }
        }
        Ok(())
    };
    let s = &spec.sensors;
    for (name, sensor) in [("gyro", &s.gyro), ("accel", &s.accel), ("mag", &s.mag)] {
        let term = ranges::SENSOR_TERM;
        let matrices = [
            ("scale_factor", &sensor.scale_factor),
            ("misalignment", &sensor.misalignment),
            ("g_sensitivity", &sensor.g_sensitivity),
            ("soft_iron", &sensor.soft_iron),
        ];
        for (key, m) in matrices {
            for (row, values) in m.iter().flatten().enumerate() {
                check(values, &["sensors", name, key], term).map_err(|v| v.index(row))?;
            }
        }
        let vectors = [
            ("bias", &sensor.bias),
            ("noise_density", &sensor.noise_density),
            ("rate_random_walk", &sensor.rate_random_walk),
            ("resolution", &sensor.resolution),
            ("range", &sensor.range),
            ("lever_arm", &sensor.lever_arm),
            ("hard_iron", &sensor.hard_iron),
        ];
        for (key, v) in vectors {
            if let Some(v) = v {
                check(v, &["sensors", name, key], term)?;
            }
        }
        if let Some(b) = &sensor.bias_instability {
            let at = ["sensors", name, "bias_instability"];
            check(&b.coefficient, &[at[0], at[1], at[2], "coefficient"], term)?;
            let time = [b.correlation_time];
            check(
                &time,
                &[at[0], at[1], at[2], "correlation_time"],
                ranges::CORRELATION_TIME,
            )
            .map_err(|mut v| {
                v.path.pop();
                v
            })?;
        }
        if let Some(t) = &sensor.temperature_bias {
            let at = ["sensors", name, "temperature_bias"];
            check(&t.coefficient, &[at[0], at[1], at[2], "coefficient"], term)?;
            check(
                &[t.reference],
                &[at[0], at[1], at[2], "reference"],
                ranges::TEMPERATURE,
            )
            .map_err(|mut v| {
                v.path.pop();
                v
            })?;
        }
    }
    if let Some(p) = &spec.perturbation {
        let scalar = |x: f64, key: &str, range: Plausible| {
            if x.is_finite() {
                range.check(x, &["perturbation", key])
            } else {
                Ok(())
            }
        };
        scalar(p.window, "window", ranges::TIME)?;
        scalar(p.cutoff, "cutoff", ranges::FREQUENCY)?;
        check(
            &p.amplitude,
            &["perturbation", "amplitude"],
            ranges::PERTURBATION_AMPLITUDE,
        )?;
        check(&p.gap, &["perturbation", "gap"], ranges::TIME)?;
        if let Some(d) = &p.direction {
            check(d, &["perturbation", "direction"], ranges::SENSOR_TERM)?;
        }
    }
    Ok(())
}

/// The TOML key path of a model parameter named `what` (e.g. `gyro.noise_density` →
/// `sensors.gyro.noise_density`, `perturbation.window_s` → `perturbation.window`).
pub(crate) fn key_path(what: &str) -> Vec<String> {
    let mut parts: Vec<String> = what
        .split('.')
        .map(|p| {
            let stripped = ["_s", "_hz", "_m", "_c"]
                .iter()
                .find_map(|suffix| p.strip_suffix(suffix));
            stripped.unwrap_or(p).to_owned()
        })
        .collect();
    match parts.first().map(String::as_str) {
        Some("gyro" | "accel" | "mag") => parts.insert(0, "sensors".into()),
        Some("perturbation") if parts.get(1).is_some_and(|p| p == "placement") => {
            parts.truncate(1);
            parts.push("direction".into());
        }
        _ => {}
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_parameter_names_map_to_scene_keys() {
        assert_eq!(
            key_path("gyro.noise_density"),
            ["sensors", "gyro", "noise_density"]
        );
        assert_eq!(
            key_path("accel.lever_arm_m"),
            ["sensors", "accel", "lever_arm"]
        );
        assert_eq!(
            key_path("perturbation.window_s"),
            ["perturbation", "window"]
        );
        assert_eq!(
            key_path("perturbation.amplitude.hi"),
            ["perturbation", "amplitude", "hi"]
        );
        assert_eq!(
            key_path("perturbation.placement.direction"),
            ["perturbation", "direction"]
        );
    }
}
