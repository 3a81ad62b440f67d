//! [`Reports`]: what the device has said so far (its HelloAck, its newest credit window and
//! Telemetry, what the host's receiver counted, and its Served reports checked against the
//! prediction), and how each device message is logged (the writer thread writes it).
//!
//! [`Reports::message`] logs a message and keeps what it says; it fails on the messages that
//! end a session (a Reset after the handshake, a fatal Error) and hands a Telemetry back to the
//! run, which checks it for a lost batch (a go-back, see [`super::resend`] and `pacing.rs`).

use super::logger::Logger;
use super::plan::Plan;
use super::rx::DeviceMessage;
use super::served::{ServedCheck, ServedStats};
use super::StreamError;
use margemu_protocol::link::{
    Credit, DeviceState, ErrorCode, ErrorReport, HelloAck, Rate, RxStats, ServedSample, Telemetry,
};

/// What the device has said so far (see the module docs).
pub(super) struct Reports {
    /// The session number sent in Hello: a HelloAck for another session is ignored.
    session_id: u32,
    ack: Option<HelloAck>,
    /// The device's newest credit window.
    credit: Credit,
    /// A credit window arrived since [`Reports::expect_credit`].
    credit_seen: bool,
    telemetry: Option<Telemetry>,
    host_rx: RxStats,
    /// The Served reports against the prediction (its window set by the plan).
    served: ServedCheck,
}

impl Reports {
    /// Nothing heard yet, for a session planned as `plan` before the handshake.
    pub(super) fn new(plan: &Plan) -> Self {
        Self {
            session_id: plan.session_id(),
            ack: None,
            credit: Credit::default(),
            credit_seen: false,
            telemetry: None,
            host_rx: RxStats::default(),
            served: ServedCheck::new(plan.samples(), 1),
        }
    }

    /// Sizes the Served check for the plan set from the HelloAck (before anything is
    /// predicted).
    pub(super) fn plan(&mut self, plan: &Plan) {
        self.served = ServedCheck::new(plan.samples(), plan.served_window());
    }

    /// The device's HelloAck to our Hello.
    pub(super) fn ack(&self) -> Option<HelloAck> {
        self.ack
    }

    /// Waits for a new credit window: [`Reports::credit_seen`] is false until one arrives.
    pub(super) fn expect_credit(&mut self) {
        self.credit_seen = false;
    }

    /// Whether a credit window arrived since [`Reports::expect_credit`].
    pub(super) fn credit_seen(&self) -> bool {
        self.credit_seen
    }

    /// The newest credit window's limit: the host may write items below it.
    pub(super) fn credit_limit(&self) -> u64 {
        self.credit.limit
    }

    /// How many items the credit window lets the host write from item `next`.
    pub(super) fn available(&self, next: u64) -> u64 {
        self.credit.available(next)
    }

    /// The device's newest Telemetry.
    pub(super) fn telemetry(&self) -> Option<Telemetry> {
        self.telemetry
    }

    /// What the host's receiver counted.
    pub(super) fn host_rx(&self) -> RxStats {
        self.host_rx
    }

    /// What the device reported serving so far, against the prediction.
    pub(super) fn served(&self) -> ServedStats {
        self.served.stats()
    }

    /// The Served check, to give it the predicted images.
    pub(super) fn served_check_mut(&mut self) -> &mut ServedCheck {
        &mut self.served
    }

    /// Whether the device reported serving sample `last` (a Served entry or a Telemetry).
    pub(super) fn has_served(&self, last: u64) -> bool {
        self.served.stats().last_index >= Some(last)
            || self
                .telemetry
                .is_some_and(|t| t.samples_served > 0 && t.last_served_index >= last)
    }

    /// Whether the device's newest Telemetry says it has stopped.
    pub(super) fn device_stopped(&self) -> bool {
        self.telemetry
            .is_some_and(|t| t.state == DeviceState::Stopped)
    }

    /// Keeps the receiver's counters `s`; returns a description of them when they count new
    /// errors (for `events.csv`).
    pub(super) fn rx_stats(&mut self, s: RxStats) -> Option<String> {
        let old = self.host_rx;
        self.host_rx = s;
        let changed = s.crc_errors != old.crc_errors
            || s.framing_errors != old.framing_errors
            || s.lost_frames != old.lost_frames
            || s.rejected_messages != old.rejected_messages;
        changed.then(|| {
            format!(
                "crc {} framing {} lost {} rejected {}",
                s.crc_errors, s.framing_errors, s.lost_frames, s.rejected_messages
            )
        })
    }

    /// Logs in `log` and keeps a device message received at host time `at_ns` (times of
    /// samples at the scene's `rate`); returns a Telemetry for the run to check.
    pub(super) fn message(
        &mut self,
        log: &mut Logger,
        rate: Rate,
        at_ns: u64,
        seq: u16,
        message: DeviceMessage,
    ) -> Result<Option<Telemetry>, StreamError> {
        self.log(log, rate, at_ns as i64, seq, &message)?;
        match message {
            DeviceMessage::Credit(c) => self.window(c),
            DeviceMessage::Telemetry(t) => {
                self.window(t.credit());
                self.telemetry = Some(t);
                return Ok(Some(t));
            }
            DeviceMessage::HelloAck(a) if a.session == self.session_id => {
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
        Ok(None)
    }

    /// Logs a device message received at host time `host_ns`; checks a Served report.
    fn log(
        &mut self,
        log: &mut Logger,
        rate: Rate,
        host_ns: i64,
        seq: u16,
        message: &DeviceMessage,
    ) -> Result<(), StreamError> {
        match message {
            DeviceMessage::Telemetry(t) => {
                let t_ns = (t.samples_served > 0).then(|| rate.sample_time_ns(t.last_served_index));
                let t = *t;
                log.queue(move |log| log.telemetry(host_ns, seq, &t, t_ns))
            }
            DeviceMessage::RegisterWrites { dropped, writes } => {
                let (dropped, writes) = (*dropped, writes.clone());
                log.queue(move |log| log.register_writes(host_ns, dropped, &writes))
            }
            DeviceMessage::HelloAck(a) => {
                let detail = describe_ack(a);
                log.queue(move |log| log.event(host_ns, "hello_ack", &detail))
            }
            DeviceMessage::Reset(r) => {
                let detail = format!("{:?}", r.cause);
                log.queue(move |log| log.event(host_ns, "device_reset", &detail))
            }
            DeviceMessage::Error(e) => {
                let detail = describe_error(e);
                log.queue(move |log| log.event(host_ns, "device_error", &detail))
            }
            DeviceMessage::Served {
                first_index,
                first_time_ns,
                samples,
            } => {
                let rows = self.check_served(rate, *first_index, *first_time_ns, samples);
                log.queue(move |log| {
                    rows.iter()
                        .try_for_each(|(k, t, entry, m)| log.served(host_ns, *k, *t, entry, *m))
                })
            }
            DeviceMessage::Credit(_) => Ok(()),
        }
    }

    /// Checks each entry of a Served report; returns the rows of `served.csv`.
    fn check_served(
        &mut self,
        rate: Rate,
        first_index: u64,
        first_time_ns: u64,
        samples: &[ServedSample],
    ) -> Vec<(u64, u64, ServedSample, Option<bool>)> {
        (first_index..)
            .zip(samples)
            .map(|(k, entry)| {
                let time_ns = match k == first_index {
                    true => first_time_ns,
                    false => rate.sample_time_ns(k),
                };
                (k, time_ns, *entry, self.served.observe(k, entry))
            })
            .collect()
    }

    fn window(&mut self, c: Credit) {
        self.credit = c;
        self.credit_seen = true;
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
