//! [`Session`]: the host side of one streaming run (handshake, configuration, prefill, paced
//! batches, stop), over any byte port.

use super::images::{predict, ImageSettings, PredictedSample};
use super::log::SessionLog;
use super::meta::{device_meta, metadata};
use super::rx::{self, DeviceMessage, RxEvent};
use super::{JitterStats, Progress, StreamError, Summary};
use crate::scene::Scene;
use margemu_protocol::link::{
    Chips, Configure, Credit, DeviceState, Encoder, ErrorCode, ErrorReport, Hello, HelloAck, Image,
    ImageBatch, Message, Modes, Rate, RxStats, Start, Telemetry, MAX_IMAGES_PER_BATCH,
    MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Receiver;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// WHO_AM_I of the emulated chip: the MPU-9250.
pub const WHO_AM_I: u8 = 0x71;

/// Settings of a streaming session. `Default` suits a board or a PTY at 1–8 kHz.
#[derive(Clone, Debug)]
pub struct StreamConfig {
    /// The port's name, for `meta.toml`.
    pub port: String,
    /// The line rate, for `meta.toml` (a PTY or USB CDC ignores it).
    pub baud: u32,
    /// Physical → register conversion; `None`: [`ImageSettings::for_scene`].
    pub images: Option<ImageSettings>,
    /// How far ahead of its first sample's instant a batch is written.
    pub lead: Duration,
    /// Most images per batch (also capped by the device's `max_batch` and the frame size).
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
}

impl Default for StreamConfig {
    fn default() -> Self {
        Self {
            port: String::new(),
            baud: 921_600,
            images: None,
            lead: Duration::from_millis(20),
            batch: 32,
            telemetry_period: Duration::from_millis(50),
            hello_timeout: Duration::from_secs(2),
            credit_timeout: Duration::from_secs(2),
            drain_timeout: Duration::from_secs(1),
            spin: Duration::from_micros(200),
            session_id: 0x6D61_7267, // "marg"
        }
    }
}

/// One streaming run of one scene: its predicted samples, its settings and its log directory.
pub struct Session {
    config: StreamConfig,
    settings: ImageSettings,
    rate: Rate,
    samples: Vec<PredictedSample>,
    log: SessionLog,
    stop: Arc<AtomicBool>,
}

impl Session {
    /// Predicts every image of `scene` and creates the session directory `dir` (`meta.toml`,
    /// `truth.csv`, the other files with their headers).
    pub fn new(scene: &Scene, config: StreamConfig, dir: &Path) -> Result<Self, StreamError> {
        let settings = config
            .images
            .unwrap_or_else(|| ImageSettings::for_scene(scene));
        let rate = rate_of(scene)?;
        let samples = predict(scene, &settings)?;
        let meta = metadata(scene, &config, &settings, rate);
        let log_err = |source| StreamError::Log {
            path: dir.to_path_buf(),
            source,
        };
        let log = SessionLog::create(dir, &meta).map_err(log_err)?;
        log.write_truth(samples.iter().map(|s| &s.truth))
            .map_err(log_err)?;
        Ok(Self {
            config,
            settings,
            rate,
            samples,
            log,
            stop: Arc::new(AtomicBool::new(false)),
        })
    }

    /// Setting this flag (e.g. from a Ctrl-C handler) stops the session: it sends Stop, flushes
    /// the logs and returns [`StreamError::Interrupted`].
    pub fn stop_flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// The predicted samples, in order (truth and image).
    pub fn samples(&self) -> &[PredictedSample] {
        &self.samples
    }

    /// The register settings the images were computed with.
    pub fn image_settings(&self) -> &ImageSettings {
        &self.settings
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
    /// return from `read` now and then, by data, timeout or end of file). `progress` is called
    /// about ten times a second. Whatever the outcome, the logs are flushed and `events.csv` ends
    /// with an `end` row saying how the session ended.
    pub fn run(
        mut self,
        reader: impl Read + Send + 'static,
        writer: impl Write,
        progress: impl FnMut(&Progress),
    ) -> Result<Summary, StreamError> {
        let shutdown = Arc::new(AtomicBool::new(false));
        let (events, _thread) = rx::spawn(reader, shutdown.clone());
        let origin = Instant::now();
        let total = self.samples.len() as u64;
        let mut run = Run {
            writer,
            encoder: Encoder::new(),
            wire: vec![0; MAX_WIRE_LEN],
            events,
            origin,
            start: None,
            credit: Credit::default(),
            credit_seen: false,
            ack: None,
            telemetry: None,
            host_rx: RxStats::default(),
            late: Vec::with_capacity(total as usize / 8 + 1),
            max_late_ns: 0,
            credit_stalls: 0,
            next: 0,
            progress,
            last_progress: origin,
            session: &mut self,
        };
        let result = run.session_flow();
        let end_ns = run.host_ns(Instant::now());
        let summary = run.summary();
        drop(run);
        shutdown.store(true, Ordering::Relaxed);
        let (event, detail) = match &result {
            Ok(()) => ("end", "completed".to_string()),
            Err(e) => ("end", format!("error: {e}")),
        };
        let logged = self
            .log
            .event(end_ns, event, &detail)
            .and_then(|()| self.log.flush());
        result?;
        logged.map_err(|source| StreamError::Log {
            path: self.log.dir().to_path_buf(),
            source,
        })?;
        Ok(summary)
    }
}

/// The state of a running session.
struct Run<'s, W: Write, P: FnMut(&Progress)> {
    session: &'s mut Session,
    writer: W,
    encoder: Encoder,
    wire: Vec<u8>,
    events: Receiver<RxEvent>,
    origin: Instant,
    start: Option<Instant>,
    credit: Credit,
    credit_seen: bool,
    ack: Option<HelloAck>,
    telemetry: Option<Telemetry>,
    host_rx: RxStats,
    late: Vec<i64>,
    max_late_ns: i64,
    credit_stalls: u64,
    next: u64,
    progress: P,
    last_progress: Instant,
}

impl<W: Write, P: FnMut(&Progress)> Run<'_, W, P> {
    fn total(&self) -> u64 {
        self.session.samples.len() as u64
    }

    fn host_ns(&self, at: Instant) -> i64 {
        at.saturating_duration_since(self.origin).as_nanos() as i64
    }

    fn log_err(&self) -> impl Fn(std::io::Error) -> StreamError + '_ {
        move |source| StreamError::Log {
            path: self.session.log.dir().to_path_buf(),
            source,
        }
    }

    fn event(&mut self, event: &str, detail: &str) -> Result<(), StreamError> {
        let now = self.host_ns(Instant::now());
        let r = self.session.log.event(now, event, detail);
        r.map_err(self.log_err())
    }

    fn session_flow(&mut self) -> Result<(), StreamError> {
        let result = self
            .handshake()
            .and_then(|()| self.configure())
            .and_then(|()| self.stream())
            .and_then(|()| self.finish());
        if matches!(result, Err(StreamError::Interrupted)) {
            // Best effort: the device holds its last sample instead of counting underruns.
            let _ = self.send(&Message::Stop);
        }
        result
    }

    fn send(&mut self, message: &Message<'_>) -> Result<(), StreamError> {
        let n = self
            .encoder
            .encode(message, &mut self.wire)
            .expect("every message the host builds fits a frame");
        self.writer
            .write_all(&self.wire[..n])
            .map_err(|e| StreamError::Disconnected {
                detail: format!("writing to the port failed: {e}"),
            })
    }

    /// Waits for the next event until `deadline` and handles it; checks the stop flag.
    fn pump(&mut self, deadline: Instant) -> Result<(), StreamError> {
        if self.session.stop.load(Ordering::Relaxed) {
            return Err(StreamError::Interrupted);
        }
        let deadline = deadline.min(Instant::now() + Duration::from_millis(50));
        if let Some(event) = rx::recv_until(&self.events, deadline) {
            self.handle(event)?;
            while let Ok(event) = self.events.try_recv() {
                self.handle(event)?;
            }
        }
        Ok(())
    }

    fn handle(&mut self, event: RxEvent) -> Result<(), StreamError> {
        match event {
            RxEvent::Stats(s) => {
                if s.crc_errors != self.host_rx.crc_errors
                    || s.framing_errors != self.host_rx.framing_errors
                    || s.lost_frames != self.host_rx.lost_frames
                    || s.rejected_messages != self.host_rx.rejected_messages
                {
                    let detail = format!(
                        "crc {} framing {} lost {} rejected {}",
                        s.crc_errors, s.framing_errors, s.lost_frames, s.rejected_messages
                    );
                    self.host_rx = s;
                    self.event("host_rx_errors", &detail)?;
                }
                self.host_rx = s;
                Ok(())
            }
            RxEvent::Closed(e) => Err(StreamError::Disconnected {
                detail: match e {
                    None => "the port reached end of file".into(),
                    Some(e) => format!("reading the port failed: {e}"),
                },
            }),
            RxEvent::Message { at, seq, message } => self.message(at, seq, message),
        }
    }

    fn message(
        &mut self,
        at: Instant,
        seq: u16,
        message: DeviceMessage,
    ) -> Result<(), StreamError> {
        let host_ns = self.host_ns(at);
        let log = &mut self.session.log;
        let written = match &message {
            DeviceMessage::Telemetry(t) => {
                let t_ns = (t.samples_served > 0)
                    .then(|| self.session.rate.sample_time_ns(t.last_served_index));
                log.telemetry(host_ns, seq, t, t_ns)
            }
            DeviceMessage::RegisterWrites { dropped, writes } => {
                log.register_writes(host_ns, *dropped, writes)
            }
            DeviceMessage::HelloAck(a) => log.event(host_ns, "hello_ack", &describe_ack(a)),
            DeviceMessage::Reset(r) => {
                log.event(host_ns, "device_reset", &format!("{:?}", r.cause))
            }
            DeviceMessage::Error(e) => log.event(host_ns, "device_error", &describe_error(e)),
            DeviceMessage::Credit(_) => Ok(()),
        };
        written.map_err(self.log_err())?;
        match message {
            DeviceMessage::Credit(c) => self.window(c),
            DeviceMessage::Telemetry(t) => {
                self.window(t.credit());
                self.telemetry = Some(t);
            }
            DeviceMessage::HelloAck(a) if a.session == self.session.config.session_id => {
                self.ack = Some(a);
            }
            DeviceMessage::HelloAck(_) | DeviceMessage::RegisterWrites { .. } => {}
            DeviceMessage::Reset(r) if self.ack.is_some() => {
                return Err(StreamError::DeviceReset {
                    cause: format!("{:?}", r.cause),
                })
            }
            DeviceMessage::Reset(_) => {} // the boot announcement, before our Hello was answered
            DeviceMessage::Error(e) if is_fatal(e.code) => {
                return Err(StreamError::DeviceRefused {
                    detail: describe_error(&e),
                })
            }
            DeviceMessage::Error(_) => {}
        }
        Ok(())
    }

    fn window(&mut self, c: Credit) {
        self.credit = c;
        self.credit_seen = true;
    }

    fn handshake(&mut self) -> Result<(), StreamError> {
        let hello = Hello {
            protocol_version: PROTOCOL_VERSION,
            session: self.session.config.session_id,
        };
        self.send(&Message::Hello(hello))?;
        let deadline = Instant::now() + self.session.config.hello_timeout;
        while self.ack.is_none() {
            if Instant::now() >= deadline {
                return Err(StreamError::HelloTimeout {
                    timeout: self.session.config.hello_timeout,
                });
            }
            self.pump(deadline)?;
        }
        let ack = self.ack.expect("checked above");
        if ack.protocol_version != PROTOCOL_VERSION {
            return Err(StreamError::VersionMismatch {
                device: ack.protocol_version,
                host: PROTOCOL_VERSION,
            });
        }
        let caps = ack.capabilities;
        let missing = if !caps.chips.contains(Chips::MPU9250) {
            Some("it does not emulate the MPU-9250")
        } else if !caps.modes.contains(Modes::IMAGES) {
            Some("it does not take register images")
        } else if caps.max_batch == 0 || caps.buffer_capacity == 0 {
            Some("it announces no batch or buffer space")
        } else {
            None
        };
        if let Some(reason) = missing {
            return Err(StreamError::Unsupported { reason });
        }
        let device = device_meta(&ack);
        let meta = self.session.log.dir().join("meta.toml");
        let appended = std::fs::OpenOptions::new()
            .append(true)
            .open(&meta)
            .and_then(|mut f| f.write_all(device.as_bytes()));
        appended.map_err(self.log_err())
    }

    fn configure(&mut self) -> Result<(), StreamError> {
        let period = self.session.config.telemetry_period.as_nanos() as u64;
        let cfg = Configure {
            telemetry_period_ns: period,
            ..Configure::new(WHO_AM_I, self.session.rate)
        };
        self.credit_seen = false;
        self.send(&Message::Configure(cfg))?;
        let deadline = Instant::now() + self.session.config.hello_timeout;
        while !self.credit_seen {
            if Instant::now() >= deadline {
                return Err(StreamError::CreditTimeout {
                    index: 0,
                    timeout: self.session.config.hello_timeout,
                });
            }
            self.pump(deadline)?;
        }
        self.event("configured", &format!("credit limit {}", self.credit.limit))
    }

    fn batch_len(&self) -> u64 {
        let device = self
            .ack
            .map_or(1, |a| usize::from(a.capabilities.max_batch));
        self.session
            .config
            .batch
            .min(device)
            .clamp(1, MAX_IMAGES_PER_BATCH) as u64
    }

    /// The instant the batch starting at sample `k` is due (`None` before Start).
    fn due(&self, k: u64) -> Option<Instant> {
        let t = Duration::from_nanos(self.session.rate.sample_time_ns(k));
        let start = self.start?;
        Some(
            (start + t)
                .checked_sub(self.session.config.lead)
                .unwrap_or(start)
                .max(start),
        )
    }

    fn write_batch(
        &mut self,
        n: u64,
        late_ns: Option<i64>,
        paced: bool,
    ) -> Result<(), StreamError> {
        let first = self.next;
        let range = first as usize..(first + n) as usize;
        let images: Vec<Image> = self.session.samples[range.clone()]
            .iter()
            .map(|s| s.image)
            .collect();
        self.send(&Message::Images(ImageBatch::new(first, &images)))?;
        let send_ns = self.host_ns(Instant::now());
        if let (Some(l), true) = (late_ns, paced) {
            self.late.push(l);
            self.max_late_ns = self.max_late_ns.max(l);
        }
        for (i, s) in self.session.samples[range].iter().enumerate() {
            let k = first + i as u64;
            let r = self
                .session
                .log
                .sent(k, s.truth.t_ns, send_ns, late_ns, &s.image);
            r.map_err(self.log_err())?;
        }
        self.next += n;
        let r = self.session.log.flush();
        r.map_err(self.log_err())
    }

    fn stream(&mut self) -> Result<(), StreamError> {
        let total = self.total();
        let batch = self.batch_len();
        let lead_ns = self.session.config.lead.as_nanos() as u64;
        // Prefill: every sample due at Start, within the first window.
        while self.next < total
            && self.session.rate.sample_time_ns(self.next) <= lead_ns
            && self.credit.available(self.next) > 0
        {
            let n = batch
                .min(self.credit.available(self.next))
                .min(total - self.next);
            self.write_batch(n, None, false)?;
        }
        self.send(&Message::Start(Start { t0_ns: 0 }))?;
        let start = Instant::now();
        self.start = Some(start);
        let start_ns = self.host_ns(start);
        self.event(
            "start",
            &format!("start_host_ns {start_ns}; prefill {}", self.next),
        )?;
        let mut stall: Option<Instant> = None;
        while self.next < total {
            self.report(false);
            let due = self.due(self.next).expect("started");
            let now = Instant::now();
            if now + self.session.config.spin < due {
                self.pump(due - self.session.config.spin)?;
                continue;
            }
            while Instant::now() < due {
                std::hint::spin_loop();
            }
            while let Ok(event) = self.events.try_recv() {
                self.handle(event)?;
            }
            let available = self.credit.available(self.next);
            if available == 0 {
                let since = *stall.get_or_insert_with(|| {
                    self.credit_stalls += 1;
                    Instant::now()
                });
                let limit = since + self.session.config.credit_timeout;
                if Instant::now() >= limit {
                    return Err(StreamError::CreditTimeout {
                        index: self.next,
                        timeout: self.session.config.credit_timeout,
                    });
                }
                self.pump(limit)?;
                continue;
            }
            // A batch held back by the credit window is late because of the device, not of
            // the pacing: logged, but left out of the jitter figures.
            let paced = stall.take().is_none();
            let n = batch.min(available).min(total - self.next);
            let late = Instant::now().saturating_duration_since(due).as_nanos() as i64;
            self.write_batch(n, Some(late), paced)?;
        }
        Ok(())
    }

    /// Sends Stop half a period after the last sample's instant (so the device serves it and
    /// no instant after it), then waits for Telemetry in the stopped state.
    fn finish(&mut self) -> Result<(), StreamError> {
        let total = self.total();
        let drain = self.session.config.drain_timeout;
        if let (Some(start), Some(last)) = (self.start, total.checked_sub(1)) {
            let rate = self.session.rate;
            let (t_last, t_next) = (rate.sample_time_ns(last), rate.sample_time_ns(total));
            let stop_at = start + Duration::from_nanos(t_last + (t_next - t_last) / 2);
            while Instant::now() + self.session.config.spin < stop_at {
                self.report(false);
                self.pump(stop_at - self.session.config.spin)?;
            }
            while Instant::now() < stop_at {
                std::hint::spin_loop();
            }
        }
        self.send(&Message::Stop)?;
        let deadline = Instant::now() + drain;
        while Instant::now() < deadline
            && !self
                .telemetry
                .is_some_and(|t| t.state == DeviceState::Stopped)
        {
            self.pump(deadline)?;
        }
        self.report(true);
        match self.telemetry {
            Some(t) if t.state == DeviceState::Stopped => {
                let detail = format!(
                    "served {} samples, last index {}, underruns {}",
                    t.samples_served, t.last_served_index, t.underruns
                );
                self.event("stopped", &detail)
            }
            _ => self.event("stop_unconfirmed", "no Telemetry in the stopped state"),
        }
    }

    fn report(&mut self, force: bool) {
        let now = Instant::now();
        if !force && now.duration_since(self.last_progress) < Duration::from_millis(100) {
            return;
        }
        self.last_progress = now;
        let p = self.progress_now();
        (self.progress)(&p);
    }

    fn progress_now(&self) -> Progress {
        Progress {
            sent: self.next,
            total: self.total(),
            elapsed: self.start.map_or(Duration::ZERO, |s| s.elapsed()),
            telemetry: self.telemetry,
            host_rx: self.host_rx,
            last_late_ns: self.late.last().copied().unwrap_or(0),
            max_late_ns: self.max_late_ns,
        }
    }

    fn summary(&self) -> Summary {
        Summary {
            samples: self.total(),
            sent: self.next,
            dir: self.session.log.dir().to_path_buf(),
            start_host_ns: self.start.map(|s| self.host_ns(s)),
            jitter: JitterStats::from_lateness(&self.late),
            telemetry: self.telemetry,
            device: self.ack,
            host_rx: self.host_rx,
            credit_stalls: self.credit_stalls,
            image_settings: self.session.settings,
            elapsed: self.start.map_or(Duration::ZERO, |s| s.elapsed()),
        }
    }
}

fn is_fatal(code: ErrorCode) -> bool {
    !matches!(
        code,
        ErrorCode::CreditExceeded | ErrorCode::MalformedMessage | ErrorCode::UnknownMessage
    )
}

fn describe_error(e: &ErrorReport) -> String {
    format!(
        "{:?} (host frame seq {}, detail {})",
        e.code, e.seq, e.detail
    )
}

fn describe_ack(a: &HelloAck) -> String {
    let c = a.capabilities;
    format!(
        "protocol {} session {:#x} firmware {}.{}.{} max_batch {} buffer {}",
        a.protocol_version,
        a.session,
        a.firmware.major,
        a.firmware.minor,
        a.firmware.patch,
        c.max_batch,
        c.buffer_capacity
    )
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
