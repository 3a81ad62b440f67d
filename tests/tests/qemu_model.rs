//! QEMU test of source mode (b): the host streams a scene's truth as Kinematics at 100 Hz to the
//! `qemu-mps2-an386` firmware, which runs the shared sensor model (seeded from the scene, noise
//! and biases on) at the chip's 500 Hz output rate on the emulated Cortex-M4F. Every image it
//! served (its Served reports: CRC-32C per image) must equal the host's own prediction, computed
//! on x86-64 with the same `margemu_model` code ([`ModelStream`]). Passing proves the shared model
//! is bit-identical on both targets, noise draws included. A second scene adds the sampling
//! chain (AddVibration: the ICM-20602's internal path, motor tones and a shock), served byte
//! for byte as well.
//!
//! The scene is the paper's Figure 3 bench motion (setpoint steps and 0.5–5 Hz sines, through
//! the closed-loop dynamics) for 2 s, with the noise densities of section 3.2, constant biases,
//! hard iron and a warming die. The link is driven with `protocol::link` directly
//! ([`margemu_tests::drive`]).
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::path::Path;

use margemu::scene::Scene;
use margemu_tests::model_source::ModelStream;
use margemu_tests::qemu;
use margemu_tests::qemu_session::{build_board, model_script, run_model};
use margemu_tests::SENSORS;

/// Figure 3 motion; the [`SENSORS`] are appended.
const MOTION: &str = r#"
name = "qemu-model"
duration = 2.0
rate = 500.0
seed = 5
[bench]
initial = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]
[joints.x]
type = "steps"
points = [[0.1, 1.5], [1.1, 1.0]]
[joints.y]
type = "steps"
points = [[0.4, 0.6], [1.4, 1.2]]
[joints.z]
type = "steps"
points = [[0.7, 1.4], [1.7, 0.9]]
[joints.roll]
type = "sine"
amplitude = 0.4
frequency = 2.0
[joints.pitch]
type = "sine"
amplitude = 0.6
frequency = 0.5
[joints.yaw]
type = "sine"
amplitude = 0.3
frequency = 5.0
"#;

/// Output samples per kinematics sample: 500 Hz out, 100 Hz truth. The rates, and the lead of
/// 1.5 s (most of the scene buffered before Start), are what QEMU's one-byte-per-turn UART
/// sustains beside CPU hogs on a 2-core machine: this test checks bit-identity, the benchmark
/// `qemu_rates` the speed.
const DECIMATION: u32 = 5;

#[test]
fn model_mode_serves_the_hosts_prediction_bit_for_bit() {
    if !qemu::prerequisites_or_skip("qemu_model") {
        return;
    }
    let (elf, build) = build_board();

    let scene = Scene::parse_str(&format!("{MOTION}{SENSORS}"), Path::new("qemu-model.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let stream = ModelStream::from_scene(&scene, DECIMATION).unwrap_or_else(|e| panic!("{e}"));
    let predicted = stream.predicted_crcs();
    assert_eq!((predicted.len(), stream.kinematics.len()), (1000, 200));
    // Noise on: no two consecutive predicted images are equal, although the truth is held.
    assert!(stream.images.windows(2).all(|w| w[0] != w[1]));

    let script = model_script(&stream, stream.configure(50_000_000));
    // The device stops by itself at the scene's end (Start's end_index), before the host's Stop
    // arrives: every instant of the scene served, none after it, no underrun.
    let run = run_model(&elf, &script, &predicted, 1000);
    let (report, check, telemetry, streamed) = (run.report, run.check, run.telemetry, run.streamed);

    eprintln!(
        "qemu_model: build {build:.2?}, boot + stream {streamed:.2?}: {} of {} images served \
         byte-exact (500 Hz model on the Cortex-M4F, 100 Hz kinematics); {} batches, {} credit \
         stalls, pacing {:?}; device served {} instants, {} underruns",
        check.exact,
        check.expected,
        report.batches,
        report.credit_stalls,
        report.jitter(),
        telemetry.samples_served,
        telemetry.underruns,
    );
}

/// A level ICM-20602 at 500 Hz for 1 s on the chip's internal path (gyro 8 kHz, accelerometer
/// 4 kHz, the declared filters), four motors on an rpm ramp and a shock; the [`SENSORS`] are
/// appended.
const VIBRATION: &str = r#"
name = "qemu-model-vibration"
duration = 1.0
rate = 500.0
seed = 8
motion = "static"
[chip]
model = "icm20602"
[vibration]
path = "internal"
[[vibration.tones]]
motors = 4
spread = 0.02
rpm_ramp = { from = 6000, to = 18000, start = 0.2, end = 0.8 }
[[vibration.tones.harmonics]]
order = 1.0
linear = [0.5, 0.0, 3.0]
angular = [0.0, 0.2, 0.0]
[[vibration.shocks]]
at = 0.5
duration = 0.011
linear = [0.0, 0.0, 200.0]
angular = [1.0, 0.0, 0.0]
"#;

#[test]
fn model_mode_runs_the_sampling_chain_bit_for_bit() {
    if !qemu::prerequisites_or_skip("qemu_model") {
        return;
    }
    let (elf, build) = build_board();
    let scene = Scene::parse_str(&format!("{VIBRATION}{SENSORS}"), Path::new("vib.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let stream = ModelStream::from_scene(&scene, DECIMATION).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(stream.vibration.len(), 3, "path, tones, shock");
    let predicted = stream.predicted_crcs();
    let script = model_script(&stream, stream.configure(50_000_000));
    let run = run_model(&elf, &script, &predicted, 500);
    eprintln!(
        "qemu_model (vibration): build {build:.2?}, boot + stream {:.2?}: {} of {} images \
         served byte-exact (internal path, tones and a shock on the Cortex-M4F)",
        run.streamed, run.check.exact, run.check.expected,
    );
}
