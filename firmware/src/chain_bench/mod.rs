//! A fixed set of sampling-chain benchmark cases, shared by the host and the device: the same
//! code runs natively (the reference) and on the Cortex-M4F (QEMU's `mps2-an386`,
//! `firmware/boards/qemu-mps2-an386/src/bin/chain_bench.rs`), and both must give the same
//! bits.
//!
//! A [`Case`] is a chip family ([`Family`]: ICM-20602 at 8 kHz, ICM-42688-P at 8 kHz with its
//! 32 kHz internal rate, BMI270 at 3.2 kHz, BMI088 at 2 kHz, each with its declared chain
//! [`Family::declared`]: internal rates, filters, full scales) and a [`Path`] through the chain
//! (the output path or the internal path, without vibration, with motor tones, with tones and
//! a shock, with random vibration). [`run`] builds the case's
//! [`DeviceChain`](margemu_model::chain::DeviceChain) and a
//! [`Marg`] with white noise from fixed-size values and the
//! caller's random-vibration buffer (no allocation), runs [`Case::output_samples`] output
//! samples (half a second) of a deterministic synthetic truth (a slow rotation through gravity),
//! and folds the bits of every output sample (`f32::to_bits` of the accelerometer's then the
//! gyroscope's axes, little-endian) into a 64-bit FNV-1a hash. It returns the hash, the
//! clipping counts of both front ends and the caller's clock difference across the sample
//! loop only (construction excluded): on the device the instructions spent.
//!
//! [`harness`] runs the same loop without chain or sensor model (truth and hash only): its cost
//! is the bench's own, to subtract from a case's.
//!
//! Nothing here panics: a case that cannot be built returns a [`BenchError`].
//!
//! ```
//! use margemu_firmware::chain_bench::{self, Family, Path, Case};
//! let case = Case { family: Family::Bmi088, path: Path::OutputTones };
//! let mut ticks = 0u64;
//! let mut clock = || { ticks += 1; ticks };
//! let outcome = chain_bench::run(&case, &mut [], &mut clock)?;
//! assert_eq!(outcome.samples, case.output_samples());
//! assert_eq!(outcome.elapsed, 1); // the clock is read once before and once after the loop
//! // Deterministic: the same case gives the same bits.
//! assert_eq!(chain_bench::run(&case, &mut [], &mut || 0)?.hash, outcome.hash);
//! # Ok::<(), chain_bench::BenchError>(())
//! ```

mod cases;

pub use cases::{random_buffer_len, Family, Path, RANDOM_BUFFER_LEN};

use core::fmt;

use margemu_model::perturbation::Complex;
use margemu_model::sensor::{Marg, Truth};
use margemu_model::vec3::Vec3;
use margemu_protocol::chip::{ChainError, SettingsError};

/// Seconds of truth each case runs.
pub const DURATION_NS: u64 = 500_000_000;
/// The seed of every case (the chain's vibration and the sensor's noise).
pub const SEED: u64 = 0x6d61_7267_6368_6e31;

/// One benchmark case: a chip family and a path through its chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Case {
    /// The chip family, its output rate and internal rates.
    pub family: Family,
    /// The path and the vibration.
    pub path: Path,
}

/// Every case, family by family, in [`Path::ALL`] order within a family.
pub const CASES: [Case; 20] = {
    let mut cases = [Case {
        family: Family::Icm20602,
        path: Path::Output,
    }; 20];
    let mut i = 0;
    while i < 20 {
        cases[i] = Case {
            family: Family::ALL[i / 5],
            path: Path::ALL[i % 5],
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
}

impl fmt::Display for Case {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.family, self.path)
    }
}

/// What a case gave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// Output samples run.
    pub samples: u32,
    /// 64-bit FNV-1a of every output sample's bits.
    pub hash: u64,
    /// Internal samples of the accelerometer's front end that clipped, per axis.
    pub accel_clips: [u64; 3],
    /// Internal samples of the gyroscope's front end that clipped, per axis.
    pub gyro_clips: [u64; 3],
    /// Internal samples run (accelerometer, gyroscope).
    pub internal_samples: [u64; 2],
    /// The clock's difference across the sample loop (wrapping), in the clock's unit.
    pub elapsed: u64,
}

/// Why a case could not be built.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BenchError {
    /// The model refused a part of the case (a vibration source, the sensor model, or the
    /// random-vibration buffer is too small).
    Model(margemu_model::Error),
    /// The chip's declared chain could not be built.
    Chain(ChainError),
    /// The chip has no such full scale.
    Settings(SettingsError),
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Model(e) => write!(f, "chain bench: {e}"),
            Self::Chain(e) => write!(f, "chain bench: {e}"),
            Self::Settings(e) => write!(f, "chain bench: full scale: {e:?}"),
        }
    }
}

impl core::error::Error for BenchError {}

impl From<margemu_model::Error> for BenchError {
    fn from(e: margemu_model::Error) -> Self {
        Self::Model(e)
    }
}

impl From<ChainError> for BenchError {
    fn from(e: ChainError) -> Self {
        Self::Chain(e)
    }
}

/// Runs `case` with `random` as the random synthesis's buffer (at least
/// [`RANDOM_BUFFER_LEN`] values for a [`Path::InternalRandom`] case; other cases take none),
/// reading `clock` once before and once after the sample loop.
pub fn run(
    case: &Case,
    random: &mut [Complex],
    clock: &mut impl FnMut() -> u64,
) -> Result<Outcome, BenchError> {
    let period = case.family.output_period_ns();
    let mut chain = cases::chain(case, random)?;
    let mut marg = Marg::new(&cases::noise(), 1e9 / period as f64, SEED)?;
    let mut motion = Motion::new(period);
    let mut hash = Fnv1a::new();
    let samples = case.output_samples();
    let start = clock();
    for j in 0..u64::from(samples) {
        let truth = motion.next();
        let sample = chain.sample(&mut marg, j * period, &truth);
        hash.write_vec(sample.acc);
        hash.write_vec(sample.gyr);
    }
    let elapsed = clock().wrapping_sub(start);
    Ok(Outcome {
        samples,
        hash: hash.finish(),
        accel_clips: chain.accel.clips(),
        gyro_clips: chain.gyro.clips(),
        internal_samples: [
            chain.accel.internal_samples(),
            chain.gyro.internal_samples(),
        ],
        elapsed,
    })
}

/// The bench's own loop for `samples` samples at `period_ns`: the truth and the hash of its
/// specific force and rate, no chain, no sensor model. Returns the hash and the clock's
/// difference across the loop.
pub fn harness(samples: u32, period_ns: u64, clock: &mut impl FnMut() -> u64) -> (u64, u64) {
    let mut motion = Motion::new(period_ns);
    let mut hash = Fnv1a::new();
    let start = clock();
    for _ in 0..samples {
        let truth = motion.next();
        hash.write_vec(truth.specific_force);
        hash.write_vec(truth.angular_rate);
    }
    let elapsed = clock().wrapping_sub(start);
    (hash.finish(), elapsed)
}

/// The synthetic truth: the body turning about its y axis at [`Motion::RATE`] through gravity
/// (the rotation advanced by a fixed `f32` rotation per sample, no transcendental function in
/// the loop), with a small roll rate following the same angle.
pub(crate) struct Motion {
    cos: f32,
    sin: f32,
    step_cos: f32,
    step_sin: f32,
}

impl Motion {
    /// Pitch rate, rad/s.
    const RATE: f32 = 2.0;
    /// Standard gravity, m/s².
    pub(crate) const G: f32 = 9.806_65;

    pub(crate) fn new(period_ns: u64) -> Self {
        let step = f64::from(Self::RATE) * period_ns as f64 * 1e-9;
        Self {
            cos: 1.0,
            sin: 0.0,
            step_cos: libm::cos(step) as f32,
            step_sin: libm::sin(step) as f32,
        }
    }

    pub(crate) fn next(&mut self) -> Truth {
        let (c, s) = (self.cos, self.sin);
        let truth = Truth {
            angular_rate: [0.25 * s, Self::RATE, 0.1 * c],
            specific_force: [-Self::G * s, 0.0, Self::G * c],
            ..Truth::default()
        };
        self.cos = c * self.step_cos - s * self.step_sin;
        self.sin = s * self.step_cos + c * self.step_sin;
        truth
    }
}

/// 64-bit FNV-1a, fed incrementally.
pub(crate) struct Fnv1a(u64);

impl Fnv1a {
    pub(crate) fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    pub(crate) fn write_vec(&mut self, v: Vec3) {
        for x in v {
            self.write(&x.to_bits().to_le_bytes());
        }
    }

    pub(crate) fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    pub(crate) fn finish(&self) -> u64 {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_the_models_one_shot_hash() {
        let mut h = Fnv1a::new();
        h.write_vec([1.0, -2.5, 0.0]);
        let mut bytes = [0u8; 12];
        for (chunk, x) in bytes.chunks_mut(4).zip([1.0f32, -2.5, 0.0]) {
            chunk.copy_from_slice(&x.to_bits().to_le_bytes());
        }
        assert_eq!(h.finish(), margemu_model::rng::fnv1a64(&bytes));
    }

    #[test]
    fn cases_cover_every_family_and_path_once() {
        for family in Family::ALL {
            for path in Path::ALL {
                let n = CASES
                    .iter()
                    .filter(|c| c.family == family && c.path == path)
                    .count();
                assert_eq!(n, 1, "{family}/{path}");
            }
        }
    }
}
