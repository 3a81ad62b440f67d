//! The scene file's types, with the paper's Table 1 and Table 2 as defaults.
//!
//! Units are SI (m, s, rad, kg, N, N·m) except where a key's name says otherwise; arrays of six
//! follow the joint order `x, y, z, roll, pitch, yaw` (the paper's `q = (x_b, y_b, z_b, φ, θ, ψ)`).

use super::sensors::{PerturbationSpec, SensorsSpec};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Names of the six joints, in the order of the generalized coordinates.
pub const JOINT_NAMES: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];

/// The whole scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    /// Optional human name of the scene.
    #[serde(default)]
    pub name: Option<String>,
    /// Optional description.
    #[serde(default)]
    pub description: Option<String>,
    /// Run length (s); a whole number of integrator steps.
    pub duration: f64,
    /// Output sample rate (Hz).
    pub rate: f64,
    /// Seed of every random stream of the run.
    pub seed: u64,
    /// How the plate moves.
    #[serde(default)]
    pub motion: MotionMode,
    /// Integrator of the bench dynamics.
    #[serde(default)]
    pub integrator: IntegratorSpec,
    /// Reference magnetic field.
    #[serde(default)]
    pub field: FieldSpec,
    /// Bench parameters (Table 1).
    #[serde(default)]
    pub bench: BenchSpec,
    /// Control requirements (Table 2) and the PID design.
    #[serde(default)]
    pub control: ControlSpec,
    /// Reference source per joint, keyed by joint name; absent joints hold their initial value.
    #[serde(default)]
    pub joints: BTreeMap<String, SourceSpec>,
    /// Sensor error terms (each off unless named).
    #[serde(default)]
    pub sensors: SensorsSpec,
    /// Magnetic perturbation bursts; none when the table is absent.
    #[serde(default)]
    pub perturbation: Option<PerturbationSpec>,
    /// The emulated chip; the MPU-9250 at power-on when the table is absent.
    #[serde(default)]
    pub chip: Option<super::chip::ChipSpec>,
    /// The devices of a rig (`[[device]]`), instead of `[chip]`.
    #[serde(default)]
    pub device: Vec<super::chip::ChipSpec>,
    /// Vibration: motor tones, random vibration, shocks (`[vibration]`); none when absent.
    #[serde(default)]
    pub vibration: super::vibration::VibrationSpec,
    /// The fault schedule (`[[fault]]`, [`super::fault`]); none when absent.
    #[serde(default)]
    pub fault: Vec<super::fault::FaultSpec>,
}

/// How the plate's motion is produced; a scene pays only for the mode it names.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum MotionMode {
    /// Closed-loop bench: Lagrange dynamics, friction and PID joints track the references.
    #[default]
    Bench,
    /// The joint sources prescribe the plate's motion directly: no dynamics, no PID.
    Kinematic,
    /// The plate rests at `bench.initial`: nothing is integrated.
    Static,
}

impl MotionMode {
    /// The mode's name in a scene file (`motion = "…"`).
    pub fn name(self) -> &'static str {
        match self {
            MotionMode::Bench => "bench",
            MotionMode::Kinematic => "kinematic",
            MotionMode::Static => "static",
        }
    }
}

/// Integration method of the bench dynamics.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Classical fourth-order Runge–Kutta.
    #[default]
    Rk4,
    /// Semi-implicit (symplectic) Euler: velocity first, then position with the new velocity.
    SemiImplicitEuler,
}

/// `[integrator]`: method and internal step, independent of the output rate.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IntegratorSpec {
    /// Method.
    pub method: Method,
    /// Largest internal step (s); steps also land exactly on every output instant.
    pub step: f64,
}

impl Default for IntegratorSpec {
    fn default() -> Self {
        Self {
            method: Method::Rk4,
            step: 0.001,
        }
    }
}

/// Unit of the magnetic field.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
pub enum FieldUnit {
    /// Normalized units (the author's Simulink model: about unit norm).
    #[default]
    #[serde(rename = "nu")]
    Normalized,
    /// Microtesla.
    #[serde(rename = "uT")]
    Microtesla,
}

impl FieldUnit {
    /// The unit's symbol in files and reports.
    pub fn symbol(self) -> &'static str {
        match self {
            FieldUnit::Normalized => "nu",
            FieldUnit::Microtesla => "uT",
        }
    }
}

/// `[field]`: the reference magnetic field in the world frame.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FieldSpec {
    /// World-frame field vector (x, y, z up), in `unit`.
    pub reference: [f64; 3],
    /// Unit of `reference` and of every magnetometer column.
    pub unit: FieldUnit,
}

impl Default for FieldSpec {
    fn default() -> Self {
        Self {
            reference: [0.5, 0.0, -0.83],
            unit: FieldUnit::Normalized,
        }
    }
}

/// `[bench]`: Table 1 of the paper, plus effort limits and the initial pose.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BenchSpec {
    /// Masses of links 1–3 (kg).
    pub link_mass: [f64; 3],
    /// Mass of the body plate (kg).
    pub plate_mass: f64,
    /// Plate moments of inertia about roll, pitch, yaw (kg·m²).
    pub plate_inertia: [f64; 3],
    /// Viscous friction per joint (N·s/m for 1–3, N·m·s/rad for 4–6).
    pub viscous_friction: [f64; 6],
    /// Static friction threshold per joint (N for 1–3, N·m for 4–6); 0 disables stiction.
    pub static_friction: [f64; 6],
    /// Largest actuator effort per joint (N or N·m); absent means unlimited.
    pub effort_limit: Option<[f64; 6]>,
    /// Joint coordinates at t = 0 (m, rad); also the pose of a static scene.
    pub initial: [f64; 6],
    /// Gravitational acceleration (m/s²).
    pub gravity: f64,
}

impl Default for BenchSpec {
    fn default() -> Self {
        Self {
            link_mass: [500.0, 500.0, 200.0],
            plate_mass: 0.2,
            plate_inertia: [60e-6, 60e-6, 40e-6],
            viscous_friction: [100.0, 100.0, 100.0, 0.001, 0.001, 0.001],
            static_friction: [0.0; 6],
            effort_limit: None,
            initial: [0.0; 6],
            gravity: 9.80665,
        }
    }
}

/// `[control]`: Table 2 requirements and how the PID gains are derived from them.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlSpec {
    /// Largest step-response overshoot per joint (fraction: 0.2 = 20 %).
    pub overshoot: [f64; 6],
    /// 2 % settling time per joint (s).
    pub settling_time: [f64; 6],
    /// Ratio of the extra real pole to the dominant real part: `T = 1 / (pole_ratio · ζ · ωn)`.
    pub pole_ratio: f64,
    /// Retune ζ and ωn on the real closed loop (eq. 14 has a zero that eq. 16 omits).
    pub retune: bool,
    /// Fraction of each requirement the retuned design aims for (head-room).
    pub retune_margin: f64,
    /// Explicit `[kp, ki, kd]` per joint, replacing the synthesis.
    pub gains: Option<[[f64; 3]; 6]>,
    /// Table 2's external acceleration to be reached by joints 1–3 (g), reported by `scene check`.
    pub external_acceleration: f64,
    /// Table 2's oscillation rate to be reached by joints 4–6 (rad/s), reported by `scene check`.
    pub oscillation_rate: f64,
}

impl Default for ControlSpec {
    fn default() -> Self {
        Self {
            overshoot: [0.2, 0.2, 0.2, 0.4, 0.4, 0.4],
            settling_time: [1.0, 1.0, 1.0, 0.3, 0.3, 0.3],
            pole_ratio: 10.0,
            retune: true,
            retune_margin: 0.9,
            gains: None,
            external_acceleration: 30.0,
            oscillation_rate: 40.0,
        }
    }
}

/// Optional second-order smoothing of a joint's setpoint.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SmoothingSpec {
    /// Natural frequency (rad/s).
    pub natural_frequency: f64,
    /// Damping ratio.
    pub damping: f64,
}

/// `[joints.<name>]`: where a joint's reference comes from.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SourceSpec {
    /// A constant value.
    Constant {
        /// The value (m or rad).
        value: f64,
    },
    /// Stair steps: `[time s, value]` pairs; each value holds from its time on.
    Steps {
        /// `[time, value]` pairs, times increasing; before the first, the joint's initial value.
        points: Vec<[f64; 2]>,
        /// Optional setpoint smoothing.
        #[serde(default)]
        smoothing: Option<SmoothingSpec>,
    },
    /// Waypoints: `[value, hold s]` pairs taken in turn from t = 0.
    Waypoints {
        /// `[value, hold]` pairs.
        points: Vec<[f64; 2]>,
        /// Start again from the first waypoint after the last.
        #[serde(default)]
        repeat: bool,
        /// Optional setpoint smoothing.
        #[serde(default)]
        smoothing: Option<SmoothingSpec>,
    },
    /// `offset + amplitude · sin(2π · frequency · t + phase)`.
    Sine {
        /// Amplitude (m or rad).
        amplitude: f64,
        /// Frequency (Hz).
        frequency: f64,
        /// Phase (rad).
        #[serde(default)]
        phase: f64,
        /// Offset (m or rad).
        #[serde(default)]
        offset: f64,
    },
    /// `Σ cᵢ tⁱ`: constant, ramp (constant rate), parabola…
    Polynomial {
        /// Coefficients from the constant term up.
        coefficients: Vec<f64>,
    },
    /// Section 3.2, prismatic joints: random setpoints held for random times.
    RandomSetpoints {
        /// Setpoints are drawn uniformly from `[lo, hi]`.
        range: [f64; 2],
        /// Each setpoint holds for a time drawn uniformly from `[lo, hi]` (s).
        hold: [f64; 2],
        /// Optional setpoint smoothing.
        #[serde(default)]
        smoothing: Option<SmoothingSpec>,
    },
    /// Section 3.2, revolute joints: sinusoid segments of random amplitude and frequency.
    RandomSine {
        /// Amplitude drawn uniformly from `[lo, hi]` per segment (m or rad).
        amplitude: [f64; 2],
        /// Frequency drawn uniformly from `[lo, hi]` per segment (Hz).
        frequency: [f64; 2],
        /// Segment length drawn uniformly from `[lo, hi]` (s), rounded to whole half periods
        /// so the signal stays continuous.
        segment: [f64; 2],
        /// Offset (m or rad).
        #[serde(default)]
        offset: f64,
    },
    /// Setpoints from a CSV file: a header row, a time column `t` (s) and a value column.
    Csv {
        /// Path, relative to the scene file.
        file: PathBuf,
        /// Name of the value column.
        column: String,
        /// Optional setpoint smoothing (bench mode).
        #[serde(default)]
        smoothing: Option<SmoothingSpec>,
    },
}

impl SourceSpec {
    /// The smoothing this source asks for, if any.
    pub fn smoothing(&self) -> Option<SmoothingSpec> {
        match self {
            SourceSpec::Steps { smoothing, .. }
            | SourceSpec::Waypoints { smoothing, .. }
            | SourceSpec::RandomSetpoints { smoothing, .. }
            | SourceSpec::Csv { smoothing, .. } => *smoothing,
            _ => None,
        }
    }

    /// Whether the source is smooth enough (twice differentiable) to prescribe motion directly.
    pub fn is_kinematic(&self) -> bool {
        matches!(
            self,
            SourceSpec::Constant { .. }
                | SourceSpec::Sine { .. }
                | SourceSpec::Polynomial { .. }
                | SourceSpec::RandomSine { .. }
                | SourceSpec::Csv { .. }
        )
    }

    /// The `type` name in scene files.
    pub fn type_name(&self) -> &'static str {
        match self {
            SourceSpec::Constant { .. } => "constant",
            SourceSpec::Steps { .. } => "steps",
            SourceSpec::Waypoints { .. } => "waypoints",
            SourceSpec::Sine { .. } => "sine",
            SourceSpec::Polynomial { .. } => "polynomial",
            SourceSpec::RandomSetpoints { .. } => "random-setpoints",
            SourceSpec::RandomSine { .. } => "random-sine",
            SourceSpec::Csv { .. } => "csv",
        }
    }
}
