//! Helpers shared by the system tests in `tests/tests/` and the benches in `tests/benches/`:
//! where the fixtures live; [`qemu`] builds the QEMU board firmware and boots it; [`drive`] is a
//! scripted link host for either source mode; [`model_source`] prepares a scene for source
//! mode (b) and predicts its images; [`served`] checks the device's Served reports against a
//! prediction; [`qemu_session`] runs and checks one QEMU session of either source mode;
//! [`qemu_chip`] runs a chip model on the QEMU board in both; [`qemu_chain`] runs the
//! sampling-chain benchmark on it and tabulates its cost.

use std::path::{Path, PathBuf};

use margemu::scene::Scene;

pub mod drive;
pub mod model_source;
pub mod qemu;
pub mod qemu_chain;
pub mod qemu_chip;
pub mod qemu_session;
pub mod served;

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A scene from `hil-fixtures/scenes/`.
pub fn fixture_scene(name: &str) -> PathBuf {
    workspace_root().join("hil-fixtures/scenes").join(name)
}

/// The `[sensors]` of the QEMU scenes: section 3.2's noise densities (gyro 0.0224 (rad/s)/√Hz,
/// accel 0.0224 (m/s²)/√Hz, mag 0.0022 nu/√Hz), constant gyro and accel biases, hard iron, and
/// a die warming from 25 °C at 0.5 °C/s.
pub const SENSORS: &str = r#"[sensors]
temperature = [25.0, 0.5]
[sensors.gyro]
noise_density = [0.0224, 0.0224, 0.0224]
bias = [0.01, -0.02, 0.005]
[sensors.accel]
noise_density = [0.0224, 0.0224, 0.0224]
bias = [0.05, -0.03, 0.02]
[sensors.mag]
noise_density = [0.0022, 0.0022, 0.0022]
hard_iron = [0.05, 0.0, -0.02]
"#;

/// A kinematic scene of `seconds` at `rate_hz` with real motion (sines on all six joints, up to
/// 5 Hz and about 7 rad/s) and the [`SENSORS`]: what the QEMU streaming tests and benches send.
pub fn motion_scene(rate_hz: u32, seconds: f64, seed: u64) -> Scene {
    let text = motion_scene_text(rate_hz, seconds, seed);
    Scene::parse_str(&text, Path::new("qemu-motion.toml"))
        .unwrap_or_else(|e| panic!("the built-in scene is valid: {e}"))
}

/// The TOML text of [`motion_scene`], for a test that appends tables of its own (`[chip]`).
pub fn motion_scene_text(rate_hz: u32, seconds: f64, seed: u64) -> String {
    format!(
        r#"name = "qemu-motion"
duration = {seconds}
rate = {rate_hz}.0
seed = {seed}
motion = "kinematic"
[joints.x]
type = "sine"
amplitude = 0.05
frequency = 1.0
offset = 1.0
[joints.y]
type = "sine"
amplitude = 0.04
frequency = 1.5
offset = 1.0
[joints.z]
type = "sine"
amplitude = 0.03
frequency = 2.0
offset = 1.0
[joints.roll]
type = "sine"
amplitude = 0.5
frequency = 1.5
phase = 0.3
[joints.pitch]
type = "sine"
amplitude = 0.3
frequency = 0.8
[joints.yaw]
type = "sine"
amplitude = 0.2
frequency = 5.0
"#
    ) + SENSORS
}

#[cfg(test)]
mod tests {
    #[test]
    fn motion_scene_moves_and_has_noise() {
        let scene = super::motion_scene(1000, 0.5, 1);
        assert_eq!(scene.samples(), 500);
        let truth = margemu::run::collect(&scene).unwrap();
        let peak = truth
            .iter()
            .map(|t| t.body_rate[2].abs())
            .fold(0.0, f64::max);
        assert!(peak > 5.0, "yaw rate peak {peak}");
        assert!(scene
            .spec
            .sensors
            .config()
            .gyro
            .errors
            .noise_density
            .is_some());
    }
}
