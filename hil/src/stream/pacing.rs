//! Pacing: the prefill, the batches written in real time on the host's monotonic clock within
//! the device's credit window, and the Stop after the last sample's instant.
//!
//! Items (images, or kinematics in source mode model) are written in batches of up to
//! `StreamConfig::batch`, capped by the frame, by the device's `max_batch` and by a quarter of
//! its buffer. The batch starting at item `j` is due at `start + t_j − lead`, where the lead is
//! `StreamConfig::lead` capped at 3/8 of the device's buffer (so a due batch normally finds the
//! credit it needs: the device grants its window a quarter of its buffer at a time). The last
//! 200 µs before a due instant are busy-waited. Stop: see [`Run::finish`].

use super::flow::Run;
use super::resend::GoBackN;
use super::served::{served_window, ServedCheck, MAX_WINDOW};
use super::window::Window;
use super::Progress;
use super::StreamError;
use margemu_protocol::link::{DeviceState, Message, Start};
use std::io::Write;
use std::time::{Duration, Instant};

/// Batches predicted beyond the next one to write.
const PREDICT_AHEAD: u64 = 2;

impl<W: Write, P: FnMut(&Progress)> Run<'_, W, P> {
    /// Sets the batch size and the lead from the device's HelloAck (see the module docs), and
    /// the windows of what the session keeps: the write times of the last `buffer_capacity`
    /// items and a batch (a go-back starts no earlier than the credit window, `limit −
    /// buffer_capacity`, and nothing was written at or beyond `limit`); the items themselves,
    /// predicted up to [`PREDICT_AHEAD`] batches beyond the next to write (so a go-back always
    /// finds them); the Served check's ([`served_window`], those predicted ahead counted as
    /// buffered).
    pub(super) fn plan_pacing(&mut self) {
        let (max_batch, capacity) = self.ack.map_or((1, 4), |a| {
            let c = a.capabilities;
            (usize::from(c.max_batch), c.buffer_capacity as usize)
        });
        let batch = self
            .session
            .config
            .batch
            .min(max_batch)
            .min(self.session.max_per_frame())
            .min(capacity / 4)
            .max(1);
        let window = self
            .session
            .item_rate()
            .sample_time_ns(3 * capacity as u64 / 8);
        self.batch = batch as u64;
        self.lead = self.session.config.lead.min(Duration::from_nanos(window));
        let ahead = PREDICT_AHEAD as usize * batch;
        let buffered = u32::try_from(capacity.saturating_add(ahead)).unwrap_or(u32::MAX);
        let hold = u32::try_from(self.session.hold()).unwrap_or(u32::MAX);
        self.served = ServedCheck::new(self.total(), served_window(buffered, hold));
        let items = capacity.saturating_add(batch).min(MAX_WINDOW);
        self.go_back = GoBackN::new(items);
        self.session.prediction.items = Window::new(items + ahead + batch);
    }

    /// The instant the batch starting at item `j` is due (`None` before Start).
    fn due(&self, j: u64) -> Option<Instant> {
        let t = Duration::from_nanos(self.session.item_rate().sample_time_ns(j));
        let start = self.start?;
        Some(
            (start + t)
                .checked_sub(self.lead)
                .unwrap_or(start)
                .max(start),
        )
    }

    /// Writes items `next .. next + n`. A batch `due` at an instant is logged with how late its
    /// write completed against it; for a `paced` one (not held back by credit, not a resend) the
    /// jitter figures keep how late the write started (the pacing) and completed (the port's
    /// share added).
    fn write_batch(
        &mut self,
        n: u64,
        due: Option<Instant>,
        paced: bool,
    ) -> Result<(), StreamError> {
        let first = self.next;
        let resend = first < self.go_back.high();
        self.session.predict_through(first + n, &mut self.served)?;
        let started = Instant::now();
        let len = self
            .session
            .emit_batch(first, n, &mut self.encoder, &mut self.wire);
        self.write_wire(len)?;
        self.link.batch_frames += 1;
        self.link.batch_wire_bytes += len as u64;
        self.link.item_bytes += n * self.session.item_len();
        let sent_at = Instant::now();
        let send_ns = self.host_ns(sent_at);
        let late_ns = due.map(|due| sent_at.saturating_duration_since(due).as_nanos() as i64);
        self.go_back.written(first, n, send_ns);
        if let (Some(due), true) = (due, paced && !resend) {
            let late = |at: Instant| at.saturating_duration_since(due).as_nanos() as i64;
            self.late.record(late(started));
            self.written_late.record(late(sent_at));
            self.max_late_ns = self.max_late_ns.max(late(started));
        }
        self.next += n;
        let late_ns = late_ns.filter(|_| !resend);
        let logged = self.session.log_sent(first, n, send_ns, late_ns, resend);
        logged.map_err(self.log_err())
    }

    /// Prefill, Start, then every item at its due instant (and every go-back at once).
    pub(super) fn stream(&mut self) -> Result<(), StreamError> {
        let total = self.session.stream_len();
        let lead_ns = self.lead.as_nanos() as u64;
        let rate = self.session.item_rate();
        // Prefill: every item due at Start, within the first window.
        while self.next < total
            && rate.sample_time_ns(self.next) <= lead_ns
            && self.credit.available(self.next) > 0
        {
            let n = self
                .batch
                .min(self.credit.available(self.next))
                .min(total - self.next);
            self.write_batch(n, None, false)?;
        }
        // The device serves samples 0..total and stops by itself at the scene's end.
        self.send(&Message::Start(Start::scene(0, self.total())))?;
        let start = Instant::now();
        self.start = Some(start);
        let start_ns = self.host_ns(start);
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
    fn send_next(&mut self, stall: &mut Option<Instant>) -> Result<(), StreamError> {
        let total = self.session.stream_len();
        self.report(false);
        // Predicted ahead while there is time, so a due batch never waits for its prediction.
        let ahead = (self.next + PREDICT_AHEAD * self.batch).min(total);
        self.session.predict_through(ahead, &mut self.served)?;
        let due = self.due(self.next).expect("started");
        let spin = self.session.config.spin;
        if Instant::now() + spin < due {
            return self.pump(due - spin);
        }
        while Instant::now() < due {
            std::hint::spin_loop();
        }
        // The batch goes out first; device messages wait, unless the window is short.
        let wanted = self.batch.min(total - self.next);
        if self.credit.available(self.next) < wanted {
            while let Ok(event) = self.events.try_recv() {
                self.handle(event)?;
            }
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
            return self.pump(limit);
        }
        // A batch held back by the credit window is late because of the device, not of the
        // pacing: logged, but left out of the jitter figures.
        let paced = stall.take().is_none();
        let mut n = self.batch.min(available).min(total - self.next);
        if self.next < self.go_back.high() {
            n = n.min(self.go_back.high() - self.next);
        }
        self.write_batch(n, Some(due), paced)
    }

    /// Waits until the device reports serving sample `last` (a Served entry or a Telemetry), or
    /// `deadline`.
    fn await_served(&mut self, last: u64, deadline: Instant) -> Result<(), StreamError> {
        let served = |run: &Self| {
            run.served.stats().last_index >= Some(last)
                || run
                    .telemetry
                    .is_some_and(|t| t.samples_served > 0 && t.last_served_index >= last)
        };
        while !served(self) && Instant::now() < deadline {
            self.pump(deadline)?;
        }
        Ok(())
    }

    /// Sends Stop half an output period after the last sample's instant, on the host's clock.
    /// The device stops by itself at the scene's end (Start's `end_index`), so it never serves
    /// an instant after the last sample, however late Stop arrives; Stop confirms that. In
    /// source images a Stop that arrives early is graceful (the device serves what it still
    /// holds). In source model it stops at once, and the device's clock lags the host's by the
    /// Start's delivery time, so the host first waits until the device reports serving the last
    /// sample. Then it waits for Telemetry in the stopped state.
    pub(super) fn finish(&mut self) -> Result<(), StreamError> {
        let total = self.total();
        let drain = self.session.config.drain_timeout;
        if let (Some(start), Some(last)) = (self.start, total.checked_sub(1)) {
            let rate = self.session.rate;
            let (t_last, t_next) = (rate.sample_time_ns(last), rate.sample_time_ns(total));
            let stop_at = start + Duration::from_nanos(t_last + (t_next - t_last) / 2);
            let mut stall = None;
            while Instant::now() + self.session.config.spin < stop_at {
                if self.next < self.session.stream_len() {
                    self.send_next(&mut stall)?; // a go-back
                    continue;
                }
                self.report(false);
                self.pump(stop_at - self.session.config.spin)?;
            }
            while Instant::now() < stop_at {
                std::hint::spin_loop();
            }
            if self.session.stops_at_once() {
                self.await_served(last, Instant::now() + drain)?;
            }
        }
        self.stop_sent = true;
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
        self.log_stop_outcome()
    }
}
