//! `margemu evaluate`: scores a device's or a filter's attitude against the truth (library:
//! `margemu::evaluate`).

use anyhow::{bail, Result};
use margemu::evaluate::{
    report, EvalOptions, LatencyMode, LatencySearch, Mask, PhaseRules, ScoreOptions, Source,
};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Cmd {
    /// A session directory (truth.csv, meta.toml, dut_attitude.csv), or with --estimates any run
    /// directory with a truth.csv (simulate output).
    dir: Option<PathBuf>,
    /// Estimates `t_s,qw,qx,qy,qz` (s from the scene start, or the external recording's axis).
    #[arg(long)]
    estimates: Option<PathBuf>,
    /// An external recording `t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz[,qw_est,qx_est,qy_est,qz_est]`.
    #[arg(long, conflicts_with = "dir")]
    external: Option<PathBuf>,
    /// Where report.md, errors.csv and the figures go (default: the session directory, or
    /// `<recording>-evaluation/` beside an external recording).
    #[arg(long)]
    out: Option<PathBuf>,
    /// `auto` (estimate it) or a fixed latency in ms (default: auto for sessions, 0 otherwise).
    #[arg(long)]
    latency: Option<String>,
    /// Largest latency searched either way (ms).
    #[arg(long, default_value_t = 500.0)]
    max_lag: f64,
    /// Seconds at the start left out of the scores (filter convergence).
    #[arg(long, default_value_t = 0.0)]
    warmup: f64,
    /// Truth samples further apart than this (ms) are not interpolated across (default: 4 ×
    /// their median spacing).
    #[arg(long)]
    max_gap: Option<f64>,
    /// Keep only dut_attitude.csv rows with this `message`.
    #[arg(long)]
    message: Option<String>,
    /// Stamp device output with its host arrival time even when it carries device times.
    #[arg(long)]
    host_time: bool,
    /// Static phase: body rate below this (rad/s).
    #[arg(long, default_value_t = 0.05)]
    static_rate: f64,
    /// Static phase: external acceleration below this (m/s²).
    #[arg(long, default_value_t = 0.1)]
    static_accel: f64,
    /// Magnetic phase: field deviation above this fraction of the reference norm.
    #[arg(long, default_value_t = 0.1)]
    mag_threshold: f64,
    /// Averaging window of measured signals for the phases (ms).
    #[arg(long, default_value_t = 100.0)]
    window: f64,
    /// Score only the external recording's rows whose value in this column is nonzero.
    #[arg(long, requires = "external", conflicts_with = "mask")]
    mask_column: Option<String>,
    /// Score only the external recording's rows at rest or in motion: the gyro norm, averaged
    /// over --window as the phases are, below (rest) or at or above (motion) --rest-rate.
    #[arg(long, requires = "external", value_parser = ["rest", "motion"])]
    mask: Option<String>,
    /// The rate (rad/s) that separates rest from motion for --mask.
    #[arg(
        long,
        default_value_t = 0.05,
        requires = "mask",
        allow_negative_numbers = true
    )]
    rest_rate: f64,
    /// The world frame of the external recording and its estimates: nwu (margemu's), enu, or
    /// ned (body FRD).
    #[arg(long, default_value = "nwu", requires = "external")]
    frame: margemu::frame::Frame,
    /// Skip the figures.
    #[arg(long)]
    no_plots: bool,
    /// Score a run that did not complete (killed, interrupted or failed: meta.toml's
    /// completion record); the report then says so.
    #[arg(long)]
    allow_incomplete: bool,
    /// Fault windows (events.csv): recovered once the geodesic error stays below this (°)
    /// instead of --recovery-factor × its RMS before the window.
    #[arg(long)]
    recovery_threshold: Option<f64>,
    /// Fault windows: the recovery threshold as a multiple of the geodesic RMS before the
    /// window (at least 1°).
    #[arg(long, default_value_t = 2.0)]
    recovery_factor: f64,
    /// Fault windows: how long the error must stay below the threshold (ms).
    #[arg(long, default_value_t = 500.0)]
    recovery_hold: f64,
}

fn ms_to_ns(name: &str, ms: f64) -> Result<u64> {
    if !(ms.is_finite() && ms >= 0.0) {
        bail!("--{name} must be a finite number ≥ 0, not {ms}");
    }
    Ok((ms * 1e6).round() as u64)
}

impl Cmd {
    fn fault_options(&self) -> Result<margemu::evaluate::faults::FaultOptions> {
        let positive = |name: &str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                bail!("--{name} must be a finite number > 0, not {x}")
            }
        };
        Ok(margemu::evaluate::faults::FaultOptions {
            factor: positive("recovery-factor", self.recovery_factor)?,
            threshold_rad: self
                .recovery_threshold
                .map(|t| positive("recovery-threshold", t).map(f64::to_radians))
                .transpose()?,
            hold_ns: ms_to_ns("recovery-hold", self.recovery_hold)?,
            ..Default::default()
        })
    }

    pub fn run(self) -> Result<()> {
        let faults = self.fault_options()?;
        let (source, default_out) = match (&self.dir, &self.external) {
            (None, Some(file)) => {
                let stem = file.file_stem().unwrap_or_default().to_string_lossy();
                let out = file.with_file_name(format!("{stem}-evaluation"));
                let estimates = self.estimates.clone();
                (
                    Source::External {
                        file: file.clone(),
                        estimates,
                    },
                    out,
                )
            }
            (Some(dir), None) => match &self.estimates {
                Some(estimates) => {
                    let estimates = estimates.clone();
                    (
                        Source::Estimates {
                            dir: dir.clone(),
                            estimates,
                        },
                        dir.clone(),
                    )
                }
                None => (Source::Session(dir.clone()), dir.clone()),
            },
            _ => bail!("give a session or run directory, or --external FILE"),
        };
        let latency = match self.latency.as_deref() {
            None => None,
            Some("auto") => Some(LatencyMode::Auto),
            Some(text) => match text.parse::<f64>() {
                Ok(ms) if ms.is_finite() => Some(LatencyMode::Fixed((ms * 1e6).round() as i64)),
                _ => bail!("--latency must be `auto` or a number of ms, not {text:?}"),
            },
        };
        if !(self.rest_rate.is_finite() && self.rest_rate > 0.0) {
            bail!(
                "--rest-rate must be a finite rate > 0 (rad/s), not {}",
                self.rest_rate
            );
        }
        let mask = match (self.mask.as_deref(), self.mask_column) {
            (Some("rest"), _) => Mask::Rest(self.rest_rate),
            (Some(_), _) => Mask::Motion(self.rest_rate),
            (None, Some(column)) => Mask::Column(column),
            (None, None) => Mask::All,
        };
        let options = EvalOptions {
            frame: self.frame,
            mask,
            latency,
            search: LatencySearch {
                max_lag_ns: ms_to_ns("max-lag", self.max_lag)?,
                step_ns: None,
                score: ScoreOptions {
                    latency_ns: 0,
                    warmup_ns: ms_to_ns("warmup", self.warmup * 1e3)?,
                    max_gap_ns: self.max_gap.map(|g| ms_to_ns("max-gap", g)).transpose()?,
                },
            },
            message: self.message,
            device_time: !self.host_time,
            rules: PhaseRules {
                static_rate: self.static_rate,
                static_accel: self.static_accel,
                magnetic_fraction: self.mag_threshold,
                window_ns: ms_to_ns("window", self.window)?,
            },
            allow_incomplete: self.allow_incomplete,
            faults,
        };
        let out = self.out.unwrap_or(default_out);
        let eval =
            margemu::evaluate::evaluate_writing(&source, &options, Some(&out.join("errors.csv")))?;
        print!("{}", report::summary(&eval));
        let written = report::write(&eval, &out, !self.no_plots)?;
        let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
        println!("wrote {}", names.join(", "));
        Ok(())
    }
}
