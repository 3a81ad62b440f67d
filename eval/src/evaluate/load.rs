//! Reading a source into what alignment and scoring read again: the truth and the estimates as
//! [`Series`], the phase of every truth instant, the norms for the figures, notes.
//!
//! A run directory's `truth.csv` and an estimates file stay on disk: one pass here checks them
//! and gathers the phases (one byte per instant), the median step and the norms (thinned), and
//! the passes of alignment and scoring read them again, so memory does not grow with the run.
//! A session's device output is read into memory (with its truth's field, for the measured
//! magnetic phase). An external recording scored against an estimates file is streamed like a
//! run: its reference and the estimates are read from the files on each pass
//! (`Series::Recording`, `Series::FramedEstimates`, converted from `--frame` as read), and only
//! what the phases and masks need is held (instants and IMU vectors, one flag per row); with
//! estimate columns in the recording instead, its attitudes are held.
//!
//! An external recording's rows without a reference quaternion are left out of the truth and
//! counted; with a [`Mask`], the rows it keeps are counted, and an estimate is scored only when
//! the recording row nearest its aligned instant has a reference and is kept.
//!
//! Time stamps of `dut_attitude.csv` rows, on the scene's axis (ns since scene time 0):
//! - `host_ns − start_host_ns` (arrival time) by default;
//! - when every kept row has a `device_time_us` and those increase: the clock fit's host time
//!   of the device time ([`fit_clock`]), which is the arrival time without its jitter. The fit
//!   is reported whenever two or more rows carry a device time.
//!
//! Rows stamped before scene time 0 are dropped, and of rows with equal stamps only the last
//! (newest) is kept; both are counted in the notes.

use super::align::{fit_clock, TruthFacts};
use super::device_log::{read_meta, read_sent};
use super::input::{read_dut_attitude, read_external_rows, DutRow, Imu, VectorRows};
use super::phase::{classify, classify_marks, Marks, Phase, PhaseRules, PhaseSample};
use super::quat::{from_euler, geodesic, normalize};
use super::run::{Clock, EvalError, EvalOptions, LatencyMode, Mask, Norms, Source};
use super::score::{ScoreError, Stamped};
use super::series::{Extent, Series};
use super::signals::{external_phases, measured_field_deviation, norms};
use super::walk::MedianStep;
use margemu_sim::csv_table::Table;
use std::path::Path;

/// What a source holds, ready to score.
pub(super) struct Loaded {
    pub(super) inputs: Vec<String>,
    pub(super) notes: Vec<String>,
    pub(super) truth: Series,
    pub(super) truth_extent: Extent,
    pub(super) facts: TruthFacts,
    pub(super) estimates: Series,
    pub(super) estimate_extent: Extent,
    pub(super) phases: Vec<Phase>,
    pub(super) norms: Norms,
    pub(super) clock: Clock,
    pub(super) default_latency: LatencyMode,
    /// An external recording's rows and which of them are scored.
    pub(super) rows: Option<ScoredRows>,
}

/// The instants of a recording's rows and whether each is scored (it has a reference and the
/// mask keeps it).
pub(super) struct ScoredRows {
    t_ns: Vec<u64>,
    scored: Vec<bool>,
}

impl ScoredRows {
    /// Whether the row nearest `t_ns` (the earlier of two equally near) is scored.
    pub(super) fn scores(&self, t_ns: i64) -> bool {
        let t = t_ns.max(0) as u64;
        let after = self.t_ns.partition_point(|&r| r < t);
        let nearest = match (after.checked_sub(1), self.t_ns.get(after)) {
            (Some(b), Some(&a)) if a - t < t - self.t_ns[b] => after,
            (Some(b), _) => b,
            (None, _) => after,
        };
        self.scored.get(nearest).copied().unwrap_or(false)
    }
}

/// Reads `source`.
pub(super) fn load(source: &Source, options: &EvalOptions) -> Result<Loaded, EvalError> {
    let incomplete = match source {
        Source::Session(dir) | Source::Estimates { dir, .. } => run_directory(dir, options)?,
        Source::External { .. } => None,
    };
    let mut loaded = match source {
        Source::Session(dir) => load_session(dir, options),
        Source::Estimates { dir, estimates } => load_run(dir, estimates, &options.rules),
        Source::External { file, estimates } => load_external(file, estimates.as_deref(), options),
    }?;
    loaded.notes.extend(incomplete);
    Ok(loaded)
}

/// Checks a run or session directory as a whole before any of its files is read (the one place
/// for such checks): that it is one, and that its run completed
/// ([`margemu_sim::rundir::check_complete`]); with `allow_incomplete`, the note saying it did not.
fn run_directory(dir: &Path, options: &EvalOptions) -> Result<Option<String>, EvalError> {
    if !dir.is_dir() {
        return Err(EvalError::Input {
            path: dir.to_path_buf(),
            reason: "no such directory".into(),
        });
    }
    Ok(margemu_sim::rundir::check_complete(
        dir,
        options.allow_incomplete,
    )?)
}

fn norm(v: &[f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// A run directory's truth, read once (see the module docs).
struct TruthScan {
    extent: Option<Extent>,
    facts: TruthFacts,
    phases: Vec<Phase>,
    norms: Norms,
}

/// Reads `dir/truth.csv` through once, with `perturbation.csv` and `marg.csv` when there, and
/// `sent` (a session's decoded images) for the measured magnetic phase and the norms.
fn scan_truth(
    dir: &Path,
    sent: Option<&Imu>,
    rules: &PhaseRules,
    inputs: &mut Vec<String>,
) -> Result<TruthScan, EvalError> {
    let path = dir.join("truth.csv");
    let mut table = Table::open(&path)?;
    let t_col = table.column("t_ns")?;
    let q_cols = table.columns(["qw", "qx", "qy", "qz"])?;
    let w_cols = table.columns(["wx", "wy", "wz"])?;
    let f_cols = table.columns(["fx", "fy", "fz"])?;
    let a_cols = table.columns(["ax_b", "ay_b", "az_b"])?;
    let m_cols = table.columns(["mx", "my", "mz"])?;
    let perturbation_path = dir.join("perturbation.csv");
    let mut perturbation = if perturbation_path.exists() {
        Some(VectorRows::open(
            &perturbation_path,
            [["mag_x", "mag_y", "mag_z"]],
        )?)
    } else {
        None
    };
    let marg = dir.join("marg.csv");
    let norms_from_truth = sent.is_none() && !marg.exists();
    let mut figure_norms = Norms::new("truth.csv (specific force, field; noise-free)");
    let (mut extent, mut median, mut marks) = (None::<Extent>, MedianStep::default(), Vec::new());
    // A session's truth field and instants, for the measured deviation.
    let (mut times, mut fields) = (Vec::new(), Vec::new());
    while let Some(row) = table.next_row()? {
        let t: u64 = row.int(t_col)?;
        row.check_order(t_col, extent.map(|e| e.last_ns), t, true)?;
        super::input::unit(&row, row.f64s(q_cols)?)?;
        let rate = row.f64s(w_cols)?;
        let specific_force = row.f64s(f_cols)?;
        let accel = row.f64s(a_cols)?;
        let field = row.f64s(m_cols)?;
        Extent::add(&mut extent, t);
        median.add(t);
        let disturbance = match &mut perturbation {
            Some(p) => p.at(t)?.map_or([0.0; 3], |[d]| d),
            None => [0.0; 3],
        };
        let sample = PhaseSample {
            rate: norm(&rate),
            accel: norm(&accel),
            field: if perturbation.is_some() {
                norm(&disturbance) / norm(&field).max(1e-12)
            } else {
                0.0
            },
        };
        marks.push(Marks::of(&sample, rules));
        if sent.is_some() {
            times.push(t);
            fields.push(field);
        }
        if norms_from_truth {
            let total = [0, 1, 2].map(|i| field[i] + disturbance[i]);
            figure_norms.push(t, &specific_force, &total);
        }
    }
    inputs.push(format!(
        "{} ({} samples)",
        path.display(),
        extent.map_or(0, |e| e.count)
    ));
    if perturbation.is_some() {
        inputs.push(format!("{} (magnetic phases)", perturbation_path.display()));
    }
    let step = median.median();
    if let (Some(sent), None) = (sent, &perturbation) {
        let m = on_grid(&times, &sent.t_ns, &sent.mag);
        let deviation = measured_field_deviation(&times, &m, &fields, rules.window_ns);
        for (mark, d) in marks.iter_mut().zip(deviation) {
            mark.perturbed = d > rules.magnetic_fraction;
        }
    }
    if let Some(sent) = sent {
        figure_norms = norms(
            "sent.csv (register images decoded)",
            &sent.t_ns,
            &sent.acc,
            &sent.mag,
        );
    } else if marg.exists() {
        figure_norms = Norms::new("marg.csv (sensor model output)");
        let mut v = VectorRows::open(
            &marg,
            [["acc_x", "acc_y", "acc_z"], ["mag_x", "mag_y", "mag_z"]],
        )?;
        while let Some((t, [a, m])) = v.next()? {
            figure_norms.push(t, &a, &m);
        }
    }
    Ok(TruthScan {
        facts: TruthFacts {
            first_ns: extent.map_or(0, |e| e.first_ns),
            median_step_ns: step,
        },
        extent,
        phases: classify_marks(&marks, rules, step),
        norms: figure_norms,
    })
}

/// `values` (at `times`) at each instant of `grid`; zero where `times` has no such instant.
fn on_grid(grid: &[u64], times: &[u64], values: &[[f64; 3]]) -> Vec<[f64; 3]> {
    grid.iter()
        .map(|t| times.binary_search(t).map_or([0.0; 3], |i| values[i]))
        .collect()
}

/// The error of an empty series, as the scoring functions word it.
fn empty(inputs: &[String], what: &'static str) -> EvalError {
    EvalError::Score {
        context: inputs.join(", "),
        reason: ScoreError::Empty { what },
    }
}

fn scored(inputs: &[String], reason: ScoreError) -> EvalError {
    EvalError::Score {
        context: inputs.join(", "),
        reason,
    }
}

fn load_run(dir: &Path, estimates: &Path, rules: &PhaseRules) -> Result<Loaded, EvalError> {
    let mut inputs = Vec::new();
    let scan = scan_truth(dir, None, rules, &mut inputs)?;
    let series = Series::Estimates(estimates.to_path_buf());
    let estimate_extent = series.extent()?;
    inputs.push(format!(
        "{} ({} estimates)",
        estimates.display(),
        estimate_extent.map_or(0, |e| e.count)
    ));
    let truth_extent = scan.extent.ok_or_else(|| empty(&inputs, "truth"))?;
    let estimate_extent = estimate_extent.ok_or_else(|| empty(&inputs, "estimate"))?;
    Ok(Loaded {
        inputs,
        notes: Vec::new(),
        truth: Series::Truth(dir.join("truth.csv")),
        truth_extent,
        facts: scan.facts,
        estimates: series,
        estimate_extent,
        phases: scan.phases,
        norms: scan.norms,
        clock: Clock::Absent,
        default_latency: LatencyMode::Fixed(0),
        rows: None,
    })
}

/// Series, extents and facts of a truth and estimates held in memory.
fn in_memory(
    inputs: &[String],
    truth: &[Stamped],
    estimates: &[Stamped],
) -> Result<(Series, Extent, TruthFacts, Series, Extent), EvalError> {
    let truth_series = Series::memory(truth, "truth").map_err(|e| scored(inputs, e))?;
    let estimate_series = Series::memory(estimates, "estimate").map_err(|e| scored(inputs, e))?;
    let extent = |s: &[Stamped]| Extent {
        count: s.len(),
        first_ns: s[0].0,
        last_ns: s[s.len() - 1].0,
    };
    let mut median = MedianStep::default();
    truth.iter().for_each(|s| median.add(s.0));
    let facts = TruthFacts {
        first_ns: truth[0].0,
        median_step_ns: median.median(),
    };
    Ok((
        truth_series,
        extent(truth),
        facts,
        estimate_series,
        extent(estimates),
    ))
}

fn load_external(
    file: &Path,
    estimates: Option<&Path>,
    options: &EvalOptions,
) -> Result<Loaded, EvalError> {
    let rules = &options.rules;
    let column = match &options.mask {
        Mask::Column(c) => Some(c.as_str()),
        _ => None,
    };
    // With an estimates file, both attitude series are streamed from the files; with estimate
    // columns, the recording's attitudes are held.
    let mut rec = read_external_rows(file, column, estimates.is_none())?;
    let frame = options.frame;
    let to_margemu = |list: &mut Vec<Stamped>| {
        for s in list.iter_mut() {
            s.1 = frame.quat_in(s.1);
        }
    };
    to_margemu(&mut rec.reference);
    if let Some(e) = rec.estimate.as_mut() {
        to_margemu(e);
    }
    let rows = rec.imu.t_ns.len();
    let mut inputs = vec![format!("{} ({rows} rows)", file.display())];
    let mut notes = Vec::new();
    if frame != crate::frame::Frame::Nwu {
        notes.push(format!(
            "frame {frame}: the recording's and the estimates' quaternions converted to margemu's NWU as read; Euler angles here and in errors.csv are NWU (ZYX), geodesic, heading and inclination do not depend on the frame"
        ));
    }
    if rec.missing_reference > 0 {
        notes.push(format!(
            "{} of {rows} rows have no reference quaternion (empty or NaN): skipped",
            rec.missing_reference
        ));
    }
    if rec.reference_rows.is_empty() {
        return Err(EvalError::Input {
            path: file.to_path_buf(),
            reason: format!("no row has a reference quaternion ({rows} rows)"),
        });
    }
    let (truth, truth_extent, facts, estimates, estimate_extent) = match (estimates, rec.estimate.take()) {
        (Some(path), _) => {
            let series = Series::FramedEstimates(path.to_path_buf(), frame);
            let extent = series.extent()?;
            inputs.push(format!(
                "{} ({} estimates)",
                path.display(),
                extent.map_or(0, |e| e.count)
            ));
            let estimate_extent = extent.ok_or_else(|| empty(&inputs, "estimate"))?;
            let times = || rec.reference_rows.iter().map(|&r| rec.imu.t_ns[r]);
            let mut median = MedianStep::default();
            times().for_each(|t| median.add(t));
            let mut extent = None;
            times().for_each(|t| Extent::add(&mut extent, t));
            let truth_extent = extent.ok_or_else(|| empty(&inputs, "truth"))?;
            let facts = TruthFacts {
                first_ns: truth_extent.first_ns,
                median_step_ns: median.median(),
            };
            (
                Series::Recording(file.to_path_buf(), frame),
                truth_extent,
                facts,
                series,
                estimate_extent,
            )
        }
        (None, Some(e)) => in_memory(&inputs, &rec.reference, &e)?,
        (None, None) => {
            return Err(EvalError::Input {
                path: file.to_path_buf(),
                reason: "no estimate: the file has no qw_est, qx_est, qy_est, qz_est columns and no estimates file was given (run a filter over it first)".into(),
            })
        }
    };
    let imu = &rec.imu;
    let samples = external_phases(imu, rules);
    let all_phases = classify(&samples, rules, facts.median_step_ns);
    let phases = rec.reference_rows.iter().map(|&r| all_phases[r]).collect();
    let (kept, rule): (Vec<bool>, String) = match &options.mask {
        Mask::All => (vec![true; rows], String::new()),
        Mask::Column(c) => (
            rec.mask.clone().unwrap_or_default(),
            format!("column `{c}` nonzero"),
        ),
        Mask::Rest(r) => (
            samples.iter().map(|s| s.rate < *r).collect(),
            format!("rest: averaged gyro norm below {r} rad/s"),
        ),
        Mask::Motion(r) => (
            samples.iter().map(|s| s.rate >= *r).collect(),
            format!("motion: averaged gyro norm at or above {r} rad/s"),
        ),
    };
    let mut scored = vec![false; rows];
    for &r in &rec.reference_rows {
        scored[r] = kept[r];
    }
    if options.mask != Mask::All {
        notes.push(format!(
            "mask ({rule}): {} of {rows} rows kept, {} of them with a reference",
            kept.iter().filter(|&&k| k).count(),
            scored.iter().filter(|&&k| k).count()
        ));
    }
    Ok(Loaded {
        inputs,
        notes,
        truth,
        truth_extent,
        facts,
        estimates,
        estimate_extent,
        phases,
        norms: norms("the recording's IMU columns", &imu.t_ns, &imu.acc, &imu.mag),
        clock: Clock::Absent,
        default_latency: LatencyMode::Fixed(0),
        rows: Some(ScoredRows {
            t_ns: rec.imu.t_ns,
            scored,
        }),
    })
}

fn load_session(dir: &Path, options: &EvalOptions) -> Result<Loaded, EvalError> {
    let meta = read_meta(dir)?;
    let sent_path = dir.join("sent.csv");
    let sent = if sent_path.exists() {
        Some(read_sent(&sent_path, &meta)?)
    } else {
        None
    };
    let mut inputs = Vec::new();
    let scan = scan_truth(dir, sent.as_ref(), &options.rules, &mut inputs)?;
    let path = dir.join("dut_attitude.csv");
    let dut = read_dut_attitude(&path)?;
    let listing: Vec<String> = dut
        .messages
        .iter()
        .map(|(m, n)| format!("{m}: {n}"))
        .collect();
    let mut notes = Vec::new();
    let kept: Vec<usize> = match &options.message {
        Some(m) => dut.streams_of(m),
        None => {
            let chosen = dut.preferred_stream();
            if dut.messages.len() > 1 {
                if let Some(i) = chosen {
                    notes.push(format!(
                        "{} holds several message streams ({}); scored {} (choose another with --message)",
                        path.display(),
                        listing.join(", "),
                        dut.messages[i].0
                    ));
                }
            }
            chosen.into_iter().collect()
        }
    };
    let rows: Vec<&DutRow> = dut
        .rows
        .iter()
        .filter(|r| kept.contains(&r.stream))
        .collect();
    inputs.push(format!(
        "{} ({} rows kept; {})",
        path.display(),
        rows.len(),
        listing.join(", ")
    ));
    let unusable = dut.unusable.iter().filter(|s| kept.contains(s)).count();
    if unusable > 0 {
        notes.push(format!(
            "{unusable} rows with an unusable quaternion (zero, near zero or not finite) skipped"
        ));
    }
    if rows.is_empty() {
        return Err(EvalError::Input {
            path,
            reason: match &options.message {
                Some(m) => format!(
                    "no row with message {m:?} (there are: {})",
                    listing.join(", ")
                ),
                None if unusable > 0 => {
                    format!("no row with a usable quaternion ({unusable} unusable)")
                }
                None => "no data rows".into(),
            },
        });
    }
    let worst = rows
        .iter()
        .map(|r| {
            geodesic(
                &from_euler(r.euler),
                &normalize(r.q).expect("read_dut_attitude keeps usable quaternions"),
            )
        })
        .fold(0.0f64, f64::max);
    notes.push(format!(
        "Euler columns against the quaternion of the same row: largest disagreement {worst:.3e} rad"
    ));
    let (stamps, clock) = stamp_rows(&rows, meta.start_host_ns, options.device_time);
    let mut estimates: Vec<Stamped> = Vec::with_capacity(stamps.len());
    let (mut early, mut duplicate) = (0usize, 0usize);
    for (t, row) in stamps.iter().zip(&rows) {
        if *t < 0 {
            early += 1;
            continue;
        }
        let t = *t as u64;
        if estimates.last().is_some_and(|l| l.0 == t) {
            duplicate += 1;
            estimates.pop();
        }
        estimates.push((t, row.q));
    }
    if early + duplicate > 0 {
        notes.push(format!("{early} rows stamped before scene time 0 dropped; {duplicate} rows with the stamp of a later row dropped"));
    }
    let truth_extent = scan.extent.ok_or_else(|| empty(&inputs, "truth"))?;
    let series = Series::memory(&estimates, "estimate").map_err(|e| scored(&inputs, e))?;
    let estimate_extent = Extent {
        count: estimates.len(),
        first_ns: estimates.first().map_or(0, |e| e.0),
        last_ns: estimates.last().map_or(0, |e| e.0),
    };
    Ok(Loaded {
        inputs,
        notes,
        truth: Series::Truth(dir.join("truth.csv")),
        truth_extent,
        facts: scan.facts,
        estimates: series,
        estimate_extent,
        phases: scan.phases,
        norms: scan.norms,
        clock,
        default_latency: LatencyMode::Auto,
        rows: None,
    })
}

/// Scene-axis stamps (ns) of the rows and what their device times say (see the module docs).
fn stamp_rows(rows: &[&DutRow], start_host_ns: i64, use_device: bool) -> (Vec<i64>, Clock) {
    let host: Vec<i64> = rows.iter().map(|r| r.host_ns - start_host_ns).collect();
    let pairs: Vec<(f64, f64, u64)> = rows
        .iter()
        .zip(&host)
        .filter_map(|(r, h)| r.device_time_us.map(|d| (d, *h as f64, r.line)))
        .collect();
    if pairs.is_empty() {
        return (host, Clock::Absent);
    }
    if let Some(w) = pairs.windows(2).find(|w| w[1].0 <= w[0].0) {
        let reason = format!(
            "device_time_us does not increase at line {} ({} after {})",
            w[1].2, w[1].0, w[0].0
        );
        return (host, Clock::Unusable(reason));
    }
    let xy: Vec<(f64, f64)> = pairs.iter().map(|p| (p.0, p.1)).collect();
    let Some(fit) = fit_clock(&xy) else {
        return (host, Clock::Unusable("fewer than two device times".into()));
    };
    let all = pairs.len() == rows.len();
    if use_device && all {
        let stamps = rows
            .iter()
            .map(|r| fit.host_ns(r.device_time_us.unwrap_or_default()).round() as i64)
            .collect();
        (stamps, Clock::Fitted(fit, true))
    } else {
        (host, Clock::Fitted(fit, false))
    }
}
