//! The running session ([`Run`]): the port's two directions, the device's latest reports, the
//! handshake and configuration. Device messages are handled in `reports.rs`, the paced
//! sending in `pacing.rs`.

use super::meta::device_meta;
use super::resend::GoBackN;
use super::rx::{self, RxEvent};
use super::served::ServedCheck;
use super::session::Session;
use super::{Lateness, LinkStats, Progress, StreamError, Summary};
use margemu_protocol::link::{Credit, Encoder, Hello, HelloAck, Message, RxStats, Telemetry};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_sim::meta::Appended;
use std::io::Write;
use std::sync::atomic::Ordering;
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

/// The state of a running session.
pub(super) struct Run<'s, W: Write, P: FnMut(&Progress)> {
    pub(super) session: &'s mut Session,
    pub(super) writer: W,
    pub(super) encoder: Encoder,
    pub(super) wire: Vec<u8>,
    pub(super) events: Receiver<RxEvent>,
    /// Host time 0 of the logs: when the session opened the port, unless `Session::set_origin`.
    pub(super) origin: Instant,
    /// When Start was written: scene time 0.
    pub(super) start: Option<Instant>,
    /// The device's newest credit window.
    pub(super) credit: Credit,
    pub(super) credit_seen: bool,
    pub(super) ack: Option<HelloAck>,
    pub(super) telemetry: Option<Telemetry>,
    pub(super) host_rx: RxStats,
    /// The Served reports against the prediction (its window set by [`Run::plan_pacing`]).
    pub(super) served: ServedCheck,
    /// How late the paced batches' writes started.
    pub(super) late: Lateness,
    /// How late the same writes completed.
    pub(super) written_late: Lateness,
    pub(super) max_late_ns: i64,
    pub(super) credit_stalls: u64,
    /// The next item to write.
    pub(super) next: u64,
    /// Items per batch and lead, from the device's capabilities ([`Run::plan_pacing`]).
    pub(super) batch: u64,
    pub(super) lead: Duration,
    /// Bytes written to the port: all, and those of sample batches with their item bytes.
    pub(super) link: LinkStats,
    /// When each recent item was last written (its window set by [`Run::plan_pacing`]); the
    /// go-backs.
    pub(super) go_back: GoBackN,
    /// Stop was written: reports no longer lead to resends.
    pub(super) stop_sent: bool,
    pub(super) progress: P,
    pub(super) last_progress: Instant,
}

impl<'s, W: Write, P: FnMut(&Progress)> Run<'s, W, P> {
    /// A session about to open with Hello: `events` come from the receive thread.
    pub(super) fn new(
        session: &'s mut Session,
        writer: W,
        events: Receiver<RxEvent>,
        progress: P,
    ) -> Self {
        let origin = session.origin.unwrap_or_else(Instant::now);
        let samples = session.samples;
        Self {
            session,
            writer,
            encoder: Encoder::new(),
            wire: vec![0; margemu_protocol::link::MAX_WIRE_LEN],
            events,
            origin,
            start: None,
            credit: Credit::default(),
            credit_seen: false,
            ack: None,
            telemetry: None,
            host_rx: RxStats::default(),
            served: ServedCheck::new(samples, 1),
            late: Lateness::new(),
            written_late: Lateness::new(),
            max_late_ns: 0,
            credit_stalls: 0,
            next: 0,
            batch: 1,
            lead: Duration::ZERO,
            link: LinkStats::default(),
            go_back: GoBackN::new(1),
            stop_sent: false,
            progress,
            last_progress: origin,
        }
    }
}

impl<W: Write, P: FnMut(&Progress)> Run<'_, W, P> {
    pub(super) fn total(&self) -> u64 {
        self.session.samples
    }

    pub(super) fn host_ns(&self, at: Instant) -> i64 {
        at.saturating_duration_since(self.origin).as_nanos() as i64
    }

    pub(super) fn log_err(&self) -> impl Fn(std::io::Error) -> StreamError + '_ {
        move |source| StreamError::Log {
            path: self.session.log.dir().to_path_buf(),
            source,
        }
    }

    pub(super) fn event(&mut self, event: &'static str, detail: &str) -> Result<(), StreamError> {
        let now = self.host_ns(Instant::now());
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
        self.link.wire_bytes += len as u64;
        self.writer
            .write_all(&self.wire[..len])
            .map_err(|e| StreamError::Disconnected {
                detail: format!("writing to the port failed: {e}"),
            })
    }

    /// Waits for the next event until `deadline` and handles it; checks the stop flag.
    pub(super) fn pump(&mut self, deadline: Instant) -> Result<(), StreamError> {
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

    pub(super) fn handle(&mut self, event: RxEvent) -> Result<(), StreamError> {
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
        self.plan_pacing();
        let detail = format!(
            "credit limit {}; batch {}; lead {} us",
            self.credit.limit,
            self.batch,
            self.lead.as_micros()
        );
        self.event("configured", &detail)
    }

    pub(super) fn report(&mut self, force: bool) {
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
            sent: self.go_back.high(),
            total: self.session.stream_len(),
            resends: self.go_back.rewinds(),
            elapsed: self.start.map_or(Duration::ZERO, |s| s.elapsed()),
            telemetry: self.telemetry,
            host_rx: self.host_rx,
            last_late_ns: self.late.last_ns(),
            max_late_ns: self.max_late_ns,
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
            start_host_ns: self.start.map(|s| self.host_ns(s)),
            jitter: self.late.stats(),
            written_jitter: self.written_late.stats(),
            telemetry: self.telemetry,
            device: self.ack,
            host_rx: self.host_rx,
            credit_stalls: self.credit_stalls,
            served: self.served.stats(),
            stream_len: self.session.stream_len(),
            source: self.session.source(),
            batch: self.batch,
            lead: self.lead,
            link: self.link,
            image_settings: self.session.settings,
            elapsed: self.start.map_or(Duration::ZERO, |s| s.elapsed()),
        }
    }
}
