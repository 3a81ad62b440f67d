//! Wiring a flight controller into a loopback session:
//!
//! - [`spawn`]: the firmware device on one end of the link's PTY pair, with a [`VirtualFc`] in
//!   its thread, whose UART writes to one end of a second PTY pair; the other end is returned,
//!   for the device-under-test reader;
//! - [`attach`]: a device-under-test reader ([`crate::dut`]) on any port, on the session's own
//!   clock (its origin is set on the session) and in its directory; [`AttachedDut::finish`],
//!   once the session has run, stops it and records its summary: a `dut` row appended to
//!   `events.csv` (after the session's `end` row) and a `[dut]` table to `meta.toml`, then
//!   lets go of its share of the completion record ([`margemu_sim::rundir`]), so the record follows
//!   the `[dut]` table (a reader that fails marks the run failed). This is
//!   what `margemu stream --dut` and `margemu loopback --dut` do;
//! - [`run_loopback`]: one whole loopback run with a flight controller, in process.

use super::fc::{FcReport, VirtualFc};
use super::uart::{self, UartReport, UartThread};
use super::VfcConfig;
use crate::dut::{DutConfig, DutError, DutProgress, DutProtocol, DutReader, DutSummary};
use crate::loopback::{spawn_device_with_local, DeviceReport, LoopbackDevice};
use crate::stream::{Progress, Session, StreamConfig, StreamError, Summary};
use margemu_protocol::chip::ChipSettings;
use margemu_sim::meta::Appended;
use margemu_sim::rundir::CompletionRecord;
use margemu_sim::scene::Scene;
use serialport::{SerialPort, TTYPort};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Why a flight-controller run could not be set up.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum VfcError {
    /// cannot open a pseudo-terminal pair or start a thread
    Io(#[source] std::io::Error),
    /// the flight controller's filter refuses its parameters: {0}
    Filter(margemu_sim::filter_params::ParamError),
    /// {0}
    Stream(#[from] StreamError),
    /// {0}
    Dut(#[from] DutError),
    /// {0}
    NoBoard(#[from] super::board::NoBoard),
}

/// The device with its flight controller, running.
pub struct VfcRig {
    device: LoopbackDevice,
    uart: UartThread,
    report: Arc<Mutex<FcReport>>,
    /// The flight controller's end of its UART line, held open until the outcome is dropped,
    /// so the reader at the other end sees no hang-up while it takes the last bytes.
    line: Arc<TTYPort>,
}

/// How the device and its flight controller ended.
#[derive(Clone, Debug)]
pub struct FcOutcome {
    /// The device's counters and why its loop ended.
    pub device: DeviceReport,
    /// What the flight controller did.
    pub fc: FcReport,
    /// What its UART wrote.
    pub uart: UartReport,
    /// See [`VfcRig`]'s `line`.
    _line: Arc<TTYPort>,
}

impl VfcRig {
    /// What the flight controller has done so far.
    pub fn report(&self) -> FcReport {
        self.report
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }

    /// Stops the device (and so the flight controller), then waits for its UART to write what
    /// was queued.
    pub fn stop(self) -> FcOutcome {
        let device = self.device.stop();
        let uart = self.uart.join();
        let fc = self
            .report
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        FcOutcome {
            device,
            fc,
            uart,
            _line: self.line,
        }
    }
}

/// Starts the firmware device on `device_port` with a flight controller of `config` in its
/// thread; `expected` is the conversion the host computes images with
/// ([`super::board::chip_settings`] of the scene's chip). Returns the rig and the host end of the flight
/// controller's UART (a PTY with a 5 ms read timeout).
pub fn spawn(
    device_port: TTYPort,
    config: VfcConfig,
    expected: ChipSettings,
) -> Result<(VfcRig, TTYPort), VfcError> {
    config
        .filter
        .build(config.mag_reference, margemu_filters::Initial::FirstSample)
        .map_err(VfcError::Filter)?;
    let (fc_end, mut host_end) = TTYPort::pair().map_err(|e| VfcError::Io(e.into()))?;
    host_end
        .set_timeout(Duration::from_millis(5))
        .map_err(|e| VfcError::Io(e.into()))?;
    let line = Arc::new(
        fc_end
            .try_clone_native()
            .map_err(|e| VfcError::Io(e.into()))?,
    );
    let (tx, uart) = uart::spawn(fc_end).map_err(VfcError::Io)?;
    let report = Arc::new(Mutex::new(FcReport::default()));
    let shared = report.clone();
    let device = spawn_device_with_local(device_port, move || {
        // Checked above: the filter builds.
        let mut fc = VirtualFc::new(config, expected, tx, shared).ok();
        move |device: &mut crate::loopback::Firmware, now: u64| match &mut fc {
            Some(fc) => fc.step(device, now),
            None => std::ops::ControlFlow::Break("the flight controller's filter".into()),
        }
    })
    .map_err(VfcError::Io)?;
    Ok((
        VfcRig {
            device,
            uart,
            report,
            line,
        },
        host_end,
    ))
}

/// A device-under-test reader sharing a session's clock and directory.
pub struct AttachedDut {
    reader: DutReader,
    origin: Instant,
    dir: PathBuf,
    completion: Option<CompletionRecord>,
}

/// Starts a reader of `config` on `port`, logging into `dir` (the session's directory, which
/// [`Session::new`] created), and makes its start the session's host time 0.
pub fn attach(
    session: &mut Session,
    port: impl Read + Write + Send + 'static,
    config: DutConfig,
    dir: &Path,
) -> Result<AttachedDut, DutError> {
    let origin = Instant::now();
    session.set_origin(origin);
    let config = DutConfig {
        session_log: session.log_sink(),
        ..config
    };
    AttachedDut::start(port, config, dir, origin, session.completion_record())
}

impl AttachedDut {
    /// Starts a reader of `config` on `port`, logging into `dir` (which must exist) with host
    /// times since `origin`; `completion` is the directory's shared completion record, if any,
    /// released by [`Self::finish`].
    pub fn start(
        port: impl Read + Write + Send + 'static,
        config: DutConfig,
        dir: &Path,
        origin: Instant,
        completion: Option<CompletionRecord>,
    ) -> Result<Self, DutError> {
        let reader = DutReader::spawn(port, config, dir, origin)?;
        Ok(Self {
            reader,
            origin,
            dir: dir.to_path_buf(),
            completion,
        })
    }

    /// What the reader has seen so far.
    pub fn progress(&self) -> DutProgress {
        self.reader.progress()
    }

    /// Waits until the reader has taken at least `bytes` bytes, the reader has ended, or
    /// `timeout` has passed; whether it got them.
    pub fn wait_for_bytes(&self, bytes: u64, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        loop {
            if self.progress().counters.bytes >= bytes {
                return true;
            }
            if self.reader.is_finished() || Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// Stops the reader and records its summary in the session directory (call it after the
    /// session has run: the session's own logs are closed then).
    pub fn finish(self) -> Result<DutSummary, DutError> {
        let completion = self.completion;
        let fail = |why: String| {
            if let Some(record) = &completion {
                record.update(|c| c.fail(why));
            }
        };
        let summary = self
            .reader
            .stop()
            .inspect_err(|e| fail(format!("device under test: {e}")))?;
        let host_ns = self.origin.elapsed().as_nanos() as i64;
        let detail = summary.to_string().replace([',', '\n'], ";");
        let log_err = |source| DutError::Log {
            path: self.dir.clone(),
            source,
        };
        append(
            &self.dir.join(crate::stream::log::EVENTS_FILE),
            &format!("{host_ns},dut,{detail}\n"),
        )
        .and_then(|()| margemu_sim::meta::append(&self.dir, Appended::Dut(&summary.meta())))
        .inspect_err(|e| {
            fail(format!(
                "cannot record the device under test's summary: {e}"
            ))
        })
        .map_err(log_err)?;
        completion
            .map_or(Ok(()), CompletionRecord::release)
            .map_err(log_err)?;
        Ok(summary)
    }
}

fn append(path: &Path, text: &str) -> std::io::Result<()> {
    let mut file = std::fs::OpenOptions::new().append(true).open(path)?;
    file.write_all(text.as_bytes())
}

/// One loopback run with a flight controller.
#[derive(Debug)]
pub struct VfcRun {
    /// The session's outcome.
    pub session: Result<Summary, StreamError>,
    /// The device's and the flight controller's.
    pub fc: FcOutcome,
    /// The device-under-test reader's (`dut_*.csv` in the session directory).
    pub dut: Result<DutSummary, DutError>,
}

/// Streams `scene` to the firmware device with a flight controller of `config` on it, reads
/// the flight controller's MAVLink into the session directory `dir`, and returns how each part
/// ended. `stream`'s image settings are replaced by [`super::image_settings`]. Setting `stop`
/// interrupts the session (as Ctrl-C does). Fails only if the run cannot be set up.
pub fn run_loopback(
    scene: &Scene,
    config: VfcConfig,
    stream: StreamConfig,
    dir: &Path,
    stop: &AtomicBool,
    mut progress: impl FnMut(&Progress),
) -> Result<VfcRun, VfcError> {
    let (host_end, device_end) = TTYPort::pair().map_err(|e| VfcError::Io(e.into()))?;
    let stream = StreamConfig {
        port: device_end
            .name()
            .unwrap_or_else(|| "a pseudo-terminal".into()),
        images: Some(super::image_settings(scene)?),
        ..stream
    };
    let expected = super::board::chip_settings(scene.chip.model)?;
    let mut session = Session::new(scene, stream, dir)?;
    let (rig, fc_port) = spawn(device_end, config, expected)?;
    let dut = match attach(
        &mut session,
        fc_port,
        DutConfig::new(DutProtocol::Mavlink),
        dir,
    ) {
        Ok(dut) => dut,
        Err(e) => {
            rig.stop();
            return Err(e.into());
        }
    };
    let flag = session.stop_flag();
    let result = session.run_on_port(host_end, |p| {
        if stop.load(Ordering::Relaxed) {
            flag.store(true, Ordering::Relaxed);
        }
        progress(p)
    });
    let fc = rig.stop();
    dut.wait_for_bytes(fc.uart.bytes, Duration::from_secs(2));
    let dut = dut.finish();
    Ok(VfcRun {
        session: result,
        dut,
        fc,
    })
}

impl FcOutcome {
    /// Whether the device-under-test reader decoded exactly the frames the flight controller
    /// queued, per message, and the UART wrote them all; else what differs.
    pub fn check_delivery(&self, dut: &DutSummary) -> Result<(), String> {
        let mut problems = Vec::new();
        for (name, sent) in &self.fc.sent {
            let got = dut.messages.get(*name).copied().unwrap_or(0);
            if got != *sent {
                problems.push(format!("{name}: {sent} sent, {got} decoded"));
            }
        }
        for (name, got) in &dut.messages {
            if !self.fc.sent.contains_key(name.as_str()) {
                problems.push(format!("{name}: none sent, {got} decoded"));
            }
        }
        if self.uart.frames != self.fc.frames() {
            problems.push(format!(
                "the UART wrote {} of {} frames",
                self.uart.frames,
                self.fc.frames()
            ));
        }
        let c = &dut.counters;
        if c.bad_bytes + c.bad_frames + c.unknown_ids + c.undecoded > 0 {
            problems.push(format!("the reader counted damage: {c:?}"));
        }
        match problems.is_empty() {
            true => Ok(()),
            false => Err(problems.join("; ")),
        }
    }
}
