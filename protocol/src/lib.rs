//! The host ↔ firmware link of margemu, and the register maps of the emulated chips.
//!
//! Layers, bottom up (filled in by the link work, issue 4):
//! - **frame**: COBS framing with a CRC; a stream accumulator that returns outcomes as values;
//! - **message**: handshake, configuration, sample batches, flow-control credits, telemetry;
//! - **register map**: addresses, reset values and masks of each emulated chip.
//!
//! The crate is `no_std`, allocation-free, and never panics on any input.
#![no_std]
#![warn(missing_docs)]

/// Version of the link protocol spoken by this crate.
pub const PROTOCOL_VERSION: u16 = 0;
