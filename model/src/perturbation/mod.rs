//! The magnetic perturbation generator of the paper's section 2.4 (eq. 19–23), no_std and no
//! alloc: bursts of a random, smooth, realistic-looking disturbance at random times.
//!
//! # One burst ([`BurstShaper::shape`])
//! 1. the artificial signal `m` of `n = round(Δt·fs)` samples, five waveforms at random blocks
//!    (eq. 19, [`waveforms`]);
//! 2. its analytic signal `m_a` by FFT (eq. 20, [`hilbert::analytic`], FFT in [`fft`]);
//! 3. `m_p[k] = imag(m_a[k]) + |m_a[n−1−k]|` (eq. 21) and the least-squares detrend (eq. 22);
//! 4. the 2nd-order Butterworth low-pass at the configured cutoff, from zero state (eq. 23,
//!    [`butterworth`], in `f32`);
//! 5. normalised to a peak magnitude of 1, so that the burst amplitude is its peak disturbance
//!    (our addition: it makes the paper's "0–4 nu disturbance range" a property of the output).
//!
//! Steps 1–3 run in `f64` (once per burst), steps 4–5 in `f32`; every step is deterministic.
//!
//! # Bursts in time ([`Perturbation`])
//! A burst of `n` samples is scaled by an amplitude drawn per burst ([`Amplitude`]: the paper's
//! uniform `[lo, hi]` range, or the reference code's `1 + 4.5·U(0,1)`) and followed by a quiet gap
//! drawn from `U(gap_s)`; the run starts with a gap. Bursts are independent per axis (the
//! reference code, streams `perturbation/mag/x`, `/y`, `/z`), or shared by all axes along a fixed
//! or per-burst random direction (stream `perturbation/mag`). Outside its bursts the disturbance
//! is exactly zero. It is meant to be added to the true field before the magnetometer model.
//!
//! # Memory
//! The caller supplies, once, `plan.scratch_len()` [`Complex`] values (the FFT tables and one
//! complex window: `3n` when `n` has no prime factor above 5, else `2n + 4m` ≈ 10–12·n with `m`
//! the Bluestein length) and `plan.signal_len()` `f32` values (one window per channel: `3n` per
//! axis, `n` along a direction), as owned `Vec`s on the host or `&mut` static arrays on firmware.
//! At 8 kHz and Δt = 2 s (`n` = 16 000 = 2⁷·5³) that is 48 000 complex values (768 KB) and
//! 48 000 `f32` (192 KB).
//!
//! ```
//! use margemu_model::perturbation::{fft::Complex, Perturbation, PerturbationConfig, PerturbationPlan};
//! let plan = PerturbationPlan::new(&PerturbationConfig::default(), 200.0)?;
//! assert_eq!((plan.window_len(), plan.scratch_len(), plan.signal_len()), (400, 1200, 1200));
//! // Owned buffers (a `Vec` on the host), or `&mut [..]` to static arrays on the firmware.
//! let mut scratch = [Complex::ZERO; 1200];
//! let mut signal = [0.0f32; 1200];
//! let mut pert = Perturbation::new(&plan, 7, &mut scratch[..], &mut signal[..])?;
//! let mut peak = 0.0f32;
//! for _ in 0..200 * 30 {
//!     let d = pert.sample();
//!     peak = d.iter().fold(peak, |p, x| p.max(x.abs()));
//! }
//! assert!(peak > 0.0 && peak <= 4.0);
//! # Ok::<(), margemu_model::Error>(())
//! ```

pub mod butterworth;
pub mod fft;
pub mod hilbert;
mod runner;
pub mod waveforms;

pub use fft::Complex;
pub use runner::Perturbation;

use crate::error::{finite, non_negative, positive, Error};
use butterworth::Butterworth2;
use fft::FftPlan;
use waveforms::Waveforms;

/// The longest window accepted, in samples (2 s at 500 kHz).
pub const MAX_WINDOW_SAMPLES: usize = 1_000_000;

/// How each burst is scaled (its peak disturbance, in the scene's magnetic unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Amplitude {
    /// `U(lo, hi)`: the paper's "0–4 nu disturbance range" is `lo = 0, hi = 4`.
    Uniform {
        /// Lower bound (≥ 0).
        lo: f64,
        /// Upper bound (> 0, ≥ `lo`).
        hi: f64,
    },
    /// `1 + 4.5·U(0, 1)`, the author's reference code.
    Reference,
}

/// Where the bursts act.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// Independent bursts on each axis (the reference code).
    PerAxis,
    /// One burst sequence along this direction (normalised; not zero).
    Direction([f64; 3]),
    /// One burst sequence, each burst along a uniformly random direction.
    RandomDirection,
}

/// The perturbation of a scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerturbationConfig {
    /// Burst length Δt, s (paper: 2 s).
    pub window_s: f64,
    /// Low-pass cutoff, Hz (paper: 5 Hz); below the Nyquist frequency.
    pub cutoff_hz: f64,
    /// Burst scaling.
    pub amplitude: Amplitude,
    /// Quiet time before the first burst and between bursts, `U(gap_s[0], gap_s[1])` s.
    pub gap_s: [f64; 2],
    /// Per axis, or along a direction.
    pub placement: Placement,
}

impl Default for PerturbationConfig {
    /// The paper's setting: 2 s windows, 5 Hz, 0–4 per axis; gaps of 1–5 s (about three bursts
    /// in 15 s, as the paper's Figure 6; the paper does not give the gaps).
    fn default() -> Self {
        Self {
            window_s: 2.0,
            cutoff_hz: 5.0,
            amplitude: Amplitude::Uniform { lo: 0.0, hi: 4.0 },
            gap_s: [1.0, 5.0],
            placement: Placement::PerAxis,
        }
    }
}

/// A validated configuration at one output rate, with its buffer sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PerturbationPlan {
    n: usize,
    rate_hz: f64,
    filter: Butterworth2,
    amplitude: Amplitude,
    gap_s: [f64; 2],
    placement: Placement,
    scratch_len: usize,
}

impl PerturbationPlan {
    /// Validates `cfg` for samples at `rate_hz`.
    pub fn new(cfg: &PerturbationConfig, rate_hz: f64) -> Result<Self, Error> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(Error::InvalidRate);
        }
        let window = positive(cfg.window_s, "perturbation.window_s")?;
        let samples = libm::round(window * rate_hz);
        if samples > MAX_WINDOW_SAMPLES as f64 {
            return Err(Error::PerturbationWindowTooLong);
        }
        let n = samples as usize;
        if n < 10 {
            return Err(Error::PerturbationWindowTooShort { samples: n });
        }
        let filter = Butterworth2::low_pass(cfg.cutoff_hz, rate_hz)?;
        let amplitude = match cfg.amplitude {
            Amplitude::Uniform { lo, hi } => {
                let lo = non_negative(lo, "perturbation.amplitude.lo")?;
                let hi = finite(hi, "perturbation.amplitude.hi")?;
                if lo > hi {
                    return Err(Error::InvertedAmplitudeRange);
                }
                if hi <= 0.0 {
                    return Err(Error::ZeroAmplitudeRange);
                }
                Amplitude::Uniform { lo, hi }
            }
            Amplitude::Reference => Amplitude::Reference,
        };
        let gap_s = [
            non_negative(cfg.gap_s[0], "perturbation.gap_s")?,
            non_negative(cfg.gap_s[1], "perturbation.gap_s")?,
        ];
        if gap_s[0] > gap_s[1] {
            return Err(Error::InvertedGapRange);
        }
        let placement = match cfg.placement {
            Placement::Direction(d) => {
                for x in d {
                    finite(x, "perturbation.placement.direction")?;
                }
                let norm = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if !(norm > 0.0 && norm.is_finite()) {
                    return Err(Error::ZeroDirection);
                }
                Placement::Direction(d.map(|x| x / norm))
            }
            p => p,
        };
        let scratch_len = FftPlan::new(n)?
            .scratch_len()
            .checked_add(n)
            .ok_or(Error::FftTooLong)?;
        Ok(Self {
            n,
            rate_hz,
            filter,
            amplitude,
            gap_s,
            placement,
            scratch_len,
        })
    }

    /// The window length `n = round(Δt·fs)`, samples.
    pub fn window_len(&self) -> usize {
        self.n
    }

    /// The output rate, Hz.
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// The [`Complex`] scratch values [`BurstShaper`] and [`Perturbation`] need.
    pub fn scratch_len(&self) -> usize {
        self.scratch_len
    }

    /// The number of independent burst sequences: 3 per axis, 1 along a direction.
    pub fn channels(&self) -> usize {
        match self.placement {
            Placement::PerAxis => 3,
            _ => 1,
        }
    }

    /// The `f32` values [`Perturbation`] needs: one window per channel.
    pub fn signal_len(&self) -> usize {
        self.channels() * self.n
    }

    /// The normalised direction, if the bursts act along a fixed one.
    pub fn direction(&self) -> Option<[f64; 3]> {
        match self.placement {
            Placement::Direction(d) => Some(d),
            _ => None,
        }
    }
}

/// Shapes bursts (eq. 19–23) in caller-supplied scratch `S` (owned, e.g. a `Vec<Complex>`, or a
/// borrowed `&mut [Complex]`).
pub struct BurstShaper<S> {
    plan: PerturbationPlan,
    fft: FftPlan,
    storage: S,
}

impl<S: AsMut<[Complex]>> BurstShaper<S> {
    /// A shaper for `plan` in `scratch` (at least `plan.scratch_len()` values; its FFT tables are
    /// filled here, once).
    pub fn new(plan: &PerturbationPlan, mut scratch: S) -> Result<Self, Error> {
        let fft = FftPlan::new(plan.n)?;
        let storage = scratch.as_mut();
        let needed = plan.scratch_len;
        if storage.len() < needed {
            return Err(Error::BufferTooSmall {
                needed,
                got: storage.len(),
            });
        }
        fft.init(&mut storage[plan.n..])?;
        Ok(Self {
            plan: *plan,
            fft,
            storage: scratch,
        })
    }

    /// One unit-peak burst drawn from `rng` into `out[..n]` (`out` at least `n` long); returns the
    /// waveform parameters it drew.
    pub fn shape(
        &mut self,
        rng: &mut crate::rng::StreamRng,
        out: &mut [f32],
    ) -> Result<Waveforms, Error> {
        let n = self.plan.n;
        let Some(out) = out.get_mut(..n) else {
            return Err(Error::BufferTooSmall {
                needed: n,
                got: out.len(),
            });
        };
        let (data, tables) = self.storage.as_mut().split_at_mut(n);
        let w = Waveforms::draw(rng);
        w.render(data);
        hilbert::analytic(data, &self.fft, tables)?;
        hilbert::fold_reversed_envelope(data);
        hilbert::detrend(data);
        let mut filter = self.plan.filter;
        filter.reset();
        let mut peak = 0.0f32;
        for (y, z) in out.iter_mut().zip(data.iter()) {
            *y = filter.process(z.re as f32);
            peak = peak.max(libm::fabsf(*y));
        }
        if peak > 0.0 && peak.is_finite() {
            for y in out.iter_mut() {
                *y /= peak;
            }
        } else {
            out.fill(0.0);
        }
        Ok(w)
    }

    /// Gives the scratch back.
    pub fn into_scratch(self) -> S {
        self.storage
    }
}
