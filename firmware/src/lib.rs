//! Firmware library of margemu: the emulated chip (register file, SPI/I2C target state machines)
//! and the link handler. It is `no_std` and host-testable; the board crates under `boards/` are
//! thin binaries around it. The chip and link work land with issues 4 and 5.
#![no_std]
#![warn(missing_docs)]

pub use margemu_model as model;
pub use margemu_protocol as protocol;
