//! margemu simulation: a scene file becomes the 6-DOF test bench of Odry (2021), its ground
//! truth and the MARG samples of the shared sensor model, written to a run directory. The
//! hardware-in-the-loop (`margemu-hil`) and evaluation (`margemu-eval`) libraries build on it;
//! it depends on neither, nor on anything that talks to a port or draws a figure.
//!
//! Layers, bottom up:
//! - [`input_file`]: every file a scene or a command reads is a regular file of bounded size;
//!   [`csv_column`]: named numeric columns of CSV files; [`csv_row`]: the rows margemu writes;
//! - [`scene`]: the TOML scene file, validated with errors that point at file, line and column;
//! - [`reference`](mod@reference): each joint's reference signal (steps, waypoints, sines, random, CSV);
//! - [`bench`](mod@bench): the closed-loop bench (eq. 5–17): joints, friction, PID synthesis, integrators;
//! - [`motion`]: static, kinematic or bench motion, so a scene pays only for what it uses;
//! - [`truth`]: ground truth of the plate (attitude, rates, specific force, field) per sample;
//! - [`marg`]: raw MARG samples from the shared `model` crate (eq. 18, perturbation eq. 19–23);
//! - [`guard`]: the run stops at the first truth or sample value that is not finite;
//! - [`run`] and [`output`]: the sample loop and the run directory (`truth.csv`, `marg.csv`);
//! - [`meta`]: the schema of `meta.toml`, written and read by the same types;
//! - [`fault_log`]: the fault windows' rows of `events.csv`, written and read by one format;
//! - [`rundir`]: which directory a run writes to, and the completion record written last;
//! - [`frame`]: named world frames (NWU, ENU, NED/FRD) and the one NED map;
//! - [`quat`]: attitude quaternions as the logs and scores use them (normalisation, Euler
//!   angles, geodesic distance, interpolation);
//! - [`filter_params`]: which reference filter runs with which parameters, and their file
//!   (shared by the offline filters, the tuner and the virtual flight controller).
#![warn(missing_docs)]

pub mod bench;
pub mod csv_column;
pub mod csv_row;
pub mod csv_table;
pub mod fault_log;
pub mod filter_params;
pub mod frame;
pub mod guard;
pub mod input_file;
pub mod marg;
pub mod mcap;
pub mod meta;
pub mod motion;
pub mod output;
pub mod quat;
pub mod reference;
pub mod run;
pub mod rundir;
pub mod sampling;
pub mod scene;
pub mod truth;
