//! Subcommands of `margemu`, one file each.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

pub mod analyze;
pub mod bench;
mod bench_stream;
pub mod chips;
pub mod demo;
pub mod evaluate;
pub mod filter;
pub mod hitl;
pub mod loopback;
pub mod ports;
pub mod scene;
pub mod scenes;
pub mod simulate;
pub mod stream;
pub mod tune;
mod vfc;

/// Where a command writes its run or session directory (policy: [`margemu::rundir`]).
#[derive(clap::Args)]
pub struct OutputArgs {
    /// The directory to write (created if missing). Without it, a fresh directory is made
    /// under the default name, numbered (-2, -3, ...) if that one is taken.
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,
    /// Write into a non-empty --output directory: margemu's own files in it are removed first
    /// (anything else there makes the command refuse).
    #[arg(long, requires = "output")]
    force: bool,
}

impl OutputArgs {
    /// The directory, created and empty: --output, or `<parent>/<scene's stem><suffix>` made
    /// fresh (the stem: a built-in scene's name, or the file's name without its extension).
    pub fn prepare(
        &self,
        scene: &margemu::scene::Scene,
        parent: &str,
        suffix: &str,
    ) -> Result<PathBuf> {
        let stem = scene.stem();
        self.prepare_or(&Path::new(parent).join(format!("{stem}{suffix}")))
    }

    /// The directory, created and empty: --output, or `default` made fresh.
    pub fn prepare_or(&self, default: &Path) -> Result<PathBuf> {
        Ok(margemu::rundir::prepare(
            self.output.as_deref(),
            default,
            self.force,
            margemu::own_files::OWN_FILES,
        )?)
    }
}

/// SIGINT, SIGTERM and SIGHUP, caught from the start of a command: each sets every stop flag
/// handed to [`Interrupt::watch`], including flags handed over after the signal came (a session
/// whose images were still being predicted then starts stopped, and ends as interrupted).
#[derive(Clone)]
pub struct Interrupt(Arc<Mutex<Signalled>>);

#[derive(Default)]
struct Signalled {
    fired: bool,
    flags: Vec<Arc<AtomicBool>>,
}

impl Interrupt {
    /// Installs the handler (once per process).
    pub fn install() -> Result<Self> {
        let this = Self(Arc::default());
        let shared = this.0.clone();
        ctrlc::set_handler(move || {
            let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
            s.fired = true;
            s.flags
                .iter()
                .for_each(|f| f.store(true, Ordering::Relaxed));
        })
        .context("installing the SIGINT/SIGTERM/SIGHUP handler")?;
        Ok(this)
    }

    /// Sets `flag` on a signal (at once if one has come).
    pub fn watch(&self, flag: Arc<AtomicBool>) {
        let mut s = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if s.fired {
            flag.store(true, Ordering::Relaxed);
        }
        s.flags.push(flag);
    }

    /// A new flag, set on a signal.
    pub fn flag(&self) -> Arc<AtomicBool> {
        let flag = Arc::new(AtomicBool::new(false));
        self.watch(flag.clone());
        flag
    }
}

/// Every subcommand.
#[derive(clap::Subcommand)]
pub enum Command {
    /// Inspect scene files.
    #[command(subcommand)]
    Scene(scene::Cmd),
    /// List the built-in scenes (a command takes one by name wherever it takes a scene file).
    Scenes(scenes::Cmd),
    /// Stream a scene (default: the built-in figure3) to the firmware's link handler behind a
    /// pseudo-terminal pair (no hardware); the session goes to sessions/<scene name>-loopback
    /// (numbered if taken) unless -o.
    Loopback(loopback::Cmd),
    /// Simulate a scene and write its run directory (truth.csv, marg.csv, meta.toml) to
    /// runs/<scene name> (numbered if taken) unless -o.
    Simulate(simulate::Cmd),
    /// Analyse recorded columns (noise: Allan deviation and PSD).
    #[command(subcommand)]
    Analyze(analyze::Cmd),
    /// Measure speed against error on this machine.
    #[command(subcommand)]
    Bench(bench::Cmd),
    /// Stream a scene to a device in real time over a serial port and log the session to
    /// sessions/<scene name> (numbered if taken) unless -o.
    Stream(stream::Cmd),
    /// Send a scene as MAVLink HIL_SENSOR to a flight controller in HITL mode (PX4) over a
    /// serial port or UDP, log the attitude it sends back, and write the session to
    /// sessions/<scene name>-hitl (numbered if taken) unless -o.
    Hitl(hitl::Cmd),
    /// List serial ports.
    Ports(ports::Cmd),
    /// List the emulated chips: identities, buses, full scales, rates, what is emulated.
    Chips(chips::Cmd),
    /// Score a device's or a filter's attitude against the truth (eq. 27, geodesic), aligned.
    Evaluate(evaluate::Cmd),
    /// The paper's case study through loopback with the virtual flight controller: Table 3
    /// (written to demo/, numbered if taken, unless -o).
    Demo(demo::Cmd),
    /// Run a reference filter (ECF, GDA, EKF) offline over a recording; write its estimates.
    Filter(filter::Cmd),
    /// Tune a reference filter's parameters on a scene over several seeds (eq. 27, Table 3).
    Tune(tune::Cmd),
}

/// Loads the scene a command's argument stands for (a file's path, or a built-in scene's name:
/// [`margemu::scene::builtin::resolve`]), reads and checks its CSV joint sources (so a bad
/// source stops the command before it writes anything), and prints the scene's warnings to
/// stderr: the one place commands load scenes, so the warnings appear once per command.
pub fn load_scene(arg: &std::path::Path) -> anyhow::Result<margemu::scene::Scene> {
    let scene = margemu::scene::builtin::resolve(arg)?;
    for warning in &scene.warnings {
        eprintln!("warning: {warning}");
    }
    margemu::motion::Motion::new(&scene)?;
    Ok(scene)
}

/// The run-size limit of commands that run a whole scene (`margemu::scene::size`).
#[derive(clap::Args)]
pub struct SizeArgs {
    /// Run a scene beyond 10 M samples or 2 GiB of estimated output.
    #[arg(long)]
    allow_large: bool,
}

impl SizeArgs {
    /// The run's size, refused beyond the limits unless `--allow-large`.
    pub fn check(&self, scene: &margemu::scene::Scene) -> anyhow::Result<()> {
        margemu::scene::size::check(scene, self.allow_large)?;
        Ok(())
    }
}

impl Command {
    pub fn run(self) -> anyhow::Result<()> {
        match self {
            Command::Scene(c) => c.run(),
            Command::Scenes(c) => c.run(),
            Command::Simulate(c) => c.run(),
            Command::Loopback(c) => c.run(),
            Command::Bench(c) => c.run(),
            Command::Analyze(c) => c.run(),
            Command::Stream(c) => c.run(),
            Command::Hitl(c) => c.run(),
            Command::Ports(c) => c.run(),
            Command::Chips(c) => c.run(),
            Command::Evaluate(c) => c.run(),
            Command::Demo(c) => c.run(),
            Command::Filter(c) => c.run(),
            Command::Tune(c) => c.run(),
        }
    }
}

/// Three numbers `X,Y,Z` (spaces around each allowed: `"-0.36, 0, -0.93"`), finite, for the
/// option `option`; the error names it and says what it got.
pub fn parse_vector3(option: &str, text: &str) -> Result<[f64; 3]> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let numbers: Option<Vec<f64>> = parts
        .iter()
        .map(|p| p.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    match numbers.as_deref() {
        Some(&[x, y, z]) => Ok([x, y, z]),
        _ => anyhow::bail!(
            "{option} needs three finite numbers X,Y,Z (e.g. 0.36,0,-0.93), not {text:?}"
        ),
    }
}
