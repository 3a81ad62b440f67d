//! `margemu demo`: the paper's case study through loopback with the virtual flight controller,
//! every filter with its initial and tuned parameters (the tuner run in process on the scene,
//! or a parameters file), and the Table 3 analogue (library: `margemu::demo`).

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use margemu::demo::{self, table, DemoOptions, Variant};
use margemu::offline::{FilterKind, FilterParams};
use margemu::scene::Scene;
use margemu::tune::{self as tuner, Dataset, TuneOptions};
use margemu::vfc::describe;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`); default: the
    /// paper's case study.
    #[arg(long, default_value = "case-study")]
    scene: PathBuf,
    // One session per run (`<filter>-<initial|tuned>/`, with report.md and figures) and
    // table3.md; default: demo/, numbered if taken.
    #[command(flatten)]
    output: super::OutputArgs,
    /// Shorten the scene to this many seconds (each run streams in real time).
    #[arg(long, value_name = "S")]
    duration: Option<f64>,
    /// Tuned parameters from this file (TOML with [ecf], [gda] and [ekf] tables, as `margemu
    /// tune --write-params` writes it) instead of tuning on the scene.
    #[arg(long, value_name = "FILE")]
    tuned: Option<PathBuf>,
    /// Tuning: seeds of the scene the objective (mean F, eq. 27) is averaged over.
    #[arg(long, default_value_t = 4, conflicts_with = "tuned")]
    seeds: usize,
    /// Tuning: budget of objective evaluations per filter.
    #[arg(long, default_value_t = 200, conflicts_with = "tuned")]
    max_evals: usize,
    /// The filters to run: ecf, gda, ekf (comma list).
    #[arg(long, value_delimiter = ',', default_value = "ecf,gda,ekf")]
    filters: Vec<FilterKind>,
    /// Skip the figures.
    #[arg(long)]
    no_plots: bool,
}

/// Tuned parameters from a file: each filter's table must be there.
fn from_file(path: &Path) -> Result<Box<demo::Tuned<'static>>> {
    let text = margemu::input_file::read_to_string(path)?;
    let tables: toml::Table = text
        .parse()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let path = path.to_path_buf();
    Ok(Box::new(move |_: &Scene, kind: FilterKind| {
        if !tables.contains_key(kind.name()) {
            return Err(format!("{} has no [{kind}] table", path.display()));
        }
        FilterParams::from_toml(&text, &path, kind).map_err(|e| e.to_string())
    }))
}

/// Tuned parameters from the tuner, in process: the scene simulated once for all filters, the
/// tuner's defaults otherwise (warm-up 1 s, at most a quarter of the scene).
fn from_tuner(seeds: usize, max_evals: usize) -> Box<demo::Tuned<'static>> {
    let mut data: Option<Dataset> = None;
    Box::new(move |scene: &Scene, kind: FilterKind| {
        let opts = TuneOptions {
            seeds,
            max_evals,
            warmup_s: TuneOptions::default()
                .warmup_s
                .min(scene.spec.duration / 4.0),
            ..TuneOptions::default()
        };
        if data.is_none() {
            data = Some(Dataset::simulate(scene, seeds).map_err(|e| e.to_string())?);
        }
        let data = data.as_ref().expect("simulated above");
        let r = tuner::tune_dataset(data, kind, &opts, &|_| {}).map_err(|e| e.to_string())?;
        println!(
            "tuned {kind} on seeds {:?} in {} evaluations: mean F {:.4} -> {:.4} ({})",
            r.seeds,
            r.search.evaluations,
            r.initial.mean(|s| s.f),
            r.tuned.mean(|s| s.f),
            describe(&r.tuned.params)
        );
        Ok(r.tuned.params)
    })
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let interrupt = super::Interrupt::install()?;
        let mut scene = super::load_scene(&self.scene)?;
        if let Some(seconds) = self.duration {
            if !(seconds.is_finite() && seconds > 0.0) {
                bail!("--duration must be > 0 s, not {seconds}");
            }
            scene = demo::shorten(&scene, seconds)?;
        }
        let out = self.output.prepare_or(Path::new("demo"))?;
        let mut tuned = match &self.tuned {
            Some(path) => from_file(path)?,
            None => from_tuner(self.seeds, self.max_evals),
        };
        let stop = interrupt.flag();
        let (over, n, max) = demo::gyro_clipping(&scene)?;
        println!(
            "demo: {} ({} s at {} Hz) through loopback with the virtual flight controller: {} run(s) in real time",
            scene.path.display(),
            scene.spec.duration,
            scene.clock.hz(),
            2 * self.filters.len()
        );
        println!(
            "the scene's body rate reaches {max:.1} rad/s; the chip's widest gyro range (±2000 °/s = ±34.9 rad/s) clips {over} of {n} samples ({:.2} %)",
            100.0 * over as f64 / n.max(1) as f64
        );
        let options = DemoOptions {
            scene,
            out: out.clone(),
            filters: self.filters.clone(),
            plots: !self.no_plots,
        };
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template("{msg:12} {bar:30} {pos}/{len}").expect("valid"),
        );
        let runs = demo::run(&options, Some(&mut *tuned), &stop, |label, p| {
            bar.set_message(label.to_string());
            bar.set_length(p.total);
            bar.set_position(p.sent);
        });
        bar.finish_and_clear();
        let runs = runs?;
        for r in &runs {
            println!(
                "{} {}: {}; served {}/{} byte for byte; the flight controller read {} samples \
                 ({} warm-up, {} missed); latency {:.2} ms; {}",
                r.kind,
                r.variant.name(),
                describe(&r.params),
                r.served.0,
                r.served.1,
                r.fc.samples,
                r.fc.warmup,
                r.fc.missed,
                r.latency_ns as f64 * 1e-6,
                r.dir.display()
            );
        }
        println!("\nTable 3 analogue, ours (paper's):");
        print!("{}", table::render(&runs, false));
        for variant in [Variant::Initial, Variant::Tuned] {
            if let Some(line) = table::ordering(&runs, variant) {
                println!("{line}");
            }
        }
        let md = out.join(table::FILE);
        std::fs::write(&md, table::render(&runs, true))
            .with_context(|| format!("writing {}", md.display()))?;
        println!("wrote {}", md.display());
        Ok(())
    }
}
