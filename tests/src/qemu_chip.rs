//! One chip model on the QEMU board in both source modes (`qemu_icm42688p`, `qemu_bmi270`,
//! `qemu_bmi088`): the board, configured by a scene's `[chip]`, must serve every image equal to
//! the host's prediction byte for byte (the CRC-32C of each image in its Served reports).
//!
//! - [`image_mode`], as `qemu_stream` does for the MPU-9250: a `margemu::stream::Session`
//!   streams the host's images at [`ChipCase::image_rate_hz`]; the device latches them into its
//!   emulated chip.
//! - [`model_mode`], as `qemu_model` does: the host sends the truth as Kinematics at
//!   [`ChipCase::model_rate_hz`] / [`ChipCase::decimation`]; the device runs the shared sensor
//!   model at the chip's output rate and converts with the chip's conversion at the full scales
//!   the Configure's overrides wrote into its emulated chip. The host predicts the same images
//!   on x86-64 ([`ModelStream`]).
//!
//! The scene is [`motion_scene_text`] (sines on all six joints, the
//! paper's noise, biases, hard iron, a warming die) with the case's `[chip]`.

use std::path::Path;
use std::sync::{Mutex, MutexGuard};

use margemu::scene::Scene;
use margemu::stream::predict_images;
use margemu_protocol::chip::{ChipModel, FullScale};

use crate::model_source::ModelStream;
use crate::motion_scene_text;
use crate::qemu;
use crate::qemu_session::{
    build_board, image_session, model_script, predicted_crcs, run_images, run_model, scratch,
};

/// A chip model and how its QEMU sessions run.
#[derive(Clone, Copy, Debug)]
pub struct ChipCase {
    /// The model the scene's `[chip]` names.
    pub model: ChipModel,
    /// The scene's `[chip]` table.
    pub chip_toml: &'static str,
    /// The full scales that table sets.
    pub full_scale: FullScale,
    /// Output rate of source mode (a): one of the chip's, that QEMU's UART carries.
    pub image_rate_hz: u32,
    /// Output rate of source mode (b): one of the chip's.
    pub model_rate_hz: u32,
    /// Output samples per kinematics sample in source mode (b).
    pub decimation: u32,
    /// Length of the scenes, s.
    pub seconds: f64,
}

impl ChipCase {
    /// The case's scene at `rate_hz`, checked to hold its chip and full scales.
    pub fn scene(&self, rate_hz: u32, seed: u64) -> Scene {
        let text = motion_scene_text(rate_hz, self.seconds, seed) + self.chip_toml;
        let name = format!("qemu-{}.toml", self.model.name());
        let scene = Scene::parse_str(&text, Path::new(&name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(scene.chip.model, self.model);
        assert_eq!(scene.chip.settings.full_scale(), Some(self.full_scale));
        scene
    }

    fn label(&self, mode: &str) -> String {
        format!("qemu_{} ({mode})", self.model.name())
    }
}

/// One QEMU at a time in a test process: the machine's UART is slow enough alone.
static QEMU_LOCK: Mutex<()> = Mutex::new(());

/// The QEMU lock for the case's `mode` run; `None` (and a message) where the prerequisites are
/// missing ([`qemu::prerequisites_or_skip`]: a failure under `CI=true`).
fn one_qemu(case: &ChipCase, mode: &str) -> Option<MutexGuard<'static, ()>> {
    if !qemu::prerequisites_or_skip(&case.label(mode)) {
        return None;
    }
    Some(QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner()))
}

/// Source mode (a) on the board (see the module docs); skipped without QEMU or a cross
/// toolchain.
pub fn image_mode(case: &ChipCase, seed: u64) {
    let Some(_one_qemu) = one_qemu(case, "images") else {
        return;
    };
    let (elf, build) = build_board();
    let (rate, len) = (case.image_rate_hz, case.model.image_len());
    let scene = case.scene(rate, seed);
    let dir = scratch(&format!("{}-images", case.model.name()));
    let session = image_session(&scene, &dir);
    assert!(predict_images(&scene, session.image_settings()).all(|s| s.unwrap().image.len() == len));
    let predicted = predicted_crcs(&scene, &session);
    let samples = (f64::from(rate) * case.seconds) as usize;
    assert_eq!(predicted.len(), samples);
    // Noise on: no two consecutive predicted images are equal.
    assert!(predicted.windows(2).all(|w| w[0] != w[1]));

    let run = run_images(&elf, session, &dir, &predicted, samples);
    let (summary, check, streamed) = (run.summary, run.check, run.streamed);
    eprintln!(
        "{}: build {build:.2?}, boot + stream of {samples} {len}-byte {} images at {rate} Hz \
         {streamed:.2?}; {} confirmed byte-exact by CRC-32C (0 underruns, 0 overruns); credit \
         stalls {}, pacing {:?}",
        case.label("images"),
        case.model.part_name(),
        check.exact,
        summary.credit_stalls,
        summary.jitter
    );
}

/// Source mode (b) on the board (see the module docs); skipped without QEMU or a cross
/// toolchain.
pub fn model_mode(case: &ChipCase, seed: u64) {
    let Some(_one_qemu) = one_qemu(case, "model") else {
        return;
    };
    let (elf, build) = build_board();
    let (rate, len, decimation) = (case.model_rate_hz, case.model.image_len(), case.decimation);
    let scene = case.scene(rate, seed);
    let stream = ModelStream::from_scene(&scene, decimation).unwrap_or_else(|e| panic!("{e}"));
    let predicted = stream.predicted_crcs();
    let outputs = (f64::from(rate) * case.seconds) as usize;
    assert_eq!(
        (predicted.len(), stream.kinematics.len()),
        (outputs, outputs / decimation as usize)
    );
    assert!(stream.images.iter().all(|i| i.len() == len));
    // Noise on: no two consecutive predicted images are equal, although the truth is held.
    assert!(stream.images.windows(2).all(|w| w[0] != w[1]));
    let configure = stream.configure(50_000_000);
    assert_eq!(
        (configure.chip, usize::from(configure.image_len)),
        (case.model, len)
    );
    // The full scales (and the rates) travel as register overrides.
    assert!(!configure.overrides.is_empty(), "{configure:?}");

    let script = model_script(&stream, configure);
    let run = run_model(&elf, &script, &predicted, outputs as u64);
    let (report, check, telemetry, streamed) = (run.report, run.check, run.telemetry, run.streamed);
    eprintln!(
        "{}: build {build:.2?}, boot + stream {streamed:.2?}: {} of {} {len}-byte {} images \
         served byte-exact ({rate} Hz model on the Cortex-M4F, {} Hz kinematics); {} batches, {} \
         credit stalls, pacing {:?}; device served {} instants, {} underruns",
        case.label("model"),
        check.exact,
        check.expected,
        case.model.part_name(),
        rate / decimation,
        report.batches,
        report.credit_stalls,
        report.jitter(),
        telemetry.samples_served,
        telemetry.underruns,
    );
}
