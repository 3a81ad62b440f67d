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

use std::collections::VecDeque;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::{mpsc, Arc, Mutex, OnceLock};
use std::thread;
use std::time::{Duration, Instant};

use margemu_protocol::link::{Accumulator, FeedResult, FrameRepr, Message};
use serialport::TTYPort;

use crate::workspace_root;

/// The board crate's folder name under `firmware/boards/`.
pub const BOARD: &str = "qemu-mps2-an386";
/// The board binary's name (its package name).
pub const BOARD_BIN: &str = "margemu-board-qemu-mps2-an386";
/// The Cortex-M4F target the board builds for.
pub const CROSS_TARGET: &str = "thumbv7em-none-eabihf";
/// The QEMU executable.
pub const QEMU: &str = "qemu-system-arm";
/// The QEMU machine: ARM MPS2 with the AN386 FPGA image (Cortex-M4F).
pub const MACHINE: &str = "mps2-an386";
/// UART0's line rate as the firmware programs it (a PTY ignores it).
pub const UART0_BAUD: u32 = 115_200;

/// Debian's second Rust toolchain (`rustc-web`), which can build `core` for any target.
const DEBIAN_RUSTC: &str = "/usr/bin/rustc";
const DEBIAN_CARGO: &str = "/usr/bin/cargo";
const DEBIAN_PACKAGES: &str = "rustc-web cargo-web rust-web-src lld";
/// How long QEMU may take to print its PTY path.
const START_TIMEOUT: Duration = Duration::from_secs(10);
/// The serial port's read timeout: how often a waiting read looks at its deadline.
const POLL: Duration = Duration::from_millis(50);

/// Whether this runs under CI (`CI=true`), where the QEMU tests must run, not skip.
pub fn is_ci() -> bool {
    matches!(std::env::var("CI").as_deref(), Ok("true" | "1"))
}

/// Whether the QEMU tests can run here: `qemu-system-arm` and a cross toolchain are present.
/// If not, under CI this panics (CI must run them); elsewhere it prints why `test` is skipped
/// and returns `false`.
pub fn prerequisites_or_skip(test: &str) -> bool {
    let missing = missing_prerequisites();
    if missing.is_empty() {
        return true;
    }
    let why = missing.join("; ");
    if is_ci() {
        panic!("{test}: cannot run under CI=true: {why}");
    }
    eprintln!("SKIPPED {test}: {why}");
    false
}

/// What the QEMU tests need and this machine lacks, one sentence each.
pub fn missing_prerequisites() -> Vec<String> {
    let mut missing = Vec::new();
    if !runs(Command::new(QEMU).arg("--version")) {
        missing.push(format!(
            "{QEMU} not found (apt-get install qemu-system-arm)"
        ));
    }
    if let Err(e) = cross_toolchain() {
        missing.push(e.to_string());
    }
    missing
}

/// The toolchain that cross-builds the board.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrossToolchain {
    /// rustup's toolchain with the `thumbv7em-none-eabihf` target installed.
    Rustup,
    /// Debian's `rustc-web` with `rust-web-src`: `-Zbuild-std=core` (`RUSTC_BOOTSTRAP=1`).
    Debian,
}

/// Finds a toolchain that can build the board, preferring rustup's target.
pub fn cross_toolchain() -> io::Result<CrossToolchain> {
    if !runs(Command::new("ld.lld").arg("--version")) {
        return Err(not_found(
            "ld.lld not found, the board's linker (apt-get install lld)".into(),
        ));
    }
    if rustup_has_cross_target() {
        return Ok(CrossToolchain::Rustup);
    }
    let core_src = Command::new(DEBIAN_RUSTC)
        .args(["--print", "sysroot"])
        .output()
        .ok()
        .filter(|out| out.status.success())
        .map(|out| {
            let sysroot = String::from_utf8_lossy(&out.stdout).trim().to_owned();
            PathBuf::from(sysroot).join("lib/rustlib/src/rust/library/core")
        });
    match core_src {
        Some(src) if src.is_dir() && Path::new(DEBIAN_CARGO).exists() => Ok(CrossToolchain::Debian),
        _ => Err(not_found(format!(
            "no {CROSS_TARGET} toolchain: rustup lacks the target and Debian's is incomplete \
             (apt-get install {DEBIAN_PACKAGES})"
        ))),
    }
}

fn rustup_has_cross_target() -> bool {
    Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .is_ok_and(|out| {
            out.status.success()
                && String::from_utf8_lossy(&out.stdout)
                    .lines()
                    .any(|line| line.trim() == CROSS_TARGET)
        })
}

/// The board's folder, `firmware/boards/qemu-mps2-an386`.
pub fn board_dir() -> PathBuf {
    workspace_root().join("firmware/boards").join(BOARD)
}

/// Where board builds go: `$MARGEMU_BOARD_TARGET_DIR`, else `target/thumbv7em` (shared with
/// the cross build of `scripts/test-all`).
pub fn board_target_dir() -> PathBuf {
    std::env::var_os("MARGEMU_BOARD_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("target/thumbv7em"))
}

/// The board ELF, built once per test process (release profile); `$MARGEMU_BOARD_ELF`, if set,
/// names a prebuilt one to use instead (e.g. a variant under measurement).
pub fn board_elf() -> io::Result<PathBuf> {
    if let Some(elf) = std::env::var_os("MARGEMU_BOARD_ELF") {
        return Ok(PathBuf::from(elf));
    }
    static ELF: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    ELF.get_or_init(|| build_board(&board_dir(), &board_target_dir()).map_err(|e| e.to_string()))
        .clone()
        .map_err(io::Error::other)
}

/// Cross-builds the board crate in `board` (release) into `target_dir` and returns its ELF.
/// Cargo runs in the board's folder so its `.cargo/config.toml` (target, linker) applies.
pub fn build_board(board: &Path, target_dir: &Path) -> io::Result<PathBuf> {
    let toolchain = cross_toolchain()?;
    let mut cmd = match toolchain {
        CrossToolchain::Rustup => {
            let mut cmd = Command::new("cargo");
            cmd.env_remove("RUSTC");
            cmd
        }
        CrossToolchain::Debian => {
            let mut cmd = Command::new(DEBIAN_CARGO);
            cmd.env("RUSTC", DEBIAN_RUSTC).env("RUSTC_BOOTSTRAP", "1");
            cmd
        }
    };
    cmd.current_dir(board).args(["build", "--release"]);
    if toolchain == CrossToolchain::Debian {
        cmd.arg("-Zbuild-std=core");
    }
    // The host build's flags and target must not leak into the cross build.
    for var in [
        "RUSTFLAGS",
        "CARGO_ENCODED_RUSTFLAGS",
        "CARGO_BUILD_RUSTFLAGS",
        "CARGO_BUILD_TARGET",
    ] {
        cmd.env_remove(var);
    }
    cmd.env("CARGO_TARGET_DIR", target_dir);
    let out = cmd.stdin(Stdio::null()).output()?;
    if !out.status.success() {
        return Err(io::Error::other(format!(
            "board build ({toolchain:?} toolchain) in {} failed with {}:\n{}",
            board.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    let elf = target_dir
        .join(CROSS_TARGET)
        .join("release")
        .join(BOARD_BIN);
    if !elf.is_file() {
        return Err(not_found(format!(
            "built, but {} is missing",
            elf.display()
        )));
    }
    Ok(elf)
}

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

/// Decodes link frames from a byte stream (any chunking), as the host's receiver does.
#[derive(Default)]
pub struct LinkDecoder {
    accumulator: Accumulator,
    /// Damaged frames and bytes between frames (the accumulator's errors), counted.
    pub damaged: u64,
}

impl LinkDecoder {
    /// Feeds `bytes`; calls `on_message` with every intact frame's message, in order
    /// (frames whose message does not parse count as damaged).
    pub fn feed(&mut self, mut bytes: &[u8], on_message: &mut impl FnMut(&Message<'_>)) {
        while !bytes.is_empty() {
            match self.accumulator.feed(bytes) {
                FeedResult::Consumed => break,
                FeedResult::Success { frame, remaining } => {
                    match FrameRepr::parse(&frame) {
                        Ok(repr) => on_message(&repr.message),
                        Err(_) => self.damaged += 1,
                    }
                    bytes = remaining;
                }
                other => {
                    self.damaged += 1;
                    bytes = other.remaining();
                }
            }
        }
    }
}

/// A serial port (here, a PTY) with deadline-bounded reads.
pub struct SerialLink {
    port: TTYPort,
    pending: VecDeque<u8>,
}

impl SerialLink {
    /// Opens `path` raw at `baud`, 8N1, no flow control.
    pub fn open(path: &Path, baud: u32) -> io::Result<Self> {
        let port = serialport::new(path.to_string_lossy(), baud)
            .timeout(POLL)
            .open_native()
            .map_err(|e| {
                let msg = format!("{}: {e}", path.display());
                io::Error::new(io::Error::from(e).kind(), msg)
            })?;
        Ok(Self {
            port,
            pending: VecDeque::new(),
        })
    }

    /// Sends `bytes` and flushes.
    pub fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.port.write_all(bytes)?;
        self.port.flush()
    }

    /// Reads up to and including `delim`, waiting at most `timeout`.
    pub fn read_until(&mut self, delim: u8, timeout: Duration) -> io::Result<Vec<u8>> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(i) = self.pending.iter().position(|&b| b == delim) {
                return Ok(self.pending.drain(..=i).collect());
            }
            self.fill(deadline, timeout)?;
        }
    }

    /// Reads one `\n`-terminated line, without its line ending, waiting at most `timeout`.
    pub fn read_line(&mut self, timeout: Duration) -> io::Result<String> {
        let mut line = self.read_until(b'\n', timeout)?;
        line.pop();
        if line.last() == Some(&b'\r') {
            line.pop();
        }
        String::from_utf8(line).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
    }

    /// Reads exactly `n` bytes, waiting at most `timeout`.
    pub fn read_exact(&mut self, n: usize, timeout: Duration) -> io::Result<Vec<u8>> {
        let deadline = Instant::now() + timeout;
        while self.pending.len() < n {
            self.fill(deadline, timeout)?;
        }
        Ok(self.pending.drain(..n).collect())
    }

    /// The port itself, for a [`Session`](margemu::stream::Session) or other unbuffered use;
    /// bytes already buffered here are dropped.
    pub fn into_port(self) -> TTYPort {
        self.port
    }

    /// The port itself, for settings and unbuffered use (bytes already buffered here stay here).
    pub fn port_mut(&mut self) -> &mut TTYPort {
        &mut self.port
    }

    /// One read of the port into `pending`; an error once `deadline` has passed.
    fn fill(&mut self, deadline: Instant, timeout: Duration) -> io::Result<()> {
        if Instant::now() >= deadline {
            return Err(io::Error::new(
                io::ErrorKind::TimedOut,
                format!(
                    "nothing more within {timeout:?}; buffered: {:?}",
                    self.pending
                ),
            ));
        }
        let mut buf = [0u8; 256];
        match self.port.read(&mut buf) {
            Ok(0) => Err(io::Error::new(
                io::ErrorKind::UnexpectedEof,
                "serial port closed",
            )),
            Ok(n) => {
                self.pending.extend(&buf[..n]);
                Ok(())
            }
            Err(e) if is_transient(&e) => Ok(()),
            Err(e) => Err(e),
        }
    }
}

fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

fn runs(cmd: &mut Command) -> bool {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn not_found(msg: String) -> io::Error {
    io::Error::new(io::ErrorKind::NotFound, msg)
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
