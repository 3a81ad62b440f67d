//! Running a scene: samples its motion at every output instant, turns each into ground truth,
//! and hands it to a sink ([`run`]), or writes the run directory ([`simulate_to_dir`]).

use crate::bench::{pid::Design, FrictionEvent};
use crate::marg::{MargSim, MargWriter};
use crate::mcap::{self, MargReading, McapLog, McapSetup};
use crate::meta::{PidMeta, RunMeta};
use crate::motion::Motion;
use crate::output::{TruthWriter, RUN_FILES, TRUTH_COLUMNS};
use crate::reference::ReferenceError;
use crate::rundir::{self, Completion, Status};
use crate::scene::{Scene, JOINT_NAMES};
use crate::truth::{Truth, TruthModel};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// A run that failed.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum RunError {
    /// the scene's motion failed
    Reference(#[from] ReferenceError),
    /// {0}
    NonFinite(Box<crate::guard::NonFinite>),
    /// the sensor model refused the scene: {0}
    Model(margemu_model::Error),
    /// interrupted; the files hold the samples written so far
    Interrupted,
    /// cannot write {path}
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
}

/// What a finished run reports.
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    /// Output samples produced.
    pub samples: u64,
    /// Friction mode changes (bench mode with static friction).
    pub friction_events: Vec<FrictionEvent>,
}

/// Runs `scene`, calling `sink` with the truth of every output sample in time order and
/// `progress(done, total)` every 4096 samples. The run stops at the first truth value that is not
/// finite ([`crate::guard::check_truth`]): [`ReferenceError::NonFinite`].
pub fn run<E>(
    scene: &Scene,
    mut sink: impl FnMut(&Truth) -> Result<(), E>,
    mut progress: impl FnMut(u64, u64),
) -> Result<Result<RunSummary, E>, ReferenceError> {
    let mut motion = Motion::new(scene)?;
    let model = TruthModel::new(scene.spec.field.reference, scene.spec.bench.gravity);
    let total = scene.samples();
    // A static plate's truth is the same at every instant but for the time stamp.
    let fixed = match &motion {
        Motion::Static(pose) => {
            let truth = model.compute(0, pose);
            crate::guard::check_truth(scene, &motion, 0, pose, &truth)
                .map_err(ReferenceError::NonFinite)?;
            Some(truth)
        }
        _ => None,
    };
    for k in 0..total {
        let t_ns = scene.clock.instant(k);
        let truth = match &fixed {
            Some(truth) => Truth { t_ns, ..*truth },
            None => {
                let joints = motion.sample_at(t_ns);
                let truth = model.compute(t_ns, &joints);
                crate::guard::check_truth(scene, &motion, k, &joints, &truth)
                    .map_err(ReferenceError::NonFinite)?;
                truth
            }
        };
        if let Err(e) = sink(&truth) {
            return Ok(Err(e));
        }
        if k % 4096 == 4095 {
            progress(k + 1, total);
        }
    }
    progress(total, total);
    let friction_events = motion
        .bench()
        .map(|b| b.friction_log().to_vec())
        .unwrap_or_default();
    Ok(Ok(RunSummary {
        samples: total,
        friction_events,
    }))
}

/// Runs `scene`, handing the truth of every output sample to `each`, in time order.
pub fn for_each(scene: &Scene, mut each: impl FnMut(&Truth)) -> Result<RunSummary, ReferenceError> {
    let sink = |t: &Truth| -> Result<(), std::convert::Infallible> {
        each(t);
        Ok(())
    };
    match run(scene, sink, |_, _| {})? {
        Ok(summary) => Ok(summary),
        Err(never) => match never {},
    }
}

/// The truth of every output sample of `scene`.
pub fn collect(scene: &Scene) -> Result<Vec<Truth>, ReferenceError> {
    let mut out = Vec::with_capacity(scene.samples() as usize);
    for_each(scene, |t| out.push(*t))?;
    Ok(out)
}

/// Runs `scene` and writes `dir/meta.toml`, `dir/truth.csv`, `dir/marg.csv` and, when the
/// scene has a perturbation, `dir/perturbation.csv` (creating `dir`; choose it with
/// [`crate::rundir::prepare`]). The CSV files are written under their `.partial` names and
/// renamed when the run ends; then the completion record is appended to `meta.toml`
/// ([`crate::rundir`]): complete, interrupted (`stop` was set; the files hold the samples so
/// far) or failed. A run killed outright leaves `.partial` files and no record.
pub fn simulate_to_dir(
    scene: &Scene,
    dir: &Path,
    stop: &AtomicBool,
    progress: impl FnMut(u64, u64),
) -> Result<RunSummary, RunError> {
    simulate_to_dir_with(scene, dir, stop, progress, &RunOutputs::default())
}

/// What a run directory holds besides the CSV files, which are always written.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOutputs {
    /// Also write `run.mcap` ([`crate::mcap`]): the truth and device 0's MARG samples (plate
    /// axes, frame `plate`), written, renamed and counted like the CSV files.
    pub mcap: bool,
}

/// [`simulate_to_dir`], with the extra files `outputs` asks for.
pub fn simulate_to_dir_with(
    scene: &Scene,
    dir: &Path,
    stop: &AtomicBool,
    progress: impl FnMut(u64, u64),
    outputs: &RunOutputs,
) -> Result<RunSummary, RunError> {
    std::fs::create_dir_all(dir).map_err(write_err(dir))?;
    crate::meta::write(dir, &metadata(scene)).map_err(write_err(&dir.join(rundir::META_FILE)))?;
    crate::fault_log::write_run_events(dir, scene)
        .map_err(write_err(&dir.join(crate::fault_log::EVENTS_FILE)))?;
    let mut written = 0;
    let outcome = write_files(scene, dir, stop, &mut written, progress, outputs);
    let (status, ended) = match &outcome {
        Ok(_) => (Status::Complete, "completed".to_string()),
        Err(RunError::Interrupted) => (Status::Interrupted, RunError::Interrupted.to_string()),
        Err(e) => (Status::Failed, e.to_string()),
    };
    let completion = Completion {
        status,
        samples_written: written,
        samples_expected: Some(scene.samples()),
        ended,
    };
    let recorded = rundir::write_completion(dir, &completion);
    let summary = outcome?;
    recorded.map_err(write_err(&dir.join(rundir::META_FILE)))?;
    Ok(summary)
}

fn write_err(path: &Path) -> impl FnOnce(std::io::Error) -> RunError {
    let path = path.to_path_buf();
    move |source| RunError::Write { path, source }
}

/// The CSV files of [`simulate_to_dir`], renamed to their final names once the sample loop
/// has ended, however it ended (interrupted: whole rows up to the stop; a write error: what
/// reached the disk); `written` counts the samples written.
fn write_files(
    scene: &Scene,
    dir: &Path,
    stop: &AtomicBool,
    written: &mut u64,
    progress: impl FnMut(u64, u64),
    outputs: &RunOutputs,
) -> Result<RunSummary, RunError> {
    let mut marg = MargSim::new(scene).map_err(RunError::Model)?;
    let [truth_name, marg_name, pert_name] = RUN_FILES;
    let create = |name: &str| -> Result<BufWriter<File>, RunError> {
        let path = rundir::partial_path(dir, name);
        let file = File::create(&path).map_err(write_err(&path))?;
        Ok(BufWriter::with_capacity(FILE_BUFFER, file))
    };
    let truth_path = rundir::partial_path(dir, truth_name);
    let marg_path = rundir::partial_path(dir, marg_name);
    let mut names = vec![truth_name, marg_name];
    let mut truth_out = TruthWriter::new(create(truth_name)?).map_err(write_err(&truth_path))?;
    let pert_out = if marg.has_perturbation() {
        names.push(pert_name);
        Some(create(pert_name)?)
    } else {
        None
    };
    let mut marg_out =
        MargWriter::new(create(marg_name)?, pert_out).map_err(write_err(&marg_path))?;
    let mcap_path = rundir::partial_path(dir, mcap::RUN_MCAP);
    let mut mcap_out = match outputs.mcap {
        true => {
            names.push(mcap::RUN_MCAP);
            Some(McapLog::create(&mcap_path, &mcap_setup(scene)).map_err(write_err(&mcap_path))?)
        }
        false => None,
    };
    let sink = |t: &Truth| -> Result<(), RunError> {
        if stop.load(Ordering::Relaxed) {
            return Err(RunError::Interrupted);
        }
        let failed = |path: &PathBuf, source| RunError::Write {
            path: path.clone(),
            source,
        };
        truth_out.write(t).map_err(|e| failed(&truth_path, e))?;
        let sample = marg.try_sample(scene, t).map_err(RunError::NonFinite)?;
        marg_out.write(&sample).map_err(|e| failed(&marg_path, e))?;
        if let Some(out) = &mut mcap_out {
            out.truth(t)
                .and_then(|_| out.marg(0, &reading(scene, &sample)))
                .map_err(|e| failed(&mcap_path, e))?;
        }
        *written += 1;
        Ok(())
    };
    let outcome = run(scene, sink, progress)?;
    let flushed = truth_out
        .finish()
        .map_err(write_err(&truth_path))
        .and_then(|_| marg_out.finish().map_err(write_err(&marg_path)))
        .and_then(|_| match mcap_out {
            Some(out) => out.finish().map(drop).map_err(write_err(&mcap_path)),
            None => Ok(()),
        });
    for name in names {
        rundir::commit_partial(dir, name).map_err(write_err(&dir.join(name)))?;
    }
    let summary = outcome?;
    flushed?;
    Ok(summary)
}

/// The write buffer of each CSV file: rows go out in chunks of this size. Small enough to stay
/// in the heap and in cache (a fresh megabyte per file cost a page fault per 4 KiB), large
/// enough that the system calls do not count.
const FILE_BUFFER: usize = 64 * 1024;

/// `run.mcap`'s channels and metadata: the truth and device 0 in plate axes.
fn mcap_setup(scene: &Scene) -> McapSetup {
    McapSetup {
        scene: scene.stem().to_string(),
        seed: scene.spec.seed,
        field_unit: scene.spec.field.unit,
        ut_per_unit: mcap::ut_per_unit(scene.spec.field.unit),
        devices: vec![(scene.chip_name.clone(), mcap::PLATE_FRAME.to_string())],
        clock: "scene time (ns since the scene start)".to_string(),
    }
}

/// A MARG sample of `scene` as `run.mcap` writes it: marg.csv's values, the field in µT.
pub fn reading(scene: &Scene, sample: &crate::marg::MargSample) -> MargReading {
    let s = &sample.sample;
    let ut = mcap::ut_per_unit(scene.spec.field.unit);
    MargReading {
        t_ns: sample.t_ns,
        acc: s.acc.map(f64::from),
        gyr: s.gyr.map(f64::from),
        mag_ut: Some(s.mag.map(|v| f64::from(v) * ut)),
    }
}

/// The run's `meta.toml`: scene, its SHA-256, seed, settings, PID gains and the scene text.
pub fn metadata(scene: &Scene) -> RunMeta {
    let spec = &scene.spec;
    let designs = crate::bench::designs(scene);
    let pid = JOINT_NAMES
        .iter()
        .enumerate()
        .map(|(i, joint)| {
            let d: Option<&Design> = designs[i].as_ref();
            let [kp, ki, kd] = match (&spec.control.gains, d) {
                (Some(g), _) => g[i],
                (None, Some(d)) => [d.gains.kp, d.gains.ki, d.gains.kd],
                (None, None) => [f64::NAN; 3],
            };
            PidMeta {
                joint: joint.to_string(),
                kp,
                ki,
                kd,
                zeta: d.map(|d| d.tuned.0),
                natural_frequency: d.map(|d| d.tuned.1),
                time_constant: d.map(|d| d.time_constant),
            }
        })
        .collect();
    RunMeta {
        margemu_version: env!("CARGO_PKG_VERSION").to_string(),
        scene_file: scene.path.display().to_string(),
        scene_sha256: scene.hash(),
        seed: spec.seed,
        motion: format!("{:?}", spec.motion).to_lowercase(),
        rate_hz: scene.clock.hz(),
        duration_s: spec.duration,
        samples: scene.samples(),
        integrator: format!("{:?}", spec.integrator.method),
        integrator_step_s: spec.integrator.step,
        field_unit: spec.field.unit.symbol().to_string(),
        truth_columns: TRUTH_COLUMNS.iter().map(|c| c.to_string()).collect(),
        pid,
        scene_text: scene.text.clone(),
        completion: None,
    }
}
