//! The evaluation as text: a summary for the terminal, `report.md` (the tables, the alignment,
//! the rules, the figures linked), `errors.csv` (every scored instant) and, for a scene with
//! faults, `faults.csv` ([`super::faults`]).
//!
//! The score table follows the paper's Table 3: rows `F`, `MSE` and `STD` per angle (rad², rad),
//! then the geodesic RMS and maximum, then BROAD's heading and inclination errors (RMS and
//! maximum, see [`score`](mod@super::score)); one column per phase, after the whole run.
//!
//! `errors.csv` (one row per scored estimate, written as it is scored by
//! [`evaluate_writing`](super::run::evaluate_writing); `t_ns` its aligned instant in
//! nanoseconds): `t_ns,phase,roll,pitch,yaw,roll_est,pitch_est,yaw_est,e_roll,e_pitch,e_yaw,geodesic,heading,inclination`
//! (rad; `e = wrap(true − estimate)`; `heading`, `inclination`: BROAD's split of the error).

use super::phase::Phase;
use super::run::{Clock, EvalError, Evaluation};
use super::score::{Compared, Scores};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

const ANGLES: [&str; 3] = ["φ", "θ", "ψ"];

/// A table row: its name and a value per column (`None`: no instant in that column).
type TableRow = (String, Vec<Option<f64>>);

/// The score table: a header, then its rows.
fn table(eval: &Evaluation) -> (Vec<String>, Vec<TableRow>) {
    let mut columns: Vec<(String, Option<Scores>)> = vec![("all".into(), Some(eval.scores))];
    columns.extend(
        eval.by_phase
            .iter()
            .map(|(p, s)| (p.name().to_string(), *s)),
    );
    let header = columns.iter().map(|c| c.0.clone()).collect();
    let row = |name: String, f: &dyn Fn(&Scores) -> f64| {
        (name, columns.iter().map(|c| c.1.as_ref().map(f)).collect())
    };
    let mut rows = vec![
        row("N".into(), &|s| s.count as f64),
        row("F (rad²)".into(), &|s| s.f),
    ];
    for (i, a) in ANGLES.iter().enumerate() {
        rows.push(row(format!("MSE ({a}) (rad²)"), &move |s| s.angles[i].mse));
        rows.push(row(format!("STD ({a}) (rad)"), &move |s| s.angles[i].std));
    }
    for (i, a) in ANGLES.iter().enumerate() {
        rows.push(row(format!("mean ({a}) (rad)"), &move |s| s.angles[i].mean));
        rows.push(row(format!("max |e| ({a}) (rad)"), &move |s| {
            s.angles[i].max_abs
        }));
    }
    rows.push(row("geodesic RMS (rad)".into(), &|s| s.geodesic_rms));
    rows.push(row("geodesic RMS (°)".into(), &|s| {
        s.geodesic_rms.to_degrees()
    }));
    rows.push(row("geodesic max (°)".into(), &|s| {
        s.geodesic_max.to_degrees()
    }));
    for (i, name) in ["heading", "inclination"].iter().enumerate() {
        rows.push(row(format!("{name} RMS (°)"), &move |s| {
            s.heading_inclination_rms[i].to_degrees()
        }));
        rows.push(row(format!("{name} max (°)"), &move |s| {
            s.heading_inclination_max[i].to_degrees()
        }));
    }
    (header, rows)
}

fn cell(name: &str, v: Option<f64>) -> String {
    match v {
        None => "–".into(),
        Some(v) if name == "N" => format!("{v:.0}"),
        Some(v) => format!("{v:.4e}"),
    }
}

/// One line on the latency.
pub fn latency_line(eval: &Evaluation) -> String {
    let applied = eval.latency_applied_ns as f64 * 1e-6;
    let search = eval.options.search.max_lag_ns as f64 * 1e-6;
    match &eval.latency {
        Some(l) => format!(
            "latency {applied:.3} ms applied ({}); estimate {:.3} ms, contrast {:.3}, searched ±{search:.0} ms",
            eval.latency_reason,
            l.lag_ns as f64 * 1e-6,
            l.contrast
        ),
        None => format!("latency {applied:.3} ms applied ({}); no lag within ±{search:.0} ms overlaps the truth", eval.latency_reason),
    }
}

/// One line on the device clock.
pub fn clock_line(eval: &Evaluation) -> String {
    match &eval.clock {
        Clock::Absent if eval.recording => {
            "clock: the estimates' own time stamps, on the recording's (or run's) axis; no device clock to fit".into()
        }
        Clock::Absent => "clock: no device time stamps (rows stamped with their host arrival time)".into(),
        Clock::Unusable(why) => format!("clock: device time stamps not used: {why}"),
        Clock::Fitted(f, used) => format!(
            "clock: offset {:.3} ms (host time of device time 0, scene axis), drift {:+.2} ppm, residual RMS {:.1} µs (max {:.1} µs) over {} stamps; {}",
            f.offset_ns * 1e-6,
            f.drift_ppm,
            f.residual_rms_ns * 1e-3,
            f.residual_max_ns * 1e-3,
            f.points,
            if *used { "rows stamped through the fit" } else { "rows stamped with their host arrival time" }
        ),
    }
}

/// The terminal summary.
pub fn summary(eval: &Evaluation) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "evaluate: {}", eval.inputs.join(", "));
    let _ = writeln!(out, "{}", latency_line(eval));
    let _ = writeln!(out, "{}", clock_line(eval));
    for note in &eval.notes {
        let _ = writeln!(out, "note: {note}");
    }
    for line in super::faults::lines(&eval.faults) {
        let _ = writeln!(out, "{line}");
    }
    let (header, rows) = table(eval);
    let _ = write!(out, "{:<22}", "");
    for h in &header {
        let _ = write!(out, "{h:>12}");
    }
    out.push('\n');
    for (name, values) in rows {
        let _ = write!(out, "{name:<22}");
        for v in values {
            let _ = write!(out, "{:>12}", cell(&name, v));
        }
        out.push('\n');
    }
    out
}

/// `report.md`, with `figures` (paths) linked relative to `dir`.
pub fn markdown(eval: &Evaluation, dir: &Path, figures: &[PathBuf]) -> String {
    let mut md = String::from("# Attitude evaluation\n\n");
    let _ = writeln!(md, "Inputs:\n");
    for i in &eval.inputs {
        let _ = writeln!(md, "- {i}");
    }
    let _ = writeln!(
        md,
        "\n## Alignment\n\n- {}\n- {}",
        latency_line(eval),
        clock_line(eval)
    );
    for note in &eval.notes {
        let _ = writeln!(md, "- {note}");
    }
    let w = &eval.options.search.score;
    let _ = writeln!(
        md,
        "\n## Scores\n\nEuler errors `e = wrap(true − estimate)` into (−π, π]; `F = ∛(MSE_φ·MSE_θ·MSE_ψ)` (eq. 27); \
         geodesic `2·acos|⟨q, q̂⟩|`; heading and inclination as BROAD splits the error `q̂ ⊗ q⁻¹` (world frame: rotation about the vertical, remaining tilt). Warm-up {:.3} s; the truth interpolated (slerp) onto each estimate's aligned instant; N counts estimates.\n",
        w.warmup_ns as f64 * 1e-9
    );
    let (header, rows) = table(eval);
    let _ = writeln!(md, "| | {} |", header.join(" | "));
    let _ = writeln!(md, "|---|{}", "---:|".repeat(header.len()));
    for (name, values) in rows {
        let cells: Vec<String> = values.iter().map(|v| cell(&name, *v)).collect();
        let _ = writeln!(md, "| {name} | {} |", cells.join(" | "));
    }
    if !eval.faults.is_empty() {
        let o = &eval.options.faults;
        let threshold = match o.threshold_rad {
            Some(t) => format!("{:.3}°", t.to_degrees()),
            None => format!(
                "{} × the geodesic RMS before the window, at least {:.3}°",
                o.factor,
                o.floor_rad.to_degrees()
            ),
        };
        let _ = writeln!(
            md,
            "\n## Fault windows\n\nFrom `events.csv`, per window: the geodesic error before it, inside it, and the time to \
             recover after its end (the error below {threshold} for {:.3} s of scored instants). Every window in `faults.csv`.\n",
            o.hold_ns as f64 * 1e-9
        );
        for line in super::faults::lines(&eval.faults) {
            let _ = writeln!(md, "- {line}");
        }
    }
    let r = &eval.options.rules;
    let _ = writeln!(
        md,
        "\n## Phases\n\nPer truth instant: **magnetic** when the field deviates from its reference by more than {:.0} % of its norm; \
         else **static** when the body rate is below {} rad/s and the external acceleration below {} m/s²; else **dynamic**. \
         Measured signals are averaged over {:.0} ms first. Samples per phase:",
        r.magnetic_fraction * 100.0,
        r.static_rate,
        r.static_accel,
        r.window_ns as f64 * 1e-6
    );
    for p in Phase::ALL {
        let n = eval.phases.iter().filter(|&&q| q == p).count();
        let _ = writeln!(md, "- {}: {n}", p.name());
    }
    let _ = writeln!(md, "\nNorms from {}.\n\n## Figures\n", eval.norms.source);
    for f in figures {
        let rel = f.strip_prefix(dir).unwrap_or(f).display().to_string();
        if rel.ends_with(".png") {
            let _ = writeln!(md, "![{rel}]({rel})\n");
        } else {
            let _ = writeln!(md, "- [{rel}]({rel})");
        }
    }
    md
}

/// Every file [`write()`] and [`evaluate_writing`](super::run::evaluate_writing) may write.
pub const FILES: [&str; 7] = [
    "errors.csv",
    super::faults::FAULTS_FILE,
    "report.md",
    "attitude.png",
    "attitude.svg",
    "alignment.png",
    "alignment.svg",
];

/// The columns of `errors.csv`.
pub const ERRORS_HEADER: &str =
    "t_ns,phase,roll,pitch,yaw,roll_est,pitch_est,yaw_est,e_roll,e_pitch,e_yaw,geodesic,heading,inclination";

/// `errors.csv` being written, one scored instant at a time.
pub(super) struct ErrorsCsv {
    path: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
}

impl ErrorsCsv {
    /// Creates the file (and its directory) and writes the header.
    pub(super) fn create(path: &Path) -> Result<Self, EvalError> {
        let fail = |error| EvalError::Write {
            path: path.to_path_buf(),
            error,
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(fail)?;
        }
        let file = std::fs::File::create(path).map_err(fail)?;
        let mut out = std::io::BufWriter::with_capacity(1 << 16, file);
        writeln!(out, "{ERRORS_HEADER}").map_err(fail)?;
        Ok(Self {
            path: path.to_path_buf(),
            out,
        })
    }

    /// Writes one scored instant (`phase`: of its nearest truth instant).
    pub(super) fn row(&mut self, c: &Compared, phase: Option<Phase>) -> Result<(), EvalError> {
        let phase = phase.map_or("", Phase::name);
        let [t, e, r] = [c.truth, c.estimate, c.error];
        let [h, i] = c.heading_inclination;
        writeln!(
            self.out,
            "{},{phase},{},{},{},{},{},{},{},{},{},{},{h},{i}",
            c.t_ns, t[0], t[1], t[2], e[0], e[1], e[2], r[0], r[1], r[2], c.geodesic
        )
        .map_err(|error| EvalError::Write {
            path: self.path.clone(),
            error,
        })
    }

    /// Flushes the file.
    pub(super) fn finish(mut self) -> Result<(), EvalError> {
        self.out.flush().map_err(|error| EvalError::Write {
            path: self.path.clone(),
            error,
        })
    }

    /// Removes the unfinished file.
    pub(super) fn discard(self) {
        let path = self.path.clone();
        drop(self);
        let _ = std::fs::remove_file(path);
    }
}

/// Writes the figures and `report.md` into `dir`; returns the files written, `errors.csv`
/// first when the evaluation wrote one.
pub fn write(eval: &Evaluation, dir: &Path, plots: bool) -> Result<Vec<PathBuf>, EvalError> {
    let write_err = |path: &Path| {
        let path = path.to_path_buf();
        move |error| EvalError::Write { path, error }
    };
    std::fs::create_dir_all(dir).map_err(write_err(dir))?;
    let mut written: Vec<PathBuf> = eval.errors_csv.iter().cloned().collect();
    let figures = if plots {
        super::plot::write(eval, dir)?
    } else {
        Vec::new()
    };
    if !eval.faults.is_empty() {
        let path = dir.join(super::faults::FAULTS_FILE);
        std::fs::write(&path, super::faults::csv(&eval.faults)).map_err(write_err(&path))?;
        written.push(path);
    }
    let report = dir.join("report.md");
    std::fs::write(&report, markdown(eval, dir, &figures)).map_err(write_err(&report))?;
    written.extend(figures);
    written.push(report);
    Ok(written)
}
