//! The cases' sensor-model terms and chains.
//!
//! The terms ([`Terms`]) follow the paper's eq. 18 with ICM-42688-P-like magnitudes; the chains
//! ([`Chain`]) are those source mode (b) can run (no random vibration: its FFT buffers do not
//! fit a no-alloc device), sent as the host sends them (AddVibration: the path, the tone
//! source, the shock) with the chain bench's motor tones and shock.

use core::fmt;

use margemu_model::perturbation::{PerturbationConfig, Placement};
use margemu_model::sensor::{BiasInstability, MargConfig, SensorErrors, TemperatureBias};
use margemu_model::vec3::Mat3d;
use margemu_model::vibration::{Harmonic, RpmPoint, Shock, ToneSource};
use margemu_protocol::chip::ChainConfig;
use margemu_protocol::link::{AddVibration, Rate, RpmProfile};

use margemu_protocol::chip::ChipModel;

use super::DURATION_NS;
use crate::chain_bench::Family;

/// The chips the cases serve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The ICM-20602 at 8 kHz.
    Icm20602,
    /// The ICM-42688-P at 8 kHz.
    Icm42688p,
    /// The BMI270 at 3.2 kHz.
    Bmi270,
    /// The BMI088 at 2 kHz.
    Bmi088,
    /// The MPU-9250 (with its AK8963 magnetometer in the image) at 1 kHz.
    Mpu9250,
}

impl Part {
    /// Every chip, in [`super::CASES`] order.
    pub const ALL: [Self; 5] = [
        Self::Icm20602,
        Self::Icm42688p,
        Self::Bmi270,
        Self::Bmi088,
        Self::Mpu9250,
    ];

    /// The chain bench's family of the same chip and rate, if it has one.
    pub fn family(self) -> Option<Family> {
        match self {
            Self::Icm20602 => Some(Family::Icm20602),
            Self::Icm42688p => Some(Family::Icm42688p),
            Self::Bmi270 => Some(Family::Bmi270),
            Self::Bmi088 => Some(Family::Bmi088),
            Self::Mpu9250 => None,
        }
    }

    /// The chip model.
    pub fn model(self) -> ChipModel {
        self.family().map_or(ChipModel::Mpu9250, Family::model)
    }

    /// The output (data-ready) period, ns.
    pub fn output_period_ns(self) -> u64 {
        self.family().map_or(1_000_000, Family::output_period_ns)
    }

    /// The output rate, Hz.
    pub fn output_rate_hz(self) -> f64 {
        1e9 / self.output_period_ns() as f64
    }
}

impl fmt::Display for Part {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.family() {
            Some(family) => family.fmt(f),
            None => f.write_str("mpu9250"),
        }
    }
}

/// The sensor model's terms a case configures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Terms {
    /// No term: the truth, clipped at the chip's full scale.
    Ideal,
    /// The paper's eq. 18: scale factor ΔS, misalignment M, bias, white noise on the three
    /// sensors, soft and hard iron on the magnetometer.
    Eq18,
    /// Eq. 18 and the magnetic perturbation per axis (eq. 19–23, the paper's model), bursts
    /// back to back (no quiet gap: a burst shaped every 2 s window, the most it costs).
    Eq18Perturbation,
    /// Every term of the model: eq. 18, bias instability, rate random walk, temperature bias,
    /// resolution, range, g-sensitivity and the lever arm (no perturbation).
    Every,
}

impl Terms {
    /// Every configuration, in [`super::CASES`] order.
    pub const ALL: [Self; 4] = [Self::Ideal, Self::Eq18, Self::Eq18Perturbation, Self::Every];

    /// The terms as the link carries them.
    pub fn marg(self) -> MargConfig {
        match self {
            Self::Ideal => MargConfig::default(),
            Self::Eq18 | Self::Eq18Perturbation => eq18(),
            Self::Every => every(),
        }
    }

    /// The perturbation, if the case has one.
    pub fn perturbation(self) -> Option<PerturbationConfig> {
        (self == Self::Eq18Perturbation).then_some(PerturbationConfig {
            gap_s: [0.0, 0.0],
            placement: Placement::PerAxis,
            ..PerturbationConfig::default()
        })
    }
}

impl fmt::Display for Terms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Ideal => "ideal",
            Self::Eq18 => "eq18",
            Self::Eq18Perturbation => "eq18+perturbation",
            Self::Every => "every-term",
        })
    }
}

/// The chain a case runs behind the model (what the host's AddVibration messages build).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chain {
    /// The output path, nothing vibrating: the clipping front end alone.
    Output,
    /// The output path with the motor tones (4 motors × 2 harmonics, both sensors).
    OutputTones,
    /// The chip's internal path with its declared filters, nothing vibrating.
    Internal,
    /// The internal path with the motor tones and a shock.
    InternalTonesShock,
}

impl Chain {
    /// Every chain.
    pub const ALL: [Self; 4] = [
        Self::Output,
        Self::OutputTones,
        Self::Internal,
        Self::InternalTonesShock,
    ];

    /// The AddVibration messages that build it for `family` at its rate (none for
    /// [`Chain::Output`]), in the host's order: the path, the tone source, the shock.
    pub fn messages(self, family: Part, rate: Rate) -> heapless::Vec<AddVibration, 3> {
        let mut out = heapless::Vec::new();
        let internal = matches!(self, Self::Internal | Self::InternalTonesShock);
        let tones = matches!(self, Self::OutputTones | Self::InternalTonesShock);
        if internal {
            let config = ChainConfig::default_for(family.model(), rate);
            let _ = out.push(AddVibration::Path(config));
        }
        if tones {
            let _ = out.push(AddVibration::Tones(tones_source()));
        }
        if self == Self::InternalTonesShock {
            let _ = out.push(AddVibration::Shock(SHOCK));
        }
        out
    }
}

impl fmt::Display for Chain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Output => "output",
            Self::OutputTones => "output+tones",
            Self::Internal => "internal",
            Self::InternalTonesShock => "internal+tones+shock",
        })
    }
}

/// Four motors within ±3 % of a ramp from 6000 to 24 000 rpm over the case, the rotation and
/// the blade pass (the chain bench's tones).
fn tones_source() -> ToneSource<RpmProfile> {
    let mut profile = RpmProfile::new();
    for (t_ns, rpm) in [(0, 6000.0), (DURATION_NS, 24_000.0)] {
        let _ = profile.push(RpmPoint { t_ns, rpm });
    }
    let mut tones = ToneSource::new(4, profile);
    tones.spread = 0.03;
    let harmonics = [
        (1.0, [6.0, 4.0, 10.0], [0.4, 0.4, 0.2]),
        (2.0, [3.0, 3.0, 6.0], [0.2, 0.2, 0.1]),
    ];
    for (order, linear, angular) in harmonics {
        let _ = tones.push(Harmonic {
            order,
            linear,
            angular,
        });
    }
    tones
}

/// A 2 ms half-sine at a quarter of the case (the chain bench's shock).
const SHOCK: Shock = Shock {
    t_ns: DURATION_NS / 4,
    duration_ns: 2_000_000,
    linear: [20.0, 0.0, 300.0],
    angular: [40.0, 0.0, 5.0],
};

/// A small scale-factor error and misalignment.
const SCALE: Mat3d = [[0.01, 0.0, 0.0], [0.0, -0.02, 0.0], [0.0, 0.0, 0.015]];
const MISALIGNMENT: Mat3d = [
    [1.0, 0.002, -0.001],
    [-0.002, 1.0, 0.003],
    [0.001, -0.003, 1.0],
];

fn eq18_errors(bias: f64, noise: f64) -> SensorErrors {
    SensorErrors {
        scale_factor: Some(SCALE),
        misalignment: Some(MISALIGNMENT),
        bias: Some([bias, -bias, 0.5 * bias]),
        noise_density: Some([noise; 3]),
        ..SensorErrors::default()
    }
}

/// The paper's eq. 18 terms.
fn eq18() -> MargConfig {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors = eq18_errors(0.01, 4.9e-5);
    cfg.accel.errors = eq18_errors(0.05, 6.9e-4);
    cfg.mag.errors = eq18_errors(0.02, 0.0022);
    cfg.mag.soft_iron = Some([[1.05, 0.02, 0.0], [0.02, 0.97, 0.01], [0.0, 0.01, 1.0]]);
    cfg.mag.hard_iron = Some([0.1, -0.05, 0.2]);
    cfg
}

/// Eq. 18 and every other term.
fn every() -> MargConfig {
    let mut cfg = eq18();
    let extra = |e: &mut SensorErrors, unit: f64| {
        e.bias_instability = Some(BiasInstability {
            coefficient: [unit; 3],
            correlation_time_s: 100.0,
        });
        e.rate_random_walk = Some([0.1 * unit; 3]);
        e.temperature_bias = Some(TemperatureBias {
            coefficient: [0.1 * unit; 3],
            reference_c: 25.0,
        });
        e.resolution = Some([0.01 * unit; 3]);
        e.range = Some([1e6 * unit; 3]);
    };
    extra(&mut cfg.gyro.errors, 1e-4);
    extra(&mut cfg.accel.errors, 1e-3);
    extra(&mut cfg.mag.errors, 1e-3);
    cfg.gyro.g_sensitivity = Some([[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 1e-4]]);
    cfg.accel.lever_arm_m = Some([0.01, -0.02, 0.005]);
    cfg
}
