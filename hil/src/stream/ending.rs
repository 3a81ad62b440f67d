//! How a session's device is stopped: after the last sample ([`Run::finish`](super::pacing)) or
//! when the session is interrupted (SIGINT, SIGTERM, SIGHUP, the stop flag). Either way Stop is
//! sent, the host waits up to the drain timeout for Telemetry in the stopped state, and
//! `events.csv` says whether the device confirmed it (`stopped`) or not (`stop_unconfirmed`).

use super::flow::Run;
use super::port::Port;
use super::{Progress, StreamError};
use margemu_protocol::link::{DeviceState, Message};

impl<L: Port, P: FnMut(&Progress)> Run<'_, L, P> {
    /// Whether the device's last Telemetry says it has stopped.
    pub(super) fn device_stopped(&self) -> bool {
        self.reports
            .telemetry
            .is_some_and(|t| t.state == DeviceState::Stopped)
    }

    /// Logs whether the device confirmed Stop: `stopped` (with what it served) or
    /// `stop_unconfirmed`.
    pub(super) fn log_stop_outcome(&mut self) -> Result<(), StreamError> {
        match self.reports.telemetry {
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

    /// After an interruption: sends Stop (the device then holds its last sample instead of
    /// counting underruns), waits up to the drain timeout for the device to confirm it (the
    /// stop flag no longer counts), and logs the outcome. Errors are left to the session's
    /// `end` row: this is the best that can be done on the way out.
    pub(super) fn stop_after_interrupt(&mut self) {
        self.stop_sent = true;
        if self.send(&Message::Stop).is_err() {
            let _ = self.event("stop_unconfirmed", "Stop could not be written");
            return;
        }
        let deadline = self.now() + self.plan.drain_ns;
        while !self.device_stopped() && self.now() < deadline {
            if let Some(event) = self.port.wait(deadline) {
                if self.handle(event).is_err() {
                    break;
                }
            }
        }
        let _ = self.log_stop_outcome();
    }
}
