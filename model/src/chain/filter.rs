//! The digital filters of a chip's sampling chain.
//!
//! A [`FilterDesign`] is a cascade of at most [`MAX_SECTIONS`] low-pass sections (first or
//! second order) and a pure delay of at most [`MAX_DELAY`] samples, designed once in `f64` (with
//! `libm`) at the internal rate it runs at and rounded to `f32`. [`FilterDesign::step`] filters
//! one internal sample of one axis in `f32` with a fixed order of operations and no fused
//! multiply-add (host and firmware give the same bits) and never panics.
//! [`FilterDesign::gain_at`] and [`FilterDesign::delay_s`] evaluate the response the rounded
//! `f32` coefficients actually have (for predictions and tests).
//!
//! **Designs.** [`FilterDesign::butterworth`] maps the analog Butterworth prototype of order
//! 1–8 by the bilinear transform with the cutoff prewarped (`g = tan(π·fc/fs)`), so the digital
//! response is −3 dB at `fc` exactly; [`FilterDesign::then`] cascades two designs (the decimation
//! and UI filters of a chip after its anti-alias filter) and [`FilterDesign::with_delay`] adds
//! whole samples of pure delay (pipeline latency the datasheet states beyond the filter's own).
//!
//! **Numerics.** Every section runs in the trapezoidal state-variable form of
//! [`crate::perturbation::butterworth`] (Zavalishin/Simper), generalised to any damping, and the
//! first-order section in the same increment form: the states are integrator states of the
//! size of the signal, the coefficients small numbers (never differences from 1 in `f32`), so the
//! DC gain is 1 whatever the rounding, and each state sum carries a Kahan compensation term so the
//! tiny increments of a low cutoff (5 Hz at 1 kHz, 10 Hz at 32 kHz) are not lost.
//!
//! **Non-finite input.** A NaN entering an IIR state would poison every later output, so
//! [`FilterDesign::step`] never lets one in: a NaN or infinite input is replaced by the previous
//! (finite) input of that state (0 before the first), and finite inputs are clamped to
//! ±[`MAX_INPUT`]. The output at that sample is therefore the filter's response to a held input,
//! and the samples after it are unaffected by the fault.
//!
//! ```
//! use margemu_model::chain::filter::{FilterDesign, FilterState};
//! // A 2nd-order 41 Hz low-pass at 1 kHz, plus one sample of pure delay.
//! let f = FilterDesign::butterworth(2, 41.0, 1000.0)?.with_delay(1)?;
//! assert!((f.gain_at(41.0) - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-4);
//! let mut s = FilterState::default();
//! let mut y = 0.0;
//! for _ in 0..2000 {
//!     y = f.step(&mut s, 1.0);
//! }
//! assert_eq!(y, 1.0); // unit DC gain
//! assert_eq!(f.step(&mut s, f32::NAN), 1.0); // a NaN is taken as the previous input
//! # Ok::<(), margemu_model::Error>(())
//! ```

use crate::error::{positive, Error};
use core::f64::consts::PI;

/// Most sections (first or second order) in one design.
pub const MAX_SECTIONS: usize = 4;
/// Longest pure delay, in internal samples.
pub const MAX_DELAY: usize = 160;
/// Largest input magnitude [`FilterDesign::step`] passes on; larger finite inputs are clamped.
pub const MAX_INPUT: f32 = 1.0e30;

/// Highest Butterworth order [`FilterDesign::butterworth`] designs.
pub const MAX_ORDER: u8 = 2 * MAX_SECTIONS as u8;

/// One low-pass section: `k = None` first order, else second order with damping `k = 1/Q`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Section {
    /// Second order: `a1 − 1`; first order: unused.
    m1: f32,
    /// Second order: `g·a1`; first order: `G = g/(1+g)`.
    a2: f32,
    /// Second order: `g·a2`; first order: unused.
    a3: f32,
    second: bool,
}

impl Section {
    const NONE: Self = Self {
        m1: 0.0,
        a2: 0.0,
        a3: 0.0,
        second: false,
    };

    fn first(g: f64) -> Self {
        Self {
            a2: (g / (1.0 + g)) as f32,
            ..Self::NONE
        }
    }

    fn second(g: f64, k: f64) -> Self {
        let a1 = 1.0 / (1.0 + g * (g + k));
        let a2 = g * a1;
        Self {
            m1: (-g * (g + k) * a1) as f32,
            a2: a2 as f32,
            a3: (g * a2) as f32,
            second: true,
        }
    }

    /// One sample through the section, states `s = [s1, s2, c1, c2]`.
    #[inline(always)]
    fn step(&self, s: &mut [f32; 4], x: f32) -> f32 {
        let [s1, s2, c1, c2] = *s;
        if self.second {
            let v3 = x - s2;
            let d1 = self.m1 * s1 + self.a2 * v3;
            let d2 = self.a2 * s1 + self.a3 * v3;
            let y = s2 + d2;
            let (n1, k1) = compensated_add(s1, 2.0 * d1, c1);
            let (n2, k2) = compensated_add(s2, 2.0 * d2, c2);
            *s = [n1, n2, k1, k2];
            y
        } else {
            let d = self.a2 * (x - s1);
            let y = s1 + d;
            let (n1, k1) = compensated_add(s1, 2.0 * d, c1);
            *s = [n1, 0.0, k1, 0.0];
            y
        }
    }

    /// The section's state-space `(A, B, C, D)` as the `f32` coefficients define it, in `f64`.
    fn state_space(&self) -> ([[f64; 2]; 2], [f64; 2], [f64; 2], f64) {
        let (m1, a2, a3) = (f64::from(self.m1), f64::from(self.a2), f64::from(self.a3));
        if self.second {
            (
                [[1.0 + 2.0 * m1, -2.0 * a2], [2.0 * a2, 1.0 - 2.0 * a3]],
                [2.0 * a2, 2.0 * a3],
                [a2, 1.0 - a3],
                a3,
            )
        } else {
            (
                [[1.0 - 2.0 * a2, 0.0], [0.0, 0.0]],
                [2.0 * a2, 0.0],
                [1.0 - a2, 0.0],
                a2,
            )
        }
    }

    /// `H(e^{jω})` of the section (`ω` in radians per sample), as `(re, im)`.
    fn response(&self, w: f64) -> (f64, f64) {
        let (a, b, c, d) = self.state_space();
        let z = (libm::cos(w), libm::sin(w));
        // (zI − A)⁻¹ B by Cramer's rule on the 2×2 complex system.
        let m = [
            [(z.0 - a[0][0], z.1), (-a[0][1], 0.0)],
            [(-a[1][0], 0.0), (z.0 - a[1][1], z.1)],
        ];
        let det = sub(mul(m[0][0], m[1][1]), mul(m[0][1], m[1][0]));
        let x0 = sub(scale(m[1][1], b[0]), scale(m[0][1], b[1]));
        let x1 = sub(scale(m[0][0], b[1]), scale(m[1][0], b[0]));
        let num = add(scale(x0, c[0]), scale(x1, c[1]));
        add(div(num, det), (d, 0.0))
    }

    /// The low-frequency group delay, samples: `−arg H(e^{jω})/ω` at a tiny `ω` (the phase is
    /// odd in `ω`, so the error is of order `ω²`).
    fn delay_samples(&self) -> f64 {
        const W: f64 = 1e-6;
        let (re, im) = self.response(W);
        -libm::atan2(im, re) / W
    }
}

type C = (f64, f64);
fn add(a: C, b: C) -> C {
    (a.0 + b.0, a.1 + b.1)
}
fn sub(a: C, b: C) -> C {
    (a.0 - b.0, a.1 - b.1)
}
fn mul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
fn scale(a: C, s: f64) -> C {
    (a.0 * s, a.1 * s)
}
fn div(a: C, b: C) -> C {
    let n = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / n, (a.1 * b.0 - a.0 * b.1) / n)
}

/// `s + d` with Kahan compensation `c`: the new sum and compensation.
#[inline(always)]
fn compensated_add(s: f32, d: f32, c: f32) -> (f32, f32) {
    let u = d - c;
    let t = s + u;
    (t, (t - s) - u)
}

/// A filter design at one internal rate: low-pass sections, then a pure delay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterDesign {
    rate_hz: f64,
    sections: [Section; MAX_SECTIONS],
    n_sections: u8,
    delay: u8,
}

/// One axis's state of a [`FilterDesign`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterState {
    /// Per section: `s1, s2` and their compensation terms.
    sections: [[f32; 4]; MAX_SECTIONS],
    /// The delay line (a ring), and the slot the next sample is written to.
    line: [f32; MAX_DELAY],
    head: u8,
    /// The last finite input, stand-in for a non-finite one.
    last: f32,
}

impl Default for FilterState {
    fn default() -> Self {
        Self {
            sections: [[0.0; 4]; MAX_SECTIONS],
            line: [0.0; MAX_DELAY],
            head: 0,
            last: 0.0,
        }
    }
}

fn check_rate(rate_hz: f64) -> Result<f64, Error> {
    if rate_hz.is_finite() && rate_hz > 0.0 {
        Ok(rate_hz)
    } else {
        Err(Error::InvalidRate)
    }
}

impl FilterDesign {
    /// The identity (no filtering, no delay) at `rate_hz`.
    pub fn identity(rate_hz: f64) -> Result<Self, Error> {
        Ok(Self {
            rate_hz: check_rate(rate_hz)?,
            sections: [Section::NONE; MAX_SECTIONS],
            n_sections: 0,
            delay: 0,
        })
    }

    /// The Butterworth low-pass of `order` (1 to [`MAX_ORDER`]) with its −3 dB point at
    /// `cutoff_hz`, for samples at `rate_hz` (bilinear, prewarped).
    pub fn butterworth(order: u8, cutoff_hz: f64, rate_hz: f64) -> Result<Self, Error> {
        let mut design = Self::identity(rate_hz)?;
        let fc = positive(cutoff_hz, "filter cutoff")?;
        if fc >= 0.5 * rate_hz {
            return Err(Error::CutoffAboveNyquist);
        }
        if order == 0 || order > MAX_ORDER {
            return Err(Error::FilterOrder { order });
        }
        let g = libm::tan(PI * fc / rate_hz);
        let n = f64::from(order);
        for pair in 0..order / 2 {
            // Pole pair at angle (2p + 1)π/(2n) from the imaginary axis: k = 2 sin(that).
            let k = 2.0 * libm::sin((2.0 * f64::from(pair) + 1.0) * PI / (2.0 * n));
            design.push(Section::second(g, k))?;
        }
        if order % 2 == 1 {
            design.push(Section::first(g))?;
        }
        Ok(design)
    }

    /// The first-order low-pass with its −3 dB point at `cutoff_hz`.
    pub fn first_order(cutoff_hz: f64, rate_hz: f64) -> Result<Self, Error> {
        Self::butterworth(1, cutoff_hz, rate_hz)
    }

    fn push(&mut self, section: Section) -> Result<(), Error> {
        let slot = self
            .sections
            .get_mut(usize::from(self.n_sections))
            .ok_or(Error::TooManyFilterSections)?;
        *slot = section;
        self.n_sections += 1;
        Ok(())
    }

    /// This design followed by `other` (same rate within 10⁻⁹ relative; sections and delays
    /// add up).
    pub fn then(mut self, other: Self) -> Result<Self, Error> {
        if (self.rate_hz - other.rate_hz).abs() > 1e-9 * self.rate_hz {
            return Err(Error::FilterRateMismatch);
        }
        for section in other.active() {
            self.push(*section)?;
        }
        self.with_delay(usize::from(other.delay))
    }

    /// This design with `samples` more samples of pure delay.
    pub fn with_delay(mut self, samples: usize) -> Result<Self, Error> {
        let total = usize::from(self.delay) + samples;
        if total > MAX_DELAY {
            return Err(Error::FilterDelayTooLong { samples: total });
        }
        self.delay = total as u8;
        Ok(self)
    }

    fn active(&self) -> &[Section] {
        self.sections
            .get(..usize::from(self.n_sections))
            .unwrap_or(&[])
    }

    /// The internal rate the design runs at, Hz.
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// The number of sections (a second-order section counts once).
    pub fn sections(&self) -> usize {
        self.active().len()
    }

    /// The filter order (the sum of the sections' orders).
    pub fn order(&self) -> usize {
        self.active()
            .iter()
            .map(|s| if s.second { 2 } else { 1 })
            .sum()
    }

    /// The pure delay, internal samples.
    pub fn delay_samples(&self) -> usize {
        usize::from(self.delay)
    }

    /// Filters one sample of one axis (see the module docs for non-finite input).
    #[inline]
    pub fn step(&self, state: &mut FilterState, x: f32) -> f32 {
        let x = if x.is_finite() {
            x.clamp(-MAX_INPUT, MAX_INPUT)
        } else {
            state.last
        };
        state.last = x;
        let mut y = x;
        for (section, s) in self.active().iter().zip(state.sections.iter_mut()) {
            y = section.step(s, y);
        }
        if self.delay == 0 {
            return y;
        }
        let len = usize::from(self.delay);
        let head = usize::from(state.head) % len;
        let out = state.line.get(head).copied().unwrap_or(y);
        if let Some(slot) = state.line.get_mut(head) {
            *slot = y;
        }
        state.head = ((head + 1) % len) as u8;
        out
    }

    /// Sets `state` to the steady state of a constant input `x` (as if `x` had been applied
    /// forever), so a chain starting at rest under gravity shows no start-up transient.
    pub fn settle(&self, state: &mut FilterState, x: f32) {
        let x = if x.is_finite() {
            x.clamp(-MAX_INPUT, MAX_INPUT)
        } else {
            0.0
        };
        *state = FilterState {
            last: x,
            ..FilterState::default()
        };
        for s in state.sections.iter_mut() {
            // A low-pass at DC: the integrator carrying the output holds x, the other 0.
            *s = [x, x, 0.0, 0.0];
        }
        for (section, s) in self.active().iter().zip(state.sections.iter_mut()) {
            if section.second {
                s[0] = 0.0;
            }
        }
        state.line = [x; MAX_DELAY];
    }

    /// The magnitude of the response at `f_hz` (linear, 1 = 0 dB).
    pub fn gain_at(&self, f_hz: f64) -> f64 {
        let w = 2.0 * PI * f_hz / self.rate_hz;
        self.active()
            .iter()
            .map(|s| {
                let (re, im) = s.response(w);
                libm::sqrt(re * re + im * im)
            })
            .product()
    }

    /// The group delay at low frequency (sections and pure delay), seconds.
    pub fn delay_s(&self) -> f64 {
        let sections: f64 = self.active().iter().map(Section::delay_samples).sum();
        (sections + f64::from(self.delay)) / self.rate_hz
    }

    /// The lowest frequency at which the gain falls to −3 dB (1/√2), found by bisection over
    /// (0, rate/2); `None` for a design without sections (it never falls).
    pub fn bandwidth_hz(&self) -> Option<f64> {
        if self.n_sections == 0 {
            return None;
        }
        let target = core::f64::consts::FRAC_1_SQRT_2;
        let (mut lo, mut hi) = (0.0, 0.5 * self.rate_hz);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if self.gain_at(mid) > target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Some(0.5 * (lo + hi))
    }
}
