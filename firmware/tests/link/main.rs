//! The firmware link handler against a fake clock and in-memory byte streams: the host side is
//! the protocol's own `Encoder`, the device's output is decoded with the shared `Accumulator`.

mod bmi088;
mod bmi270;
mod common;
mod faults;
mod fuzz_device;
mod model;
mod rig;
mod robustness;
mod session;
mod streaming;
mod vibration;
