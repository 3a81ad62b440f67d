//! `margemu demo`: the paper's case study (section 3.2) end to end. The case-study scene streams
//! in real time to the firmware device in loopback, with the virtual flight controller
//! ([`margemu_hil::vfc`]) on its chip running each reference filter with its initial (default) and its
//! tuned parameters; the flight controller's MAVLink is read back through a second PTY pair and
//! scored with `margemu evaluate`'s library. The result is the analogue of the paper's Table 3
//! ([`table`]), with the paper's figures beside ours, and each run's session directory with its
//! report and figures (as Figures 8–10).
//!
//! Runs are in real time: each takes the scene's duration (20 s for `case-study.toml`); a shorter
//! scene ([`shorten`]) keeps a test in seconds. Every sample's estimate is sent (the paper scores
//! every epoch).
//!
//! **Tuned parameters** come from the caller ([`Tuned`]: a closure from the scene and the
//! filter to [`FilterParams`]): `margemu demo` runs the tuner ([`margemu_eval::tune`]) in process on
//! the scene, or reads a parameters file.

pub mod table;

use margemu_eval::evaluate::{EvalError, Scores};
use margemu_eval::offline::{FilterKind, FilterParams};
use margemu_hil::stream::{Progress, StreamConfig};
use margemu_hil::vfc::{run_loopback, FcReport, OutputRate, VfcConfig, VfcError};
use margemu_sim::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// How far ahead of each sample's instant the demo's sessions send it.
pub const DEMO_LEAD: std::time::Duration = std::time::Duration::from_secs(1);

/// Which parameters a run used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The filters crate's defaults (the paper's "initial").
    Initial,
    /// From [`Tuned`].
    Tuned,
}

impl Variant {
    /// `initial` or `tuned`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Initial => "initial",
            Self::Tuned => "tuned",
        }
    }
}

/// The tuned parameters of a filter for a scene.
pub type Tuned<'a> = dyn FnMut(&Scene, FilterKind) -> Result<FilterParams, String> + 'a;

/// What the demo runs.
pub struct DemoOptions {
    /// The scene (the case study, possibly [`shorten`]ed).
    pub scene: Scene,
    /// Where each run's session directory goes (`<out>/<filter>-<variant>`), and `table3.md`.
    pub out: PathBuf,
    /// The filters, in order.
    pub filters: Vec<FilterKind>,
    /// Whether to draw each run's figures.
    pub plots: bool,
}

/// One run of the demo.
#[derive(Clone, Debug)]
pub struct DemoRun {
    /// The filter.
    pub kind: FilterKind,
    /// Initial or tuned.
    pub variant: Variant,
    /// The parameters.
    pub params: FilterParams,
    /// Its session directory.
    pub dir: PathBuf,
    /// The scores over the whole run.
    pub scores: Scores,
    /// The latency the evaluation applied, ns.
    pub latency_ns: i64,
    /// What the flight controller did.
    pub fc: FcReport,
    /// Images served as predicted, of those in the scene.
    pub served: (u64, u64),
}

/// Why the demo stopped.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum DemoError {
    /// {0}
    Scene(SceneError),
    /// {label}: {source}
    Setup {
        /// The run.
        label: String,
        /// Why.
        #[source]
        source: VfcError,
    },
    /// {label}: {reason} (logs in {dir})
    Run {
        /// The run.
        label: String,
        /// What went wrong.
        reason: String,
        /// Its session directory.
        dir: PathBuf,
    },
    /// {label}: evaluating: {source}
    Evaluate {
        /// The run.
        label: String,
        /// Why.
        #[source]
        source: EvalError,
    },
    /// the tuned parameters of {kind}: {reason}
    Tuned {
        /// The filter.
        kind: FilterKind,
        /// Why.
        reason: String,
    },
}

/// `scene` with its duration set to `seconds` (the scene text edited, then validated again).
pub fn shorten(scene: &Scene, seconds: f64) -> Result<Scene, SceneError> {
    let mut doc: toml_edit::DocumentMut = scene.text.parse().map_err(|e| SceneError {
        file: scene.path.clone(),
        position: None,
        reason: format!("cannot edit the scene: {e}"),
    })?;
    doc["duration"] = toml_edit::value(seconds);
    Scene::parse_str(&doc.to_string(), &scene.path)
}

/// Runs every filter of `options` with its initial parameters and, when `tuned` is given, its
/// tuned ones; `progress` sees each run's label and its streaming progress; setting `stop`
/// interrupts the current run (and so the demo).
pub fn run(
    options: &DemoOptions,
    mut tuned: Option<&mut Tuned<'_>>,
    stop: &AtomicBool,
    mut progress: impl FnMut(&str, &Progress),
) -> Result<Vec<DemoRun>, DemoError> {
    // Every parameter set first, so a missing one stops the demo before minutes of streaming.
    let mut plan = Vec::new();
    for &kind in &options.filters {
        plan.push((kind, Variant::Initial, FilterParams::defaults(kind)));
        if let Some(tuned) = tuned.as_deref_mut() {
            let params =
                tuned(&options.scene, kind).map_err(|reason| DemoError::Tuned { kind, reason })?;
            if params.kind() != kind {
                return Err(DemoError::Tuned {
                    kind,
                    reason: format!("got parameters of {}", params.kind()),
                });
            }
            plan.push((kind, Variant::Tuned, params));
        }
    }
    let mut runs = Vec::new();
    for (kind, variant, params) in plan {
        let label = format!("{kind} {}", variant.name());
        let dir = options.out.join(format!("{kind}-{}", variant.name()));
        let r = one(options, kind, variant, params, &dir, stop, |p| {
            progress(&label, p)
        });
        runs.push(r.map_err(|e| match e {
            One::Setup(source) => DemoError::Setup {
                label: label.clone(),
                source,
            },
            One::Run(reason) => DemoError::Run {
                label: label.clone(),
                reason,
                dir: dir.clone(),
            },
            One::Evaluate(source) => DemoError::Evaluate {
                label: label.clone(),
                source,
            },
        })?);
    }
    Ok(runs)
}

enum One {
    Setup(VfcError),
    Run(String),
    Evaluate(EvalError),
}

fn one(
    options: &DemoOptions,
    kind: FilterKind,
    variant: Variant,
    params: FilterParams,
    dir: &Path,
    stop: &AtomicBool,
    progress: impl FnMut(&Progress),
) -> Result<DemoRun, One> {
    let _ = std::fs::remove_dir_all(dir);
    let config = VfcConfig {
        output: OutputRate::EverySample,
        ..VfcConfig::for_scene(&options.scene, params.clone())
    };
    // A lead of a second: the session must not underrun when the machine is loaded (beside two
    // CPU-bound processes the default 200 ms was seen to leave up to a third of the images
    // unserved as predicted), or the table would depend on the load.
    let stream = StreamConfig {
        lead: DEMO_LEAD,
        ..StreamConfig::default()
    };
    let run =
        run_loopback(&options.scene, config, stream, dir, stop, progress).map_err(One::Setup)?;
    let summary = run.session.map_err(|e| One::Run(e.to_string()))?;
    let dut = run.dut.map_err(|e| One::Run(e.to_string()))?;
    if let Some(why) = &run.fc.fc.error {
        return Err(One::Run(why.clone()));
    }
    run.fc.check_delivery(&dut).map_err(One::Run)?;
    let eval = crate::vfc_score::evaluate_session(dir).map_err(One::Evaluate)?;
    margemu_eval::evaluate::report::write(&eval, dir, options.plots).map_err(One::Evaluate)?;
    Ok(DemoRun {
        kind,
        variant,
        params,
        dir: dir.to_path_buf(),
        scores: eval.scores,
        latency_ns: eval.latency_applied_ns,
        fc: run.fc.fc,
        served: (summary.served.byte_exact, summary.samples),
    })
}

/// How often the scene's true body rate exceeds the chip's gyro range (±2000 °/s, the widest
/// the flight controller can set): `(samples with some axis beyond it, samples, largest |ω|
/// component in rad/s)`.
pub fn gyro_clipping(
    scene: &Scene,
) -> Result<(u64, u64, f64), margemu_sim::reference::ReferenceError> {
    let limit = 2000f64.to_radians();
    let (mut over, mut n, mut max) = (0u64, 0u64, 0f64);
    margemu_sim::run::for_each(scene, |t| {
        let peak = t.body_rate.iter().fold(0f64, |m, w| m.max(w.abs()));
        max = max.max(peak);
        over += u64::from(peak > limit);
        n += 1;
    })?;
    Ok((over, n, max))
}
