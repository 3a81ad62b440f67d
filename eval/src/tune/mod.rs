//! Tuning a reference filter's parameters on a scene (paper section 3.2, Table 3): minimise
//! the mean over several seeds of `F` (eq. 27) or of the geodesic RMS, with Nelder–Mead.
//!
//! - [`dataset`]: the scene simulated once per seed (truth and MARG samples kept), and the
//!   scores of one parameter set on every seed, seeds in parallel;
//! - [`search`]: Nelder–Mead (argmin) in log-parameter space, box bounds, evaluation budget;
//! - [`report`]: the table of initial against tuned values, and the parameters file.
//!
//! Scores come from [`crate::evaluate`] (the estimates are on the truth's own instants, so
//! they are compared sample for sample), with the first [`TuneOptions::warmup_s`] seconds left
//! out: every filter starts from its first sample and needs a moment to settle. The objective
//! of a parameter set is the mean of its per-seed values. Same scene, options and filter give
//! the same result, whatever the number of threads.
//!
//! ```no_run
//! use margemu_eval::offline::FilterKind;
//! use margemu_sim::scene::builtin;
//! use margemu_eval::tune::{tune, TuneOptions};
//! let scene = builtin::load("case-study")?;
//! let result = tune(&scene, FilterKind::Ekf, &TuneOptions::default())?;
//! println!("{}", margemu_eval::tune::report::table(&result));
//! assert!(result.tuned.objective <= result.initial.objective);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod dataset;
pub mod report;
pub mod search;

pub use dataset::{CandidateError, Dataset, SeedRun};
pub use search::SearchOutcome;

use crate::evaluate::{ScoreError, ScoreOptions, Scores};
pub use crate::offline::AttitudeStart;
use crate::offline::{FilterKind, FilterParams};
use margemu_sim::run::RunError;
use margemu_sim::scene::Scene;
use std::fmt;

/// What the tuner minimises (mean over seeds).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Objective {
    /// `F` of eq. 27 (rad²).
    #[default]
    F,
    /// RMS of the quaternion geodesic error (rad).
    Geodesic,
}

impl Objective {
    /// The value of this objective in `scores`.
    pub fn of(self, scores: &Scores) -> f64 {
        match self {
            Self::F => scores.f,
            Self::Geodesic => scores.geodesic_rms,
        }
    }
}

impl fmt::Display for Objective {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::F => "F (eq. 27)",
            Self::Geodesic => "geodesic RMS",
        })
    }
}

impl std::str::FromStr for Objective {
    type Err = String;

    /// `f` or `geodesic`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "f" | "F" => Ok(Self::F),
            "geodesic" => Ok(Self::Geodesic),
            _ => Err(format!("unknown objective `{s}` (f or geodesic)")),
        }
    }
}

/// How to tune.
#[derive(Clone, Debug, PartialEq)]
pub struct TuneOptions {
    /// Seeds: the scene's seed and the next `seeds − 1`. Default 4.
    pub seeds: usize,
    /// What to minimise. Default `F`.
    pub objective: Objective,
    /// Budget of objective evaluations (each runs the filter on every seed). Default 200.
    pub max_evals: usize,
    /// Seconds at the start of each run left out of the scores. Default 1.
    pub warmup_s: f64,
    /// Where each filter run starts. Default: from the first sample.
    pub attitude_start: AttitudeStart,
    /// Where the search starts; `None`: the filter's defaults (which are also the "initial"
    /// column).
    pub initial_params: Option<FilterParams>,
}

impl Default for TuneOptions {
    fn default() -> Self {
        Self {
            seeds: 4,
            objective: Objective::F,
            max_evals: 200,
            warmup_s: 1.0,
            attitude_start: AttitudeStart::FirstSample,
            initial_params: None,
        }
    }
}

/// One parameter set, scored on every seed.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluated {
    /// The parameters.
    pub params: FilterParams,
    /// The objective: mean over seeds.
    pub objective: f64,
    /// Scores per seed, in seed order.
    pub per_seed: Vec<Scores>,
}

impl Evaluated {
    /// Mean over seeds of a score.
    pub fn mean(&self, of: impl Fn(&Scores) -> f64) -> f64 {
        self.per_seed.iter().map(of).sum::<f64>() / self.per_seed.len().max(1) as f64
    }
}

/// What a tuning found.
#[derive(Clone, Debug, PartialEq)]
pub struct TuneResult {
    /// The filter.
    pub kind: FilterKind,
    /// The objective minimised.
    pub objective: Objective,
    /// The scene file.
    pub scene: String,
    /// The seeds.
    pub seeds: Vec<u64>,
    /// Warm-up left out (s).
    pub warmup_s: f64,
    /// Where each filter run started.
    pub attitude_start: AttitudeStart,
    /// The start (the filter's defaults unless [`TuneOptions::initial_params`]).
    pub initial: Evaluated,
    /// The best parameters found (the start when nothing beat it).
    pub tuned: Evaluated,
    /// The search.
    pub search: SearchOutcome,
}

/// A tuning that could not run.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum TuneError {
    /// simulating the scene: {0}
    Run(RunError),
    /// seed {seed}: the simulated truth was refused: {reason}
    Truth {
        /// The seed.
        seed: u64,
        /// Why.
        reason: ScoreError,
    },
    /// at least one seed is needed
    NoSeeds,
    /// the warm-up must be a finite number of seconds ≥ 0, not {0}
    Warmup(f64),
    /// the start is for {start}, not {kind}
    StartKind {
        /// The filter tuned.
        kind: FilterKind,
        /// The start's filter.
        start: FilterKind,
    },
    /// the start cannot be scored: {0}
    Candidate(CandidateError),
    /// the optimiser failed: {0}
    Search(String),
}

/// Tunes `kind` on `scene` (see the module docs).
pub fn tune(scene: &Scene, kind: FilterKind, opts: &TuneOptions) -> Result<TuneResult, TuneError> {
    let data = Dataset::simulate(scene, opts.seeds)?;
    tune_dataset(&data, kind, opts, &|_| {})
}

/// Tunes `kind` on runs already simulated (to tune several filters on the same seeds), calling
/// `progress(evaluations so far)` after each evaluation.
pub fn tune_dataset(
    data: &Dataset,
    kind: FilterKind,
    opts: &TuneOptions,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<TuneResult, TuneError> {
    if !(opts.warmup_s.is_finite() && opts.warmup_s >= 0.0) {
        return Err(TuneError::Warmup(opts.warmup_s));
    }
    let start = opts
        .initial_params
        .clone()
        .unwrap_or_else(|| FilterParams::defaults(kind));
    if start.kind() != kind {
        return Err(TuneError::StartKind {
            kind,
            start: start.kind(),
        });
    }
    let score_opts = ScoreOptions {
        warmup_ns: (opts.warmup_s * 1e9).round() as u64,
        ..ScoreOptions::default()
    };
    let evaluate = |params: &FilterParams| -> Result<Evaluated, CandidateError> {
        let per_seed = data.score(params, opts.attitude_start, &score_opts)?;
        let n = per_seed.len() as f64;
        let objective = per_seed.iter().map(|s| opts.objective.of(s)).sum::<f64>() / n;
        Ok(Evaluated {
            params: params.clone(),
            objective,
            per_seed,
        })
    };
    let initial = evaluate(&start).map_err(TuneError::Candidate)?;
    let cost = |p: &FilterParams| evaluate(p).map_or(search::FAILED_COST, |e| e.objective);
    let outcome = search::minimize(&start, opts.max_evals, &cost, progress)
        .map_err(|e| TuneError::Search(e.to_string()))?;
    let tuned = if outcome.cost < initial.objective {
        evaluate(&outcome.best).map_err(TuneError::Candidate)?
    } else {
        initial.clone()
    };
    Ok(TuneResult {
        kind,
        objective: opts.objective,
        scene: data.scene.clone(),
        seeds: data.seeds(),
        warmup_s: opts.warmup_s,
        attitude_start: opts.attitude_start,
        initial,
        tuned,
        search: outcome,
    })
}

impl From<RunError> for TuneError {
    fn from(e: RunError) -> Self {
        Self::Run(e)
    }
}
