//! The `margemu` command line; each subcommand lives in `cmd/<name>.rs`.

mod cmd;

use clap::Parser;

/// margemu: a hardware-in-the-loop MARG sensor emulator built on the 6-DOF test bench of
/// Odry (2021).
#[derive(Parser)]
#[command(name = "margemu", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: cmd::Command,
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    match cli.command.run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
