//! margemu: the `margemu` command and the parts that need every layer beneath it. The
//! libraries, bottom up:
//!
//! - `margemu-sim` ([`scene`], [`bench`](mod@bench), [`truth`], [`marg`], [`run`], [`meta`],
//!   [`rundir`], ...): a scene file to the bench, its ground truth, MARG samples and a run
//!   directory;
//! - `margemu-hil` ([`stream`], [`loopback`], [`bus`], [`dut`], [`vfc`]): real-time streaming to
//!   an emulated chip and the device under test's output;
//! - `margemu-eval` ([`evaluate`](mod@evaluate), [`analysis`], [`offline`], [`tune`](mod@tune)):
//!   scores, noise analysis, offline filters and tuning.
//!
//! Each library's modules are re-exported here under their own names, so `margemu::scene` is
//! `margemu_sim::scene`. This crate adds:
//! - [`demo`]: the case study through loopback with the virtual flight controller (Table 3);
//! - [`vfc_score`]: a virtual flight controller's session scored against the truth;
//! - [`own_files`]: every file name margemu writes into a run or session directory;
//! - [`perf`]: speed-against-error benchmarks behind `margemu bench`.
#![warn(missing_docs)]

pub use margemu_eval::{analysis, evaluate, frame, offline, tune};
pub use margemu_hil::{bus, dut, hitl, loopback, realtime, stream, vfc};
pub use margemu_sim::{
    bench, csv_column, filter_params, guard, input_file, marg, mcap, meta, motion, output, quat,
    reference, run, rundir, sampling, scene, truth,
};

pub mod demo;
pub mod own_files;
pub mod perf;
pub mod perf_chain;
pub mod perf_faults;
pub mod perf_mcap;
pub mod vfc_score;
