//! The per-sample cost of source mode (b) on the device, per sensor-model configuration: a
//! fixed set of cases the host and the Cortex-M4F both run (QEMU's `mps2-an386`,
//! `firmware/boards/qemu-mps2-an386/src/bin/model_bench.rs`), which must give the same bits.
//!
//! A [`Case`] is a chip ([`Part`]: the chain bench's four families at their output rates, and
//! the MPU-9250 with its magnetometer at 1 kHz, the one that shows the field's terms), the
//! sensor model's terms ([`Terms`]: ideal, the paper's eq. 18, eq. 18 with the magnetic
//! perturbation, every term) and the chain behind it ([`Chain`]: the output path or the chip's
//! internal path, quiet or with motor tones and a shock). [`run`] builds what a device builds
//! on Configure and AddVibration (`link::setup::build_chip`, `link::setup::Model` and its
//! `add_vibration`, a [`Rig`]) and runs what it runs per output sample in mode (b): the
//! kinematics index of the instant and the hold of a new kinematics sample (at the default
//! kinematics rate, the output rate over `max(2, ⌈rate / 1 kHz⌉)`), the model with its chain,
//! the conversion into the chip's register image and the image's latch into the chip (its
//! registers and FIFO). Its [`Outcome`] carries a 64-bit FNV-1a hash of every image's bytes and
//! the caller's clock difference across the sample loop (construction excluded): on the device
//! the instructions spent.
//!
//! **The perturbation.** The device does not run it yet (the host refuses it in mode (b)): the
//! case adds [`Perturbation`]'s disturbance to the held field at every output sample, the way
//! the host's model does, with the caller's buffers ([`perturbation_buffer_lens`], at most
//! [`PERTURBATION_SCRATCH_LEN`] and [`PERTURBATION_SIGNAL_LEN`]). Its bursts
//! run back to back, so each 2 s window is shaped once (three FFT-based shapings, one per
//! axis, at the window's first sample); the case runs one window, so the count is the
//! shaping's average over the window plus the per-sample work.
//!
//! [`harness`] runs the same loop with an ideal model and no latch: the kinematics and the
//! hash, the bench's own cost.
//!
//! Nothing here panics: a case that cannot be built returns a [`BenchError`].
//!
//! ```
//! use margemu_firmware::model_bench::{self, Case, Chain, Part, Terms};
//! let case = Case { family: Part::Bmi088, terms: Terms::Eq18, chain: Chain::Output };
//! let outcome = model_bench::run(&case, &mut [], &mut [], &mut || 0)?;
//! assert_eq!(outcome.samples, case.output_samples());
//! assert_eq!(model_bench::run(&case, &mut [], &mut [], &mut || 0)?.hash, outcome.hash);
//! # Ok::<(), model_bench::BenchError>(())
//! ```

mod cases;

pub use cases::{Chain, Part, Terms};

use core::fmt;

use margemu_model::perturbation::{Complex, Perturbation, PerturbationPlan};
use margemu_model::sensor::Truth;
use margemu_protocol::link::{Configure, ErrorCode, ModelParams, Rate};

use crate::budget::Load;
use crate::chain_bench::{Fnv1a, Motion};
use crate::chip::Chip;
use crate::link::rig::Rig;
use crate::link::setup::{self, ChainSetup, Model};

/// Scene time each case runs (one perturbation window).
pub const DURATION_NS: u64 = 2_000_000_000;
/// The seed of every case.
pub const SEED: u64 = 0x6d61_7267_6d6f_6431;
/// µT per unit of the cases' normalised field.
pub const MAG_UT_PER_UNIT: f64 = 50.0;
/// The field in world axes, normalised units (the conventions' reference field, 56° down).
const FIELD_W: [f32; 3] = [0.5, 0.0, -0.83];

/// `Complex` scratch values the largest perturbation case needs (2 s at 8 kHz: a window of
/// 16 000 = 2⁷·5³ samples, three windows' worth; 768 KB).
pub const PERTURBATION_SCRATCH_LEN: usize = 48_000;
/// `f32` signal values the largest perturbation case needs (one window per axis; 192 KB).
pub const PERTURBATION_SIGNAL_LEN: usize = 48_000;

/// One case: a chip at its output rate, the model's terms, the chain behind them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Case {
    /// The chip and its output rate.
    pub family: Part,
    /// The sensor model's terms.
    pub terms: Terms,
    /// The chain.
    pub chain: Chain,
}

/// Cases per family: every term configuration on the quiet output path, then eq. 18 behind
/// every other chain, then every term behind the internal path with tones and a shock.
const PER_FAMILY: [(Terms, Chain); 8] = [
    (Terms::Ideal, Chain::Output),
    (Terms::Eq18, Chain::Output),
    (Terms::Eq18Perturbation, Chain::Output),
    (Terms::Every, Chain::Output),
    (Terms::Eq18, Chain::OutputTones),
    (Terms::Eq18, Chain::Internal),
    (Terms::Eq18, Chain::InternalTonesShock),
    (Terms::Every, Chain::InternalTonesShock),
];

/// Every case, chip by chip.
pub const CASES: [Case; 40] = {
    let mut cases = [Case {
        family: Part::Icm20602,
        terms: Terms::Ideal,
        chain: Chain::Output,
    }; 40];
    let mut i = 0;
    while i < 40 {
        let (terms, chain) = PER_FAMILY[i % 8];
        cases[i] = Case {
            family: Part::ALL[i / 8],
            terms,
            chain,
        };
        i += 1;
    }
    cases
};

impl Case {
    /// Output samples the case runs: [`DURATION_NS`] at the family's output rate.
    pub fn output_samples(&self) -> u32 {
        u32::try_from(DURATION_NS / self.family.output_period_ns()).unwrap_or(u32::MAX)
    }

    /// The output rate, Hz (whole for every family).
    pub fn rate_hz(&self) -> u32 {
        u32::try_from(1_000_000_000 / self.family.output_period_ns()).unwrap_or(u32::MAX)
    }

    /// The output rate, and the kinematics rate: the output rate over [`Case::hold`].
    pub fn rates(&self) -> Option<(Rate, Rate)> {
        let hz = self.rate_hz();
        Some((Rate::hz(hz)?, Rate::new(hz, self.hold())?))
    }

    /// Output samples per kinematics sample: the host's default, `max(2, ⌈rate / 1 kHz⌉)`.
    pub fn hold(&self) -> u32 {
        self.rate_hz().div_ceil(1000).max(2)
    }
}

impl fmt::Display for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}/{}", self.family, self.terms, self.chain)
    }
}

/// What a case gave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// Output samples run.
    pub samples: u32,
    /// 64-bit FNV-1a of every image's bytes.
    pub hash: u64,
    /// The clock's difference across the sample loop (wrapping), in the clock's unit.
    pub elapsed: u64,
}

/// Why a case could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BenchError {
    /// The firmware refused the chip's Configure.
    Chip(ErrorCode),
    /// The firmware refused the model's terms.
    ModelRefused,
    /// The firmware refused an AddVibration piece of the chain (its index).
    ChainRefused(usize),
    /// The perturbation could not be built (or its buffers are too small).
    Perturbation(margemu_model::Error),
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Chip(code) => write!(f, "model bench: the chip's Configure refused ({code:?})"),
            Self::ModelRefused => f.write_str("model bench: the model's terms refused"),
            Self::ChainRefused(i) => write!(f, "model bench: AddVibration piece {i} refused"),
            Self::Perturbation(e) => write!(f, "model bench: perturbation: {e}"),
        }
    }
}

impl core::error::Error for BenchError {}

/// The perturbation buffers `case` needs: (`Complex` scratch, `f32` signal) values; zeros
/// without a perturbation.
pub fn perturbation_buffer_lens(case: &Case) -> Result<(usize, usize), BenchError> {
    match case.terms.perturbation() {
        None => Ok((0, 0)),
        Some(cfg) => {
            let plan = PerturbationPlan::new(&cfg, case.family.output_rate_hz())
                .map_err(BenchError::Perturbation)?;
            Ok((plan.scratch_len(), plan.signal_len()))
        }
    }
}

/// What `case` runs per output sample, for the [`budget`](crate::budget)'s cost model: its
/// chip, terms and the chain its AddVibration messages build.
pub fn load(case: &Case) -> Result<Load, BenchError> {
    let (rate, _) = case.rates().ok_or(BenchError::ModelRefused)?;
    let chip =
        setup::build_chip(&Configure::new(case.family.model(), rate)).map_err(BenchError::Chip)?;
    let mut chain = ChainSetup::default();
    for (i, piece) in case.chain.messages(case.family, rate).iter().enumerate() {
        if !chain.add(piece) {
            return Err(BenchError::ChainRefused(i));
        }
    }
    let front = setup::model_chain(&chip.settings(), rate, SEED, &chain)
        .transpose()
        .map_err(|_| BenchError::ChainRefused(0))?;
    let terms = case.terms;
    let load = Load::output_path(chip.model(), &terms.marg(), terms.perturbation().is_some());
    Ok(load.with_chain(&chain, front.as_ref()))
}

/// Runs `case` (see the module docs), with `scratch` and `signal` as the perturbation's buffers
/// (at least [`perturbation_buffer_lens`]; other cases take none), reading `clock` once before
/// and once after the sample loop.
pub fn run(
    case: &Case,
    scratch: &mut [Complex],
    signal: &mut [f32],
    clock: &mut impl FnMut() -> u64,
) -> Result<Outcome, BenchError> {
    let (rate, truth_rate) = case.rates().ok_or(BenchError::ModelRefused)?;
    let chip =
        setup::build_chip(&Configure::new(case.family.model(), rate)).map_err(BenchError::Chip)?;
    let mut params = ModelParams::new(SEED, truth_rate, case.terms.marg());
    params.mag_ut_per_unit = MAG_UT_PER_UNIT;
    let mut model = Model::new(&params, rate, &chip).ok_or(BenchError::ModelRefused)?;
    for (i, piece) in case.chain.messages(case.family, rate).iter().enumerate() {
        if !model.add_vibration(piece, &chip) {
            return Err(BenchError::ChainRefused(i));
        }
    }
    let mut perturbation = match case.terms.perturbation() {
        None => None,
        Some(cfg) => {
            let plan =
                PerturbationPlan::new(&cfg, rate.as_hz_f64()).map_err(BenchError::Perturbation)?;
            let p = Perturbation::new(&plan, SEED, scratch, signal);
            Some(p.map_err(BenchError::Perturbation)?)
        }
    };
    let mut rig = Rig::new(chip);
    let mut kinematics = Kinematics::new(truth_rate);
    let mut hash = Fnv1a::new();
    let samples = case.output_samples();
    let start = clock();
    for k in 0..u64::from(samples) {
        let t = rate.sample_time_ns(k);
        let truth = *kinematics.at(model.truth_index_at(t));
        match perturbation.as_mut() {
            None if kinematics.fresh => model.hold(truth),
            None => {}
            Some(p) => {
                let d = p.sample();
                let mut disturbed = truth;
                for (b, d) in disturbed.magnetic_field.iter_mut().zip(d) {
                    *b += d;
                }
                model.hold(disturbed);
            }
        }
        if let Some(image) = model.image(t, rig.primary()) {
            hash.write(image.as_bytes());
            rig.latch_image_at(&image, t);
        }
    }
    let elapsed = clock().wrapping_sub(start);
    Ok(Outcome {
        samples,
        hash: hash.finish(),
        elapsed,
    })
}

/// The bench's own loop for `case`'s samples: the kinematics and the hash of the held truth's
/// bits, no model, no image, no latch. Returns the hash and the clock's difference.
pub fn harness(case: &Case, clock: &mut impl FnMut() -> u64) -> (u64, u64) {
    let Some((rate, truth_rate)) = case.rates() else {
        return (0, 0);
    };
    let mut kinematics = Kinematics::new(truth_rate);
    let mut hash = Fnv1a::new();
    let start = clock();
    for k in 0..u64::from(case.output_samples()) {
        let t = rate.sample_time_ns(k);
        let truth = kinematics.at(setup::truth_index_at(truth_rate, t));
        hash.write_vec(truth.magnetic_field);
    }
    let elapsed = clock().wrapping_sub(start);
    (hash.finish(), elapsed)
}

/// The kinematics the host would send: the chain bench's motion at the kinematics rate, with
/// the field turning with it; advanced when the device's kinematics index moves on.
struct Kinematics {
    motion: Motion,
    index: Option<u64>,
    truth: Truth,
    /// Whether the last [`Kinematics::at`] moved on to a new sample.
    fresh: bool,
}

impl Kinematics {
    fn new(truth_rate: Rate) -> Self {
        let period_ns = 1e9 / truth_rate.as_hz_f64();
        Self {
            motion: Motion::new(period_ns as u64),
            index: None,
            truth: Truth::default(),
            fresh: false,
        }
    }

    /// The kinematics sample `j` (the next one when `j` moves on; `j` only grows here).
    fn at(&mut self, j: u64) -> &Truth {
        self.fresh = self.index != Some(j);
        if self.fresh {
            self.index = Some(j);
            let mut truth = self.motion.next();
            // The motion turns about y: body = Ry(θ)ᵀ·world, cos θ and sin θ from gravity's.
            let (c, s) = (
                truth.specific_force[2] / Motion::G,
                -truth.specific_force[0] / Motion::G,
            );
            let [x, _, z] = FIELD_W;
            truth.magnetic_field = [c * x - s * z, FIELD_W[1], s * x + c * z];
            self.truth = truth;
        }
        &self.truth
    }
}

#[cfg(test)]
mod tests;
