//! [`Session`]: the host side of one streaming run (handshake, configuration, prefill, paced
//! batches, stop), over any byte port. It owns the settings, what is streamed (`source.rs`:
//! the items and their lazy prediction) and the log writer (`logger.rs`), and hands itself to
//! the run (`flow.rs`), which reaches them only through the session's methods.

use super::budget::{board_of, budget_refusal, scene_load, BudgetPolicy};
use super::clock::SystemClock;
use super::flow::Run;
use super::images::{predict_images, ImageSettings};
use super::log::{SentLayout, SessionLog};
use super::logger::Logger;
use super::mcap_log::SessionMcap;
use super::meta::metadata;
use super::model::predict_model;
use super::plan::Plan;
use super::port::{Port, SystemPort};
use super::served::ServedCheck;
use super::source::{Items, Prediction, Source};
use super::{Progress, StreamError, Summary};
use crate::realtime::{self, Realtime, Scheduler, SystemScheduler};
use margemu_firmware::budget::Load;
use margemu_protocol::link::{Configure, Encoder, HelloAck, Rate};
use margemu_sim::rundir::{Completion, CompletionRecord, Status};
use margemu_sim::scene::Scene;
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where the device's samples come from (`docs/spec/link.md` §5.3).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SourceMode {
    /// (a) The host sends every register image.
    #[default]
    Images,
    /// (b) The host sends true kinematics and the device runs the shared sensor model
    /// ([`predict_model`](super::predict_model)).
    Model {
        /// Kinematics rate, Hz: the output rate over a whole number; `None`: the default of
        /// [`kinematics_hold`](super::kinematics_hold).
        kinematics_hz: Option<f64>,
    },
}

/// Settings of a streaming session. `Default` suits a board or a PTY at 1–8 kHz.
#[derive(Clone, Debug)]
pub struct StreamConfig {
    /// The port's name, for `meta.toml`.
    pub port: String,
    /// The line rate, for `meta.toml` (a PTY or USB CDC ignores it).
    pub baud: u32,
    /// Physical → register conversion; `None`: [`ImageSettings::for_scene`].
    pub images: Option<ImageSettings>,
    /// Register images or the device's own model.
    pub source: SourceMode,
    /// How far ahead of its first sample's instant a batch is written (capped at 3/8 of the
    /// device's buffer).
    pub lead: Duration,
    /// Most samples per batch (also capped by the device's `max_batch` and the frame size).
    pub batch: usize,
    /// Telemetry period asked of the device.
    pub telemetry_period: Duration,
    /// How long to wait for HelloAck and for the first credit window.
    pub hello_timeout: Duration,
    /// How long a due batch may wait for credit before the session gives up.
    pub credit_timeout: Duration,
    /// After the last sample's instant: how long to wait for the device to report it served,
    /// and then for it to confirm Stop.
    pub drain_timeout: Duration,
    /// The last stretch before a send instant is busy-waited, for pacing precision.
    pub spin: Duration,
    /// The session number sent in Hello.
    pub session_id: u32,
    /// Go-back-N: how long after its last write an item the device reports lost (it holds items
    /// after it) may be written again: the line's delivery time (a loaded machine's PTY can
    /// take over 10 ms). Over a UART, add the line time of a batch (`margemu stream` does).
    pub resend_after: Duration,
    /// Also write `session.mcap` (ROS 2 messages for Foxglove and `ros2 bag`), on the log
    /// writer thread with the CSV files.
    pub mcap: bool,
    /// Source mode (b) on a real board: which board, and whether to stream beyond its budget
    /// ([`budget`](super::budget)).
    pub budget: BudgetPolicy,
    /// Real-time pacing of the thread that runs the session ([`crate::realtime`]; off by
    /// default, the command line's default is auto).
    pub realtime: Realtime,
}

impl Default for StreamConfig {
    fn default() -> Self {
        Self {
            port: String::new(),
            baud: 921_600,
            images: None,
            source: SourceMode::Images,
            lead: Duration::from_millis(200),
            batch: 32,
            telemetry_period: Duration::from_millis(20),
            hello_timeout: Duration::from_secs(2),
            credit_timeout: Duration::from_secs(2),
            drain_timeout: Duration::from_secs(1),
            spin: Duration::from_micros(200),
            session_id: 0x6D61_7267, // "marg"
            resend_after: Duration::from_millis(20),
            mcap: false,
            budget: BudgetPolicy::default(),
            realtime: Realtime::Off,
        }
    }
}

/// One streaming run of one scene: its prediction (read lazily, a bounded window at a time),
/// its settings and its log directory.
pub struct Session {
    config: StreamConfig,
    settings: ImageSettings,
    /// The items and their prediction.
    source: Source,
    /// The AddFault messages of the scene's schedule.
    faults: Vec<margemu_protocol::link::AddFault>,
    log: Logger,
    stop: Arc<AtomicBool>,
    /// Host time 0 of the logs; `None`: when the run begins.
    origin: Option<Instant>,
    /// Source mode (b): what the device runs per output sample, and the output rate, Hz.
    load: Option<(Load, f64)>,
    /// How [`StreamConfig::realtime`] is applied.
    scheduler: Arc<dyn Scheduler>,
}

impl Session {
    /// Starts predicting the images of `scene` (in source mode model, after checking the device
    /// can run it; the prediction runs lazily, a bounded window ahead of what is sent, so this
    /// takes the same time and memory for any length of scene) and creates the session
    /// directory `dir` (`meta.toml`, every file with its header). Nothing is sent yet.
    pub fn new(scene: &Scene, config: StreamConfig, dir: &Path) -> Result<Self, StreamError> {
        let settings = config
            .images
            .unwrap_or_else(|| ImageSettings::for_scene(scene));
        let rate = rate_of(scene)?;
        if let Some(reason) = super::faults::fault_refusal(scene) {
            return Err(StreamError::Unsupported { reason });
        }
        let (mut prediction, items, hold) = match config.source {
            SourceMode::Images => (
                Prediction::images(predict_images(scene, &settings)),
                Items::Images,
                None,
            ),
            SourceMode::Model { kinematics_hz } => {
                let p = predict_model(scene, &settings, kinematics_hz)?;
                let items = Items::Kinematics {
                    params: Box::new(p.params),
                    hold: p.hold,
                    vibration: p.vibration,
                };
                (Prediction::model(p.samples), items, Some(p.hold))
            }
        };
        prediction.check_start()?;
        let load = match config.source {
            SourceMode::Images => None,
            SourceMode::Model { .. } => Some((scene_load(scene, rate)?, rate.as_hz_f64())),
        };
        let meta = metadata(scene, &config, &settings, rate, hold);
        let log_err = |source| StreamError::Log {
            path: dir.to_path_buf(),
            source,
        };
        let sent = match items {
            Items::Images => SentLayout::Images(
                scene
                    .devices()
                    .into_iter()
                    .map(|d| (d.name, d.chip.model.image_len()))
                    .collect(),
            ),
            Items::Kinematics { .. } => SentLayout::Kinematics,
        };
        let devices = scene.devices();
        let mut log = SessionLog::create(dir, &meta, &sent, &devices).map_err(log_err)?;
        // The scene's fault windows, first (margemu_sim::fault_log).
        for detail in margemu_sim::fault_log::details(scene) {
            let event = margemu_sim::fault_log::FAULT_EVENT;
            log.event(0, event, &detail).map_err(log_err)?;
        }
        if config.mcap {
            let images = matches!(items, Items::Images);
            let mcap =
                SessionMcap::create(dir, scene, images, settings.chip, settings.mag_ut_per_unit);
            log = log.with_mcap(mcap.map_err(log_err)?);
        }
        let log = Logger::spawn(log).map_err(log_err)?;
        let others = scene.other_devices.iter().map(|d| d.chip).collect();
        let chips = (scene.chip, others);
        let source = Source::new(items, prediction, chips, rate, scene.samples());
        Ok(Self {
            config,
            settings,
            source,
            faults: super::faults::fault_messages(scene),
            log,
            stop: Arc::new(AtomicBool::new(false)),
            origin: None,
            load,
            scheduler: Arc::new(SystemScheduler),
        })
    }

    /// Setting this flag (e.g. from a Ctrl-C handler) stops the session: it sends Stop, flushes
    /// the logs and returns [`StreamError::Interrupted`].
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// Makes `origin` host time 0 of the logs (every `host_ns`, `start_host_ns`) instead of the
    /// moment the run begins, so that another logger (the device under test's reader,
    /// [`crate::dut`]) can share the session's clock.
    pub fn set_origin(&mut self, origin: Instant) {
        self.origin = Some(origin);
    }

    /// Applies [`StreamConfig::realtime`] through `scheduler` instead of the operating
    /// system's ([`SystemScheduler`]): a test makes it refuse.
    pub fn set_scheduler(&mut self, scheduler: Arc<dyn Scheduler>) {
        self.scheduler = scheduler;
    }

    /// A handle the device under test's reader writes its attitude into `session.mcap` with;
    /// `None` unless the session writes one ([`StreamConfig::mcap`]).
    pub fn log_sink(&mut self) -> Option<super::LogSink> {
        self.config.mcap.then(|| self.log.sink())
    }

    /// A share of the session directory's completion record ([`margemu_sim::rundir`]), for a writer
    /// that logs into the directory beside the session (the device under test's reader): the
    /// record is written to `meta.toml` when the session has ended and every share is let go.
    pub fn completion_record(&self) -> Option<CompletionRecord> {
        self.log.completion()
    }

    /// Output samples in the scene (their images: [`predict_images`](super::predict_images)
    /// with [`Session::image_settings`]).
    pub fn sample_count(&self) -> u64 {
        self.source.samples()
    }

    /// The source mode, with the kinematics rate resolved.
    pub fn source(&self) -> SourceMode {
        self.source.mode()
    }

    /// The register settings the images were computed with.
    pub fn image_settings(&self) -> &ImageSettings {
        &self.settings
    }

    /// The plan before the device has answered Hello ([`Plan::before_handshake`]).
    pub(super) fn plan_before_handshake(&self) -> Plan {
        Plan::before_handshake(&self.source, &self.config)
    }

    /// The plan for a device that answered `ack` ([`Plan::new`]).
    pub(super) fn plan(&self, ack: Option<&HelloAck>) -> Plan {
        Plan::new(&self.source, &self.config, ack)
    }

    /// Why the device that answered `ack` cannot serve this session (`None`: it can): its
    /// capabilities, or in source mode (b) a real board's budget ([`budget_refusal`]).
    pub(super) fn refusal(&self, ack: &HelloAck) -> Option<String> {
        self.source.refusal(&ack.capabilities).or_else(|| {
            let (load, rate_hz) = self.load.as_ref()?;
            let board = board_of(self.config.budget.board, &ack.device_id)?;
            budget_refusal(&self.config.budget, &board, &ack.device_id, load, *rate_hz)
        })
    }

    /// One AddDevice per other device of a rig, to follow Configure.
    pub(super) fn add_device_messages(&self) -> Vec<margemu_protocol::link::AddDevice> {
        self.source.add_device_messages()
    }

    /// The AddFault messages of the scene's schedule, in order, to follow AddVibration.
    pub(super) fn add_fault_messages(&self) -> &[margemu_protocol::link::AddFault] {
        &self.faults
    }

    /// The AddVibration messages of source model, to follow Configure.
    pub(super) fn add_vibration_messages(&self) -> Vec<margemu_protocol::link::AddVibration> {
        self.source.add_vibration_messages().to_vec()
    }

    /// Configure for this session.
    pub(super) fn configure_message(&self) -> Configure {
        let period = self.config.telemetry_period.as_nanos() as u64;
        self.source.configure_message(period)
    }

    /// Keeps the newest `span` items predicted (`Plan::items_kept`).
    pub(super) fn keep_items(&mut self, span: usize) {
        self.source.keep_items(span);
    }

    /// Predicts items `.. end` ([`Source::predict_through`]).
    pub(super) fn predict_through(
        &mut self,
        end: u64,
        served: &mut ServedCheck,
    ) -> Result<(), StreamError> {
        self.source.predict_through(end, served, &mut self.log)
    }

    /// Encodes the batch of items `first .. first + n` into `wire`; returns its length.
    pub(super) fn emit_batch(
        &self,
        first: u64,
        n: u64,
        encoder: &mut Encoder,
        wire: &mut [u8],
    ) -> usize {
        self.source.emit_batch(first, n, encoder, wire)
    }

    /// Bytes of one item on the wire (before framing).
    pub(super) fn item_len(&self) -> u64 {
        self.source.item_len()
    }

    /// Logs items `first .. first + n` in `sent.csv`, written at host time `send_ns`.
    pub(super) fn log_sent(
        &mut self,
        first: u64,
        n: u64,
        send_ns: i64,
        late_ns: Option<i64>,
        resend: bool,
    ) -> Result<(), StreamError> {
        let log = &mut self.log;
        self.source
            .log_sent(log, first, n, send_ns, late_ns, resend)
    }

    /// The session's log writer.
    pub(super) fn logger(&self) -> &Logger {
        &self.log
    }

    /// The session's log writer, to queue rows.
    pub(super) fn logger_mut(&mut self) -> &mut Logger {
        &mut self.log
    }

    /// Ends the session but for its logs: the log writer, to close them.
    pub(super) fn into_logger(self) -> Logger {
        self.log
    }

    /// Whether the stop flag ([`Session::stop_flag`]) is set.
    pub(super) fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Runs the session on a serial port (a clone of it feeds the receive thread).
    pub fn run_on_port(
        self,
        port: serialport::TTYPort,
        progress: impl FnMut(&Progress),
    ) -> Result<Summary, StreamError> {
        let reader = port
            .try_clone_native()
            .map_err(|e| StreamError::Port { source: e.into() })?;
        self.run(reader, port, progress)
    }

    /// Runs the session: `reader` and `writer` are the two directions of the port (`reader` must
    /// return from `read` now and then, by data, timeout or end of file), on the host's
    /// monotonic clock ([`SystemClock`], host time 0 when the run begins unless
    /// [`Session::set_origin`]). `progress` is called about ten times a second of that clock.
    /// Whatever the outcome, the logs are flushed, `events.csv` ends with an `end` row saying
    /// how the session ended, and `meta.toml` gets its completion record (complete, interrupted
    /// or failed; [`margemu_sim::rundir`]) once every other writer of the directory has let go of its
    /// share ([`Session::completion_record`]).
    pub fn run(
        self,
        reader: impl Read + Send + 'static,
        writer: impl Write,
        progress: impl FnMut(&Progress),
    ) -> Result<Summary, StreamError> {
        let clock = self
            .origin
            .map_or_else(SystemClock::new, SystemClock::with_origin);
        self.run_with(SystemPort::new(reader, writer, clock), progress)
    }

    /// [`Session::run`] on any [`Port`]: every host time the session waits for or logs comes
    /// from the port's clock (e.g. a [`VirtualPort`](super::virtual_port::VirtualPort) on a
    /// virtual clock). The port is dropped before the logs are closed.
    ///
    /// The calling thread paces the run: it asks for [`StreamConfig::realtime`] once the port
    /// (and its receive thread) exists, and is put back when the run ends; what it obtained is
    /// `events.csv`'s `pacing` row and [`Summary::pacing`], and a refusal is one warning line
    /// on standard error ([`crate::realtime::warn_once`]).
    pub fn run_with(
        mut self,
        port: impl Port,
        progress: impl FnMut(&Progress),
    ) -> Result<Summary, StreamError> {
        let (guard, pacing) = realtime::enter(self.config.realtime, self.scheduler.clone());
        realtime::warn_once(&pacing);
        if pacing.fifo_priority.is_some() {
            self.config.spin = self.config.spin.min(realtime::MAX_SPIN);
        }
        let detail = pacing.to_string();
        let logged = self.log.queue(move |log| log.event(0, "pacing", &detail));
        let mut run = Run::new(self, port, progress);
        let result = logged.and_then(|()| run.session_flow());
        drop(guard);
        let end_ns = run.now() as i64;
        let mut summary = run.summary();
        summary.pacing = pacing;
        let mut log = run.into_logger(); // the port is dropped here
        let (status, ended) = match &result {
            Ok(()) => (Status::Complete, "completed".to_string()),
            Err(e @ StreamError::Interrupted) => (Status::Interrupted, e.to_string()),
            Err(e) => (Status::Failed, e.to_string()),
        };
        let detail = match status {
            Status::Complete => ended.clone(),
            _ => format!("error: {ended}"),
        };
        let served = &summary.served;
        let completion = Completion {
            status,
            samples_written: served.samples - served.unreported,
            samples_expected: Some(served.samples),
            ended,
        };
        let logged = log
            .write(move |log| log.event(end_ns, "end", &detail))
            .and_then(|()| log.end(completion));
        result?;
        logged.map_err(|source| log.error(source))?;
        Ok(summary)
    }
}

/// The scene's output rate as the link's exact ratio, checked against the scene clock.
pub fn rate_of(scene: &Scene) -> Result<Rate, StreamError> {
    let hz = scene.clock.hz();
    let mhz = (hz * 1000.0).round() as u64;
    let g = gcd(mhz, 1000);
    let rate = u32::try_from(mhz / g)
        .ok()
        .and_then(|num| Rate::new(num, (1000 / g) as u32));
    let total = scene.samples();
    match rate {
        Some(rate)
            if [1, 2, 3, 7, total.saturating_sub(1), total]
                .iter()
                .all(|&k| rate.sample_time_ns(k) == scene.clock.instant(k)) =>
        {
            Ok(rate)
        }
        _ => Err(StreamError::Rate { hz }),
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}
