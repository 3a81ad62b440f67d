//! The sample-by-sample perturbation: bursts placed in time, per axis or along a direction.

use super::{Amplitude, BurstShaper, Complex, PerturbationPlan, Placement};
use crate::error::Error;
use crate::rng::{standard_normal, stream, uniform, unit_f64, StreamRng};
use crate::vec3::Vec3;

/// Stream names: one per axis, or one for a direction.
const AXIS_STREAMS: [&str; 3] = [
    "perturbation/mag/x",
    "perturbation/mag/y",
    "perturbation/mag/z",
];
const DIRECTION_STREAM: &str = "perturbation/mag";

/// One burst sequence.
#[derive(Clone, Debug)]
struct Channel {
    rng: StreamRng,
    /// The sample at which the next burst starts (while idle).
    next_start: u64,
    /// Position in the current burst, or `None` while idle.
    pos: Option<usize>,
    /// The current burst's amplitude times its direction (or unit axis).
    gain: Vec3,
}

/// The magnetic disturbance, one sample per call to [`Perturbation::sample`], over caller storage:
/// `S` holds the complex scratch, `T` the `f32` burst signals (owned `Vec`s, or borrowed slices).
///
/// The burst that starts at a sample is shaped at that call (two FFTs of the window length: about
/// 12 µs for 2 s at 200 Hz, 0.5 ms for 2 s at 8 kHz on the development machine); every other call
/// costs a few nanoseconds.
pub struct Perturbation<S, T> {
    plan: PerturbationPlan,
    shaper: BurstShaper<S>,
    signal: T,
    channels: [Channel; 3],
    k: u64,
}

impl<S: AsMut<[Complex]>, T: AsMut<[f32]>> Perturbation<S, T> {
    /// The perturbation of `plan` for the scene seed `seed`, in `scratch` (at least
    /// `plan.scratch_len()` values) and `signal` (at least `plan.signal_len()` values).
    pub fn new(
        plan: &PerturbationPlan,
        seed: u64,
        scratch: S,
        mut signal: T,
    ) -> Result<Self, Error> {
        let needed = plan.signal_len();
        let got = signal.as_mut().len();
        if got < needed {
            return Err(Error::BufferTooSmall { needed, got });
        }
        let shaper = BurstShaper::new(plan, scratch)?;
        let names = match plan.placement {
            Placement::PerAxis => AXIS_STREAMS,
            _ => [DIRECTION_STREAM; 3],
        };
        let channels = names.map(|name| {
            let mut rng = stream(seed, name);
            let next_start = gap_samples(plan, &mut rng);
            Channel {
                rng,
                next_start,
                pos: None,
                gain: [0.0; 3],
            }
        });
        Ok(Self {
            plan: *plan,
            shaper,
            signal,
            channels,
            k: 0,
        })
    }

    /// Gives the storage back.
    pub fn into_parts(self) -> (S, T) {
        (self.shaper.into_scratch(), self.signal)
    }

    /// The index of the next sample.
    pub fn sample_index(&self) -> u64 {
        self.k
    }

    /// Whether any burst is under way at the next sample's index (before it starts).
    pub fn is_active(&self) -> bool {
        self.channels[..self.plan.channels()]
            .iter()
            .any(|c| c.pos.is_some())
    }

    /// The disturbance at the next sample, per axis, scene unit; zero outside bursts.
    #[inline]
    pub fn sample(&mut self) -> Vec3 {
        let n = self.plan.n;
        let mut out = [0.0f32; 3];
        let signal = self.signal.as_mut();
        for (c, ch) in self.channels[..self.plan.channels()].iter_mut().enumerate() {
            let window = &mut signal[c * n..(c + 1) * n];
            if ch.pos.is_none() && ch.next_start == self.k {
                if self.shaper.shape(&mut ch.rng, window).is_err() {
                    window.fill(0.0); // unreachable: the sizes were checked at construction
                }
                ch.gain = burst_gain(&self.plan, &mut ch.rng, c);
                ch.pos = Some(0);
            }
            if let Some(pos) = ch.pos {
                let v = window[pos];
                for (o, g) in out.iter_mut().zip(ch.gain) {
                    *o += g * v;
                }
                if pos + 1 < n {
                    ch.pos = Some(pos + 1);
                } else {
                    ch.pos = None;
                    let gap = gap_samples(&self.plan, &mut ch.rng);
                    ch.next_start = self.k.saturating_add(1).saturating_add(gap);
                }
            }
        }
        self.k = self.k.wrapping_add(1);
        out
    }
}

/// A quiet gap in samples, `round(U(gap_s)·fs)`.
fn gap_samples(plan: &PerturbationPlan, rng: &mut StreamRng) -> u64 {
    let s = uniform(rng, plan.gap_s[0], plan.gap_s[1]);
    libm::round(s * plan.rate_hz) as u64 // saturating cast
}

/// A burst's amplitude times its direction: the axis of channel `c`, the fixed direction, or a
/// uniformly random one (three normal draws after the amplitude).
fn burst_gain(plan: &PerturbationPlan, rng: &mut StreamRng, c: usize) -> Vec3 {
    let a = match plan.amplitude {
        Amplitude::Uniform { lo, hi } => uniform(rng, lo, hi),
        Amplitude::Reference => 1.0 + 4.5 * unit_f64(rng),
    };
    let d = match plan.placement {
        Placement::PerAxis => {
            let mut e = [0.0; 3];
            e[c] = 1.0;
            e
        }
        Placement::Direction(d) => d,
        Placement::RandomDirection => loop {
            let v: [f64; 3] = core::array::from_fn(|_| f64::from(standard_normal(rng)));
            let norm = libm::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if norm > 1e-6 {
                break v.map(|x| x / norm);
            }
        },
    };
    d.map(|x| (a * x) as f32)
}
