//! Reading a source into truth, estimates, phase magnitudes and norms.
//!
//! Time stamps of `dut_attitude.csv` rows, on the scene's axis (ns since scene time 0):
//! - `host_ns − start_host_ns` (arrival time) by default;
//! - when every kept row has a `device_time_us` and those increase: the clock fit's host time
//!   of the device time ([`fit_clock`]), which is the arrival time without its jitter. The fit
//!   is reported whenever two or more rows carry a device time.
//!
//! Rows stamped before scene time 0 are dropped, and of rows with equal stamps only the last
//! (newest) is kept; both are counted in the notes.

use super::align::fit_clock;
use super::device_log::{read_meta, read_sent};
use super::input::{
    read_dut_attitude, read_estimates, read_external, read_truth, read_vectors, DutRow, Imu,
    TruthRun,
};
use super::phase::{PhaseRules, PhaseSample};
use super::quat::{from_euler, geodesic, normalize};
use super::run::{Clock, EvalError, EvalOptions, LatencyMode, Norms, Source};
use super::score::Stamped;
use super::signals::{external_phases, measured_field_deviation, norms};
use std::path::Path;

/// What a source holds, ready to score.
pub(super) struct Loaded {
    pub(super) inputs: Vec<String>,
    pub(super) notes: Vec<String>,
    pub(super) truth: Vec<Stamped>,
    pub(super) estimates: Vec<Stamped>,
    pub(super) phase_samples: Vec<PhaseSample>,
    pub(super) norms: Norms,
    pub(super) clock: Clock,
    pub(super) default_latency: LatencyMode,
}

/// Reads `source`.
pub(super) fn load(source: &Source, options: &EvalOptions) -> Result<Loaded, EvalError> {
    match source {
        Source::Session(dir) => load_session(dir, options),
        Source::Estimates { dir, estimates } => load_run(dir, estimates, &options.rules),
        Source::External { file, estimates } => {
            load_external(file, estimates.as_deref(), &options.rules)
        }
    }
}

fn truth_phases(truth: &TruthRun, field_deviation: &[f64]) -> Vec<PhaseSample> {
    let norm = |v: &[f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (0..truth.attitude.len())
        .map(|k| PhaseSample {
            rate: norm(&truth.rate[k]),
            accel: norm(&truth.accel[k]),
            field: field_deviation.get(k).copied().unwrap_or(0.0),
        })
        .collect()
}

/// The truth, its phase samples and norms of a run directory, with `sent` for a session.
fn load_truth(
    dir: &Path,
    sent: Option<&Imu>,
    rules: &PhaseRules,
    inputs: &mut Vec<String>,
) -> Result<(TruthRun, Vec<PhaseSample>, Norms), EvalError> {
    let path = dir.join("truth.csv");
    let truth = read_truth(&path)?;
    inputs.push(format!(
        "{} ({} samples)",
        path.display(),
        truth.attitude.len()
    ));
    let t: Vec<u64> = truth.attitude.iter().map(|s| s.0).collect();
    let perturbation = dir.join("perturbation.csv");
    let (deviation, disturbance) = if perturbation.exists() {
        let (pt, [d]) = read_vectors(&perturbation, [["mag_x", "mag_y", "mag_z"]])?;
        inputs.push(format!("{} (magnetic phases)", perturbation.display()));
        let d = on_grid(&t, &pt, &d);
        let dev = d
            .iter()
            .zip(&truth.field)
            .map(|(d, f)| ratio(*d, *f))
            .collect();
        (dev, Some(d))
    } else if let Some(sent) = sent {
        let m = on_grid(&t, &sent.t_ns, &sent.mag);
        let dev = measured_field_deviation(&t, &m, &truth.field, rules.window_ns);
        (dev, None)
    } else {
        (Vec::new(), None)
    };
    let marg = dir.join("marg.csv");
    let norms = if let Some(sent) = sent {
        norms(
            "sent.csv (register images decoded)",
            &sent.t_ns,
            &sent.acc,
            &sent.mag,
        )
    } else if marg.exists() {
        let (mt, [a, m]) = read_vectors(
            &marg,
            [["acc_x", "acc_y", "acc_z"], ["mag_x", "mag_y", "mag_z"]],
        )?;
        norms("marg.csv (sensor model output)", &mt, &a, &m)
    } else {
        let field: Vec<[f64; 3]> = match &disturbance {
            Some(d) => truth
                .field
                .iter()
                .zip(d)
                .map(|(f, d)| [0, 1, 2].map(|i| f[i] + d[i]))
                .collect(),
            None => truth.field.clone(),
        };
        norms(
            "truth.csv (specific force, field; noise-free)",
            &t,
            &truth.specific_force,
            &field,
        )
    };
    let phases = truth_phases(&truth, &deviation);
    Ok((truth, phases, norms))
}

fn ratio(d: [f64; 3], f: [f64; 3]) -> f64 {
    let n = |v: [f64; 3]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    n(d) / n(f).max(1e-12)
}

/// `values` (at `times`) at each instant of `grid`; zero where `times` has no such instant.
fn on_grid(grid: &[u64], times: &[u64], values: &[[f64; 3]]) -> Vec<[f64; 3]> {
    grid.iter()
        .map(|t| times.binary_search(t).map_or([0.0; 3], |i| values[i]))
        .collect()
}

fn load_run(dir: &Path, estimates: &Path, rules: &PhaseRules) -> Result<Loaded, EvalError> {
    let mut inputs = Vec::new();
    let (truth, phase_samples, norms) = load_truth(dir, None, rules, &mut inputs)?;
    let est = read_estimates(estimates)?;
    inputs.push(format!("{} ({} estimates)", estimates.display(), est.len()));
    Ok(Loaded {
        inputs,
        notes: Vec::new(),
        truth: truth.attitude,
        estimates: est,
        phase_samples,
        norms,
        clock: Clock::Absent,
        default_latency: LatencyMode::Fixed(0),
    })
}

fn load_external(
    file: &Path,
    estimates: Option<&Path>,
    rules: &PhaseRules,
) -> Result<Loaded, EvalError> {
    let rec = read_external(file)?;
    let mut inputs = vec![format!("{} ({} rows)", file.display(), rec.reference.len())];
    let est = match (estimates, rec.estimate) {
        (Some(path), _) => {
            let e = read_estimates(path)?;
            inputs.push(format!("{} ({} estimates)", path.display(), e.len()));
            e
        }
        (None, Some(e)) => e,
        (None, None) => {
            return Err(EvalError::Input {
                path: file.to_path_buf(),
                reason: "no estimate: the file has no qw_est, qx_est, qy_est, qz_est columns and no estimates file was given (run a filter over it first)".into(),
            })
        }
    };
    let imu = &rec.imu;
    Ok(Loaded {
        inputs,
        notes: Vec::new(),
        phase_samples: external_phases(imu, rules),
        norms: norms("the recording's IMU columns", &imu.t_ns, &imu.acc, &imu.mag),
        truth: rec.reference,
        estimates: est,
        clock: Clock::Absent,
        default_latency: LatencyMode::Fixed(0),
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
    let (truth, phase_samples, norms) =
        load_truth(dir, sent.as_ref(), &options.rules, &mut inputs)?;
    let path = dir.join("dut_attitude.csv");
    let dut = read_dut_attitude(&path, options.message.as_deref())?;
    let listing: Vec<String> = dut
        .messages
        .iter()
        .map(|(m, n)| format!("{m}: {n}"))
        .collect();
    inputs.push(format!(
        "{} ({} rows kept; {})",
        path.display(),
        dut.rows.len(),
        listing.join(", ")
    ));
    if dut.rows.is_empty() {
        return Err(EvalError::Input {
            path,
            reason: match &options.message {
                Some(m) => format!(
                    "no row with message {m:?} (there are: {})",
                    listing.join(", ")
                ),
                None => "no data rows".into(),
            },
        });
    }
    let mut notes = Vec::new();
    let worst = dut
        .rows
        .iter()
        .map(|r| {
            geodesic(
                &from_euler(r.euler),
                &normalize(r.q).expect("read_dut_attitude normalised it"),
            )
        })
        .fold(0.0f64, f64::max);
    notes.push(format!(
        "Euler columns against the quaternion of the same row: largest disagreement {worst:.3e} rad"
    ));
    let (stamps, clock) = stamp_rows(&dut.rows, meta.start_host_ns, options.device_time);
    let mut estimates: Vec<Stamped> = Vec::with_capacity(stamps.len());
    let (mut early, mut duplicate) = (0usize, 0usize);
    for (t, row) in stamps.iter().zip(&dut.rows) {
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
    Ok(Loaded {
        inputs,
        notes,
        truth: truth.attitude,
        estimates,
        phase_samples,
        norms,
        clock,
        default_latency: LatencyMode::Auto,
    })
}

/// Scene-axis stamps (ns) of the rows and what their device times say (see the module docs).
fn stamp_rows(rows: &[DutRow], start_host_ns: i64, use_device: bool) -> (Vec<i64>, Clock) {
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
