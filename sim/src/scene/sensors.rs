//! `[sensors.<gyro|accel|mag>]` and `[perturbation]`: the MARG error model (paper eq. 18 plus
//! the terms real parts show) and the magnetic perturbation generator (eq. 19–23).
//!
//! The sensor terms are the model's own types ([`SensorTable`], one per `[sensors.*]` table,
//! read by the model's `serde` feature); this module adds the temperature, the plausible ranges
//! and the TOML key of each model parameter. Every term is off unless the scene names it; a
//! scene without `[sensors]` produces ideal samples (the truth rounded to `f32`) at the cost of
//! a copy, and one without `[perturbation]` runs no generator at all. Units: gyro rad/s, accel m/s², mag the scene's
//! field unit; densities per √Hz, random walks per √s, times in s, temperatures in °C.

use super::error::Violation;
use margemu_model::perturbation::{Amplitude, PerturbationConfig, Placement};
use margemu_model::sensor::{MargConfig, SensorTable};
use serde::Deserialize;

/// `[sensors]`: one table per sensor, and the temperature the sensors see.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SensorsSpec {
    /// Gyroscope (rad/s).
    pub gyro: SensorTable,
    /// Accelerometer (m/s²).
    pub accel: SensorTable,
    /// Magnetometer (scene field unit).
    pub mag: SensorTable,
    /// `[start °C, slope °C/s]`: the temperature for temperature-dependent biases.
    pub temperature: Option<[f64; 2]>,
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
    /// The model's defaults ([`PerturbationConfig::default`], the paper's setting), spelled as
    /// the scene spells them.
    fn default() -> Self {
        Self::from(&PerturbationConfig::default())
    }
}

impl From<&PerturbationConfig> for PerturbationSpec {
    /// The scene table that [`PerturbationSpec::config`] turns back into `config`.
    fn from(config: &PerturbationConfig) -> Self {
        let (scaling, amplitude) = match config.amplitude {
            Amplitude::Uniform { lo, hi } => (Scaling::Uniform, [lo, hi]),
            Amplitude::Reference => (Scaling::Reference, [0.0, 4.0]),
        };
        let (placement, direction) = match config.placement {
            Placement::PerAxis => (PlacementSpec::PerAxis, None),
            Placement::Direction(d) => (PlacementSpec::Direction, Some(d)),
            Placement::RandomDirection => (PlacementSpec::RandomDirection, None),
        };
        Self {
            window: config.window_s,
            cutoff: config.cutoff_hz,
            scaling,
            amplitude,
            gap: config.gap_s,
            placement,
            direction,
        }
    }
}

impl SensorsSpec {
    /// The model configuration (terms in the table of another sensor, which validation
    /// refuses, are left out).
    pub fn config(&self) -> MargConfig {
        MargConfig::from_tables(&self.gyro, &self.accel, &self.mag)
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
            ("scale_factor", &sensor.errors.scale_factor),
            ("misalignment", &sensor.errors.misalignment),
            ("g_sensitivity", &sensor.g_sensitivity),
            ("soft_iron", &sensor.soft_iron),
        ];
        for (key, m) in matrices {
            for (row, values) in m.iter().flatten().enumerate() {
                check(values, &["sensors", name, key], term).map_err(|v| v.index(row))?;
            }
        }
        let vectors = [
            ("bias", &sensor.errors.bias),
            ("noise_density", &sensor.errors.noise_density),
            ("rate_random_walk", &sensor.errors.rate_random_walk),
            ("resolution", &sensor.errors.resolution),
            ("range", &sensor.errors.range),
            ("lever_arm", &sensor.lever_arm_m),
            ("hard_iron", &sensor.hard_iron),
        ];
        for (key, v) in vectors {
            if let Some(v) = v {
                check(v, &["sensors", name, key], term)?;
            }
        }
        if let Some(b) = &sensor.errors.bias_instability {
            let at = ["sensors", name, "bias_instability"];
            check(&b.coefficient, &[at[0], at[1], at[2], "coefficient"], term)?;
            let time = [b.correlation_time_s];
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
        if let Some(t) = &sensor.errors.temperature_bias {
            let at = ["sensors", name, "temperature_bias"];
            check(&t.coefficient, &[at[0], at[1], at[2], "coefficient"], term)?;
            check(
                &[t.reference_c],
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
    fn perturbation_table_round_trips_the_model_configuration() {
        assert_eq!(
            PerturbationSpec::default().config(),
            PerturbationConfig::default()
        );
        for placement in [
            Placement::Direction([0.0, 0.6, 0.8]),
            Placement::RandomDirection,
        ] {
            let config = PerturbationConfig {
                window_s: 1.5,
                cutoff_hz: 3.0,
                amplitude: Amplitude::Reference,
                gap_s: [0.5, 2.0],
                placement,
            };
            assert_eq!(PerturbationSpec::from(&config).config(), config);
        }
    }

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
