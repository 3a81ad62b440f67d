#![doc = include_str!("../README.md")]
#![no_std]
#![warn(missing_docs)]

pub mod ecf;
pub mod ekf;
pub mod error;
pub mod filter;
pub mod gda;
pub mod init;
pub mod quat;
pub mod real;

pub use ecf::{Ecf, EcfConfig};
pub use ekf::{Ekf, EkfConfig};
pub use error::Error;
pub use filter::{run, run_stamped, AttitudeFilter, Diagnostics, Imu};
pub use gda::{Gda, GdaConfig, GdaNormalization};
pub use init::Initial;
pub use real::Real;
