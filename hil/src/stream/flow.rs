//! The running session ([`Run`]): it owns the [`Session`] (its items and log writer), its
//! [`Port`] (which also tells the time), the fixed [`Plan`] and the run's parts, each with its
//! own state behind its own methods: [`Reports`] (what the device has said, `reports.rs`),
//! [`Pacing`] (what to write when, and the figures of the writes, `pacing.rs`) and [`Ending`]
//! (how the device is stopped, `ending.rs`). The run is the only thing that sequences them: the
//! handshake, the configuration, the prefill, Start, the paced batches, Stop, and the device
//! events handled while it waits. Every time the run reads or waits for comes from the port
//! ([`Port::now_ns`], [`Port::wait`], [`Port::spin_until`]): host time, ns since the session's
//! origin.

use super::ending::Ending;
use super::logger::Logger;
use super::meta::device_meta;
use super::pacing::{Pacing, Step};
use super::plan::Plan;
use super::port::Port;
use super::reports::Reports;
use super::rx::RxEvent;
use super::session::Session;
use super::{Progress, StreamError, Summary};
use margemu_protocol::link::{Encoder, Hello, Message, Start};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_sim::meta::Appended;
use std::time::Duration;

/// The longest the run waits for a device event before it checks its stop flag again, ns.
const PUMP_NS: u64 = 50_000_000;
/// How often the progress callback is called, ns.
const PROGRESS_NS: u64 = 100_000_000;

/// A running session (see the module docs).
pub(super) struct Run<L: Port, P: FnMut(&Progress)> {
    session: Session,
    /// The device's link and the session's clock.
    port: L,
    /// What is fixed for the session (set from the HelloAck by [`Run::configure`]).
    plan: Plan,
    encoder: Encoder,
    wire: Vec<u8>,
    reports: Reports,
    pacing: Pacing,
    ending: Ending,
    progress: P,
    /// When the progress callback was last called, host ns.
    last_progress: u64,
}

/// A host time as the logs write it.
fn host_ns(at: u64) -> i64 {
    at as i64
}

impl<L: Port, P: FnMut(&Progress)> Run<L, P> {
    /// `session` about to open with Hello on `port`.
    pub(super) fn new(session: Session, port: L, progress: P) -> Self {
        let plan = session.plan_before_handshake();
        let last_progress = port.now_ns();
        Self {
            reports: Reports::new(&plan),
            plan,
            session,
            port,
            encoder: Encoder::new(),
            wire: vec![0; margemu_protocol::link::MAX_WIRE_LEN],
            pacing: Pacing::new(),
            ending: Ending::default(),
            progress,
            last_progress,
        }
    }

    /// Ends the run: drops the port and returns the session's log writer, to close the logs.
    pub(super) fn into_logger(self) -> Logger {
        let Self { session, port, .. } = self;
        drop(port);
        session.into_logger()
    }

    /// Host time now, ns since the session's origin.
    pub(super) fn now(&self) -> u64 {
        self.port.now_ns()
    }

    /// Runs the session to its end: handshake, configuration, streaming and Stop (after an
    /// interruption, Stop at once).
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

    fn event(&mut self, event: &'static str, detail: &str) -> Result<(), StreamError> {
        let now = host_ns(self.now());
        let detail = detail.to_owned();
        let log = self.session.logger_mut();
        log.queue(move |log| log.event(now, event, &detail))
    }

    fn send(&mut self, message: &Message<'_>) -> Result<(), StreamError> {
        let n = self
            .encoder
            .encode(message, &mut self.wire)
            .expect("every message the host builds fits a frame");
        self.write_wire(n)
    }

    /// Writes the first `len` bytes of the wire buffer (one encoded frame).
    fn write_wire(&mut self, len: usize) -> Result<(), StreamError> {
        self.pacing.wrote(len);
        self.port
            .write(&self.wire[..len])
            .map_err(|e| StreamError::Disconnected {
                detail: format!("writing to the port failed: {e}"),
            })
    }

    /// Waits for the next event until host time `deadline` (at most [`PUMP_NS`]) and handles
    /// it and every event waiting behind it; checks the stop flag.
    fn pump(&mut self, deadline: u64) -> Result<(), StreamError> {
        if self.session.stop_requested() {
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
    fn handle_waiting(&mut self) -> Result<(), StreamError> {
        while let Some(event) = self.port.try_event() {
            self.handle(event)?;
        }
        Ok(())
    }

    /// Hands a device event to the reports; a Telemetry then to the pacing, which may go back
    /// to an item lost (until Stop is written).
    fn handle(&mut self, event: RxEvent) -> Result<(), StreamError> {
        match event {
            RxEvent::Stats(s) => match self.reports.rx_stats(s) {
                Some(detail) => self.event("host_rx_errors", &detail),
                None => Ok(()),
            },
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
            } => {
                let log = self.session.logger_mut();
                let telemetry = self
                    .reports
                    .message(log, self.plan.rate(), at_ns, seq, message)?;
                let lost = match telemetry {
                    Some(t) if !self.ending.stopping() => self.pacing.check_lost(&self.plan, &t),
                    _ => None,
                };
                match lost {
                    Some((event, detail)) => self.event(event, &detail),
                    None => Ok(()),
                }
            }
        }
    }

    fn handshake(&mut self) -> Result<(), StreamError> {
        let hello = Hello {
            protocol_version: PROTOCOL_VERSION,
            session: self.plan.session_id(),
        };
        self.send(&Message::Hello(hello))?;
        let timeout = self.plan.hello_timeout();
        let deadline = self.now() + timeout.as_nanos() as u64;
        while self.reports.ack().is_none() {
            if self.now() >= deadline {
                return Err(StreamError::HelloTimeout { timeout });
            }
            self.pump(deadline)?;
        }
        let ack = self.reports.ack().expect("checked above");
        if ack.protocol_version != PROTOCOL_VERSION {
            return Err(StreamError::VersionMismatch {
                device: ack.protocol_version,
                host: PROTOCOL_VERSION,
            });
        }
        if let Some(reason) = self.session.refusal(&ack) {
            return Err(StreamError::Unsupported { reason });
        }
        let device = device_meta(&ack);
        let log = self.session.logger_mut();
        log.queue(move |log| log.append_meta(Appended::Device(&device)))
    }

    /// Writes Configure, waits for the first credit window and sets the plan from the HelloAck
    /// ([`Plan::new`]: batch size, lead, the windows of what the session keeps).
    fn configure(&mut self) -> Result<(), StreamError> {
        let cfg = self.session.configure_message();
        self.reports.expect_credit();
        self.send(&Message::Configure(cfg))?;
        for add in self.session.add_device_messages() {
            self.send(&Message::AddDevice(add))?;
        }
        for piece in self.session.add_vibration_messages() {
            self.send(&Message::AddVibration(piece))?;
        }
        for fault in self.session.add_fault_messages().to_vec() {
            self.send(&Message::AddFault(fault))?;
        }
        let timeout = self.plan.hello_timeout();
        let deadline = self.now() + timeout.as_nanos() as u64;
        while !self.reports.credit_seen() {
            if self.now() >= deadline {
                return Err(StreamError::CreditTimeout { index: 0, timeout });
            }
            self.pump(deadline)?;
        }
        self.plan = self.session.plan(self.reports.ack().as_ref());
        self.reports.plan(&self.plan);
        self.pacing.plan(&self.plan);
        self.session.keep_items(self.plan.items_kept());
        let detail = format!(
            "credit limit {}; batch {}; lead {} us",
            self.reports.credit_limit(),
            self.plan.batch(),
            self.plan.lead().as_micros()
        );
        self.event("configured", &detail)
    }

    /// Prefill, Start, then every item at its due instant (and every go-back at once).
    fn stream(&mut self) -> Result<(), StreamError> {
        while let Some(n) = self.prefill_batch() {
            self.write_batch(n, None, false)?;
        }
        // The device serves samples 0..total and stops by itself at the scene's end.
        self.send(&Message::Start(Start::scene(0, self.plan.samples())))?;
        let start = self.now();
        self.pacing.started(start);
        let detail = format!(
            "start_host_ns {}; prefill {}",
            host_ns(start),
            self.pacing.next()
        );
        let start_ns = host_ns(start);
        let log = self.session.logger_mut();
        log.queue(move |log| {
            log.started(start_ns);
            Ok(())
        })?;
        self.event("start", &detail)?;
        while self.pacing.has_next(&self.plan) {
            self.send_next()?;
        }
        Ok(())
    }

    /// The next prefill batch's size within the credit window (`None`: the prefill is done).
    fn prefill_batch(&self) -> Option<u64> {
        let available = self.reports.available(self.pacing.next());
        self.pacing.prefill(&self.plan, available)
    }

    /// Waits for the next item's instant (handling device messages meanwhile) and writes its
    /// batch, within the credit window; a go-back is written at once, up to where it left off.
    fn send_next(&mut self) -> Result<(), StreamError> {
        self.report(false);
        // Predicted ahead while there is time, so a due batch never waits for its prediction.
        self.predict_through(self.pacing.predict_to(&self.plan))?;
        let due = self.pacing.due(&self.plan).expect("started");
        let spin = self.plan.spin_ns();
        if self.now() + spin < due {
            return self.pump(due - spin);
        }
        self.port.spin_until(due);
        // The batch goes out first; device messages wait, unless the window is short.
        if self.reports.available(self.pacing.next()) < self.pacing.wanted(&self.plan) {
            self.handle_waiting()?;
        }
        let available = self.reports.available(self.pacing.next());
        match self.pacing.step(&self.plan, available, self.now())? {
            Step::Write { n, paced } => self.write_batch(n, Some(due), paced),
            Step::Stalled(until) => self.pump(until),
        }
    }

    /// Predicts items `.. end` (their images go to the Served check).
    fn predict_through(&mut self, end: u64) -> Result<(), StreamError> {
        let served = self.reports.served_check_mut();
        self.session.predict_through(end, served)
    }

    /// Writes the next `n` items, `due` at an instant (`None`: the prefill), `paced` if not
    /// held back by credit; logs them in `sent.csv`.
    fn write_batch(&mut self, n: u64, due: Option<u64>, paced: bool) -> Result<(), StreamError> {
        let first = self.pacing.next();
        let resend = self.pacing.resending();
        self.predict_through(first + n)?;
        let started = self.now();
        let len = self
            .session
            .emit_batch(first, n, &mut self.encoder, &mut self.wire);
        self.write_wire(len)?;
        self.pacing.wrote_batch(len, n * self.session.item_len());
        let sent_at = self.now();
        let late_ns = self.pacing.written(n, due, paced, started, sent_at);
        let send_ns = host_ns(sent_at);
        self.session.log_sent(first, n, send_ns, late_ns, resend)
    }

    /// Writes Stop after the last sample ([`Ending`]: go-backs until then, and in source model
    /// the last sample reported served first), waits for the device to confirm it and logs
    /// the outcome.
    fn finish(&mut self) -> Result<(), StreamError> {
        let drain = self.plan.drain_ns();
        if let Some(stop_at) = Ending::stop_at(&self.plan, self.pacing.start()) {
            let spin = self.plan.spin_ns();
            while self.now() + spin < stop_at {
                if self.pacing.has_next(&self.plan) {
                    self.send_next()?; // a go-back
                    continue;
                }
                self.report(false);
                self.pump(stop_at - spin)?;
            }
            self.port.spin_until(stop_at);
            if let Some(last) = Ending::awaited(&self.plan) {
                let deadline = self.now() + drain;
                while !self.reports.has_served(last) && self.now() < deadline {
                    self.pump(deadline)?;
                }
            }
        }
        self.ending.stop();
        self.send(&Message::Stop)?;
        let deadline = self.now() + drain;
        while self.now() < deadline && !self.reports.device_stopped() {
            self.pump(deadline)?;
        }
        self.report(true);
        let (event, detail) = Ending::outcome(&self.reports);
        self.event(event, &detail)
    }

    /// After an interruption: writes Stop, waits up to the drain timeout for the device to
    /// confirm it (the stop flag no longer counts), and logs the outcome. Errors are left to
    /// the session's `end` row: this is the best that can be done on the way out.
    fn stop_after_interrupt(&mut self) {
        self.ending.stop();
        if self.send(&Message::Stop).is_err() {
            let (event, detail) = Ending::unwritten();
            let _ = self.event(event, &detail);
            return;
        }
        let deadline = self.now() + self.plan.drain_ns();
        while !self.reports.device_stopped() && self.now() < deadline {
            if let Some(event) = self.port.wait(deadline) {
                if self.handle(event).is_err() {
                    break;
                }
            }
        }
        let (event, detail) = Ending::outcome(&self.reports);
        let _ = self.event(event, &detail);
    }

    /// Calls the progress callback, at most every [`PROGRESS_NS`] unless `force`.
    fn report(&mut self, force: bool) {
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
            sent: self.pacing.sent(),
            total: self.plan.stream_len(),
            resends: self.pacing.rewinds(),
            elapsed: self.elapsed(),
            telemetry: self.reports.telemetry(),
            host_rx: self.reports.host_rx(),
            last_late_ns: self.pacing.last_late_ns(),
            max_late_ns: self.pacing.max_late_ns(),
            served: self.reports.served(),
        }
    }

    /// How the run went, so far.
    pub(super) fn summary(&self) -> Summary {
        Summary {
            samples: self.plan.samples(),
            sent: self.pacing.sent(),
            resends: self.pacing.rewinds(),
            resent: self.pacing.resent(),
            dir: self.session.logger().dir().to_path_buf(),
            start_host_ns: self.pacing.start().map(host_ns),
            jitter: self.pacing.jitter(),
            written_jitter: self.pacing.written_jitter(),
            telemetry: self.reports.telemetry(),
            device: self.reports.ack(),
            host_rx: self.reports.host_rx(),
            credit_stalls: self.pacing.credit_stalls(),
            served: self.reports.served(),
            stream_len: self.plan.stream_len(),
            source: self.session.source(),
            batch: self.plan.batch(),
            lead: self.plan.lead(),
            link: self.pacing.link(),
            image_settings: *self.session.image_settings(),
            elapsed: self.elapsed(),
            pacing: Default::default(),
        }
    }

    /// Time since Start.
    fn elapsed(&self) -> Duration {
        let since = |s: u64| self.now().saturating_sub(s);
        self.pacing
            .start()
            .map_or(Duration::ZERO, |s| Duration::from_nanos(since(s)))
    }
}
