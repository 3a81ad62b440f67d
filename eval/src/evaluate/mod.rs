//! Scoring an attitude estimator against ground truth: the paper's section 3.2 (MSE and STD per
//! Euler angle, `F` of eq. 27) plus the quaternion geodesic error, after aligning the device's
//! output in time, overall and per phase (static, dynamic, magnetic perturbation).
//!
//! Layers, bottom up:
//! - [`quat`]: attitude arithmetic on `[w, x, y, z]` (`q ≡ −q`, angles wrapped into (−π, π]);
//! - [`score`](mod@score): the in-process API, no files: [`score()`], or [`Reference`] +
//!   [`Estimates`] to score many estimates against one truth (a tuner); [`stats`]: the summary;
//! - [`align`]: the device's latency (geodesic error minimised over lags, refined below one
//!   sample) and its clock's offset and drift (least squares on device against host time);
//! - [`faults`]: the error inside each fault window of the scene and the time to recover;
//! - [`phase`]: the phase rules; [`signals`]: their magnitudes from measured signals;
//! - [`input`] and [`device_log`]: the files (`truth.csv`, `dut_attitude.csv`, estimates,
//!   external recordings, `meta.toml`, `sent.csv`), every bad value located;
//! - [`run`]: one evaluation from files ([`evaluate()`], [`evaluate_writing`]), read by `load`
//!   into re-readable series (`series`: a file on disk, read again for each pass) and walked with
//!   a window of the truth (`walk`), so memory does not grow with the run; [`report`] and
//!   [`plot`]: its table, `report.md`, `errors.csv` (written row by row) and the figures (PNG
//!   and SVG) from series thinned as they come ([`thin`]).
//!
//! Filters plug in as data: anything that turns IMU samples into quaternions produces an
//! estimate list ([`estimate_with`] runs such a step function over an external recording's
//! samples), which [`score()`] takes. Nothing here depends on a filter crate.

pub mod align;
pub mod device_log;
pub mod faults;
pub mod input;
mod load;
pub mod phase;
pub mod plot;
pub use margemu_sim::quat;
pub mod report;
pub mod run;
pub mod score;
mod series;
pub mod signals;
pub mod stats;
pub mod thin;
mod walk;

pub use align::{estimate_latency, fit_clock, ClockFit, Latency, LatencySearch};
pub use phase::{Phase, PhaseRules};
pub use run::{
    evaluate, evaluate_writing, EvalError, EvalOptions, Evaluation, LatencyMode, Mask, Source,
};
pub use score::{
    heading_inclination, score, Compared, Estimates, Reference, ScoreError, ScoreOptions, Scores,
    Stamped,
};

/// Steps whose median is the time step of the first sample (which has no predecessor): those
/// of the first samples only, so a reader that streams a long recording need not hold it.
pub const FIRST_STEP_WINDOW: usize = 65_536;

/// The time step (s) given to the first sample of `t_ns` (the first instants of a recording, at
/// least [`FIRST_STEP_WINDOW`]` + 1` of them when it has that many): the median step between
/// them, 0 for a single sample.
pub fn first_step_s(t_ns: &[u64]) -> f64 {
    let head = &t_ns[..t_ns.len().min(FIRST_STEP_WINDOW + 1)];
    let mut steps: Vec<u64> = head.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_unstable();
    steps.get(steps.len() / 2).copied().unwrap_or(0) as f64 * 1e-9
}

/// Runs `step` over IMU samples in order and stamps each quaternion it returns with the
/// sample's instant: `step(k, dt)` gets the sample index and the time since the previous sample
/// (s; [`first_step_s`] for the first). The seam through which an attitude filter (`update` then
/// `quaternion`) produces estimates for [`score()`].
pub fn estimate_with(
    imu: &input::Imu,
    mut step: impl FnMut(usize, f64) -> quat::Quat,
) -> Vec<Stamped> {
    let t = &imu.t_ns;
    let first = first_step_s(t);
    (0..t.len())
        .map(|k| {
            let dt = if k == 0 {
                first
            } else {
                (t[k] - t[k - 1]) as f64 * 1e-9
            };
            (t[k], step(k, dt))
        })
        .collect()
}
