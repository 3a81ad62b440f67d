//! The one error type of the crate.
//!
//! Every constructor validates its configuration once and returns an [`Error`] that names what was
//! wrong; after that, the per-sample functions cannot fail and never panic. The enum is flat and
//! `#[non_exhaustive]` (as postcard's `Error`), so new checks can be added without breaking callers.
//!
//! ```
//! use margemu_model::perturbation::{PerturbationConfig, PerturbationPlan};
//! use margemu_model::Error;
//! let cfg = PerturbationConfig { window_s: 0.01, ..PerturbationConfig::default() };
//! let err = PerturbationPlan::new(&cfg, 200.0).unwrap_err();
//! assert_eq!(err, Error::PerturbationWindowTooShort { samples: 2 });
//! assert_eq!(err.to_string(), "perturbation window of 2 samples is shorter than 10 samples");
//! ```

use core::fmt;

/// What was wrong with a configuration or a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// The output rate is not finite or not positive.
    InvalidRate,
    /// A parameter is NaN or infinite; `what` names it (e.g. `"gyro.noise_density"`).
    NonFiniteParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter is finite in `f64` but beyond the range of `f32`, in which the per-sample path
    /// runs; `what` names it.
    ParameterTooLarge {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter that must not be negative is negative; `what` names it.
    NegativeParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter that must be strictly positive is zero or negative; `what` names it.
    NonPositiveParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// The perturbation window holds fewer than 10 samples (one sample per waveform block).
    PerturbationWindowTooShort {
        /// The window length in samples, `round(window_s · rate)`.
        samples: usize,
    },
    /// The perturbation window holds more samples than [`crate::perturbation::MAX_WINDOW_SAMPLES`].
    PerturbationWindowTooLong,
    /// The low-pass cutoff is at or above the Nyquist frequency of the output rate.
    CutoffAboveNyquist,
    /// The burst amplitude range is empty at zero: every burst would be zero.
    ZeroAmplitudeRange,
    /// The burst amplitude range has `lo > hi`.
    InvertedAmplitudeRange,
    /// The quiet time between bursts has `lo > hi`.
    InvertedGapRange,
    /// The perturbation direction is the zero vector.
    ZeroDirection,
    /// A caller-supplied buffer is shorter than required.
    BufferTooSmall {
        /// Elements required.
        needed: usize,
        /// Elements supplied.
        got: usize,
    },
    /// The FFT length is too large to plan (its Bluestein length overflows `usize`).
    FftTooLong,
    /// More vibration sources, harmonics or shocks than a sensor holds.
    TooManyVibrationSources,
    /// Random vibration is given for the gyroscope (it is linear acceleration only).
    RandomVibrationNotLinear,
    /// A tone source has no motor or more than [`crate::vibration::MAX_MOTORS`].
    InvalidMotorCount,
    /// An rpm profile is empty or its instants go backwards.
    InvalidRpmProfile,
    /// A PSD has fewer than 2 or more than [`crate::vibration::MAX_PSD_POINTS`] breakpoints, or
    /// its frequencies do not increase.
    InvalidPsd,
    /// A PSD's lowest breakpoint is too low for the internal rate (the synthesis block would
    /// exceed [`crate::vibration::random::MAX_FFT_LEN`] samples).
    PsdTooFine,
    /// A chip's sampling chain cannot be built for its configuration (a scene check missed it).
    ChainRefused,
    /// A filter order outside 1 to [`crate::chain::filter::MAX_ORDER`].
    FilterOrder {
        /// The order asked for.
        order: u8,
    },
    /// A filter design needs more than [`crate::chain::filter::MAX_SECTIONS`] sections.
    TooManyFilterSections,
    /// Two filter designs cascaded run at different rates.
    FilterRateMismatch,
    /// A filter's pure delay exceeds [`crate::chain::filter::MAX_DELAY`] samples.
    FilterDelayTooLong {
        /// The delay asked for, samples.
        samples: usize,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::InvalidRate => f.write_str("output rate is not a finite positive number"),
            Error::NonFiniteParameter { what } => write!(f, "{what} is not finite"),
            Error::ParameterTooLarge { what } => {
                write!(f, "{what} exceeds the single-precision range")
            }
            Error::NegativeParameter { what } => write!(f, "{what} is negative"),
            Error::NonPositiveParameter { what } => write!(f, "{what} must be positive"),
            Error::PerturbationWindowTooShort { samples } => write!(
                f,
                "perturbation window of {samples} samples is shorter than 10 samples"
            ),
            Error::PerturbationWindowTooLong => write!(
                f,
                "perturbation window is longer than {} samples",
                crate::perturbation::MAX_WINDOW_SAMPLES
            ),
            Error::CutoffAboveNyquist => {
                f.write_str("low-pass cutoff is at or above the Nyquist frequency")
            }
            Error::ZeroAmplitudeRange => f.write_str("burst amplitude range is zero"),
            Error::InvertedAmplitudeRange => {
                f.write_str("burst amplitude range has its lower bound above its upper bound")
            }
            Error::InvertedGapRange => {
                f.write_str("burst gap range has its lower bound above its upper bound")
            }
            Error::ZeroDirection => f.write_str("perturbation direction is the zero vector"),
            Error::BufferTooSmall { needed, got } => {
                write!(f, "buffer holds {got} elements, {needed} are needed")
            }
            Error::FftTooLong => f.write_str("FFT length too large to plan"),
            Error::TooManyVibrationSources => write!(
                f,
                "too many vibration sources for one sensor (at most {} tone sources of {} \
                 harmonics, {} shocks, one random source)",
                crate::vibration::MAX_TONE_SOURCES,
                crate::vibration::MAX_HARMONICS,
                crate::vibration::MAX_SHOCKS
            ),
            Error::RandomVibrationNotLinear => {
                f.write_str("random vibration is linear acceleration only")
            }
            Error::InvalidMotorCount => write!(
                f,
                "a tone source needs 1 to {} motors",
                crate::vibration::MAX_MOTORS
            ),
            Error::InvalidRpmProfile => {
                f.write_str("an rpm profile needs at least one point, in time order")
            }
            Error::InvalidPsd => write!(
                f,
                "a PSD needs 2 to {} breakpoints with increasing frequencies",
                crate::vibration::MAX_PSD_POINTS
            ),
            Error::ChainRefused => {
                f.write_str("the chip's sampling chain cannot be built for its configuration")
            }
            Error::PsdTooFine => write!(
                f,
                "the PSD's lowest breakpoint is too low for the internal rate (synthesis block \
                 over {} samples)",
                crate::vibration::random::MAX_FFT_LEN
            ),
            Error::FilterOrder { order } => write!(
                f,
                "filter order {order} is outside 1 to {}",
                crate::chain::filter::MAX_ORDER
            ),
            Error::TooManyFilterSections => write!(
                f,
                "filter design needs more than {} sections",
                crate::chain::filter::MAX_SECTIONS
            ),
            Error::FilterRateMismatch => {
                f.write_str("cascaded filter designs run at different rates")
            }
            Error::FilterDelayTooLong { samples } => write!(
                f,
                "filter delay of {samples} samples exceeds {} samples",
                crate::chain::filter::MAX_DELAY
            ),
        }
    }
}

impl core::error::Error for Error {}

/// Checks that `x` is finite and representable as a finite `f32`.
pub(crate) fn finite(x: f64, what: &'static str) -> Result<f64, Error> {
    if !x.is_finite() {
        Err(Error::NonFiniteParameter { what })
    } else if !(x as f32).is_finite() {
        Err(Error::ParameterTooLarge { what })
    } else {
        Ok(x)
    }
}

/// Checks that `x` is finite and not negative.
pub(crate) fn non_negative(x: f64, what: &'static str) -> Result<f64, Error> {
    if finite(x, what)? < 0.0 {
        Err(Error::NegativeParameter { what })
    } else {
        Ok(x)
    }
}

/// Checks that `x` is finite and strictly positive.
pub(crate) fn positive(x: f64, what: &'static str) -> Result<f64, Error> {
    if finite(x, what)? > 0.0 {
        Ok(x)
    } else {
        Err(Error::NonPositiveParameter { what })
    }
}

/// Checks every component of `v` with `check`.
pub(crate) fn each3(
    v: [f64; 3],
    what: &'static str,
    check: fn(f64, &'static str) -> Result<f64, Error>,
) -> Result<[f64; 3], Error> {
    for x in v {
        check(x, what)?;
    }
    Ok(v)
}

/// Checks that every entry of `m` is finite.
pub(crate) fn finite3x3(m: [[f64; 3]; 3], what: &'static str) -> Result<[[f64; 3]; 3], Error> {
    for row in m {
        each3(row, what, finite)?;
    }
    Ok(m)
}
