//! The numerical core that host and firmware share, so that both produce bit-identical samples.
//!
//! - [`time`]: time as integer nanoseconds and the sample clock that turns an output rate into
//!   exact sample instants without drift;
//! - [`rng`]: one seeded generator per named stream, so every random draw is reproducible.
//!
//! The crate is `no_std` with no allocation. Transcendental functions come from `libm` on every
//! target (never `std`), and arithmetic order is fixed, so x86-64 and Cortex-M agree bit for bit.
#![no_std]
#![warn(missing_docs)]

pub mod rng;
pub mod time;
