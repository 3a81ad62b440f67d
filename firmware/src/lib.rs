//! Firmware library of margemu: the emulated chip (register file, SPI/I2C target state machines)
//! and the link handler. It is `no_std` and host-testable; the board crates under `boards/` are
//! thin binaries around it.
//!
//! - [`chip`]: the emulated MARG chips behind the [`chip::SpiTarget`] and [`chip::I2cTarget`]
//!   bus-target traits that a board's peripheral interrupts (or the host's embedded-hal
//!   adapters) drive byte by byte.
//! - [`link`]: the device side of the host link: frames in through the shared accumulator,
//!   samples (register images, or kinematics through the shared model) swapped into the chip at
//!   each sample instant, credits, telemetry and register writes out.
//! - [`fault`]: the rig's fault schedule as the host sent it (`margemu_model::fault`).
//! - [`budget`]: what an output sample of source mode (b) costs the Cortex-M4F per chip, term
//!   and chain feature, and the fastest rate a board sustains (the host refuses scenes beyond).
//! - [`bus_fault`]: the schedule's bus faults (NAK, corrupted bytes, clock stretching) applied
//!   to a chip's bus target, by the boards and by the host's virtual buses alike.
//! - [`chain_bench`]: the sampling-chain benchmark cases the host and the Cortex-M4F both run
//!   (bit-identity and cost of `margemu_model::chain`).
//! - [`model_bench`]: the per-sample cost of source mode (b) (kinematics hold, sensor model,
//!   chain, image and latch) per model configuration, on the host and the Cortex-M4F alike.
//! - [`spi_shadow`]: for boards whose SPI target cannot answer the address byte in time: the
//!   register file served from a shadow with a speculative burst preload, every transaction
//!   replayed into the chip and checked.
#![no_std]
#![warn(missing_docs)]

pub mod budget;
pub mod bus_fault;
pub mod chain_bench;
pub mod chip;
pub mod fault;
pub mod link;
pub mod model_bench;
pub mod spi_shadow;

pub use margemu_model as model;
pub use margemu_protocol as protocol;
