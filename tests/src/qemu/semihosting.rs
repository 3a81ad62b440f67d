//! Running a board binary that reports through semihosting and exits by itself (no UART, no
//! PTY): QEMU's stdout and stderr collected until it exits.

use std::io::{self, Read};
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use super::{MACHINE, QEMU};

/// Runs `elf` on the machine with semihosting on and `extra` arguments (e.g.
/// `["-icount", "shift=0"]`) until it exits, at most `timeout`; returns its exit status and
/// everything it printed (stdout, then stderr). QEMU is killed at the timeout.
pub fn run_to_exit(
    elf: &Path,
    extra: &[&str],
    timeout: Duration,
) -> io::Result<(ExitStatus, String)> {
    let mut child = Command::new(QEMU)
        .args(["-machine", MACHINE, "-nographic"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(extra)
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| io::Error::new(e.kind(), format!("cannot start {QEMU}: {e}")))?;
    let collect = |stream: Option<Box<dyn Read + Send>>| {
        thread::spawn(move || {
            let mut text = String::new();
            if let Some(mut s) = stream {
                let _ = s.read_to_string(&mut text);
            }
            text
        })
    };
    let stdout = collect(
        child
            .stdout
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>),
    );
    let stderr = collect(
        child
            .stderr
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>),
    );
    let deadline = Instant::now() + timeout;
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        thread::sleep(Duration::from_millis(20));
    };
    let output = stdout.join().unwrap_or_default() + &stderr.join().unwrap_or_default();
    match status {
        Some(status) => Ok((status, output)),
        None => Err(io::Error::new(
            io::ErrorKind::TimedOut,
            format!("{QEMU} still running after {timeout:?}; it printed:\n{output}"),
        )),
    }
}
