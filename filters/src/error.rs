//! The one error type of the crate: what was wrong with a filter configuration.
//!
//! Constructors validate a configuration once; after that, `update` cannot fail and never panics.
//!
//! ```
//! use margemu_filters::{Ecf, EcfConfig, Error};
//! let cfg = EcfConfig { kp: -1.0, ..EcfConfig::default() };
//! let err = Ecf::<f32>::new(&cfg).unwrap_err();
//! assert_eq!(err, Error::NegativeParameter { what: "kp" });
//! assert_eq!(err.to_string(), "parameter `kp` must not be negative");
//! ```

use core::fmt;

/// What was wrong with a configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is NaN or infinite; `what` names it.
    NonFiniteParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter is finite in `f64` but beyond the range of the filter's scalar type (`f32`).
    ParameterTooLarge {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter that must not be negative is negative.
    NegativeParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// A parameter that must be strictly positive is zero or negative.
    NonPositiveParameter {
        /// The configuration field.
        what: &'static str,
    },
    /// The magnetic reference field is the zero vector.
    ZeroMagneticReference,
    /// The magnetic reference field is (almost) vertical: heading would be unobservable.
    VerticalMagneticReference,
    /// The initial attitude is the zero quaternion.
    ZeroInitialAttitude,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NonFiniteParameter { what } => write!(f, "parameter `{what}` must be finite"),
            Error::ParameterTooLarge { what } => {
                write!(
                    f,
                    "parameter `{what}` is beyond the range of the filter's float type"
                )
            }
            Error::NegativeParameter { what } => {
                write!(f, "parameter `{what}` must not be negative")
            }
            Error::NonPositiveParameter { what } => write!(f, "parameter `{what}` must be > 0"),
            Error::ZeroMagneticReference => f.write_str("the magnetic reference field is zero"),
            Error::VerticalMagneticReference => f.write_str(
                "the magnetic reference field is vertical (less than 0.1 % horizontal): heading \
                 is unobservable",
            ),
            Error::ZeroInitialAttitude => f.write_str("the initial attitude quaternion is zero"),
        }
    }
}

impl core::error::Error for Error {}
