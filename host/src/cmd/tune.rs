//! `margemu tune SCENE --filter ecf|gda|ekf`: tune a reference filter's parameters on a scene
//! over several seeds, and print initial against tuned like the paper's Table 3 (library:
//! `margemu::tune`).

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use margemu::offline::FilterKind;
use margemu::tune::{self, report, AttitudeStart, Dataset, Objective, TuneOptions};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
    scene: PathBuf,
    /// The filters to tune, one after the other on the same seeds: ecf, gda, ekf (comma list).
    #[arg(long, value_delimiter = ',', required = true)]
    filter: Vec<FilterKind>,
    /// Seeds: the scene's seed and the next N − 1; the objective is the mean over them.
    #[arg(long, default_value_t = 4)]
    seeds: usize,
    /// What to minimise: f (eq. 27) or geodesic (RMS of the geodesic error).
    #[arg(long, default_value = "f")]
    objective: Objective,
    /// Budget of objective evaluations per filter.
    #[arg(long, default_value_t = 200)]
    max_evals: usize,
    /// Seconds at the start of each run left out of the scores.
    #[arg(long, default_value_t = 1.0)]
    warmup: f64,
    /// Where each filter run starts: first-sample (TRIAD, as the filters do on their own) or
    /// truth (the true attitude at the first sample: only tracking is scored).
    #[arg(long, default_value = "first-sample")]
    attitude_start: AttitudeStart,
    /// Write the tuned parameters to this file (its other filters' tables are kept).
    #[arg(long)]
    write_params: Option<PathBuf>,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let scene = super::load_scene(&self.scene)?;
        let start = Instant::now();
        let data = Dataset::simulate(&scene, self.seeds)
            .with_context(|| format!("simulating {}", scene.path.display()))?;
        let seeds = data.seeds();
        println!(
            "{}: {} s at {} Hz, seeds {:?}, simulated in {:.2} s",
            data.scene,
            data.duration_s,
            data.rate_hz,
            seeds,
            start.elapsed().as_secs_f64()
        );
        let opts = TuneOptions {
            seeds: self.seeds,
            objective: self.objective,
            max_evals: self.max_evals,
            warmup_s: self.warmup,
            attitude_start: self.attitude_start,
            initial_params: None,
        };
        println!(
            "objective: mean over seeds of {}, start {}, warm-up {} s, at most about {} evaluations \
             per filter\n",
            opts.objective, opts.attitude_start, opts.warmup_s, opts.max_evals
        );
        for kind in self.filter.iter().copied() {
            self.tune_one(&data, kind, &opts)?;
        }
        Ok(())
    }

    fn tune_one(&self, data: &Dataset, kind: FilterKind, opts: &TuneOptions) -> Result<()> {
        let bar = ProgressBar::new(opts.max_evals as u64);
        bar.set_style(
            ProgressStyle::with_template("{prefix} {bar:40} {pos}/{len} evaluations, eta {eta}")
                .expect("valid template"),
        );
        bar.set_prefix(kind.name());
        let start = Instant::now();
        let progress = |n: usize| {
            if n as u64 > bar.length().unwrap_or(0) {
                bar.set_length(n as u64);
            }
            bar.set_position(n as u64);
        };
        let result = tune::tune_dataset(data, kind, opts, &progress)
            .with_context(|| format!("tuning {kind}"))?;
        bar.finish_and_clear();
        print!("{}", report::table(&result));
        println!(
            "{}; {:.1} s\n",
            report::search_line(&result),
            start.elapsed().as_secs_f64()
        );
        if let Some(path) = &self.write_params {
            let existing = match std::fs::read_to_string(path) {
                Ok(text) => text,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
                Err(e) => return Err(e).context(format!("{}: cannot read", path.display())),
            };
            let text = report::params_file(&existing, &result)
                .with_context(|| format!("{}: not a parameters file", path.display()))?;
            std::fs::write(path, text)
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
        Ok(())
    }
}
