//! The device's budget in source mode (b): what one output sample costs a Cortex-M4F, per chip,
//! sensor-model term and chain feature, and the fastest output rate a board sustains with it.
//! The one home of these figures: the host refuses a mode (b) scene beyond a real board's
//! budget with them, and `docs/figures.md` ("Source mode (b) on the Cortex-M4F") lists the
//! measurements they come from.
//!
//! **Where the figures come from.** [`model_bench`](crate::model_bench) on QEMU's
//! `mps2-an386` (instructions, QEMU `-icount shift=0`, TIMER0): every case's instructions per
//! output sample of the whole serving path (the kinematics index and hold, the model, the chain,
//! the register image and its latch into the chip, plus the bench's hash of the image, about
//! 100 instructions). The cost model ([`instructions_per_sample`]) is
//!
//! - the chip's serving cost with an ideal model on the output path ([`serve_base`]);
//! - [`COST_EQ18`] if any of eq. 18's terms is set (ΔS, M, bias, white noise, soft or hard iron),
//!   [`COST_OTHER_TERMS`] if any other term is (bias instability, rate random walk, temperature
//!   bias, resolution, range, g-sensitivity, lever arm), [`COST_PERTURBATION`] with a magnetic
//!   perturbation (its FFT-based burst shaping averaged over the bursts' windows);
//! - per sensor on the chip's internal path, its internal samples per output sample ×
//!   [`COST_INTERNAL_STEP`] + [`COST_INTERNAL_SENSOR`];
//! - per sensor, per vibration source (tone: source × motor × harmonic; shock) that moves it
//!   and per step: [`COST_TONE_OUTPUT`] on the output path, [`COST_TONE_INTERNAL`] per internal
//!   sample.
//!
//! It matches every measured case within a few per cent, above rather than below (the tests
//! below hold it to the table). QEMU counts instructions, not cycles: a board's budget assumes
//! [`CYCLES_PER_INSTRUCTION`] and leaves half the core to the link, the buses and the
//! interrupts ([`BUDGET_SHARE`]).
//!
//! ```
//! use margemu_firmware::budget::{self, Load, SensorLoad, BLACKPILL_F411};
//! use margemu_model::sensor::MargConfig;
//! use margemu_protocol::chip::ChipModel;
//! let mut marg = MargConfig::default();
//! marg.gyro.errors.noise_density = Some([1e-4; 3]);
//! let load = Load::output_path(ChipModel::Icm42688p, &marg, false);
//! let per_sample = budget::instructions_per_sample(&load, 1000.0);
//! assert!(per_sample > 6000.0 && per_sample < 7000.0);
//! let max = BLACKPILL_F411.max_rate_hz(&load);
//! assert!(max > 5000.0 && max < 7000.0); // 96 MHz, 1.25 cycles an instruction, half the core
//! ```

use margemu_model::sensor::{MargConfig, SensorErrors};
use margemu_model::vibration::Sense;
use margemu_protocol::chip::ChipModel;

use crate::link::setup::{ChainSetup, ModelFront};

/// Cycles per instruction assumed on average (the M4's single-cycle ALU and FPU operations,
/// 2-cycle loads, 3-cycle branches, flash wait states hidden by the STM32F4's ART accelerator).
pub const CYCLES_PER_INSTRUCTION: f64 = 1.25;
/// The share of the core mode (b)'s sample path may take; the rest is the link, the buses, the
/// interrupts and the slack a real-time loop needs.
pub const BUDGET_SHARE: f64 = 0.5;

/// Eq. 18's terms (any of them), per output sample (measured: 1 007–1 009 on every chip).
pub const COST_EQ18: f64 = 1010.0;
/// Every other term of the model (any of them), per output sample (measured: 2 097–2 100).
pub const COST_OTHER_TERMS: f64 = 2100.0;
/// The magnetic perturbation per axis, per output sample: three burst shapings (FFTs in
/// software `f64`) per 2 s window, averaged (measured: 45 900 at 1 kHz to 54 900 at 8 kHz).
/// A burst's shaping runs at its first sample: a spike of about 3·10⁸ instructions per axis
/// at 8 kHz.
pub const COST_PERTURBATION: f64 = 55_000.0;
/// Per sensor and internal sample on the chip's internal path (its filters and clipping).
pub const COST_INTERNAL_STEP: f64 = 560.0;
/// Per sensor on the internal path, per output sample (its bookkeeping).
pub const COST_INTERNAL_SENSOR: f64 = 50.0;
/// Per vibration source moving a sensor, per output sample on the output path.
pub const COST_TONE_OUTPUT: f64 = 190.0;
/// Per vibration source moving a sensor, per internal sample on the internal path.
pub const COST_TONE_INTERNAL: f64 = 140.0;

/// The serving cost of `chip` per output sample, ideal model, output path: the kinematics index
/// of the instant and its hold, the model's ideal step and clipping, the chip's image and its
/// latch (measured; chips without a measurement take the dearest measured, the MPU-9250's).
pub fn serve_base(chip: ChipModel) -> f64 {
    match chip {
        ChipModel::Icm20602 => 5420.0,
        ChipModel::Icm42688p => 5380.0,
        ChipModel::Bmi270 => 4720.0,
        ChipModel::Bmi088 => 5100.0,
        _ => 6510.0,
    }
}

/// What one sensor's chain runs per output sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorLoad {
    /// Its internal sample period, ns, on the internal path; `None` on the output path.
    pub internal_period_ns: Option<u64>,
    /// Vibration sources that move it: tones (source × motor × harmonic) and shocks.
    pub sources: usize,
}

/// What a device runs per output sample in source mode (b).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Load {
    /// The chip served.
    pub chip: ChipModel,
    /// Whether any of eq. 18's terms is set.
    pub eq18: bool,
    /// Whether any other term is set.
    pub other_terms: bool,
    /// Whether a magnetic perturbation is.
    pub perturbation: bool,
    /// The accelerometer's chain.
    pub accel: SensorLoad,
    /// The gyroscope's chain.
    pub gyro: SensorLoad,
}

impl Load {
    /// `chip` with the terms of `marg` (and a perturbation if `perturbation`) on the quiet
    /// output path; set [`Load::accel`] and [`Load::gyro`] for another chain.
    pub fn output_path(chip: ChipModel, marg: &MargConfig, perturbation: bool) -> Self {
        let eq18 = |e: &SensorErrors| {
            e.scale_factor.is_some()
                || e.misalignment.is_some()
                || e.bias.is_some()
                || e.noise_density.is_some()
        };
        let other = |e: &SensorErrors| {
            e.bias_instability.is_some()
                || e.rate_random_walk.is_some()
                || e.temperature_bias.is_some()
                || e.resolution.is_some()
                || e.range.is_some()
        };
        let sensors = [&marg.gyro.errors, &marg.accel.errors, &marg.mag.errors];
        Self {
            chip,
            eq18: sensors.iter().any(|e| eq18(e))
                || marg.mag.soft_iron.is_some()
                || marg.mag.hard_iron.is_some(),
            other_terms: sensors.iter().any(|e| other(e))
                || marg.gyro.g_sensitivity.is_some()
                || marg.accel.lever_arm_m.is_some(),
            perturbation,
            accel: SensorLoad::default(),
            gyro: SensorLoad::default(),
        }
    }
}

impl Load {
    /// With the chain a device built from `setup` ([`model_chain`](crate::link::setup::model_chain); `front` is `None` for
    /// a chip without accelerometer and gyroscope): each sensor's internal period and the
    /// vibration sources that move it.
    pub fn with_chain(mut self, setup: &ChainSetup, front: Option<&ModelFront>) -> Self {
        let [accel_ns, gyro_ns] = front.map_or([0, 0], internal_periods_ns);
        let sensor = |sense: Sense, period_ns: u64| SensorLoad {
            internal_period_ns: (period_ns != 0).then_some(period_ns),
            sources: setup.sources_moving(sense),
        };
        self.accel = sensor(Sense::Linear, accel_ns);
        self.gyro = sensor(Sense::Angular, gyro_ns);
        self
    }
}

/// The internal periods (accelerometer, gyroscope) of a device's front end, 0 on the output path.
#[cfg(feature = "model-vibration")]
fn internal_periods_ns(front: &ModelFront) -> [u64; 2] {
    match front {
        margemu_model::chain::Front::Clip(_) => [0, 0],
        margemu_model::chain::Front::Chain(c) => [c.accel.period_ns(), c.gyro.period_ns()],
    }
}

/// Without the `model-vibration` feature the front end is the clipper: the output path.
#[cfg(not(feature = "model-vibration"))]
fn internal_periods_ns(_: &ModelFront) -> [u64; 2] {
    [0, 0]
}

/// Instructions per output sample of `load` at `rate_hz` (the module's cost model).
pub fn instructions_per_sample(load: &Load, rate_hz: f64) -> f64 {
    let out_ns = 1e9 / rate_hz;
    let sensor = |s: &SensorLoad| match s.internal_period_ns {
        None => s.sources as f64 * COST_TONE_OUTPUT,
        Some(period) => {
            let steps = out_ns / period.max(1) as f64;
            let per_step = COST_INTERNAL_STEP + s.sources as f64 * COST_TONE_INTERNAL;
            COST_INTERNAL_SENSOR + steps * per_step
        }
    };
    let term = |on: bool, cost: f64| if on { cost } else { 0.0 };
    serve_base(load.chip)
        + term(load.eq18, COST_EQ18)
        + term(load.other_terms, COST_OTHER_TERMS)
        + term(load.perturbation, COST_PERTURBATION)
        + sensor(&load.accel)
        + sensor(&load.gyro)
}

/// A board that runs source mode (b): its name and core clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Board {
    /// Its name, as `--board` and the docs write it.
    pub name: &'static str,
    /// Its core clock, Hz.
    pub core_hz: f64,
}

/// The device ID the QEMU board reports in HelloAck (zero-padded; QEMU's MPS2 has no unique ID):
/// the host does not budget it (it is not real time on a fixed clock).
pub const QEMU_DEVICE_ID: &[u8] = b"qemu-mps2-an386";

/// The WeAct Black Pill (STM32F411CEU6, Cortex-M4F) at 96 MHz (`docs/boards/blackpill-f411.md`).
pub const BLACKPILL_F411: Board = Board {
    name: "blackpill-f411",
    core_hz: 96e6,
};

impl Board {
    /// Instructions per second mode (b) may spend: the core's, at
    /// [`CYCLES_PER_INSTRUCTION`], times [`BUDGET_SHARE`].
    pub fn budget_instructions_per_s(&self) -> f64 {
        self.core_hz / CYCLES_PER_INSTRUCTION * BUDGET_SHARE
    }

    /// The share of the whole core `load` takes at `rate_hz` (1.0: all of it).
    pub fn core_share(&self, load: &Load, rate_hz: f64) -> f64 {
        instructions_per_sample(load, rate_hz) * rate_hz * CYCLES_PER_INSTRUCTION / self.core_hz
    }

    /// Whether `load` at `rate_hz` fits the budget.
    pub fn fits(&self, load: &Load, rate_hz: f64) -> bool {
        instructions_per_sample(load, rate_hz) * rate_hz <= self.budget_instructions_per_s()
    }

    /// The fastest output rate at which `load` fits the budget, Hz: the cost per second is
    /// `rate × (per-sample part) + (internal-path part, fixed per second)`; 0 if even the fixed
    /// part does not fit.
    pub fn max_rate_hz(&self, load: &Load) -> f64 {
        // Cost per second is affine in the rate: sample it at two rates.
        let per_s = |hz: f64| instructions_per_sample(load, hz) * hz;
        let (a, b) = (per_s(1000.0), per_s(2000.0));
        let slope = (b - a) / 1000.0;
        let fixed = a - 1000.0 * slope;
        ((self.budget_instructions_per_s() - fixed) / slope).max(0.0)
    }
}

#[cfg(test)]
mod tests;
