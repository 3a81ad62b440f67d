//! One evaluation from files: reads a source (module `load`), aligns the estimates, scores
//! them overall and per phase, and keeps what the report and the figures need. The in-process
//! scoring functions ([`score`](mod@super::score)) do the numbers; this module only feeds them.

use super::align::{estimate_latency, ClockFit, Latency, LatencySearch};
use super::device_log::SessionFileError;
use super::phase::{classify, Phase, PhaseRules};
use super::score::{Compared, Estimates, Reference, ScoreError, ScoreOptions, Scores};
use crate::csv_column::ColumnError;
use std::path::PathBuf;

/// What to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub enum Source {
    /// A session directory: `truth.csv`, `meta.toml` (or `events.csv`), `dut_attitude.csv`, and
    /// `sent.csv` for the measured norms.
    Session(PathBuf),
    /// A run directory with `truth.csv` (from `simulate` or a session) and an estimates file
    /// `t_s,qw,qx,qy,qz` on the scene's time axis.
    Estimates {
        /// The run directory.
        dir: PathBuf,
        /// The estimates file.
        estimates: PathBuf,
    },
    /// An external recording with a reference quaternion, scored against its own estimate
    /// columns or an estimates file (same time axis as the recording).
    External {
        /// The recording.
        file: PathBuf,
        /// Estimates instead of the `*_est` columns.
        estimates: Option<PathBuf>,
    },
}

/// How the latency is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatencyMode {
    /// The estimated latency when it is observable, else 0.
    Auto,
    /// This latency (ns), whatever the estimate says.
    Fixed(i64),
}

/// Options of one evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalOptions {
    /// `None`: `Auto` for sessions, `Fixed(0)` for estimates and external recordings (offline
    /// filter runs are aligned by construction; their own lag is part of their error).
    pub latency: Option<LatencyMode>,
    /// The latency search; its `score` options (warm-up, largest gap) also apply to scoring.
    pub search: LatencySearch,
    /// Keep only `dut_attitude.csv` rows with this `message`.
    pub message: Option<String>,
    /// Stamp device output with its own clock through the clock fit, when it can be.
    pub device_time: bool,
    /// Phase thresholds.
    pub rules: PhaseRules,
    /// Score a run directory whose completion record is missing or not `complete`
    /// ([`crate::rundir::check_complete`]), with a note saying so, instead of refusing it.
    pub allow_incomplete: bool,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            latency: None,
            search: LatencySearch::default(),
            message: None,
            device_time: true,
            rules: PhaseRules::default(),
            allow_incomplete: false,
        }
    }
}

/// An evaluation that could not be done. Each message is complete (file, line, cause), so the
/// variants wrapping another error show it rather than chain it.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum EvalError {
    /// {0}
    Column(ColumnError),
    /// {0}
    SessionFile(SessionFileError),
    /// {path}: {reason}
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// {context}: {reason}
    Score {
        /// The files compared.
        context: String,
        /// Why.
        reason: ScoreError,
    },
    /// {0}
    Plot(crate::analysis::plot::PlotError),
    /// {0}
    RunDir(#[from] crate::rundir::RunDirError),
    /// {path}: cannot write: {error}
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
}

impl From<ColumnError> for EvalError {
    fn from(e: ColumnError) -> Self {
        Self::Column(e)
    }
}

impl From<SessionFileError> for EvalError {
    fn from(e: SessionFileError) -> Self {
        Self::SessionFile(e)
    }
}

impl From<crate::analysis::plot::PlotError> for EvalError {
    fn from(e: crate::analysis::plot::PlotError) -> Self {
        Self::Plot(e)
    }
}

/// The device clock, as far as the output shows it.
#[derive(Clone, Debug, PartialEq)]
pub enum Clock {
    /// No row had a device time.
    Absent,
    /// The fit, and whether it stamped the estimates.
    Fitted(ClockFit, bool),
    /// Device times were there but unusable (why).
    Unusable(String),
}

/// Accelerometer and magnetometer norms for the figures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Norms {
    /// Where they come from.
    pub source: String,
    /// Instants (ns, scene axis).
    pub t_ns: Vec<u64>,
    /// `|a|` (m/s²).
    pub acc: Vec<f64>,
    /// `|m|` (field unit).
    pub mag: Vec<f64>,
}

/// Everything one evaluation found.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// The files read, one line each.
    pub inputs: Vec<String>,
    /// Notes on the input (dropped rows, consistency).
    pub notes: Vec<String>,
    /// The truth.
    pub reference: Reference,
    /// The phase of every truth instant.
    pub phases: Vec<Phase>,
    /// The latency search (`None` when no lag overlapped).
    pub latency: Option<Latency>,
    /// The latency applied (ns).
    pub latency_applied_ns: i64,
    /// Why that latency.
    pub latency_reason: String,
    /// The device clock.
    pub clock: Clock,
    /// Every scored instant.
    pub compared: Vec<Compared>,
    /// Scores over every scored instant.
    pub scores: Scores,
    /// Scores per phase (`None`: no instant of that phase).
    pub by_phase: Vec<(Phase, Option<Scores>)>,
    /// Options used.
    pub options: EvalOptions,
    /// Norms for the figures.
    pub norms: Norms,
}

/// Runs one evaluation (see the module docs).
pub fn evaluate(source: &Source, options: &EvalOptions) -> Result<Evaluation, EvalError> {
    let incomplete = match source {
        Source::Session(dir) | Source::Estimates { dir, .. } => {
            crate::rundir::check_complete(dir, options.allow_incomplete)?
        }
        Source::External { .. } => None,
    };
    let mut loaded = super::load::load(source, options)?;
    loaded.notes.extend(incomplete);
    let context = || loaded.inputs.join(", ");
    let scored = |reason| EvalError::Score {
        context: context(),
        reason,
    };
    let reference = Reference::new(&loaded.truth).map_err(scored)?;
    let estimates = Estimates::new(&loaded.estimates).map_err(scored)?;
    let latency = estimate_latency(&reference, &estimates, &options.search);
    let mode = options.latency.unwrap_or(loaded.default_latency);
    let (latency_applied_ns, latency_reason) = match (mode, &latency) {
        (LatencyMode::Fixed(ns), _) => (ns, "fixed by the caller".to_string()),
        (LatencyMode::Auto, Some(l)) if l.observable => (l.lag_ns, "estimated".to_string()),
        (LatencyMode::Auto, Some(l)) if l.at_edge => (
            0,
            "the best lag is at the end of the search range (raise --max-lag); 0 applied".into(),
        ),
        (LatencyMode::Auto, _) => (0, "not observable (too little motion); 0 applied".into()),
    };
    let opts = ScoreOptions {
        latency_ns: latency_applied_ns,
        ..options.search.score
    };
    let compared = reference.compare(&estimates, &opts).map_err(scored)?;
    let scores = Scores::from_compared(compared.iter()).expect("compare returns at least one");
    let phases = classify(
        &loaded.phase_samples,
        &options.rules,
        reference.median_step_ns(),
    );
    let by_phase = Phase::ALL
        .iter()
        .map(|&p| {
            let of_phase = compared.iter().filter(|c| phases.get(c.index) == Some(&p));
            (p, Scores::from_compared(of_phase))
        })
        .collect();
    Ok(Evaluation {
        inputs: loaded.inputs,
        notes: loaded.notes,
        reference,
        phases,
        latency,
        latency_applied_ns,
        latency_reason,
        clock: loaded.clock,
        compared,
        scores,
        by_phase,
        options: options.clone(),
        norms: loaded.norms,
    })
}
