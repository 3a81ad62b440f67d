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
    // Rust ignores SIGPIPE, so printing to a closed pipe (`margemu scene check S | head -1`)
    // would panic in `println!`; a command-line tool ends quietly instead, as `cat` does.
    // SAFETY: called first in `main`, before any thread exists; SIG_DFL is a valid handler.
    #[allow(unsafe_code)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
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
