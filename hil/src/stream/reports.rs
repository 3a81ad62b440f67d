//! What the session does with each device message: log it (the writer thread writes it), then
//! act on it: the credit window, the latest Telemetry (and a go-back when it shows a lost
//! batch, see [`super::resend`]), the HelloAck, Served reports checked against the prediction,
//! and the errors that end a session (a Reset after the handshake, a fatal Error).

use super::flow::Run;
use super::port::Port;
use super::rx::DeviceMessage;
use super::{Progress, StreamError};
use margemu_protocol::link::{
    Credit, DeviceState, ErrorCode, ErrorReport, HelloAck, ServedSample, Telemetry,
};

impl<L: Port, P: FnMut(&Progress)> Run<'_, L, P> {
    /// Logs and acts on a device message received at host time `at_ns`.
    pub(super) fn message(
        &mut self,
        at_ns: u64,
        seq: u16,
        message: DeviceMessage,
    ) -> Result<(), StreamError> {
        let host_ns = Self::host_ns(at_ns);
        let rate = self.plan.rate;
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
                self.reports.telemetry = Some(t);
                self.check_lost(&t)?;
            }
            DeviceMessage::HelloAck(a) if a.session == self.session.config.session_id => {
                self.reports.ack = Some(a);
            }
            DeviceMessage::HelloAck(_)
            | DeviceMessage::RegisterWrites { .. }
            | DeviceMessage::Served { .. } => {}
            DeviceMessage::Reset(r) if self.reports.ack.is_some() => {
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
        let rate = self.plan.rate;
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
        let capacity = self.plan.capacity;
        let contiguous = t
            .next_index
            .saturating_sub(t.credit_limit.saturating_sub(capacity));
        let all_written = self.go_back.high() == self.plan.stream_len;
        let beyond = u64::from(t.buffer_level) > contiguous || all_written;
        let running = t.state == DeviceState::Running;
        let (Some(start), true, true, false) = (self.start, running, beyond, self.stop_sent) else {
            return Ok(());
        };
        let (next_index, tau) = (t.next_index, t.time_ns);
        let margin = self.plan.resend_after_ns as i64;
        let seen_by = Self::host_ns(start) + tau as i64 - margin;
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
            None if next_index < self.next && self.go_back.forgotten(next_index) => {
                let detail = format!(
                    "device next_index {next_index} at its scene time {tau} ns is older than the \
                     items kept (from {}): not resent",
                    self.go_back.forgotten_below()
                );
                self.event("resend_out_of_window", &detail)
            }
            _ => Ok(()),
        }
    }

    fn window(&mut self, c: Credit) {
        self.reports.credit = c;
        self.reports.credit_seen = true;
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
