//! One evaluation from files: reads a source (module `load`), aligns the estimates, scores
//! them overall and per phase in one pass that writes `errors.csv` row by row, and keeps what
//! the report and the figures need (statistics gathered online, traces thinned), so memory
//! does not grow with the length of the run. The arithmetic is that of the in-process scoring
//! functions ([`score`](mod@super::score)). The same pass scores each fault window of the
//! directory's `events.csv` ([`super::faults`]).

use super::align::{latency_of_series, ClockFit, Latency, LatencySearch};
use super::device_log::SessionFileError;
use super::faults::FaultScorer;
use super::load::Loaded;
use super::phase::{Phase, PhaseRules};
use super::quat::euler;
use super::report::ErrorsCsv;
use super::score::{after_warmup, compared, locate, Sample, ScoreError, ScoreOptions, Scores};
use super::stats::Accumulator;
use super::thin::{Pieces, Thinner};
use super::walk::Walk;
use margemu_sim::csv_column::ColumnError;
use std::path::{Path, PathBuf};

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

/// Which rows of an external recording are scored (rows without a reference never are).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Mask {
    /// Every row.
    #[default]
    All,
    /// Rows whose value in this column is nonzero.
    Column(String),
    /// Rows at rest: the gyro norm, averaged over [`PhaseRules::window_ns`] as the phases
    /// average it, below this rate (rad/s).
    Rest(f64),
    /// Rows in motion: that averaged gyro norm at or above this rate (rad/s).
    Motion(f64),
}

/// Options of one evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalOptions {
    /// The world frame of an external recording and its estimates ([`crate::frame`]); their
    /// quaternions are converted into margemu's as they are read.
    pub frame: crate::frame::Frame,
    /// The rows of an external recording to score (ignored for other sources). An estimate is
    /// scored when the recording row nearest its aligned instant is.
    pub mask: Mask,
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
    /// ([`margemu_sim::rundir::check_complete`]), with a note saying so, instead of refusing it.
    pub allow_incomplete: bool,
    /// How recovery after a fault window is judged ([`super::faults`]).
    pub faults: super::faults::FaultOptions,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            frame: crate::frame::Frame::Nwu,
            mask: Mask::All,
            latency: None,
            search: LatencySearch::default(),
            message: None,
            device_time: true,
            rules: PhaseRules::default(),
            allow_incomplete: false,
            faults: super::faults::FaultOptions::default(),
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
    RunDir(#[from] margemu_sim::rundir::RunDirError),
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

/// Accelerometer and magnetometer norms for the figures, thinned.
#[derive(Clone, Debug, Default)]
pub struct Norms {
    /// Where they come from.
    pub source: String,
    /// `|a|` (m/s²) against time (s).
    pub acc: Thinner,
    /// `|m|` (field unit) against time (s).
    pub mag: Thinner,
}

impl Norms {
    /// No norms yet, from `source`.
    pub fn new(source: &str) -> Self {
        Self {
            source: source.to_owned(),
            ..Self::default()
        }
    }

    /// Adds the norms of one sample at `t_ns`.
    pub fn push(&mut self, t_ns: u64, acc: &[f64; 3], mag: &[f64; 3]) {
        let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let t = t_ns as f64 * 1e-9;
        self.acc.push(t, norm(acc));
        self.mag.push(t, norm(mag));
    }
}

/// The attitudes the figures draw, thinned, with the phases to shade.
#[derive(Clone, Debug, Default)]
pub struct Traces {
    /// First and last truth instant (s).
    pub span_s: (f64, f64),
    /// Truth roll, pitch and yaw (°) at every truth instant.
    pub truth: [Pieces; 3],
    /// Estimated roll, pitch and yaw (°) at every scored instant (aligned).
    pub estimate: [Pieces; 3],
    /// Runs of equal phase: `(phase, first instant s, last instant s)`.
    pub phases: Vec<(Phase, f64, f64)>,
}

/// Everything one evaluation found.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Whether the estimates came from a recording's or a run's own time axis (an offline
    /// filter run, an external recording), not from a device's output stamped on arrival.
    pub recording: bool,
    /// The files read, one line each.
    pub inputs: Vec<String>,
    /// Notes on the input (dropped rows, consistency).
    pub notes: Vec<String>,
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
    /// Scores over every scored instant.
    pub scores: Scores,
    /// Scores per phase (`None`: no instant of that phase).
    pub by_phase: Vec<(Phase, Option<Scores>)>,
    /// Options used.
    pub options: EvalOptions,
    /// Norms for the figures.
    pub norms: Norms,
    /// Attitudes for the figures.
    pub traces: Traces,
    /// `errors.csv`, when it was written.
    pub errors_csv: Option<PathBuf>,
    /// Scores per fault window of the directory's `events.csv`, in schedule order
    /// ([`super::faults`]; empty without faults).
    pub faults: Vec<super::faults::FaultScore>,
}

/// Runs one evaluation (see the module docs) without writing `errors.csv`.
pub fn evaluate(source: &Source, options: &EvalOptions) -> Result<Evaluation, EvalError> {
    evaluate_writing(source, options, None)
}

/// Runs one evaluation, writing every scored instant to `errors_csv` (see
/// [`report`](super::report)) as it is scored, when given; its directory is created.
pub fn evaluate_writing(
    source: &Source,
    options: &EvalOptions,
    errors_csv: Option<&Path>,
) -> Result<Evaluation, EvalError> {
    let loaded = super::load::load(source, options)?;
    let latency = latency_of_series(
        &loaded.truth,
        &loaded.facts,
        &loaded.estimates,
        loaded.estimate_extent.count,
        &options.search,
    )?;
    let mode = options.latency.unwrap_or(loaded.default_latency);
    let (latency_applied_ns, latency_reason) = match (mode, &latency) {
        (LatencyMode::Fixed(ns), _) if options.latency.is_some() => {
            (ns, "fixed by the caller".to_string())
        }
        (LatencyMode::Fixed(ns), _) => (
            ns,
            "none: the estimates share the recording's time axis; a search is optional (--latency auto)"
                .to_string(),
        ),
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
    let fault_dir = match source {
        Source::Session(dir) | Source::Estimates { dir, .. } => Some(dir.as_path()),
        Source::External { .. } => None,
    };
    let mut faults = match fault_dir {
        Some(dir) => FaultScorer::from_dir(dir, options.faults)?,
        None => FaultScorer::default(),
    };
    let mut errors = errors_csv.map(ErrorsCsv::create).transpose()?;
    let scored = score_pass(&loaded, &opts, errors.as_mut(), &mut faults);
    let mut notes = loaded.notes.clone();
    if let Ok(s) = &scored {
        if loaded.rows.is_some() {
            notes.push(format!(
                "{} estimates not scored: the recording row nearest their instant is masked out or has no reference",
                s.skipped
            ));
        }
    }
    let scored = match (scored, errors) {
        (Ok(s), Some(e)) => e.finish().map(|()| s),
        (Ok(s), None) => Ok(s),
        (Err(e), written) => {
            if let Some(w) = written {
                w.discard();
            }
            Err(e)
        }
    }?;
    let Some(scores) = scored.all.scores() else {
        if let Some(path) = errors_csv {
            let _ = std::fs::remove_file(path);
        }
        return Err(EvalError::Score {
            context: loaded.inputs.join(", "),
            reason: ScoreError::NoOverlap {
                truth: loaded.truth_extent.span(0),
                estimate: loaded.estimate_extent.span(opts.latency_ns),
                warmup_s: opts.warmup_ns as f64 * 1e-9,
            },
        });
    };
    let by_phase = Phase::ALL
        .iter()
        .zip(&scored.by_phase)
        .map(|(&p, acc)| (p, acc.scores()))
        .collect();
    Ok(Evaluation {
        recording: loaded.default_latency != LatencyMode::Auto,
        inputs: loaded.inputs,
        notes,
        phases: loaded.phases,
        latency,
        latency_applied_ns,
        latency_reason,
        clock: loaded.clock,
        scores,
        by_phase,
        options: options.clone(),
        norms: loaded.norms,
        traces: scored.traces,
        errors_csv: errors_csv.map(Path::to_path_buf),
        faults: faults.finish(),
    })
}

/// What the scoring pass gathered.
struct Scored {
    skipped: usize,
    all: Accumulator,
    by_phase: [Accumulator; 3],
    traces: Traces,
}

/// Scores every estimate at the latency of `opts` in one pass over the truth and the
/// estimates, writing each scored instant to `errors` and thinning the traces as it goes.
fn score_pass(
    loaded: &Loaded,
    opts: &ScoreOptions,
    mut errors: Option<&mut ErrorsCsv>,
    faults: &mut FaultScorer,
) -> Result<Scored, EvalError> {
    let max_gap = loaded.facts.max_gap_ns(opts);
    let first = loaded.facts.first_ns;
    let phases = &loaded.phases;
    let mut truth_traces = [Thinner::angles(), Thinner::angles(), Thinner::angles()];
    let mut estimate_traces = truth_traces.clone();
    let mut runs: Vec<(Phase, f64, f64)> = Vec::new();
    let mut on_read = |i: usize, s: &Sample| {
        let t = s.0 as f64 * 1e-9;
        let e = euler(&s.1);
        for (trace, angle) in truth_traces.iter_mut().zip(e) {
            trace.push(t, angle.to_degrees());
        }
        if let Some(&p) = phases.get(i) {
            match runs.last_mut() {
                Some(run) if run.0 == p => run.2 = t,
                _ => runs.push((p, t, t)),
            }
        }
    };
    let mut all = Accumulator::default();
    let mut by_phase = [Accumulator::default(); 3];
    let mut walk = Walk::new(&loaded.truth)?;
    let mut skipped = 0;
    for estimate in loaded.estimates.read()? {
        let (stamp, q) = estimate?;
        let aligned = stamp as i64 - opts.latency_ns;
        let (window, base) = walk.cover(aligned, aligned, &mut on_read)?;
        if !after_warmup(aligned, first, opts) {
            continue;
        }
        let Some(located) = locate(window, base, aligned, max_gap) else {
            continue;
        };
        if let Some(rows) = &loaded.rows {
            if !rows.scores(aligned) {
                skipped += 1;
                continue;
            }
        }
        let c = compared(
            &located,
            euler(&located.q),
            (stamp, &q, euler(&q)),
            opts.latency_ns,
        );
        let phase = phases.get(c.index).copied();
        if let Some(out) = errors.as_deref_mut() {
            out.row(&c, phase)?;
        }
        all.add(&c);
        if !faults.is_empty() {
            faults.add(c.t_ns, c.geodesic);
        }
        if let Some(i) = phase.and_then(|p| Phase::ALL.iter().position(|&a| a == p)) {
            by_phase[i].add(&c);
        }
        let t = c.t_ns as f64 * 1e-9;
        for (trace, angle) in estimate_traces.iter_mut().zip(c.estimate) {
            trace.push(t, angle.to_degrees());
        }
    }
    walk.drain(&mut on_read)?;
    let e = &loaded.truth_extent;
    Ok(Scored {
        skipped,
        all,
        by_phase,
        traces: Traces {
            span_s: (e.first_ns as f64 * 1e-9, e.last_ns as f64 * 1e-9),
            truth: truth_traces.map(|t| t.pieces()),
            estimate: estimate_traces.map(|t| t.pieces()),
            phases: runs,
        },
    })
}
