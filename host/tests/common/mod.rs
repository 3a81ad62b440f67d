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

/// Starts the `margemu` binary with `args` in `cwd`, its output captured.
pub fn spawn_margemu(args: &[&OsStr], cwd: &Path) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .current_dir(cwd)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

/// Polls until `ready()` holds (every 10 ms); panics, naming `what`, if `child` exits first or
/// a minute passes (a guard against hanging, not a timing assertion).
pub fn wait_until(child: &mut std::process::Child, what: &str, ready: impl Fn() -> bool) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while !ready() {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("margemu exited ({status}) before {what}");
        }
        assert!(
            std::time::Instant::now() < deadline,
            "no {what} within a minute"
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// Whether `dir/events.csv` has a row of `event`.
pub fn has_event(dir: &Path, event: &str) -> bool {
    std::fs::read_to_string(dir.join("events.csv"))
        .map(|text| text.lines().any(|l| l.split(',').nth(1) == Some(event)))
        .unwrap_or(false)
}

/// Sends `signal` (a name `kill` knows: TERM, HUP, INT, KILL) to `child`.
pub fn send_signal(child: &std::process::Child, signal: &str) {
    let status = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(status.success(), "kill -{signal}");
}

/// A scene file in `dir`: the Figure 3 bench scene lasting `seconds`, so that a run is still
/// going when a test stops it.
pub fn long_scene(dir: &Path, seconds: f64) -> PathBuf {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-fixtures/scenes/figure3.toml");
    let text = std::fs::read_to_string(fixture).unwrap();
    assert!(text.contains("duration = 3.0\n"));
    let path = dir.join("long.toml");
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        &path,
        text.replace("duration = 3.0\n", &format!("duration = {seconds}\n")),
    )
    .unwrap();
    path
}

/// `simulate` of a 10⁸-sample scene into `work/run` (long enough to be caught running, beyond
/// the size limit, so `--allow-large`), once it has written more than 1 MiB of truth rows: the
/// process and the run directory.
pub fn simulating(work: &Path) -> (std::process::Child, PathBuf) {
    let scene = long_scene(work, 100_000.0);
    let dir = work.join("run");
    let args: Vec<&OsStr> = vec![
        "simulate".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
        "--allow-large".as_ref(),
    ];
    let mut child = spawn_margemu(&args, work);
    let partial = dir.join("truth.csv.partial");
    wait_until(&mut child, "truth rows", || {
        std::fs::metadata(&partial).is_ok_and(|m| m.len() > 1 << 20)
    });
    (child, dir)
}

/// The `[completion]` table of `dir/meta.toml`.
pub fn completion(dir: &Path) -> Option<margemu::rundir::Completion> {
    margemu::rundir::read_completion(dir).unwrap()
}
