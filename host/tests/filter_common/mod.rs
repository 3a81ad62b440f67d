//! Shared by the `filter_*` and `tune_*` tests: small scenes, scratch directories and the binary.
#![allow(dead_code)]

use margemu::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Six seconds at 100 Hz of prescribed motion: random sines on the three revolute joints (up to
/// about 7 rad/s), an 8 m/s² sine on x, the paper's sensor noise and magnetic bursts of up to
/// twice the field. Cheap enough to tune in a debug build.
pub const SMALL_SCENE: &str = r#"
name = "tune-small"
duration = 6.0
rate = 100.0
seed = 7
motion = "kinematic"

[bench]
initial = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]

[joints.x]
type = "sine"
amplitude = 0.05
frequency = 2.0
offset = 1.0

[joints.roll]
type = "random-sine"
amplitude = [0.05, 0.6]
frequency = [0.2, 2.0]
segment = [1.0, 2.0]

[joints.pitch]
type = "random-sine"
amplitude = [0.05, 0.6]
frequency = [0.2, 2.0]
segment = [1.0, 2.0]

[joints.yaw]
type = "random-sine"
amplitude = [0.05, 0.6]
frequency = [0.2, 2.0]
segment = [1.0, 2.0]

[sensors.gyro]
noise_density = [0.0224, 0.0224, 0.0224]

[sensors.accel]
noise_density = [0.0224, 0.0224, 0.0224]

[sensors.mag]
noise_density = [0.0022, 0.0022, 0.0022]

[perturbation]
window = 1.0
cutoff = 5.0
amplitude = [0.0, 2.0]
gap = [0.5, 2.0]
"#;

/// A plate at rest, rolled 30°, pitched −50° and yawed 160°, with ideal sensors (the truth
/// rounded to `f32`).
pub const STATIC_SCENE: &str = r#"
name = "static-tilted"
duration = 20.0
rate = 200.0
seed = 1
motion = "static"

[bench]
initial = [1.0, 1.0, 1.0, 0.5235987755982988, -0.8726646259971648, 2.792526803190927]
"#;

/// An empty scratch directory unique to this process and `name`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-h7-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `text` as a scene named `name` in `dir`, written there and loaded.
pub fn scene_in(dir: &Path, name: &str, text: &str) -> (PathBuf, Scene) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap();
    (path, scene)
}

/// `text` as a scene named `name` in `dir`, simulated by `margemu simulate` into `dir/run`:
/// the scene file and the run directory.
pub fn simulated(dir: &Path, name: &str, text: &str) -> (PathBuf, PathBuf) {
    let (scene, _) = scene_in(dir, name, text);
    let run = dir.join("run");
    let (s, r) = (scene.to_str().unwrap(), run.to_str().unwrap());
    ok(&margemu(&["simulate", s, "-o", r]));
    (scene, run)
}

/// Runs the `margemu` binary.
pub fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .expect("runs margemu")
}

/// Asserts the run succeeded and returns its standard output.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Asserts the run failed and returns its standard error.
pub fn failed(out: &Output) -> String {
    assert!(
        !out.status.success(),
        "succeeded: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}
