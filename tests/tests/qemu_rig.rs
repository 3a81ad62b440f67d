//! QEMU test of a rig: the `qemu-mps2-an386` firmware (Cortex-M4F), configured by Configure and
//! one AddDevice as an ICM-42688-P on SPI plus an IST8310 compass on I2C, must serve every rig
//! image (the two devices' images back to back, 32 + 6 bytes) equal to the host's prediction
//! byte for byte (the CRC-32C in its Served reports), as the loopback does on x86-64.
//!
//! The scene is [`motion_scene_text`] (sines on all six joints, the paper's noise, biases, hard
//! iron, a warming die) with two `[[device]]`s: the ICM-42688-P at ±8 g and ±1000 °/s turned 90°
//! about z, and the IST8310 flipped and 4 cm off the plate's centre, so a sample that passes was
//! computed per device, in each device's axes, with each device's own noise.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::path::Path;

use margemu::scene::Scene;
use margemu::stream::predict_images;
use margemu_protocol::chip::ChipModel;
use margemu_tests::motion_scene_text;
use margemu_tests::qemu;
use margemu_tests::qemu_session::{
    build_board, image_session, predicted_crcs, run_images, scratch,
};

/// The rig: an IMU on SPI and a compass on I2C.
const DEVICES: &str = r#"
[[device]]
name = "imu"
model = "icm42688p"
accel_range = 8
gyro_range = 1000
rotation = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]

[[device]]
name = "compass"
model = "ist8310"
offset = [0.0, 0.0, -0.04]
rotation = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
"#;

/// An ICM ODR QEMU's UART carries with 38-byte rig images.
const RATE_HZ: u32 = 200;
/// Length of the scene.
const SECONDS: f64 = 2.0;

#[test]
fn rig_image_mode_serves_every_devices_images_byte_for_byte() {
    if !qemu::prerequisites_or_skip("qemu_rig") {
        return;
    }
    let (elf, build) = build_board();
    let text = motion_scene_text(RATE_HZ, SECONDS, 31) + DEVICES;
    let scene =
        Scene::parse_str(&text, Path::new("qemu-rig.toml")).unwrap_or_else(|e| panic!("{e}"));
    let models: Vec<ChipModel> = scene.devices().iter().map(|d| d.chip.model).collect();
    assert_eq!(models, [ChipModel::Icm42688p, ChipModel::Ist8310]);

    let dir = scratch("rig-images");
    let session = image_session(&scene, &dir);
    let rig_len = ChipModel::Icm42688p.image_len() + ChipModel::Ist8310.image_len();
    assert!(
        predict_images(&scene, session.image_settings()).all(|s| s.unwrap().image.len() == rig_len)
    );
    let predicted = predicted_crcs(&scene, &session);
    let samples = (f64::from(RATE_HZ) * SECONDS) as usize;
    assert_eq!(predicted.len(), samples);
    assert!(predicted.windows(2).all(|w| w[0] != w[1]));

    let header = std::fs::read_to_string(dir.join("sent.csv")).unwrap();
    assert!(
        header.starts_with("index,t_ns,send_ns,late_ns,image.imu,image.compass,resend"),
        "{}",
        header.lines().next().unwrap_or_default()
    );
    let run = run_images(&elf, session, &dir, &predicted, samples);
    eprintln!(
        "qemu_rig: build {build:.2?}, boot + stream of {samples} {rig_len}-byte rig images \
         (ICM-42688-P + IST8310) at {RATE_HZ} Hz {:.2?}; {} confirmed byte-exact by CRC-32C; \
         credit stalls {}, pacing {:?}",
        run.streamed, run.check.exact, run.summary.credit_stalls, run.summary.jitter
    );
}
