//! margemu host: simulates the 6-DOF test bench of Odry (2021), computes ground truth, and
//! (in later layers) streams samples to the emulated chip and scores the device under test.
//!
//! Layers, bottom up:
//! - [`scene`]: the TOML scene file, validated with errors that point at file, line and column;
//!   [`input_file`]: every file a scene reads is a regular file of bounded size;
//! - [`reference`](mod@reference): each joint's reference signal (steps, waypoints, sines, random, CSV);
//! - [`bench`](mod@bench): the closed-loop bench (eq. 5–17): joints, friction, PID synthesis, integrators;
//! - [`motion`]: static, kinematic or bench motion, so a scene pays only for what it uses;
//! - [`truth`]: ground truth of the plate (attitude, rates, specific force, field) per sample;
//! - [`bus`]: embedded-hal 1.0 adapters (SPI, I2C, delay) that put the emulated chip under unmodified drivers;
//! - [`marg`]: raw MARG samples from the shared `model` crate (eq. 18, perturbation eq. 19–23);
//! - [`guard`]: the run stops at the first truth or sample value that is not finite;
//! - [`run`] and [`output`]: the sample loop and the run directory (`truth.csv`, `meta.toml`);
//! - [`meta`]: the schema of `meta.toml`, written and read by the same types;
//! - [`rundir`]: which directory a run writes to, and the completion record written last;
//! - [`perf`]: speed-against-error benchmarks behind `margemu bench`;
//! - [`loopback`]: the firmware's link handler behind a pseudo-terminal pair (the embedded default);
//! - [`analysis`]: Allan deviation, PSD and their plots behind `margemu analyze`;
//! - [`stream`]: real-time streaming of register images to a device over a serial port, with session logs;
//! - [`evaluate`](mod@evaluate): scores of a device's or a filter's attitude against the truth (eq. 27, geodesic), aligned and split by phase.
//! - [`dut`]: the device under test's attitude output (MAVLink or MSP) read from a second port and logged;
//! - [`offline`]: the reference filters (`margemu-filters`) run over recorded samples, estimates written;
//! - [`tune`](mod@tune): a filter's parameters tuned on a scene over several seeds (Nelder–Mead, eq. 27);
//! - [`vfc`]: a virtual flight controller on the loopback device (the chip's third-party driver, `mpu9250` or `icm426xx`, a reference filter, MAVLink out);
//! - [`demo`]: the case study through loopback with the virtual flight controller (Table 3).
#![warn(missing_docs)]

pub mod analysis;
pub mod bench;
pub mod bus;
pub mod csv_column;
mod csv_table;
pub mod demo;
pub mod dut;
pub mod evaluate;
pub mod guard;
pub mod input_file;
pub mod loopback;
pub mod marg;
pub mod meta;
pub mod motion;
pub mod offline;
pub mod output;
pub mod perf;
pub mod reference;
pub mod run;
pub mod rundir;
pub mod scene;
pub mod stream;
pub mod truth;
pub mod tune;
pub mod vfc;
