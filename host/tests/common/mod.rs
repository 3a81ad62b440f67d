//! Shared by the streaming and command-line tests: the `margemu` binary run to success, scenes,
//! scratch directories, the real firmware `Device` behind
//! a PTY pair, and a strict reader of the session's CSV files.
#![allow(dead_code)] // each test file uses its own part

use margemu::scene::Scene;
use margemu::stream::{StreamConfig, StreamError, Summary};
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A kinematic scene with motion on two axes and gyro noise (so neighbouring images differ).
pub fn scene(duration: f64, rate: f64) -> Scene {
    let text = format!(
        "duration = {duration}\nrate = {rate}\nseed = 11\nmotion = \"kinematic\"\n\
         [joints.roll]\ntype = \"sine\"\namplitude = 0.8\nfrequency = 2.0\n\
         [joints.yaw]\ntype = \"sine\"\namplitude = 1.5\nfrequency = 0.7\n\
         [sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n"
    );
    Scene::parse_str(&text, Path::new("stream-test.toml")).unwrap()
}

/// Runs the `margemu` binary with `args`; checks that it succeeded (showing its stdout and
/// stderr if not) and returns its stdout.
pub fn margemu(args: &[&OsStr]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// A fresh directory under the system's temporary directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-stream-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Session settings for a PTY.
pub fn config() -> StreamConfig {
    StreamConfig {
        port: "pty".into(),
        ..StreamConfig::default()
    }
}

/// Streams `scene` to the real firmware `Device` (the loopback device) over a PTY pair; returns
/// the session's result and the device's report.
pub fn loopback(
    scene: &Scene,
    dir: &Path,
    config: StreamConfig,
) -> (
    Result<Summary, StreamError>,
    margemu::loopback::DeviceReport,
) {
    margemu::loopback::run(scene, config, dir).unwrap()
}

/// A CSV file of the session: its header and rows, every row as long as the header (the `csv`
/// crate, strict).
pub fn read_csv(dir: &Path, name: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_path(dir.join(name))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let header = reader
        .headers()
        .unwrap()
        .iter()
        .map(str::to_owned)
        .collect();
    let rows = reader
        .records()
        .map(|r| {
            let r = r.unwrap_or_else(|e| panic!("{name}: {e}"));
            r.iter().map(str::to_owned).collect()
        })
        .collect();
    (header, rows)
}

/// Every file of the session directory is there and parses: `meta.toml` as TOML, every CSV with
/// its documented header. Returns `events.csv`'s rows.
pub fn assert_logs_valid(dir: &Path) -> Vec<Vec<String>> {
    use margemu::stream::log;
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    meta.parse::<toml::Table>().unwrap();
    let source_model = meta.contains("source = \"model\"");
    let sent = match source_model {
        true => log::SENT_KINEMATICS_COLUMNS,
        false => log::SENT_COLUMNS,
    };
    for (name, columns) in [
        ("sent.csv", sent),
        ("served.csv", log::SERVED_COLUMNS),
        ("device.csv", log::DEVICE_COLUMNS),
        ("telemetry.csv", log::TELEMETRY_COLUMNS),
        ("register_writes.csv", log::REGISTER_WRITES_COLUMNS),
        ("events.csv", log::EVENTS_COLUMNS),
    ] {
        let (header, _) = read_csv(dir, name);
        assert_eq!(header.join(","), columns, "{name}");
    }
    let (header, _) = read_csv(dir, "truth.csv");
    assert_eq!(header[0], "t_ns");
    let (_, events) = read_csv(dir, "events.csv");
    assert_eq!(events.last().unwrap()[1], "end", "{events:?}");
    events
}

/// `served.csv` rows of scene samples (index < `total`): (index, underrun, match).
pub fn served(dir: &Path, total: u64) -> Vec<(u64, bool, bool)> {
    let (_, rows) = read_csv(dir, "served.csv");
    rows.iter()
        .map(|r| (r[1].parse().unwrap(), r[4] == "1", r[6] == "1"))
        .filter(|&(k, _, _)| k < total)
        .collect()
}
