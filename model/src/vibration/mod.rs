//! Vibration at a sensor: motor tones, random vibration from a PSD and half-sine shocks, sampled
//! at a sensor's internal rate.
//!
//! A [`Vibration`] is built for one sensor of one device ([`Sense::Linear`] for the
//! accelerometer: m/s² added to the specific force; [`Sense::Angular`] for the gyroscope: rad/s
//! added to the body rate) at that sensor's internal sample period, from the sources that reach
//! the device, with their amplitudes already in the device's axes. [`Vibration::next`] gives the
//! vibration at the next internal instant (instants `k · period` from `k = 0`, or the output
//! instants on the output path); tone phases advance one period per call.
//!
//! - **Motor tones** ([`ToneSource`]): `motors` motors follow one rpm profile (piecewise linear in
//!   time: constant, ramp, steps or a recorded table), each motor's rpm scaled by its own factor
//!   `1 + spread·u` (`u` uniform in [−1, 1], seeded), each harmonic `h` at `rpm/60 · order_h`
//!   with its own amplitude per axis (peak, per motor) and a seeded random phase per motor and
//!   harmonic. The phase is accumulated in cycles in `f32` per internal sample.
//! - **Random vibration** ([`RandomSource`]): a stationary Gaussian process with the one-sided
//!   PSD given by breakpoints (interpolated linearly in log-log, zero outside), synthesised by
//!   windowed overlap-add of inverse FFTs ([`random`]); per-axis gains; linear only.
//! - **Shocks** ([`Shock`]): half-sine pulses `peak · sin(π (t − t₀)/d)` for `t₀ ≤ t < t₀ + d`.
//!
//! Determinism: the tones and shocks run in `f32` with a fixed order of operations ([`sine`]); the
//! random synthesis runs in `f64` (the model's FFT) and rounds each sample to `f32`. Random draws
//! come from the streams `vibration/tones/<i>` (phases and spreads, at construction) and
//! `vibration/random` (per block), so the host and the firmware give the same bits.
//!
//! ```
//! use margemu_model::vibration::{Harmonic, RpmPoint, Sense, ToneSource, Vibration};
//! let profile = [RpmPoint { t_ns: 0, rpm: 12_000.0 }]; // 200 Hz
//! let mut tone = ToneSource::new(1, &profile[..]);
//! tone.push(Harmonic { order: 1.0, linear: [0.0, 0.0, 5.0], angular: [0.0; 3] })?;
//! let mut vib = Vibration::<&[RpmPoint], Vec<_>>::new(Sense::Linear, 125_000, 7);
//! vib.add_tones(tone)?;
//! let peak = (0..8000u64).map(|k| vib.next(k * 125_000)[2].abs()).fold(0.0f32, f32::max);
//! assert!((peak - 5.0).abs() < 0.01);
//! # Ok::<(), margemu_model::Error>(())
//! ```

pub mod random;
pub mod sine;
mod tones;

pub use random::{PsdPoint, RandomSource, MAX_PSD_POINTS};
pub use tones::{Harmonic, RpmPoint, ToneSource, MAX_HARMONICS, MAX_MOTORS};

use crate::error::Error;
use crate::perturbation::Complex;
use crate::vec3::{add, Vec3};
use random::Random;
use tones::Tones;

/// Most tone sources one sensor adds up.
pub const MAX_TONE_SOURCES: usize = 4;
/// Most shocks one sensor adds up.
pub const MAX_SHOCKS: usize = 8;

/// Which motion a sensor's vibration is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sense {
    /// Linear acceleration, m/s² (the accelerometer's).
    Linear,
    /// Angular rate, rad/s (the gyroscope's).
    Angular,
}

/// A half-sine shock pulse.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shock {
    /// Start, ns from the scene start.
    pub t_ns: u64,
    /// Duration, ns (> 0).
    pub duration_ns: u64,
    /// Peak linear acceleration per axis, m/s².
    pub linear: [f64; 3],
    /// Peak angular rate per axis, rad/s.
    pub angular: [f64; 3],
}

/// The vibration one sensor sees, sample by sample at its internal period.
///
/// `P` holds a tone source's rpm profile, `B` the random synthesis's buffers
/// ([`RandomSource::buffer_len`] complex values; `Vec<Complex>` on the host, a static slice on a
/// device).
pub struct Vibration<P, B> {
    sense: Sense,
    period_ns: u64,
    seed: u64,
    tones: [Option<Tones<P>>; MAX_TONE_SOURCES],
    shocks: [(u64, u64, [f32; 3]); MAX_SHOCKS],
    shock_count: usize,
    random: Option<Random<B>>,
}

impl<P: AsRef<[RpmPoint]>, B: AsMut<[Complex]> + AsRef<[Complex]>> Vibration<P, B> {
    /// No vibration yet, for `sense` at `period_ns` (> 0) with the device's seed.
    pub fn new(sense: Sense, period_ns: u64, seed: u64) -> Self {
        Self {
            sense,
            period_ns: period_ns.max(1),
            seed,
            tones: [const { None }; MAX_TONE_SOURCES],
            shocks: [(0, 0, [0.0; 3]); MAX_SHOCKS],
            shock_count: 0,
            random: None,
        }
    }

    /// The vibration of `sense` at `period_ns` with `seed`: every tone source, then every
    /// shock, in their order (the one order host and device build it in, so both give the same
    /// bits).
    pub fn with_sources<'a>(
        sense: Sense,
        period_ns: u64,
        seed: u64,
        tones: impl IntoIterator<Item = &'a ToneSource<P>>,
        shocks: impl IntoIterator<Item = &'a Shock>,
    ) -> Result<Self, Error>
    where
        P: Clone + 'a,
    {
        let mut vib = Self::new(sense, period_ns, seed);
        for t in tones {
            vib.add_tones(t.clone())?;
        }
        for shock in shocks {
            vib.add_shock(shock)?;
        }
        Ok(vib)
    }

    /// Adds a tone source (its amplitudes of this sensor's sense; a source without any is
    /// checked and left out, costing nothing); refuses a [`MAX_TONE_SOURCES`]-th + 1 or an
    /// invalid profile.
    pub fn add_tones(&mut self, source: ToneSource<P>) -> Result<(), Error> {
        if !source.moves(self.sense) {
            return Tones::new(source, self.sense, self.period_ns, self.seed, 0).map(|_| ());
        }
        let index = self.tones.iter().position(Option::is_none);
        let index = index.ok_or(Error::TooManyVibrationSources)?;
        let tones = Tones::new(source, self.sense, self.period_ns, self.seed, index)?;
        if let Some(slot) = self.tones.get_mut(index) {
            *slot = Some(tones);
        }
        Ok(())
    }

    /// Adds a shock; refuses more than [`MAX_SHOCKS`], a zero duration or a non-finite peak.
    pub fn add_shock(&mut self, shock: &Shock) -> Result<(), Error> {
        if shock.duration_ns == 0 {
            return Err(Error::NonPositiveParameter {
                what: "vibration.shock.duration",
            });
        }
        let peak = match self.sense {
            Sense::Linear => shock.linear,
            Sense::Angular => shock.angular,
        };
        let peak = crate::sensor::vec_f32_checked(peak, "vibration.shock.peak")?;
        if peak == [0.0; 3] {
            return Ok(());
        }
        let slot = self.shocks.get_mut(self.shock_count);
        let slot = slot.ok_or(Error::TooManyVibrationSources)?;
        *slot = (shock.t_ns, shock.duration_ns, peak);
        self.shock_count += 1;
        Ok(())
    }

    /// Adds the random source (linear only, at most one), with `buffers` of at least
    /// [`RandomSource::buffer_len`] complex values.
    pub fn add_random(&mut self, source: &RandomSource, buffers: B) -> Result<(), Error> {
        if self.sense == Sense::Angular {
            return Err(Error::RandomVibrationNotLinear);
        }
        if self.random.is_some() {
            return Err(Error::TooManyVibrationSources);
        }
        let rate = 1e9 / self.period_ns as f64;
        self.random = Some(Random::new(source, rate, self.seed, buffers)?);
        Ok(())
    }

    /// Whether no source was added (the sensor vibrates not at all).
    pub fn is_empty(&self) -> bool {
        self.tones.iter().all(Option::is_none) && self.shock_count == 0 && self.random.is_none()
    }

    /// The vibration at `t_ns`, the next instant (one period after the previous call's).
    #[inline]
    pub fn next(&mut self, t_ns: u64) -> Vec3 {
        let mut v = [0.0f32; 3];
        for tones in self.tones.iter_mut().flatten() {
            v = add(v, tones.next(t_ns));
        }
        for &(t0, d, peak) in self.shocks.iter().take(self.shock_count) {
            if let Some(into) = t_ns.checked_sub(t0).filter(|&dt| dt < d) {
                let s = sine::sin_cycles(0.5 * (into as f32 / d as f32));
                v = add(v, [peak[0] * s, peak[1] * s, peak[2] * s]);
            }
        }
        if let Some(random) = self.random.as_mut() {
            v = add(v, random.next());
        }
        v
    }
}
