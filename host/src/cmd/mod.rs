//! Subcommands of `margemu`, one file each.

pub mod analyze;
pub mod bench;
mod bench_stream;
pub mod chips;
pub mod demo;
pub mod evaluate;
pub mod filter;
pub mod loopback;
pub mod ports;
pub mod scene;
pub mod simulate;
pub mod stream;
pub mod tune;
mod vfc;

/// Every subcommand.
#[derive(clap::Subcommand)]
pub enum Command {
    /// Inspect scene files.
    #[command(subcommand)]
    Scene(scene::Cmd),
    /// Stream a scene to the firmware's link handler behind a pseudo-terminal pair (no hardware).
    Loopback(loopback::Cmd),
    /// Simulate a scene and write its run directory (truth.csv, meta.toml).
    Simulate(simulate::Cmd),
    /// Analyse recorded columns (noise: Allan deviation and PSD).
    #[command(subcommand)]
    Analyze(analyze::Cmd),
    /// Measure speed against error on this machine.
    #[command(subcommand)]
    Bench(bench::Cmd),
    /// Stream a scene to a device in real time over a serial port and log the session.
    Stream(stream::Cmd),
    /// List serial ports.
    Ports(ports::Cmd),
    /// List the emulated chips: identities, buses, full scales, rates, what is emulated.
    Chips(chips::Cmd),
    /// Score a device's or a filter's attitude against the truth (eq. 27, geodesic), aligned.
    Evaluate(evaluate::Cmd),
    /// The paper's case study through loopback with the virtual flight controller: Table 3.
    Demo(demo::Cmd),
    /// Run a reference filter (ECF, GDA, EKF) offline over a recording; write its estimates.
    Filter(filter::Cmd),
    /// Tune a reference filter's parameters on a scene over several seeds (eq. 27, Table 3).
    Tune(tune::Cmd),
}

/// Loads a scene file for a command, reads and checks its CSV joint sources (so a bad source
/// stops the command before it writes anything), and prints the scene's warnings to stderr:
/// the one place commands load scenes, so the warnings appear once per command.
pub fn load_scene(path: &std::path::Path) -> anyhow::Result<margemu::scene::Scene> {
    let scene = margemu::scene::Scene::load(path)?;
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
            Command::Simulate(c) => c.run(),
            Command::Loopback(c) => c.run(),
            Command::Bench(c) => c.run(),
            Command::Analyze(c) => c.run(),
            Command::Stream(c) => c.run(),
            Command::Ports(c) => c.run(),
            Command::Chips(c) => c.run(),
            Command::Evaluate(c) => c.run(),
            Command::Demo(c) => c.run(),
            Command::Filter(c) => c.run(),
            Command::Tune(c) => c.run(),
        }
    }
}
