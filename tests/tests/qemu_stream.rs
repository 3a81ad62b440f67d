//! QEMU streaming test of source mode (a): a `margemu::stream::Session` streams a kinematic
//! scene with real motion and the paper's noise ([`motion_scene`]) as register images to the
//! `qemu-mps2-an386` firmware over UART0's PTY, and every sample the firmware's link handler
//! latched into its emulated chip is checked byte for byte against the host's prediction.
//!
//! The session ignores the device's `Served` reports, so the test reads the port through a
//! [`ServedTap`], which decodes them on the side: each carries the CRC-32C of the 22-byte image
//! served at an index, compared with the CRC-32C of the predicted image. The device's final
//! Telemetry must report no underrun and no overrun.
//!
//! The rate, [`RATE_HZ`], is a third of what the benchmark (`tests/benches/qemu_rates.rs`,
//! README) found QEMU's UART to sustain on a quiet machine, and the lead of 1.5 s puts most of
//! the scene in the device's buffer before Start: QEMU takes one byte per turn of its main loop,
//! which slows far down beside CPU hogs. This test checks correctness; the benchmark the speed.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use margemu::stream::{Session, StreamConfig};
use margemu_protocol::link::CRC32C;
use margemu_tests::motion_scene;
use margemu_tests::qemu::{self, Qemu};
use margemu_tests::served::ServedTap;
use serialport::SerialPort;

/// Output rate of the stream.
const RATE_HZ: u32 = 250;
/// Length of the scene.
const SECONDS: f64 = 2.0;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-qemu-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn session_streams_to_qemu_byte_for_byte() {
    if !qemu::prerequisites_or_skip("qemu_stream") {
        return;
    }
    let t = Instant::now();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    let build = t.elapsed();

    let scene = motion_scene(RATE_HZ, SECONDS, 11);
    let dir = scratch("stream");
    let config = StreamConfig {
        port: "qemu mps2-an386 UART0 (pty)".into(),
        lead: Duration::from_millis(1500),
        drain_timeout: Duration::from_secs(5),
        ..StreamConfig::default()
    };
    let session = Session::new(&scene, config, &dir).unwrap_or_else(|e| panic!("session: {e}"));
    let predicted: Vec<u32> = session
        .samples()
        .iter()
        .map(|s| CRC32C.checksum(&s.image))
        .collect();
    let samples = (f64::from(RATE_HZ) * SECONDS) as usize;
    assert_eq!(predicted.len(), samples);

    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(&elf).unwrap_or_else(|e| panic!("boot: {e}"));
    let mut writer = uart0.into_port();
    let tap = ServedTap::new(writer.try_clone_native().expect("clone the PTY"));
    let log = tap.log();
    // QEMU takes one received byte per turn of its main loop, so on a busy machine the PTY can
    // stay full for longer than the session's 50 ms port timeout; the writer half waits longer.
    writer
        .set_timeout(Duration::from_secs(2))
        .expect("set the write timeout");
    let result = session.run(tap, writer, |_| {});
    let streamed = t.elapsed();
    let summary = result.unwrap_or_else(|e| {
        panic!(
            "session: {e}; logs in {}\nQEMU printed:\n{}",
            dir.display(),
            qemu.output()
        )
    });
    drop(qemu);

    let (served, damaged) = std::mem::take(&mut *log.lock().expect("the tap's log"));
    assert_eq!(damaged, 0, "damaged frames from the device");
    assert_eq!(served.duplicates, 0, "indices reported served twice");
    let check = served.check(&predicted);
    assert!(
        check.all_exact(),
        "{}; logs in {}",
        check.summary(),
        dir.display()
    );

    let telemetry = summary.telemetry.expect("the device's final Telemetry");
    assert_eq!(telemetry.underruns, 0, "{telemetry:?}");
    assert_eq!(telemetry.overruns, 0, "{telemetry:?}");
    assert_eq!(summary.sent, summary.samples, "{summary:?}");
    assert_eq!(telemetry.samples_served, samples as u64, "{telemetry:?}");
    let _ = std::fs::remove_dir_all(&dir);

    eprintln!(
        "qemu_stream: build {build:.2?}, boot + stream of {samples} samples at {RATE_HZ} Hz \
         {streamed:.2?}; {} confirmed byte-exact by CRC-32C (0 underruns, 0 overruns); credit \
         stalls {}, pacing {:?}",
        check.exact, summary.credit_stalls, summary.jitter
    );
}
