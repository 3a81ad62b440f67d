//! A sensor's sampling chain: the front end sampling at the chip's internal rate (vibration
//! added, the range clipped and counted), the digital filters, and the decimation to the output.
//!
//! A [`SensorPath`] runs one sensor (accelerometer or gyroscope) of one device. The rigid-body
//! input arrives once per output sample; [`SensorPath::advance`] to an output instant `t` runs
//! every internal instant `k · period ≤ t` not yet run, each with that input (held since the
//! previous output instant) plus the vibration at `k · period`, clips each axis to `±range`
//! (counting every internal sample that clipped, per axis, as flight controllers count
//! clipping), filters it, and returns the newest filter output: the value a chip whose output
//! register is updated at `t` holds.
//!
//! The **output path** ([`SensorPath::at_output`]) runs one step per output instant instead,
//! without filters: the vibration at the output instant added, the range clipped and counted.
//! It costs a few comparisons per axis when nothing vibrates.
//!
//! [`DeviceChain`] puts an accelerometer path and a gyroscope path in front of the sensor model
//! ([`Marg::sample_chained`]): the specific force at the sensor (lever arm included) and the body
//! rate go through the chain, then the error terms of eq. 18 apply at the output rate.
//!
//! ```
//! use margemu_model::chain::{filter::FilterDesign, SensorPath};
//! use margemu_model::perturbation::Complex;
//! use margemu_model::vibration::{Harmonic, RpmPoint, Sense, ToneSource, Vibration};
//! // 8 internal samples per output sample, a 20 m/s² front end, a 3 kHz tone of 30 m/s².
//! let profile = [RpmPoint { t_ns: 0, rpm: 180_000.0 }];
//! let mut tone = ToneSource::new(1, &profile[..]);
//! tone.push(Harmonic { order: 1.0, linear: [30.0, 0.0, 0.0], angular: [0.0; 3] })?;
//! let mut vib = Vibration::<_, Vec<Complex>>::new(Sense::Linear, 31_250, 1);
//! vib.add_tones(tone)?;
//! let filter = FilterDesign::identity(32_000.0)?;
//! let mut path = SensorPath::new(31_250, filter, 20.0, vib)?;
//! for j in 0..100u64 {
//!     let out = path.advance(j * 250_000, [0.0, 0.0, 9.8]);
//!     assert!(out[0].abs() <= 20.0);
//! }
//! assert!(path.clips()[0] > 0 && path.clips()[2] == 0);
//! # Ok::<(), margemu_model::Error>(())
//! ```

pub mod filter;

use crate::error::Error;
use crate::perturbation::Complex;
use crate::sensor::{Marg, Sample, Truth, INPUT_LIMIT};
use crate::vec3::{clamp, Vec3};
use crate::vibration::{RpmPoint, Vibration};
use filter::{FilterDesign, FilterState};

/// The period the output path's vibration steps by at `rate_hz`, ns: `1e9 / rate` rounded, at
/// least 1 (the tones' phases advance by it once per output sample).
pub fn output_period_ns(rate_hz: f64) -> u64 {
    libm::round(1e9 / rate_hz).max(1.0) as u64
}

/// One sensor's chain at its internal rate (or at the output instants).
pub struct SensorPath<P, B> {
    /// 0 on the output path.
    period_ns: u64,
    filter: FilterDesign,
    range: f32,
    vibration: Vibration<P, B>,
    states: [FilterState; 3],
    /// Index of the next internal instant.
    next: u64,
    /// The newest filter output.
    output: Vec3,
    clips: [u64; 3],
}

impl<P: AsRef<[RpmPoint]>, B: AsMut<[Complex]> + AsRef<[Complex]>> SensorPath<P, B> {
    /// A path sampling every `period_ns` (> 0), filtering with `filter` (designed at that rate)
    /// and clipping at `±range` (> 0; `f32::INFINITY` for none), adding `vibration` (built at the
    /// same period).
    pub fn new(
        period_ns: u64,
        filter: FilterDesign,
        range: f32,
        vibration: Vibration<P, B>,
    ) -> Result<Self, Error> {
        if period_ns == 0 {
            return Err(Error::InvalidRate);
        }
        if range.is_nan() || range <= 0.0 {
            return Err(Error::NonPositiveParameter {
                what: "chain.range",
            });
        }
        Ok(Self {
            period_ns,
            filter,
            range,
            vibration,
            states: [FilterState::default(); 3],
            next: 0,
            output: [0.0; 3],
            clips: [0; 3],
        })
    }

    /// The output path: one step per [`Self::advance`], at its instant, no filter; `vibration`
    /// built at the output period (rounded to ns) for its tone phases.
    pub fn at_output(range: f32, vibration: Vibration<P, B>) -> Result<Self, Error> {
        let mut path = Self::new(1, FilterDesign::identity(1e9)?, range, vibration)?;
        path.period_ns = 0;
        Ok(path)
    }

    /// The internal sample period, ns (0 on the output path).
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// Runs the internal instants up to `t_ns` with `input` held, and returns the newest output
    /// (the previous one if no internal instant fell since the last call). On the output path,
    /// one step at `t_ns`.
    #[inline]
    pub fn advance(&mut self, t_ns: u64, input: Vec3) -> Vec3 {
        if self.period_ns == 0 {
            self.step(t_ns, input);
            return self.output;
        }
        let end = t_ns / self.period_ns;
        while self.next <= end {
            self.step(self.next.saturating_mul(self.period_ns), input);
        }
        self.output
    }

    /// One internal sample at `t_ns`. The first one settles the filters on the rigid-body
    /// input first (the chip has been on long before the scene starts: no start-up transient).
    #[inline]
    fn step(&mut self, t_ns: u64, input: Vec3) {
        if self.next == 0 {
            for (state, x) in self.states.iter_mut().zip(input) {
                self.filter.settle(state, x.clamp(-self.range, self.range));
            }
        }
        let v = self.vibration.next(t_ns);
        let mut y = [0.0f32; 3];
        for (i, ((x, v), y)) in input.iter().zip(v).zip(&mut y).enumerate() {
            let x = *x + v;
            let clipped = if x > self.range {
                self.count_clip(i);
                self.range
            } else if x < -self.range {
                self.count_clip(i);
                -self.range
            } else {
                x
            };
            if let Some(state) = self.states.get_mut(i) {
                *y = self.filter.step(state, clipped);
            }
        }
        self.output = y;
        self.next += 1;
    }

    fn count_clip(&mut self, axis: usize) {
        if let Some(c) = self.clips.get_mut(axis) {
            *c += 1;
        }
    }

    /// Internal samples that clipped so far, per axis.
    pub fn clips(&self) -> [u64; 3] {
        self.clips
    }

    /// Internal samples run so far.
    pub fn internal_samples(&self) -> u64 {
        self.next
    }
}

/// An accelerometer path and a gyroscope path in front of the sensor model.
pub struct DeviceChain<P, B> {
    /// The accelerometer's path (specific force at the sensor, m/s²).
    pub accel: SensorPath<P, B>,
    /// The gyroscope's path (body rate, rad/s).
    pub gyro: SensorPath<P, B>,
}

impl<P: AsRef<[RpmPoint]>, B: AsMut<[Complex]> + AsRef<[Complex]>> DeviceChain<P, B> {
    /// One output sample at `t_ns` of `marg` behind the chain, from the rigid-body `truth`.
    #[inline]
    pub fn sample(&mut self, marg: &mut Marg, t_ns: u64, truth: &Truth) -> Sample {
        let f = marg.accel().specific_force_at_sensor(truth);
        let a = self.accel.advance(t_ns, f);
        let w = self
            .gyro
            .advance(t_ns, clamp(truth.angular_rate, INPUT_LIMIT));
        marg.sample_chained(truth, a, w)
    }
}

/// The output path's front end when nothing vibrates: each axis of the specific force and the
/// body rate clipped at the chip's full scale and counted, nothing else (a NaN passes as NaN,
/// for that sample only, as through the sensor model). A few bytes, where a [`DeviceChain`]
/// holds vibration sources and filter states: what a device runs in source mode (b).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clipper {
    ranges: [f32; 2],
    clips: [[u64; 3]; 2],
}

impl Clipper {
    /// Clipping at `±accel` m/s² and `±gyro` rad/s (each > 0).
    pub fn new(accel: f32, gyro: f32) -> Result<Self, Error> {
        if [accel, gyro].iter().any(|r| r.is_nan() || *r <= 0.0) {
            return Err(Error::NonPositiveParameter {
                what: "chain.range",
            });
        }
        Ok(Self {
            ranges: [accel, gyro],
            clips: [[0; 3]; 2],
        })
    }

    fn clip(v: Vec3, range: f32, clips: &mut [u64; 3]) -> Vec3 {
        let mut out = v;
        for ((x, c), o) in v.iter().zip(clips.iter_mut()).zip(out.iter_mut()) {
            if *x > range {
                *c += 1;
                *o = range;
            } else if *x < -range {
                *c += 1;
                *o = -range;
            }
        }
        out
    }

    /// One output sample of `marg` behind the clipper, from `truth`.
    #[inline]
    pub fn sample(&mut self, marg: &mut Marg, truth: &Truth) -> Sample {
        let [accel, gyro] = &mut self.clips;
        let f = marg.accel().specific_force_at_sensor(truth);
        let a = Self::clip(f, self.ranges[0], accel);
        let w = Self::clip(clamp(truth.angular_rate, INPUT_LIMIT), self.ranges[1], gyro);
        marg.sample_chained(truth, a, w)
    }

    /// Samples clipped so far, `[accel, gyro]` per axis.
    pub fn clips(&self) -> [[u64; 3]; 2] {
        self.clips
    }
}

/// What stands in front of a device's sensor model: the [`Clipper`] when nothing vibrates on
/// the output path, else a [`DeviceChain`].
#[allow(clippy::large_enum_variant)] // no alloc here to box with; one per device
pub enum Front<P, B> {
    /// Clipping only.
    Clip(Clipper),
    /// Vibration, and the internal path's filters.
    Chain(DeviceChain<P, B>),
}

impl<P: AsRef<[RpmPoint]>, B: AsMut<[Complex]> + AsRef<[Complex]>> Front<P, B> {
    /// One output sample at `t_ns` of `marg` behind this front end, from `truth`.
    #[inline]
    pub fn sample(&mut self, marg: &mut Marg, t_ns: u64, truth: &Truth) -> Sample {
        match self {
            Front::Clip(c) => c.sample(marg, truth),
            Front::Chain(c) => c.sample(marg, t_ns, truth),
        }
    }

    /// Samples (internal samples on the internal path) clipped so far, `[accel, gyro]` per
    /// axis.
    pub fn clips(&self) -> [[u64; 3]; 2] {
        match self {
            Front::Clip(c) => c.clips(),
            Front::Chain(c) => [c.accel.clips(), c.gyro.clips()],
        }
    }

    /// Whether the chain runs at the chip's internal rate.
    pub fn runs_internal_path(&self) -> bool {
        matches!(self, Front::Chain(c) if c.accel.period_ns() != 0)
    }
}
