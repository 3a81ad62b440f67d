//! Files `filter`, `analyze` and `evaluate` stream (recordings, run CSVs, parameter files): a FIFO
//! or a device is refused at once instead of blocking or filling memory, a line without end is an
//! error instead of an allocation of its length, and each cause is said once.

use std::path::{Path, PathBuf};
use std::process::Command;

fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "margemu-input-streams-{}-{test}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// Runs the CLI in `dir`, asserts exit code 1, returns stderr.
fn fails(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    err
}

#[test]
fn streamed_inputs_must_be_regular_files() {
    let dir = folder("special");
    let fifo = dir.join("fifo.csv");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (file, kind) in [(s(&fifo), "a FIFO"), ("/dev/zero", "a character device")] {
        let expected = format!("error: {file}: is {kind}, not a regular file\n");
        let filter = fails(&dir, &["filter", "--filter", "ekf", file, "-o", "out.csv"]);
        assert_eq!(filter, expected);
        let noise = fails(&dir, &["analyze", "noise", file, "--column", "ax"]);
        assert_eq!(noise, expected);
        let params = fails(
            &dir,
            &[
                "filter", "--filter", "ekf", "--params", file, "in.csv", "-o", "out.csv",
            ],
        );
        assert_eq!(params, expected);
    }
    assert!(!dir.join("out.csv").exists());
}

#[test]
fn a_line_without_end_is_refused_once() {
    let dir = folder("long-line");
    let long = dir.join("long.csv");
    std::fs::write(&long, vec![b'a'; (1 << 20) + 10]).unwrap();
    let err = fails(
        &dir,
        &["filter", "--filter", "ekf", s(&long), "-o", "out.csv"],
    );
    assert_eq!(
        err,
        format!(
            "error: {}: cannot read: a line is longer than 1048576 bytes: not a CSV file margemu reads\n",
            s(&long)
        )
    );
}
