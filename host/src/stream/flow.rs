//! The running session ([`Run`]): the port's two directions, the device's latest reports, and
//! the handling of every device message (logs first, then state). The paced sending is in
//! [`super::pacing`].

use super::meta::device_meta;
use super::resend::GoBackN;
use super::rx::{self, DeviceMessage, RxEvent};
use super::served::ServedCheck;
use super::session::Session;
use super::{JitterStats, LinkStats, Progress, StreamError, Summary};
use margemu_protocol::link::{
    Chips, Credit, DeviceState, Encoder, ErrorCode, ErrorReport, Hello, HelloAck, Message, RxStats,
    ServedSample, Telemetry, CRC32C,
};
use margemu_protocol::PROTOCOL_VERSION;
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
    pub(super) served: ServedCheck,
    /// Lateness of each paced batch, ns.
    pub(super) late: Vec<i64>,
    /// Lateness of the same batches when their write completed, ns.
    pub(super) written_late: Vec<i64>,
    pub(super) max_late_ns: i64,
    pub(super) credit_stalls: u64,
    /// The next item to write.
    pub(super) next: u64,
    /// Items per batch and lead, from the device's capabilities ([`Run::plan_pacing`]).
    pub(super) batch: u64,
    pub(super) lead: Duration,
    /// Bytes written to the port: all, and those of sample batches with their item bytes.
    pub(super) link: LinkStats,
    /// When each item was last written; the go-backs.
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
        let total = session.samples.len();
        let go_back = GoBackN::new(session.stream_len());
        let crcs = session.samples.iter().map(|s| CRC32C.checksum(&s.image));
        let served = ServedCheck::new(crcs.collect());
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
            served,
            late: Vec::with_capacity(total / 8 + 1),
            written_late: Vec::with_capacity(total / 8 + 1),
            max_late_ns: 0,
            credit_stalls: 0,
            next: 0,
            batch: 1,
            lead: Duration::ZERO,
            link: LinkStats::default(),
            go_back,
            stop_sent: false,
            progress,
            last_progress: origin,
        }
    }
}

impl<W: Write, P: FnMut(&Progress)> Run<'_, W, P> {
    pub(super) fn total(&self) -> u64 {
        self.session.samples.len() as u64
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
            // Best effort: the device holds its last sample instead of counting underruns.
            let _ = self.send(&Message::Stop);
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

    fn message(
        &mut self,
        at: Instant,
        seq: u16,
        message: DeviceMessage,
    ) -> Result<(), StreamError> {
        let host_ns = self.host_ns(at);
        let rate = self.session.rate;
        let log = &mut self.session.log;
        let written = match &message {
            DeviceMessage::Telemetry(t) => {
                let t_ns = (t.samples_served > 0).then(|| rate.sample_time_ns(t.last_served_index));
                let t = *t;
                log.write(move |log| log.telemetry(host_ns, seq, &t, t_ns))
            }
            DeviceMessage::RegisterWrites { dropped, writes } => {
                let (dropped, writes) = (*dropped, writes.clone());
                log.write(move |log| log.register_writes(host_ns, dropped, &writes))
            }
            DeviceMessage::HelloAck(a) => {
                let detail = describe_ack(a);
                log.write(move |log| log.event(host_ns, "hello_ack", &detail))
            }
            DeviceMessage::Reset(r) => {
                let detail = format!("{:?}", r.cause);
                log.write(move |log| log.event(host_ns, "device_reset", &detail))
            }
            DeviceMessage::Error(e) => {
                let detail = describe_error(e);
                log.write(move |log| log.event(host_ns, "device_error", &detail))
            }
            DeviceMessage::Served {
                first_index,
                first_time_ns,
                samples,
            } => self.log_served(host_ns, *first_index, *first_time_ns, samples),
            DeviceMessage::Credit(_) => Ok(()),
        };
        written.map_err(self.log_err())?;
        match message {
            DeviceMessage::Credit(c) => self.window(c),
            DeviceMessage::Telemetry(t) => {
                self.window(t.credit());
                self.telemetry = Some(t);
                self.check_lost(&t)?;
            }
            DeviceMessage::HelloAck(a) if a.session == self.session.config.session_id => {
                self.ack = Some(a);
            }
            DeviceMessage::HelloAck(_)
            | DeviceMessage::RegisterWrites { .. }
            | DeviceMessage::Served { .. } => {}
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

    /// Checks and logs each entry of a Served report (`served.csv`).
    fn log_served(
        &mut self,
        host_ns: i64,
        first_index: u64,
        first_time_ns: u64,
        samples: &[ServedSample],
    ) -> std::io::Result<()> {
        let rate = self.session.rate;
        let rows: Vec<_> = (first_index..)
            .zip(samples)
            .map(|(k, entry)| {
                let time_ns = match k == first_index {
                    true => first_time_ns,
                    false => rate.sample_time_ns(k),
                };
                (k, time_ns, *entry, self.served.observe(k, entry))
            })
            .collect();
        self.session.log.write(move |log| {
            rows.iter()
                .try_for_each(|(k, t, entry, m)| log.served(host_ns, *k, *t, entry, *m))
        })
    }

    /// Goes back to the device's `next_index` if its Telemetry shows that item lost: the device
    /// holds items beyond it, which a FIFO line delivered after it (or, once every item was
    /// written, nothing more is coming), and it was last written long enough before the report
    /// (see [`super::resend`]).
    fn check_lost(&mut self, t: &Telemetry) -> Result<(), StreamError> {
        let capacity = self
            .ack
            .map_or(0, |a| u64::from(a.capabilities.buffer_capacity));
        let contiguous = t
            .next_index
            .saturating_sub(t.credit_limit.saturating_sub(capacity));
        let all_written = self.go_back.high() == self.session.stream_len();
        let beyond = u64::from(t.buffer_level) > contiguous || all_written;
        let running = t.state == DeviceState::Running;
        let (Some(start), true, true, false) = (self.start, running, beyond, self.stop_sent) else {
            return Ok(());
        };
        let (next_index, tau) = (t.next_index, t.time_ns);
        let margin = self.session.config.resend_after.as_nanos() as i64;
        let seen_by = self.host_ns(start) + tau as i64 - margin;
        match self.go_back.lost(next_index, seen_by) {
            Some(hole) if hole < self.next => {
                let detail = format!(
                    "device next_index {hole} at its scene time {tau} ns, {} items buffered; going back from {}",
                    t.buffer_level, self.next
                );
                self.next = hole;
                self.go_back.rewound();
                self.event("resend", &detail)
            }
            _ => Ok(()),
        }
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
        let (mode, no_mode) = self.session.required_mode();
        let missing = if !caps.chips.contains(Chips::MPU9250) {
            Some("it does not emulate the MPU-9250")
        } else if !caps.modes.contains(mode) {
            Some(no_mode)
        } else if caps.max_batch == 0 || caps.buffer_capacity == 0 {
            Some("it announces no batch or buffer space")
        } else {
            None
        };
        if let Some(reason) = missing {
            return Err(StreamError::Unsupported { reason });
        }
        let device = device_meta(&ack);
        let appended = self.session.log.write(move |log| log.append_meta(&device));
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
            last_late_ns: self.late.last().copied().unwrap_or(0),
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
            jitter: JitterStats::from_lateness(&self.late),
            written_jitter: JitterStats::from_lateness(&self.written_late),
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
