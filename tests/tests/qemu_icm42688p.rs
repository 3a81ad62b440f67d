//! QEMU tests of the ICM-42688-P: the `qemu-mps2-an386` firmware (Cortex-M4F), configured by the
//! scene's `[chip] model = "icm42688p"` as an ICM-42688-P, must serve every image equal to the
//! host's prediction byte for byte (the CRC-32C of each 32-byte image in its Served reports), in
//! both source modes:
//!
//! - **(a) images**, as `qemu_stream` does for the MPU-9250: a `margemu::stream::Session`
//!   streams the host's 32-byte ICM images at 200 Hz (an ICM ODR; 6.4 kB/s of images, about
//!   what `qemu_stream`'s 250 Hz of 22-byte images carries); the device latches them into its
//!   emulated ICM-42688-P.
//! - **(b) model**, as `qemu_model` does: the host sends the truth as Kinematics at 100 Hz; the
//!   device runs the shared sensor model at the ICM's 500 Hz ODR and converts with the ICM's
//!   conversion at the full scales the Configure's overrides wrote into GYRO_CONFIG0 and
//!   ACCEL_CONFIG0 of its emulated chip. The host predicts the same images on x86-64
//!   ([`ModelStream`]).
//!
//! The scene is [`motion_scene_text`] (sines on all six joints, the paper's noise, biases, hard
//! iron, a warming die) with a `[chip]` that is not the power-on one: ±8 g and ±1000 °/s, and
//! mounted turned 90° about z, so an image that passes was converted at the scene's full scales
//! in the chip's axes. The two tests take turns on one lock: one QEMU at a time.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::path::Path;
use std::sync::Mutex;

use margemu::scene::Scene;
use margemu::stream::predict_images;
use margemu_protocol::chip::ChipModel;
use margemu_tests::model_source::ModelStream;
use margemu_tests::motion_scene_text;
use margemu_tests::qemu;
use margemu_tests::qemu_session::{
    build_board, image_session, model_script, predicted_crcs, run_images, run_model, scratch,
};

/// The scene's chip: an ICM-42688-P on SPI, not at its power-on full scales, turned 90° about z.
const CHIP: &str = r#"
[chip]
model = "icm42688p"
bus = "spi"
accel_range = 8
gyro_range = 1000
rotation = [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
"#;

/// Output rate of source mode (a): an ICM ODR QEMU's UART carries with 32-byte images.
const IMAGE_RATE_HZ: u32 = 200;
/// Output rate of source mode (b): an ICM ODR; the kinematics go at a fifth of it.
const MODEL_RATE_HZ: u32 = 500;
/// Output samples per kinematics sample in source mode (b).
const DECIMATION: u32 = 5;
/// Length of the scenes.
const SECONDS: f64 = 2.0;

/// One QEMU at a time: the machine's UART is slow enough alone.
static QEMU_LOCK: Mutex<()> = Mutex::new(());

fn icm_scene(rate_hz: u32, seed: u64) -> Scene {
    let text = motion_scene_text(rate_hz, SECONDS, seed) + CHIP;
    let scene =
        Scene::parse_str(&text, Path::new("qemu-icm42688p.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.chip.model, ChipModel::Icm42688p);
    let fs = scene.chip.settings.full_scale().expect("an IMU");
    assert_eq!((fs.accel_g, fs.gyro_dps), (8.0, 1000.0));
    scene
}

#[test]
fn icm42688p_image_mode_serves_the_hosts_images_byte_for_byte() {
    if !qemu::prerequisites_or_skip("qemu_icm42688p (images)") {
        return;
    }
    let _one_qemu = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let (elf, build) = build_board();

    let scene = icm_scene(IMAGE_RATE_HZ, 13);
    let dir = scratch("icm42688p-images");
    let session = image_session(&scene, &dir);
    assert!(predict_images(&scene, session.image_settings())
        .all(|s| s.unwrap().image.len() == ChipModel::Icm42688p.image_len()));
    let predicted = predicted_crcs(&scene, &session);
    let samples = (f64::from(IMAGE_RATE_HZ) * SECONDS) as usize;
    assert_eq!(predicted.len(), samples);
    // Noise on: no two consecutive predicted images are equal.
    assert!(predicted.windows(2).all(|w| w[0] != w[1]));

    let run = run_images(&elf, session, &dir, &predicted, samples);
    let (summary, check, streamed) = (run.summary, run.check, run.streamed);

    eprintln!(
        "qemu_icm42688p (images): build {build:.2?}, boot + stream of {samples} 32-byte \
         ICM-42688-P images at {IMAGE_RATE_HZ} Hz {streamed:.2?}; {} confirmed byte-exact by \
         CRC-32C (0 underruns, 0 overruns); credit stalls {}, pacing {:?}",
        check.exact, summary.credit_stalls, summary.jitter
    );
}

#[test]
fn icm42688p_model_mode_serves_the_hosts_prediction_bit_for_bit() {
    if !qemu::prerequisites_or_skip("qemu_icm42688p (model)") {
        return;
    }
    let _one_qemu = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let (elf, build) = build_board();

    let scene = icm_scene(MODEL_RATE_HZ, 17);
    let stream = ModelStream::from_scene(&scene, DECIMATION).unwrap_or_else(|e| panic!("{e}"));
    let predicted = stream.predicted_crcs();
    let outputs = (f64::from(MODEL_RATE_HZ) * SECONDS) as usize;
    assert_eq!(
        (predicted.len(), stream.kinematics.len()),
        (outputs, outputs / DECIMATION as usize)
    );
    assert!(stream
        .images
        .iter()
        .all(|i| i.len() == ChipModel::Icm42688p.image_len()));
    // Noise on: no two consecutive predicted images are equal, although the truth is held.
    assert!(stream.images.windows(2).all(|w| w[0] != w[1]));
    let configure = stream.configure(50_000_000);
    assert_eq!(
        (configure.chip, usize::from(configure.image_len)),
        (ChipModel::Icm42688p, ChipModel::Icm42688p.image_len())
    );
    // The full scales (and the ODR) travel as register overrides.
    assert!(!configure.overrides.is_empty(), "{configure:?}");

    let script = model_script(&stream, configure);
    let run = run_model(&elf, &script, &predicted, outputs as u64);
    let (report, check, telemetry, streamed) = (run.report, run.check, run.telemetry, run.streamed);

    eprintln!(
        "qemu_icm42688p (model): build {build:.2?}, boot + stream {streamed:.2?}: {} of {} \
         32-byte ICM-42688-P images served byte-exact ({MODEL_RATE_HZ} Hz model on the \
         Cortex-M4F, {} Hz kinematics); {} batches, {} credit stalls, pacing {:?}; device \
         served {} instants, {} underruns",
        check.exact,
        check.expected,
        MODEL_RATE_HZ / DECIMATION,
        report.batches,
        report.credit_stalls,
        report.jitter(),
        telemetry.samples_served,
        telemetry.underruns,
    );
}
