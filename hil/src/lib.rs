//! margemu hardware in the loop: a scene streamed in real time to an emulated chip, in the
//! firmware's link handler behind a pseudo-terminal pair or on a device behind a serial port,
//! and the device under test's output read back. Built on `margemu-sim`; independent of the
//! evaluation library (no plotting, no optimiser).
//!
//! - [`bus`]: embedded-hal 1.0 adapters (SPI, I2C, delay) that put the emulated chip under
//!   unmodified drivers;
//! - [`stream`]: real-time streaming of register images or kinematics to a device, with session
//!   logs;
//! - [`loopback`]: the firmware's link handler behind a pseudo-terminal pair (the embedded
//!   default);
//! - [`dut`]: the device under test's attitude output (MAVLink or MSP) read from a second port
//!   and logged;
//! - [`hitl`]: a scene sent as MAVLink HIL_SENSOR to a flight controller in HITL mode, its
//!   attitude read back;
//! - [`vfc`]: a virtual flight controller on the loopback device (the chip's third-party
//!   driver, a reference filter, MAVLink out).
#![warn(missing_docs)]

pub mod bus;
pub mod dut;
pub mod hitl;
pub mod loopback;
pub mod realtime;
pub mod stream;
pub mod vfc;
