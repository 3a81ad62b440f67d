//! The running session ([`Run`]): its [`Port`] (which also tells the time), the fixed
//! [`Plan`], the device's latest reports, the handshake and configuration. Device messages are
//! handled in `reports.rs`, the paced sending in `pacing.rs`. Every time the run reads or waits
//! for comes from the port ([`Port::now_ns`], [`Port::wait`], [`Port::spin_until`]): host time,
//! ns since the session's origin.

use super::meta::device_meta;
use super::plan::Plan;
use super::port::Port;
use super::resend::GoBackN;
use super::rx::RxEvent;
use super::served::ServedCheck;
use super::session::Session;
use super::{Lateness, LinkStats, Progress, StreamError, Summary};
use margemu_protocol::link::{Credit, Encoder, Hello, HelloAck, Message, RxStats, Telemetry};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_sim::meta::Appended;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// The longest the run waits for a device event before it checks its stop flag again, ns.
const PUMP_NS: u64 = 50_000_000;
/// How often the progress callback is called, ns.
const PROGRESS_NS: u64 = 100_000_000;

/// The state of a running session.
pub(super) struct Run<'s, L: Port, P: FnMut(&Progress)> {
    pub(super) session: &'s mut Session,
    /// The device's link and the session's clock.
    pub(super) port: L,
    /// What is fixed for the session (set from the HelloAck by [`Run::configure`]).
    pub(super) plan: Plan,
    pub(super) encoder: Encoder,
    pub(super) wire: Vec<u8>,
    /// When Start was written, host ns: scene time 0.
    pub(super) start: Option<u64>,
    /// What the device has said so far.
    pub(super) reports: Reports,
    /// The Served reports against the prediction (its window set by the plan).
    pub(super) served: ServedCheck,
    /// What the run measured of its own writes.
    pub(super) figures: Figures,
    /// The next item to write.
    pub(super) next: u64,
    /// When each recent item was last written (its window set by the plan); the go-backs.
    pub(super) go_back: GoBackN,
    /// Stop was written: reports no longer lead to resends.
    pub(super) stop_sent: bool,
    pub(super) progress: P,
    /// When the progress callback was last called, host ns.
    pub(super) last_progress: u64,
}

/// What the device has said so far: its HelloAck, its newest credit window and Telemetry, and
/// what the host's receiver counted.
#[derive(Default)]
pub(super) struct Reports {
    pub(super) ack: Option<HelloAck>,
    /// The device's newest credit window.
    pub(super) credit: Credit,
    /// A credit window arrived since Configure was written.
    pub(super) credit_seen: bool,
    pub(super) telemetry: Option<Telemetry>,
    pub(super) host_rx: RxStats,
}

/// What a run measured of its own writes: pacing lateness, credit stalls, bytes.
#[derive(Default)]
pub(super) struct Figures {
    /// How late the paced batches' writes started.
    pub(super) late: Lateness,
    /// How late the same writes completed.
    pub(super) written_late: Lateness,
    pub(super) max_late_ns: i64,
    /// Times a due batch had to wait for credit.
    pub(super) credit_stalls: u64,
    /// Bytes written to the port: all, and those of sample batches with their item bytes.
    pub(super) link: LinkStats,
}

impl<'s, L: Port, P: FnMut(&Progress)> Run<'s, L, P> {
    /// A session about to open with Hello on `port`.
    pub(super) fn new(session: &'s mut Session, port: L, progress: P) -> Self {
        let samples = session.samples;
        let last_progress = port.now_ns();
        Self {
            plan: Plan::before_handshake(session),
            session,
            port,
            encoder: Encoder::new(),
            wire: vec![0; margemu_protocol::link::MAX_WIRE_LEN],
            start: None,
            reports: Reports::default(),
            served: ServedCheck::new(samples, 1),
            figures: Figures::default(),
            next: 0,
            go_back: GoBackN::new(1),
            stop_sent: false,
            progress,
            last_progress,
        }
    }
}

impl<L: Port, P: FnMut(&Progress)> Run<'_, L, P> {
    pub(super) fn total(&self) -> u64 {
        self.plan.samples
    }

    /// Host time now, ns since the session's origin.
    pub(super) fn now(&self) -> u64 {
        self.port.now_ns()
    }

    /// A host time as the logs write it.
    pub(super) fn host_ns(at: u64) -> i64 {
        at as i64
    }

    pub(super) fn log_err(&self) -> impl Fn(std::io::Error) -> StreamError + '_ {
        move |source| StreamError::Log {
            path: self.session.log.dir().to_path_buf(),
            source,
        }
    }

    pub(super) fn event(&mut self, event: &'static str, detail: &str) -> Result<(), StreamError> {
        let now = Self::host_ns(self.now());
        let detail = detail.to_owned();
        let r = self
            .session
            .log
            .write(move |log| log.event(now, event, &detail));
        r.map_err(self.log_err())
    }

    pub(super) fn session_flow(&mut self) -> Result<(), StreamError> {
        let result = self
            .handshake()
            .and_then(|()| self.configure())
            .and_then(|()| self.stream())
            .and_then(|()| self.finish());
        if matches!(result, Err(StreamError::Interrupted)) {
            self.stop_after_interrupt();
        }
        result
    }

    pub(super) fn send(&mut self, message: &Message<'_>) -> Result<(), StreamError> {
        let n = self
            .encoder
            .encode(message, &mut self.wire)
            .expect("every message the host builds fits a frame");
        self.write_wire(n)
    }

    /// Writes the first `len` bytes of the wire buffer (one encoded frame).
    pub(super) fn write_wire(&mut self, len: usize) -> Result<(), StreamError> {
        self.figures.link.wire_bytes += len as u64;
        self.port
            .write(&self.wire[..len])
            .map_err(|e| StreamError::Disconnected {
                detail: format!("writing to the port failed: {e}"),
            })
    }

    /// Waits for the next event until host time `deadline` (at most [`PUMP_NS`]) and handles
    /// it and every event waiting behind it; checks the stop flag.
    pub(super) fn pump(&mut self, deadline: u64) -> Result<(), StreamError> {
        if self.session.stop.load(Ordering::Relaxed) {
            return Err(StreamError::Interrupted);
        }
        let deadline = deadline.min(self.now() + PUMP_NS);
        if let Some(event) = self.port.wait(deadline) {
            self.handle(event)?;
            self.handle_waiting()?;
        }
        Ok(())
    }

    /// Handles every device event already received, without waiting.
    pub(super) fn handle_waiting(&mut self) -> Result<(), StreamError> {
        while let Some(event) = self.port.try_event() {
            self.handle(event)?;
        }
        Ok(())
    }

    pub(super) fn handle(&mut self, event: RxEvent) -> Result<(), StreamError> {
        match event {
            RxEvent::Stats(s) => {
                if s.crc_errors != self.reports.host_rx.crc_errors
                    || s.framing_errors != self.reports.host_rx.framing_errors
                    || s.lost_frames != self.reports.host_rx.lost_frames
                    || s.rejected_messages != self.reports.host_rx.rejected_messages
                {
                    let detail = format!(
                        "crc {} framing {} lost {} rejected {}",
                        s.crc_errors, s.framing_errors, s.lost_frames, s.rejected_messages
                    );
                    self.reports.host_rx = s;
                    self.event("host_rx_errors", &detail)?;
                }
                self.reports.host_rx = s;
                Ok(())
            }
            RxEvent::Closed(e) => Err(StreamError::Disconnected {
                detail: match e {
                    None => "the port reached end of file".into(),
                    Some(e) => format!("reading the port failed: {e}"),
                },
            }),
            RxEvent::Message {
                at_ns,
                seq,
                message,
            } => self.message(at_ns, seq, message),
        }
    }

    fn handshake(&mut self) -> Result<(), StreamError> {
        let hello = Hello {
            protocol_version: PROTOCOL_VERSION,
            session: self.session.config.session_id,
        };
        self.send(&Message::Hello(hello))?;
        let deadline = self.now() + self.plan.hello_timeout_ns;
        while self.reports.ack.is_none() {
            if self.now() >= deadline {
                return Err(StreamError::HelloTimeout {
                    timeout: self.session.config.hello_timeout,
                });
            }
            self.pump(deadline)?;
        }
        let ack = self.reports.ack.expect("checked above");
        if ack.protocol_version != PROTOCOL_VERSION {
            return Err(StreamError::VersionMismatch {
                device: ack.protocol_version,
                host: PROTOCOL_VERSION,
            });
        }
        let caps = ack.capabilities;
        let (mode, no_mode) = self.session.required_mode();
        let model = self.session.chip.model;
        let missing = if !caps.chips.has(model) {
            Some(format!("it does not emulate the {}", model.part_name()))
        } else if !caps.modes.contains(mode) {
            Some(no_mode.to_owned())
        } else if caps.max_batch == 0 || caps.buffer_capacity == 0 {
            Some("it announces no batch or buffer space".to_owned())
        } else {
            None
        };
        if let Some(reason) = missing {
            return Err(StreamError::Unsupported { reason });
        }
        let device = device_meta(&ack);
        let appended = self
            .session
            .log
            .write(move |log| log.append_meta(Appended::Device(&device)));
        appended.map_err(self.log_err())
    }

    fn configure(&mut self) -> Result<(), StreamError> {
        let period = self.session.config.telemetry_period.as_nanos() as u64;
        let cfg = self.session.configure_message(period);
        self.reports.credit_seen = false;
        self.send(&Message::Configure(cfg))?;
        let deadline = self.now() + self.plan.hello_timeout_ns;
        while !self.reports.credit_seen {
            if self.now() >= deadline {
                return Err(StreamError::CreditTimeout {
                    index: 0,
                    timeout: self.session.config.hello_timeout,
                });
            }
            self.pump(deadline)?;
        }
        self.plan_pacing();
        let detail = format!(
            "credit limit {}; batch {}; lead {} us",
            self.reports.credit.limit,
            self.plan.batch,
            self.plan.lead_ns / 1000
        );
        self.event("configured", &detail)
    }

    pub(super) fn report(&mut self, force: bool) {
        let now = self.now();
        if !force && now.saturating_sub(self.last_progress) < PROGRESS_NS {
            return;
        }
        self.last_progress = now;
        let p = self.progress_now();
        (self.progress)(&p);
    }

    fn progress_now(&self) -> Progress {
        Progress {
            sent: self.go_back.high(),
            total: self.plan.stream_len,
            resends: self.go_back.rewinds(),
            elapsed: self.elapsed(),
            telemetry: self.reports.telemetry,
            host_rx: self.reports.host_rx,
            last_late_ns: self.figures.late.last_ns(),
            max_late_ns: self.figures.max_late_ns,
            served: self.served.stats(),
        }
    }

    pub(super) fn summary(&self) -> Summary {
        Summary {
            samples: self.total(),
            sent: self.go_back.high(),
            resends: self.go_back.rewinds(),
            resent: self.go_back.resent(),
            dir: self.session.log.dir().to_path_buf(),
            start_host_ns: self.start.map(Self::host_ns),
            jitter: self.figures.late.stats(),
            written_jitter: self.figures.written_late.stats(),
            telemetry: self.reports.telemetry,
            device: self.reports.ack,
            host_rx: self.reports.host_rx,
            credit_stalls: self.figures.credit_stalls,
            served: self.served.stats(),
            stream_len: self.plan.stream_len,
            source: self.session.source(),
            batch: self.plan.batch,
            lead: Duration::from_nanos(self.plan.lead_ns),
            link: self.figures.link,
            image_settings: self.session.settings,
            elapsed: self.elapsed(),
        }
    }

    /// Time since Start.
    fn elapsed(&self) -> Duration {
        let since = |s: u64| self.now().saturating_sub(s);
        self.start
            .map_or(Duration::ZERO, |s| Duration::from_nanos(since(s)))
    }
}
