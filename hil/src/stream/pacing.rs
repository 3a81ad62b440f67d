//! Pacing: the prefill, the batches written in real time on the session's clock within the
//! device's credit window, and the Stop after the last sample's instant.
//!
//! Items (images, or kinematics in source mode model) are written in batches of the plan's size
//! ([`super::plan`]). The batch starting at item `j` is due at `start + t_j − lead`
//! ([`Plan::due`](super::plan::Plan::due)). The run waits for it through its port, handling
//! device messages meanwhile, and busy-waits the last `StreamConfig::spin` (200 µs) before it
//! ([`Port::spin_until`]). Stop: see [`Run::finish`].

use super::flow::Run;
use super::plan::Plan;
use super::port::Port;
use super::resend::GoBackN;
use super::served::{served_window, ServedCheck, MAX_WINDOW};
use super::window::Window;
use super::Progress;
use super::StreamError;
use margemu_protocol::link::{Message, Start};

/// Batches predicted beyond the next one to write.
const PREDICT_AHEAD: u64 = 2;

impl<L: Port, P: FnMut(&Progress)> Run<'_, L, P> {
    /// Sets the plan from the device's HelloAck ([`Plan::new`]: batch size and lead), and the
    /// windows of what the session keeps: the write times of the last `buffer_capacity`
    /// items and a batch (a go-back starts no earlier than the credit window, `limit −
    /// buffer_capacity`, and nothing was written at or beyond `limit`); the items themselves,
    /// predicted up to [`PREDICT_AHEAD`] batches beyond the next to write (so a go-back always
    /// finds them); the Served check's ([`served_window`], those predicted ahead counted as
    /// buffered).
    pub(super) fn plan_pacing(&mut self) {
        self.plan = Plan::new(self.session, self.reports.ack.as_ref());
        let (batch, capacity) = (self.plan.batch as usize, self.plan.capacity as usize);
        let ahead = PREDICT_AHEAD as usize * batch;
        let buffered = u32::try_from(capacity.saturating_add(ahead)).unwrap_or(u32::MAX);
        let hold = u32::try_from(self.plan.hold).unwrap_or(u32::MAX);
        self.served = ServedCheck::new(self.total(), served_window(buffered, hold));
        let items = capacity.saturating_add(batch).min(MAX_WINDOW);
        self.go_back = GoBackN::new(items);
        self.session.prediction.items = Window::new(items + ahead + batch);
    }

    /// Host time at which the batch starting at item `j` is due (`None` before Start).
    fn due(&self, j: u64) -> Option<u64> {
        Some(self.plan.due(self.start?, j))
    }

    /// Writes items `next .. next + n`. A batch `due` at an instant is logged with how late its
    /// write completed against it; for a `paced` one (not held back by credit, not a resend) the
    /// jitter figures keep how late the write started (the pacing) and completed (the port's
    /// share added).
    fn write_batch(&mut self, n: u64, due: Option<u64>, paced: bool) -> Result<(), StreamError> {
        let first = self.next;
        let resend = first < self.go_back.high();
        self.session.predict_through(first + n, &mut self.served)?;
        let started = self.now();
        let len = self
            .session
            .emit_batch(first, n, &mut self.encoder, &mut self.wire);
        self.write_wire(len)?;
        self.figures.link.batch_frames += 1;
        self.figures.link.batch_wire_bytes += len as u64;
        self.figures.link.item_bytes += n * self.session.item_len();
        let sent_at = self.now();
        let send_ns = Self::host_ns(sent_at);
        let late = |due: u64, at: u64| at.saturating_sub(due) as i64;
        let late_ns = due.map(|due| late(due, sent_at));
        self.go_back.written(first, n, send_ns);
        if let (Some(due), true) = (due, paced && !resend) {
            let late = |at: u64| late(due, at);
            self.figures.late.record(late(started));
            self.figures.written_late.record(late(sent_at));
            self.figures.max_late_ns = self.figures.max_late_ns.max(late(started));
        }
        self.next += n;
        let late_ns = late_ns.filter(|_| !resend);
        let logged = self.session.log_sent(first, n, send_ns, late_ns, resend);
        logged.map_err(self.log_err())
    }

    /// Prefill, Start, then every item at its due instant (and every go-back at once).
    pub(super) fn stream(&mut self) -> Result<(), StreamError> {
        let total = self.plan.stream_len;
        let lead_ns = self.plan.lead_ns;
        let rate = self.plan.item_rate;
        // Prefill: every item due at Start, within the first window.
        while self.next < total
            && rate.sample_time_ns(self.next) <= lead_ns
            && self.reports.credit.available(self.next) > 0
        {
            let n = self
                .plan
                .batch
                .min(self.reports.credit.available(self.next))
                .min(total - self.next);
            self.write_batch(n, None, false)?;
        }
        // The device serves samples 0..total and stops by itself at the scene's end.
        self.send(&Message::Start(Start::scene(0, self.total())))?;
        let start = self.now();
        self.start = Some(start);
        let start_ns = Self::host_ns(start);
        self.event(
            "start",
            &format!("start_host_ns {start_ns}; prefill {}", self.next),
        )?;
        let mut stall = None;
        while self.next < total {
            self.send_next(&mut stall)?;
        }
        Ok(())
    }

    /// Waits for the next item's instant (handling device messages meanwhile) and writes its
    /// batch, within the credit window; a go-back is written at once, up to where it left off.
    fn send_next(&mut self, stall: &mut Option<u64>) -> Result<(), StreamError> {
        let total = self.plan.stream_len;
        self.report(false);
        // Predicted ahead while there is time, so a due batch never waits for its prediction.
        let ahead = (self.next + PREDICT_AHEAD * self.plan.batch).min(total);
        self.session.predict_through(ahead, &mut self.served)?;
        let due = self.due(self.next).expect("started");
        let spin = self.plan.spin_ns;
        if self.now() + spin < due {
            return self.pump(due - spin);
        }
        self.port.spin_until(due);
        // The batch goes out first; device messages wait, unless the window is short.
        let wanted = self.plan.batch.min(total - self.next);
        if self.reports.credit.available(self.next) < wanted {
            self.handle_waiting()?;
        }
        let available = self.reports.credit.available(self.next);
        if available == 0 {
            let now = self.now();
            let since = *stall.get_or_insert_with(|| {
                self.figures.credit_stalls += 1;
                now
            });
            let timeout = self.plan.credit_timeout;
            let limit = since + timeout.as_nanos() as u64;
            if now >= limit {
                return Err(StreamError::CreditTimeout {
                    index: self.next,
                    timeout,
                });
            }
            return self.pump(limit);
        }
        // A batch held back by the credit window is late because of the device, not of the
        // pacing: logged, but left out of the jitter figures.
        let paced = stall.take().is_none();
        let mut n = self.plan.batch.min(available).min(total - self.next);
        if self.next < self.go_back.high() {
            n = n.min(self.go_back.high() - self.next);
        }
        self.write_batch(n, Some(due), paced)
    }

    /// Waits until the device reports serving sample `last` (a Served entry or a Telemetry), or
    /// `deadline`.
    fn await_served(&mut self, last: u64, deadline: u64) -> Result<(), StreamError> {
        let served = |run: &Self| {
            run.served.stats().last_index >= Some(last)
                || run
                    .reports
                    .telemetry
                    .is_some_and(|t| t.samples_served > 0 && t.last_served_index >= last)
        };
        while !served(self) && self.now() < deadline {
            self.pump(deadline)?;
        }
        Ok(())
    }

    /// Sends Stop half an output period after the last sample's instant, on the session's clock
    /// ([`Plan::stop_at`]).
    /// The device stops by itself at the scene's end (Start's `end_index`), so it never serves
    /// an instant after the last sample, however late Stop arrives; Stop confirms that. In
    /// source images a Stop that arrives early is graceful (the device serves what it still
    /// holds). In source model it stops at once, and the device's clock lags the host's by the
    /// Start's delivery time, so the host first waits until the device reports serving the last
    /// sample. Then it waits for Telemetry in the stopped state.
    pub(super) fn finish(&mut self) -> Result<(), StreamError> {
        let drain = self.plan.drain_ns;
        let spin = self.plan.spin_ns;
        let stop_at = self.start.and_then(|start| self.plan.stop_at(start));
        if let Some(stop_at) = stop_at {
            let mut stall = None;
            while self.now() + spin < stop_at {
                if self.next < self.plan.stream_len {
                    self.send_next(&mut stall)?; // a go-back
                    continue;
                }
                self.report(false);
                self.pump(stop_at - spin)?;
            }
            self.port.spin_until(stop_at);
            if self.plan.stops_at_once {
                let last = self.total() - 1;
                self.await_served(last, self.now() + drain)?;
            }
        }
        self.stop_sent = true;
        self.send(&Message::Stop)?;
        let deadline = self.now() + drain;
        while self.now() < deadline && !self.device_stopped() {
            self.pump(deadline)?;
        }
        self.report(true);
        self.log_stop_outcome()
    }
}
