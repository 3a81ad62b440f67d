//! `margemu simulate SCENE [-o DIR] [--force] [--mcap]`: run a scene and write its run directory
//! (default `runs/<scene name>`, numbered if taken: [`margemu::rundir`]).

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;

use super::OutputArgs;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
    scene: PathBuf,
    // Default: runs/<scene name>.
    #[command(flatten)]
    output: OutputArgs,
    #[command(flatten)]
    size: super::SizeArgs,
    /// Also write `run.mcap` (ROS 2 messages for Foxglove and `ros2 bag`; docs/mcap.md).
    #[arg(long)]
    mcap: bool,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let stop = super::Interrupt::install()?.flag();
        let scene = super::load_scene(&self.scene)?;
        self.size.check(&scene)?;
        let dir = self.output.prepare(&scene, "runs", "")?;
        let bar =
            ProgressBar::with_draw_target(Some(scene.samples()), ProgressDrawTarget::hidden());
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} samples, {per_sec}, eta {eta}")
                .expect("valid template"),
        );
        let start = Instant::now();
        let mut shown = false;
        let progress = |done, _total| {
            // Only runs longer than a second get a bar.
            if !shown && start.elapsed() > Duration::from_secs(1) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
                shown = true;
            }
            bar.set_position(done);
        };
        let outputs = margemu::run::RunOutputs { mcap: self.mcap };
        let summary = margemu::run::simulate_to_dir_with(&scene, &dir, &stop, progress, &outputs)
            .with_context(|| format!("simulating {}", scene.path.display()))?;
        bar.finish_and_clear();
        println!(
            "wrote {} samples ({} s at {} Hz) to {} in {:.2} s",
            summary.samples,
            scene.spec.duration,
            scene.clock.hz(),
            dir.display(),
            start.elapsed().as_secs_f64()
        );
        if !summary.friction_events.is_empty() {
            println!("friction mode changes: {}", summary.friction_events.len());
        }
        Ok(())
    }
}
