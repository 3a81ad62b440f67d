//! Building the board: the prerequisites of the QEMU tests, the cross toolchain, and the
//! board ELF.

use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

use super::QEMU;
use crate::workspace_root;

/// The board crate's folder name under `firmware/boards/`.
pub const BOARD: &str = "qemu-mps2-an386";
/// The board binary's name (its package name).
pub const BOARD_BIN: &str = "margemu-board-qemu-mps2-an386";
/// The board crate's sampling-chain benchmark binary (`src/bin/chain_bench.rs`).
pub const CHAIN_BENCH_BIN: &str = "chain-bench";
/// The Cortex-M4F target the board builds for.
pub const CROSS_TARGET: &str = "thumbv7em-none-eabihf";

/// Debian's second Rust toolchain (`rustc-web`), which can build `core` for any target.
const DEBIAN_RUSTC: &str = "/usr/bin/rustc";
const DEBIAN_CARGO: &str = "/usr/bin/cargo";
const DEBIAN_PACKAGES: &str = "rustc-web cargo-web rust-web-src lld";

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

/// The chain-bench ELF, built once per test process (release profile, the same build as
/// [`board_elf`]'s: cargo builds every binary of the board crate).
pub fn chain_bench_elf() -> io::Result<PathBuf> {
    static ELF: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    ELF.get_or_init(|| {
        build_board_bin(&board_dir(), &board_target_dir(), CHAIN_BENCH_BIN)
            .map_err(|e| e.to_string())
    })
    .clone()
    .map_err(io::Error::other)
}

/// Cross-builds the board crate in `board` (release) into `target_dir` and returns its ELF.
/// Cargo runs in the board's folder so its `.cargo/config.toml` (target, linker) applies.
pub fn build_board(board: &Path, target_dir: &Path) -> io::Result<PathBuf> {
    build_board_bin(board, target_dir, BOARD_BIN)
}

/// Cross-builds the board crate in `board` (release, every binary) into `target_dir` and
/// returns the ELF of its binary `bin`.
pub fn build_board_bin(board: &Path, target_dir: &Path, bin: &str) -> io::Result<PathBuf> {
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
    let elf = target_dir.join(CROSS_TARGET).join("release").join(bin);
    if !elf.is_file() {
        return Err(not_found(format!(
            "built, but {} is missing",
            elf.display()
        )));
    }
    Ok(elf)
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
