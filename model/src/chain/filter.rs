//! The digital filters of a chip's sampling chain (CONTRACT STUB: the real designs land with the
//! chip chains; the API below is fixed).
//!
//! A [`FilterDesign`] is a cascade of at most [`MAX_SECTIONS`] second-order sections and a pure
//! delay of at most [`MAX_DELAY`] samples, designed once in `f64` at the internal rate it runs
//! at and rounded to `f32`. [`FilterDesign::step`] filters one internal sample of one axis in
//! `f32` with a fixed order of operations (host and firmware give the same bits) and never
//! panics. [`FilterDesign::gain_at`] and [`FilterDesign::delay_s`] evaluate the response the
//! `f32` coefficients actually have (for predictions and tests).

use crate::error::Error;

/// Most second-order sections in one design.
pub const MAX_SECTIONS: usize = 4;
/// Longest pure delay, in internal samples.
pub const MAX_DELAY: usize = 64;

/// A filter design at one internal rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterDesign {
    rate_hz: f64,
}

/// One axis's state of a [`FilterDesign`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilterState {
    _private: (),
}

impl FilterDesign {
    /// The identity (no filtering, no delay) at `rate_hz`.
    pub fn identity(rate_hz: f64) -> Result<Self, Error> {
        if rate_hz.is_finite() && rate_hz > 0.0 {
            Ok(Self { rate_hz })
        } else {
            Err(Error::InvalidRate)
        }
    }

    /// The internal rate the design runs at, Hz.
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// Filters one sample of one axis.
    #[inline]
    pub fn step(&self, _state: &mut FilterState, x: f32) -> f32 {
        x
    }

    /// The magnitude of the response at `f_hz` (linear, 1 = 0 dB).
    pub fn gain_at(&self, _f_hz: f64) -> f64 {
        1.0
    }

    /// The group delay at low frequency (sections and pure delay), seconds.
    pub fn delay_s(&self) -> f64 {
        0.0
    }
}
