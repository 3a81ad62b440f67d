//! Subcommands of `margemu`, one file each.

pub mod analyze;
pub mod bench;
pub mod scene;
pub mod simulate;

/// Every subcommand.
#[derive(clap::Subcommand)]
pub enum Command {
    /// Inspect scene files.
    #[command(subcommand)]
    Scene(scene::Cmd),
    /// Simulate a scene and write its run directory (truth.csv, meta.toml).
    Simulate(simulate::Cmd),
    /// Analyse recorded columns (noise: Allan deviation and PSD).
    #[command(subcommand)]
    Analyze(analyze::Cmd),
    /// Measure speed against error on this machine.
    #[command(subcommand)]
    Bench(bench::Cmd),
}

impl Command {
    pub fn run(self) -> anyhow::Result<()> {
        match self {
            Command::Scene(c) => c.run(),
            Command::Simulate(c) => c.run(),
            Command::Bench(c) => c.run(),
            Command::Analyze(c) => c.run(),
        }
    }
}
