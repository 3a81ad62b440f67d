//! QEMU streaming test of source mode (a): a `margemu::stream::Session` streams a kinematic
//! scene with real motion and the paper's noise ([`motion_scene`]) as register images to the
//! `qemu-mps2-an386` firmware over UART0's PTY, and every sample the firmware's link handler
//! latched into its emulated chip is checked byte for byte against the host's prediction.
//!
//! The session ignores the device's `Served` reports, so the test reads the port through a
//! [`ServedTap`](margemu_tests::served::ServedTap), which decodes them on the side: each carries the CRC-32C of the 22-byte image
//! served at an index, compared with the CRC-32C of the predicted image. The device's final
//! Telemetry must report no underrun and no overrun.
//!
//! The rate, [`RATE_HZ`], is a third of what the benchmark (`tests/benches/qemu_rates.rs`,
//! `docs/figures.md`) found QEMU's UART to sustain on a quiet machine, and the lead of 1.5 s puts most of
//! the scene in the device's buffer before Start: QEMU takes one byte per turn of its main loop,
//! which slows far down beside CPU hogs. This test checks correctness; the benchmark the speed.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use margemu_tests::motion_scene;
use margemu_tests::qemu;
use margemu_tests::qemu_session::{
    build_board, image_session, predicted_crcs, run_images, scratch,
};

/// Output rate of the stream.
const RATE_HZ: u32 = 250;
/// Length of the scene.
const SECONDS: f64 = 2.0;

#[test]
fn session_streams_to_qemu_byte_for_byte() {
    if !qemu::prerequisites_or_skip("qemu_stream") {
        return;
    }
    let (elf, build) = build_board();

    let scene = motion_scene(RATE_HZ, SECONDS, 11);
    let dir = scratch("stream");
    let session = image_session(&scene, &dir);
    let predicted = predicted_crcs(&scene, &session);
    let samples = (f64::from(RATE_HZ) * SECONDS) as usize;
    assert_eq!(predicted.len(), samples);

    let run = run_images(&elf, session, &dir, &predicted, samples);
    let (summary, check, streamed) = (run.summary, run.check, run.streamed);

    eprintln!(
        "qemu_stream: build {build:.2?}, boot + stream of {samples} samples at {RATE_HZ} Hz \
         {streamed:.2?}; {} confirmed byte-exact by CRC-32C (0 underruns, 0 overruns); credit \
         stalls {}, pacing {:?}",
        check.exact, summary.credit_stalls, summary.jitter
    );
}
