//! One QEMU session of either source mode, run against the `qemu-mps2-an386` board and checked
//! against the host's prediction, for the QEMU tests (`qemu_stream`, `qemu_model`,
//! `qemu_icm42688p`):
//!
//! - [`build_board`]: the board ELF and how long building it took;
//! - source mode (a), images: [`image_session`] prepares a `margemu::stream::Session` for QEMU's
//!   UART and [`predicted_crcs`] the CRC-32C of each image it will send; [`run_images`] boots
//!   QEMU, streams the session through a [`ServedTap`] and checks every Served report and the
//!   final Telemetry;
//! - source mode (b), model: [`model_script`] is the [`Script`] that sends a [`ModelStream`]'s
//!   kinematics; [`run_model`] boots QEMU, drives the script and checks the device's reports.
//!
//! The checks panic with what the test needs to see (the logs' directory, what QEMU printed).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use margemu::scene::Scene;
use margemu::stream::{predict_images, Session, StreamConfig, Summary};
use margemu_protocol::link::{Configure, Telemetry, CRC32C};
use serialport::SerialPort;

use crate::drive::{self, Report, Samples, Script};
use crate::model_source::ModelStream;
use crate::qemu::{self, Qemu};
use crate::served::{Check, ServedLog, ServedTap};

/// The board ELF, built (or found up to date), and how long that took.
pub fn build_board() -> (PathBuf, Duration) {
    let t = Instant::now();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    (elf, t.elapsed())
}

/// An empty scratch directory for a test's session logs (removed first if a run left it).
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-qemu-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// A source mode (a) session of `scene` for QEMU's UART0, logging into `dir`: a lead of 1.5 s
/// (most of the scene in the device's buffer before Start) and 5 s to drain.
pub fn image_session(scene: &Scene, dir: &Path) -> Session {
    let config = StreamConfig {
        port: "qemu mps2-an386 UART0 (pty)".into(),
        lead: Duration::from_millis(1500),
        drain_timeout: Duration::from_secs(5),
        ..StreamConfig::default()
    };
    Session::new(scene, config, dir).unwrap_or_else(|e| panic!("session: {e}"))
}

/// The CRC-32C of every image `session` will send for `scene`, in order.
pub fn predicted_crcs(scene: &Scene, session: &Session) -> Vec<u32> {
    predict_images(scene, session.image_settings())
        .map(|s| CRC32C.checksum(&s.expect("the scene's prediction").image))
        .collect()
}

/// How a checked source mode (a) session went.
pub struct ImageRun {
    /// The session's summary.
    pub summary: Summary,
    /// The Served reports against the prediction (all exact).
    pub check: Check,
    /// Every Served entry the device sent.
    pub served: ServedLog,
    /// Boot and stream.
    pub streamed: Duration,
}

/// Boots QEMU with `elf`, streams `session` (logging into `dir`) and checks: no damaged frame,
/// no index reported served twice, every served image equal to `predicted`, no underrun or
/// overrun, every sample sent, and `samples` served. Removes `dir` when all passed.
pub fn run_images(
    elf: &Path,
    session: Session,
    dir: &Path,
    predicted: &[u32],
    samples: usize,
) -> ImageRun {
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).unwrap_or_else(|e| panic!("boot: {e}"));
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
    let check = served.check(predicted);
    assert!(
        check.all_exact(),
        "{}; logs in {}",
        check.summary(),
        dir.display()
    );

    let telemetry = summary
        .telemetry
        .as_ref()
        .expect("the device's final Telemetry");
    assert_eq!(telemetry.underruns, 0, "{telemetry:?}");
    assert_eq!(telemetry.overruns, 0, "{telemetry:?}");
    assert_eq!(summary.sent, summary.samples, "{summary:?}");
    assert_eq!(telemetry.samples_served, samples as u64, "{telemetry:?}");
    let _ = std::fs::remove_dir_all(dir);
    ImageRun {
        summary,
        check,
        served,
        streamed,
    }
}

/// The script that sends `stream`'s kinematics after `configure`: every output image expected,
/// a lead of 1.5 s, batches of 10, 5 s to wait.
pub fn model_script<'a>(stream: &'a ModelStream, configure: Configure) -> Script<'a> {
    Script {
        configure,
        vibration: stream.vibration.clone(),
        faults: stream.faults.clone(),
        samples: Samples::Kinematics(&stream.kinematics),
        sample_rate: stream.params.truth_rate,
        outputs: stream.images.len() as u64,
        lead: Duration::from_millis(1500),
        batch: 10,
        timeout: Duration::from_secs(5),
    }
}

/// How a checked source mode (b) session went.
pub struct ModelRun {
    /// The driver's report.
    pub report: Report,
    /// The Served reports against the prediction (all exact).
    pub check: Check,
    /// The stopped Telemetry.
    pub telemetry: Telemetry,
    /// Boot and stream.
    pub streamed: Duration,
}

/// Boots QEMU with `elf`, drives `script` and checks: every served image equal to `predicted`,
/// no damaged frame, no instant reported twice, no device error, Stop confirmed, no overrun,
/// CRC or framing error, and `served` instants served with no underrun. The device stops by
/// itself at the scene's end (Start's end_index), before the host's Stop arrives: every instant
/// of the scene served, none after it.
pub fn run_model(elf: &Path, script: &Script<'_>, predicted: &[u32], served: u64) -> ModelRun {
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).unwrap_or_else(|e| panic!("boot: {e}"));
    let report = drive::run(uart0.into_port(), script)
        .unwrap_or_else(|e| panic!("session: {e}\nQEMU printed:\n{}", qemu.output()));
    let streamed = t.elapsed();
    drop(qemu);

    let check = report.served.check(predicted);
    assert!(
        check.all_exact(),
        "{}; {} batches, {} credit stalls, pacing {:?}; telemetry {:?}",
        check.summary(),
        report.batches,
        report.credit_stalls,
        report.jitter(),
        report.telemetry
    );
    assert_eq!(report.damaged, 0, "damaged device frames");
    assert_eq!(report.served.duplicates, 0, "instants reported twice");
    assert!(
        report.errors.is_empty(),
        "device errors: {:?}",
        report.errors
    );
    assert!(
        report.stopped,
        "no stopped Telemetry: {:?}",
        report.telemetry
    );
    let telemetry = report.telemetry.expect("stopped Telemetry");
    assert_eq!(
        (
            telemetry.overruns,
            telemetry.crc_errors,
            telemetry.framing_errors
        ),
        (0, 0, 0),
        "{telemetry:?}"
    );
    assert_eq!(
        (telemetry.samples_served, telemetry.underruns),
        (served, 0),
        "{telemetry:?}"
    );
    ModelRun {
        report,
        check,
        telemetry,
        streamed,
    }
}
