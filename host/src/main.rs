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
            eprintln!("error: {}", message(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// The error and its chain of causes, `: `-separated, each said once: a wrapper whose message
/// is its cause's (`/// {0}` with `#[from]`) would otherwise repeat it.
fn message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let said = cause.to_string();
        if !text.contains(&said) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&said);
        }
    }
    text
}
