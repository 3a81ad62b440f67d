//! The 2nd-order Butterworth low-pass of eq. 23, in `f32`, in a form that stays accurate when the
//! cutoff is a tiny fraction of the rate.
//!
//! The design is the textbook one: the analog prototype `1/(s² + √2·s + 1)` mapped by the bilinear
//! transform with the cutoff prewarped, `g = tan(π·fc/fs)`. Its digital magnitude is exactly
//! `|H(f)| = 1/√(1 + (tan(π f/fs)/g)⁴)` ([`Butterworth2::magnitude`]), and [`eq23_coefficients`]
//! gives the paper's direct-form `a_i`, `b_j`.
//!
//! The direct form is a poor thing to run in `f32` at 8 kHz with a 5 Hz cutoff: its poles sit at
//! radius 0.9972, `a₁ ≈ 1.99722` and `a₂ ≈ −0.99723` lose most of their information to rounding,
//! and the DC gain `Σb/(1 − Σa)` is a ratio of two numbers of order 10⁻⁵ that both carry errors of
//! order 10⁻⁷ (measured: 5·10⁻⁴ gain error in the pass band). So the filter runs as the
//! trapezoidal state-variable filter (Zavalishin's "topology-preserving transform", in Simper's
//! formulation), which has the same transfer function, written in increments:
//!
//! ```text
//! a1 = 1/(1 + g(g + √2)),  a2 = g·a1,  a3 = g·a2,  m1 = a1 − 1 = −g(g + √2)·a1
//! v3 = x − s2;  d1 = m1·s1 + a2·v3;  d2 = a2·s1 + a3·v3;  y = s2 + d2
//! s1 += 2·d1;  s2 += 2·d2        (compensated sums)
//! ```
//!
//! Its states are integrator states of the size of the signal and its coefficients small numbers
//! (never differences from 1 in `f32`), so the DC gain is 1 whatever the rounding of the
//! coefficients. The increments are tiny next to the states (10⁻⁶ of them at 8 kHz / 5 Hz) and
//! would fall below half an ulp near steady state, so each state sum carries a Kahan compensation
//! term. Measured at 8 kHz / 5 Hz (`tests/butterworth.rs`): magnitude error below 10⁻⁷ relative
//! (10⁻⁶ dB) from 0.5 Hz to 1 kHz, step response settling on exactly 1.0, impulse response
//! decaying to below the smallest normal `f32` and staying there over 10⁶ samples.
//!
//! ```
//! use margemu_model::perturbation::butterworth::Butterworth2;
//! let mut lp = Butterworth2::low_pass(5.0, 8000.0)?;
//! let mut y = 0.0;
//! for _ in 0..40_000 {
//!     y = lp.process(1.0);
//! }
//! assert_eq!(y, 1.0); // unit DC gain, exactly
//! assert!((lp.magnitude(5.0) - core::f64::consts::FRAC_1_SQRT_2).abs() < 1e-12);
//! # Ok::<(), margemu_model::Error>(())
//! ```

use crate::error::Error;
use core::f64::consts::{PI, SQRT_2};

/// A 2nd-order Butterworth low-pass, trapezoidal state-variable form, `f32` state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Butterworth2 {
    /// `a1 − 1`, computed in `f64` (a small number, not a difference from 1 in `f32`).
    m1: f32,
    a2: f32,
    a3: f32,
    s1: f32,
    s2: f32,
    /// Compensation terms of the two state sums (Kahan).
    c1: f32,
    c2: f32,
    /// `tan(π·fc/fs)`.
    g: f64,
    rate_hz: f64,
}

impl Butterworth2 {
    /// A low-pass at `cutoff_hz` for samples at `rate_hz`; refuses a cutoff that is not finite, not
    /// positive, or at or above the Nyquist frequency.
    pub fn low_pass(cutoff_hz: f64, rate_hz: f64) -> Result<Self, Error> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(Error::InvalidRate);
        }
        let fc = crate::error::positive(cutoff_hz, "perturbation.cutoff_hz")?;
        if fc >= 0.5 * rate_hz {
            return Err(Error::CutoffAboveNyquist);
        }
        let g = libm::tan(PI * fc / rate_hz);
        let a1 = 1.0 / (1.0 + g * (g + SQRT_2));
        let a2 = g * a1;
        let a3 = g * a2;
        Ok(Self {
            m1: (-g * (g + SQRT_2) * a1) as f32,
            a2: a2 as f32,
            a3: a3 as f32,
            s1: 0.0,
            s2: 0.0,
            c1: 0.0,
            c2: 0.0,
            g,
            rate_hz,
        })
    }

    /// Filters one sample.
    #[inline]
    pub fn process(&mut self, x: f32) -> f32 {
        let v3 = x - self.s2;
        // The increments v1 − s1 and v2 − s2, small numbers computed directly.
        let d1 = self.m1 * self.s1 + self.a2 * v3;
        let d2 = self.a2 * self.s1 + self.a3 * v3;
        let y = self.s2 + d2;
        (self.s1, self.c1) = compensated_add(self.s1, 2.0 * d1, self.c1);
        (self.s2, self.c2) = compensated_add(self.s2, 2.0 * d2, self.c2);
        y
    }

    /// Clears the state (as at construction).
    pub fn reset(&mut self) {
        self.s1 = 0.0;
        self.s2 = 0.0;
        self.c1 = 0.0;
        self.c2 = 0.0;
    }

    /// The analytic magnitude of the design at `f_hz`: `1/√(1 + (tan(πf/fs)/g)⁴)`.
    pub fn magnitude(&self, f_hz: f64) -> f64 {
        let r = libm::tan(PI * f_hz / self.rate_hz) / self.g;
        1.0 / libm::sqrt(1.0 + r * r * r * r)
    }

    /// The same filter's coefficients in the paper's direct form (eq. 23), `f64`.
    pub fn eq23_coefficients(&self) -> ([f64; 3], [f64; 2]) {
        eq23_coefficients_for(self.g)
    }
}

/// `s + d` with Kahan compensation `c`: returns the new sum and compensation. Without it, the
/// increments of a 5 Hz filter at 8 kHz fall below half an ulp of the state near steady state and
/// are lost (a dead band of ~2·10⁻⁵ of the signal).
#[inline(always)]
fn compensated_add(s: f32, d: f32, c: f32) -> (f32, f32) {
    let u = d - c;
    let t = s + u;
    (t, (t - s) - u)
}

/// Eq. 23's `b₀, b₁, b₂` and `a₁, a₂` (`y_k = a₁y_{k−1} + a₂y_{k−2} + b₀x_k + b₁x_{k−1} + b₂x_{k−2}`)
/// of the bilinear Butterworth low-pass at `cutoff_hz` for `rate_hz` (no validation).
pub fn eq23_coefficients(cutoff_hz: f64, rate_hz: f64) -> ([f64; 3], [f64; 2]) {
    eq23_coefficients_for(libm::tan(PI * cutoff_hz / rate_hz))
}

fn eq23_coefficients_for(g: f64) -> ([f64; 3], [f64; 2]) {
    let d = 1.0 + SQRT_2 * g + g * g;
    let b0 = g * g / d;
    let a1 = 2.0 * (1.0 - g * g) / d;
    let a2 = -(1.0 - SQRT_2 * g + g * g) / d;
    ([b0, 2.0 * b0, b0], [a1, a2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_cutoffs_are_refused() {
        assert_eq!(
            Butterworth2::low_pass(100.0, 200.0),
            Err(Error::CutoffAboveNyquist)
        );
        assert_eq!(
            Butterworth2::low_pass(150.0, 200.0),
            Err(Error::CutoffAboveNyquist)
        );
        assert!(Butterworth2::low_pass(0.0, 200.0).is_err());
        assert!(Butterworth2::low_pass(f64::NAN, 200.0).is_err());
        assert_eq!(
            Butterworth2::low_pass(5.0, f64::INFINITY),
            Err(Error::InvalidRate)
        );
        assert!(Butterworth2::low_pass(99.9, 200.0).is_ok());
    }

    #[test]
    fn state_variable_form_matches_the_direct_form_in_f64() {
        // Same transfer function: the impulse responses agree to f32 precision.
        let mut svf = Butterworth2::low_pass(5.0, 200.0).unwrap();
        let (b, a) = svf.eq23_coefficients();
        let (mut x1, mut x2, mut y1, mut y2) = (0.0, 0.0, 0.0, 0.0);
        for k in 0..400 {
            let x = if k == 0 { 1.0 } else { 0.0 };
            let y = a[0] * y1 + a[1] * y2 + b[0] * x + b[1] * x1 + b[2] * x2;
            (x2, x1, y2, y1) = (x1, x, y1, y);
            let s = f64::from(svf.process(x as f32));
            assert!((s - y).abs() < 1e-7, "k = {k}: {s} vs {y}");
        }
    }
}
