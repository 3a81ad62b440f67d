//! QEMU hardware-in-the-loop helpers: build the `qemu-mps2-an386` board ELF, boot it in
//! `qemu-system-arm` with UART0 on a pseudo-terminal, and talk to UART0 through `serialport`.
//!
//! ```no_run
//! use std::time::Duration;
//! use margemu_tests::qemu::{self, Qemu};
//!
//! if !qemu::prerequisites_or_skip("example") {
//!     return;
//! }
//! let elf = qemu::board_elf().unwrap();
//! let (qemu, mut uart0) = Qemu::boot(&elf).unwrap();
//! // The firmware speaks the binary link: the power-on Reset frame opens with a delimiter.
//! let frame = uart0.read_until(0x00, Duration::from_secs(5)).unwrap();
//! println!("{frame:02x?}");
//! drop(qemu); // kills and reaps QEMU
//! ```
//!
//! QEMU starts paused (`-S`) with its monitor on its stdin and stdout. [`Qemu::boot`] opens the
//! PTY first and only then sends `cont`, so nothing the firmware prints at boot is lost: QEMU
//! drops what a PTY-backed UART sends while nobody has the PTY open. Dropping a [`Qemu`] kills
//! and reaps the process, also while a failing test unwinds.
//!
//! The board is cross-built with rustup's `thumbv7em-none-eabihf` target where it is installed,
//! else with Debian's `rustc-web` and `-Zbuild-std=core`, exactly as `scripts/test-all` does,
//! into `target/thumbv7em` (or `$MARGEMU_BOARD_TARGET_DIR`).

mod build;
mod semihosting;
mod serial;

pub use build::*;
pub use semihosting::run_to_exit;
pub(crate) use serial::is_transient;
pub use serial::{LinkDecoder, SerialLink};

use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

/// The QEMU executable.
pub const QEMU: &str = "qemu-system-arm";
/// The QEMU machine: ARM MPS2 with the AN386 FPGA image (Cortex-M4F).
pub const MACHINE: &str = "mps2-an386";
/// UART0's line rate as the firmware programs it (a PTY ignores it).
pub const UART0_BAUD: u32 = 115_200;

/// How long QEMU may take to print its PTY path.
const START_TIMEOUT: Duration = Duration::from_secs(10);

/// A running `qemu-system-arm`, UART0 on a PTY; killed and reaped on drop.
pub struct Qemu {
    child: Child,
    monitor: Option<ChildStdin>,
    output: Arc<Mutex<Vec<u8>>>,
    pty: PathBuf,
}

impl Qemu {
    /// Boots `elf`: starts QEMU paused, opens UART0's PTY, then lets the CPU run.
    pub fn boot(elf: &Path) -> io::Result<(Self, SerialLink)> {
        let mut qemu = Self::start_paused(elf)?;
        let uart0 = qemu.open_uart0()?;
        qemu.resume()?;
        Ok((qemu, uart0))
    }

    /// Starts QEMU on `elf` with the CPU stopped (`-S`), and waits for the PTY path it prints.
    pub fn start_paused(elf: &Path) -> io::Result<Self> {
        let mut child = Command::new(QEMU)
            .args(["-machine", MACHINE, "-nographic", "-S"])
            .args(["-monitor", "stdio", "-serial", "pty"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| io::Error::new(e.kind(), format!("cannot start {QEMU}: {e}")))?;
        let output = Arc::new(Mutex::new(Vec::new()));
        let (found, pty) = mpsc::channel();
        let stdout = child
            .stdout
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>);
        let stderr = child
            .stderr
            .take()
            .map(|s| Box::new(s) as Box<dyn Read + Send>);
        for stream in [stdout, stderr].into_iter().flatten() {
            let (output, found) = (Arc::clone(&output), found.clone());
            thread::spawn(move || collect_output(stream, &output, &found));
        }
        let mut qemu = Self {
            monitor: child.stdin.take(),
            child,
            output,
            pty: PathBuf::new(),
        };
        match pty.recv_timeout(START_TIMEOUT) {
            Ok(path) => qemu.pty = path,
            Err(_) => {
                let status = qemu.child.try_wait()?;
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    format!(
                        "{QEMU} gave no PTY path within {START_TIMEOUT:?} (exit: {status:?}); \
                         it printed:\n{}",
                        qemu.output()
                    ),
                ));
            }
        }
        Ok(qemu)
    }

    /// The PTY that UART0 is connected to.
    pub fn pty(&self) -> &Path {
        &self.pty
    }

    /// Opens UART0's PTY.
    pub fn open_uart0(&self) -> io::Result<SerialLink> {
        SerialLink::open(&self.pty, UART0_BAUD)
    }

    /// Lets a CPU started with [`Qemu::start_paused`] run (monitor command `cont`).
    pub fn resume(&mut self) -> io::Result<()> {
        let monitor = self
            .monitor
            .as_mut()
            .ok_or_else(|| io::Error::other("no monitor"))?;
        monitor.write_all(b"cont\n")?;
        monitor.flush()
    }

    /// Waits up to `timeout` for QEMU to exit (the firmware exits through semihosting).
    pub fn wait_exit(&mut self, timeout: Duration) -> io::Result<ExitStatus> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.child.try_wait()? {
                return Ok(status);
            }
            if Instant::now() >= deadline {
                return Err(io::Error::new(
                    io::ErrorKind::TimedOut,
                    format!("{QEMU} still running after {timeout:?}"),
                ));
            }
            thread::sleep(Duration::from_millis(10));
        }
    }

    /// Host CPU time QEMU has used so far (all its threads: vCPU, I/O, main loop), from
    /// `/proc/<pid>/stat` (Linux).
    pub fn cpu_time(&self) -> io::Result<Duration> {
        let stat = std::fs::read_to_string(format!("/proc/{}/stat", self.child.id()))?;
        // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
        let fields: Vec<&str> = stat
            .rsplit_once(')')
            .map_or("", |(_, rest)| rest)
            .split_whitespace()
            .collect();
        let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<u64>().ok());
        let (Some(user), Some(system)) = (ticks(11), ticks(12)) else {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("/proc stat: {stat}"),
            ));
        };
        // USER_HZ is 100 on every Linux this runs on (x86-64, arm64).
        Ok(Duration::from_millis((user + system) * 10))
    }

    /// Everything QEMU printed so far on stdout and stderr (monitor, semihosting, errors).
    pub fn output(&self) -> String {
        let output = self.output.lock().unwrap_or_else(|e| e.into_inner());
        String::from_utf8_lossy(&output).into_owned()
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
        }
        let _ = self.child.wait();
    }
}

/// Copies one of QEMU's output streams into `output`, and sends the PTY path once it shows.
fn collect_output(
    stream: Box<dyn Read + Send>,
    output: &Mutex<Vec<u8>>,
    found: &mpsc::Sender<PathBuf>,
) {
    let mut reader = BufReader::new(stream);
    let mut line = Vec::new();
    while matches!(reader.read_until(b'\n', &mut line), Ok(n) if n > 0) {
        if let Some(path) = pty_path(&String::from_utf8_lossy(&line)) {
            let _ = found.send(path);
        }
        output
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend_from_slice(&line);
        line.clear();
    }
}

/// The path in QEMU's `char device redirected to /dev/pts/N (label serial0)` line.
fn pty_path(line: &str) -> Option<PathBuf> {
    const MARK: &str = "char device redirected to ";
    let rest = &line[line.find(MARK)? + MARK.len()..];
    let (path, label) = rest.split_once(char::is_whitespace)?;
    label.contains("serial0").then(|| PathBuf::from(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_pty_path_in_monitor_and_stderr_lines() {
        let monitor = "(qemu) char device redirected to /dev/pts/7 (label serial0)\n";
        assert_eq!(pty_path(monitor), Some(PathBuf::from("/dev/pts/7")));
        let stderr =
            "qemu-system-arm: -serial pty: char device redirected to /dev/pts/12 (label serial0)\n";
        assert_eq!(pty_path(stderr), Some(PathBuf::from("/dev/pts/12")));
    }

    #[test]
    fn ignores_other_lines_and_other_chardevs() {
        assert_eq!(pty_path("QEMU 7.2.22 monitor - type 'help'\n"), None);
        assert_eq!(
            pty_path("char device redirected to /dev/pts/3 (label serial1)\n"),
            None
        );
        assert_eq!(pty_path("char device redirected to /dev/pts/3"), None);
    }
}
