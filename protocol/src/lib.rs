//! The host ↔ firmware link of margemu, and the register maps of the emulated chips.
//!
//! Layers, bottom up:
//! - [`link`]: frames (COBS + CRC), the stream accumulator that returns outcomes as values, and
//!   the messages (handshake, configuration, sample batches, flow control, telemetry);
//! - [`regmap`]: addresses, reset values, masks and physical ↔ register conversions of each
//!   emulated chip, shared by the firmware (which serves them) and the host (which predicts them);
//! - [`chip`]: the boundary over them: the chip models, their register images and conversions,
//!   which everything outside a chip module uses instead of naming a register.
//!
//! The crate is `no_std`, allocation-free, and never panics on any input. The bytes are written
//! down in `docs/spec/`.
#![no_std]
#![warn(missing_docs)]

pub mod chip;
pub mod link;
pub mod regmap;

/// The crate's one error type (link framing, messages and their buffers).
pub use link::Error;

/// Version of the link protocol spoken by this crate.
pub const PROTOCOL_VERSION: u16 = 4;
