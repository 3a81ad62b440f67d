//! [`Pacing`]: which items to write and when, and what the run measured of its own writes.
//!
//! Items (images, or kinematics in source mode model) are written in batches of the plan's size
//! ([`super::plan`]): first the prefill (every item due at Start, within the first credit
//! window, [`Pacing::prefill`]), then, after Start, the batch starting at item `j` at
//! `start + t_j − lead` ([`Pacing::due`], [`Plan::due`](super::plan::Plan::due)), never beyond
//! the device's credit window ([`Pacing::step`]: a batch that finds no credit stalls, and the
//! session gives up after the credit timeout). A Telemetry that shows an item lost sends the
//! pacing back to it ([`Pacing::check_lost`], [`super::resend`]); the go-back is written at
//! once, up to where it left off.
//!
//! The pacing decides and counts; the run (`flow.rs`) waits, handles device messages meanwhile
//! and writes: it waits through its port and busy-waits the last `StreamConfig::spin` (200 µs)
//! before a due instant ([`Port::spin_until`](super::port::Port::spin_until)).

use super::plan::Plan;
use super::resend::GoBackN;
use super::{JitterStats, Lateness, LinkStats, StreamError};
use margemu_protocol::link::{DeviceState, Telemetry};

/// What to do about the next item once its instant has come.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Step {
    /// Write the batch of `n` items from [`Pacing::next`]; `paced`: it was not held back by
    /// the credit window, so it counts in the jitter figures.
    Write {
        /// Items in the batch.
        n: u64,
        /// Not held back by credit.
        paced: bool,
    },
    /// No credit: wait for device messages until this host time (the credit timeout).
    Stalled(u64),
}

/// The pacing state of a run (see the module docs).
pub(super) struct Pacing {
    /// The next item to write.
    next: u64,
    /// When each recent item was last written (its window set by the plan); the go-backs.
    go_back: GoBackN,
    /// When Start was written, host ns: scene time 0.
    start: Option<u64>,
    /// Since when a due batch has been waiting for credit, host ns.
    stall: Option<u64>,
    /// How late the paced batches' writes started.
    late: Lateness,
    /// How late the same writes completed.
    written_late: Lateness,
    max_late_ns: i64,
    /// Times a due batch had to wait for credit.
    credit_stalls: u64,
    /// Bytes written to the port: all, and those of sample batches with their item bytes.
    link: LinkStats,
}

impl Pacing {
    /// Nothing written yet.
    pub(super) fn new() -> Self {
        Self {
            next: 0,
            go_back: GoBackN::new(1),
            start: None,
            stall: None,
            late: Lateness::default(),
            written_late: Lateness::default(),
            max_late_ns: 0,
            credit_stalls: 0,
            link: LinkStats::default(),
        }
    }

    /// Keeps the write times the plan set from the HelloAck asks for
    /// ([`Plan::write_times_kept`]), before anything is written.
    pub(super) fn plan(&mut self, plan: &Plan) {
        self.go_back = GoBackN::new(plan.write_times_kept());
    }

    /// The next item to write.
    pub(super) fn next(&self) -> u64 {
        self.next
    }

    /// Whether items remain to be written (a go-back included).
    pub(super) fn has_next(&self, plan: &Plan) -> bool {
        self.next < plan.stream_len()
    }

    /// Whether the next item was written before (a go-back).
    pub(super) fn resending(&self) -> bool {
        self.next < self.go_back.high()
    }

    /// The items to predict before the next batch is due: up to [`Plan::ahead`] beyond the
    /// next to write.
    pub(super) fn predict_to(&self, plan: &Plan) -> u64 {
        (self.next + plan.ahead()).min(plan.stream_len())
    }

    /// The next prefill batch's size while `available` items of credit remain (`None`: the
    /// prefill is done): the items due at Start, within the credit window.
    pub(super) fn prefill(&self, plan: &Plan, available: u64) -> Option<u64> {
        let total = plan.stream_len();
        let due = self.next < total && plan.due_at_start(self.next);
        (due && available > 0).then(|| plan.batch().min(available).min(total - self.next))
    }

    /// Start was written at host time `at`.
    pub(super) fn started(&mut self, at: u64) {
        self.start = Some(at);
    }

    /// When Start was written, host ns.
    pub(super) fn start(&self) -> Option<u64> {
        self.start
    }

    /// Host time at which the next batch is due (`None` before Start).
    pub(super) fn due(&self, plan: &Plan) -> Option<u64> {
        Some(plan.due(self.start?, self.next))
    }

    /// The items the next batch would carry with all the credit it needs.
    pub(super) fn wanted(&self, plan: &Plan) -> u64 {
        plan.batch().min(plan.stream_len() - self.next)
    }

    /// What to do at host time `now`, once the next batch's instant has come, with `available`
    /// items of credit: write it (a go-back up to where it left off), or wait for credit (a
    /// credit stall). Fails once the batch has waited the credit timeout.
    pub(super) fn step(
        &mut self,
        plan: &Plan,
        available: u64,
        now: u64,
    ) -> Result<Step, StreamError> {
        if available == 0 {
            let since = *self.stall.get_or_insert_with(|| {
                self.credit_stalls += 1;
                now
            });
            let timeout = plan.credit_timeout();
            let limit = since + timeout.as_nanos() as u64;
            if now >= limit {
                return Err(StreamError::CreditTimeout {
                    index: self.next,
                    timeout,
                });
            }
            return Ok(Step::Stalled(limit));
        }
        // A batch held back by the credit window is late because of the device, not of the
        // pacing: logged, but left out of the jitter figures.
        let paced = self.stall.take().is_none();
        let mut n = plan
            .batch()
            .min(available)
            .min(plan.stream_len() - self.next);
        if self.resending() {
            n = n.min(self.go_back.high() - self.next);
        }
        Ok(Step::Write { n, paced })
    }

    /// A frame of `len` bytes was written.
    pub(super) fn wrote(&mut self, len: usize) {
        self.link.wire_bytes += len as u64;
    }

    /// The frame written last, of `len` bytes, was a batch carrying `item_bytes`.
    pub(super) fn wrote_batch(&mut self, len: usize, item_bytes: u64) {
        self.link.batch_frames += 1;
        self.link.batch_wire_bytes += len as u64;
        self.link.item_bytes += item_bytes;
    }

    /// The batch of the next `n` items was written: its write started at host time `started`
    /// and completed at `sent_at`. A batch `due` at an instant gets how late its write
    /// completed against it (`None` for a resend: what the log says); for a `paced` one (not
    /// held back by credit, not a resend) the jitter figures keep how late the write started
    /// (the pacing) and completed (the port's share added).
    pub(super) fn written(
        &mut self,
        n: u64,
        due: Option<u64>,
        paced: bool,
        started: u64,
        sent_at: u64,
    ) -> Option<i64> {
        let resend = self.resending();
        let late = |due: u64, at: u64| at.saturating_sub(due) as i64;
        let late_ns = due.map(|due| late(due, sent_at));
        self.go_back.written(self.next, n, sent_at as i64);
        if let (Some(due), true) = (due, paced && !resend) {
            let late = |at: u64| late(due, at);
            self.late.record(late(started));
            self.written_late.record(late(sent_at));
            self.max_late_ns = self.max_late_ns.max(late(started));
        }
        self.next += n;
        late_ns.filter(|_| !resend)
    }

    /// Goes back to the device's `next_index` if its Telemetry `t` shows that item lost: the
    /// device holds items beyond it, which a FIFO line delivered after it (or, once every item
    /// was written, nothing more is coming), and it was last written long enough before the
    /// report (see [`super::resend`]). Returns the `events.csv` row to log (`resend`, or
    /// `resend_out_of_window` for an item older than the write times kept).
    pub(super) fn check_lost(
        &mut self,
        plan: &Plan,
        t: &Telemetry,
    ) -> Option<(&'static str, String)> {
        let contiguous = t
            .next_index
            .saturating_sub(t.credit_limit.saturating_sub(plan.capacity()));
        let all_written = self.go_back.high() == plan.stream_len();
        let beyond = u64::from(t.buffer_level) > contiguous || all_written;
        let running = t.state == DeviceState::Running;
        let (Some(start), true, true) = (self.start, running, beyond) else {
            return None;
        };
        let (next_index, tau) = (t.next_index, t.time_ns);
        let margin = plan.resend_after_ns() as i64;
        let seen_by = start as i64 + tau as i64 - margin;
        match self.go_back.lost(next_index, seen_by) {
            Some(hole) if hole < self.next => {
                let detail = format!(
                    "device next_index {hole} at its scene time {tau} ns, {} items buffered; going back from {}",
                    t.buffer_level, self.next
                );
                self.next = hole;
                self.go_back.rewound();
                Some(("resend", detail))
            }
            None if next_index < self.next && self.go_back.forgotten(next_index) => {
                let detail = format!(
                    "device next_index {next_index} at its scene time {tau} ns is older than the \
                     items kept (from {}): not resent",
                    self.go_back.forgotten_below()
                );
                Some(("resend_out_of_window", detail))
            }
            _ => None,
        }
    }

    /// Items written at least once.
    pub(super) fn sent(&self) -> u64 {
        self.go_back.high()
    }

    /// Go-backs so far.
    pub(super) fn rewinds(&self) -> u64 {
        self.go_back.rewinds()
    }

    /// Items written more than once so far.
    pub(super) fn resent(&self) -> u64 {
        self.go_back.resent()
    }

    /// How late the last paced batch's write started, ns.
    pub(super) fn last_late_ns(&self) -> i64 {
        self.late.last_ns()
    }

    /// The latest a paced batch's write started so far, ns.
    pub(super) fn max_late_ns(&self) -> i64 {
        self.max_late_ns
    }

    /// How late the paced batches' writes started.
    pub(super) fn jitter(&self) -> JitterStats {
        self.late.stats()
    }

    /// How late the paced batches' writes completed.
    pub(super) fn written_jitter(&self) -> JitterStats {
        self.written_late.stats()
    }

    /// Times a due batch had to wait for credit.
    pub(super) fn credit_stalls(&self) -> u64 {
        self.credit_stalls
    }

    /// Bytes written.
    pub(super) fn link(&self) -> LinkStats {
        self.link
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_protocol::link::Rate;

    fn plan() -> Plan {
        Plan::example(1000, Rate::new(1000, 1).unwrap()) // batches of 32, 96 ms lead
    }

    #[test]
    fn the_prefill_takes_the_items_due_at_start_within_the_credit() {
        let (plan, mut p) = (plan(), Pacing::new());
        assert_eq!(p.prefill(&plan, 0), None, "no credit");
        assert_eq!(p.prefill(&plan, 20), Some(20));
        for _ in 0..3 {
            assert_eq!(p.prefill(&plan, 1000), Some(32));
            p.written(32, None, false, 0, 0);
        }
        assert_eq!(
            p.prefill(&plan, 1000),
            Some(32),
            "item 96 is due at 96 ms: the lead"
        );
        p.written(32, None, false, 0, 0);
        assert_eq!(p.prefill(&plan, 1000), None, "item 128 is not");
        assert_eq!(p.jitter().batches, 0, "the prefill is not paced");
    }

    #[test]
    fn a_batch_without_credit_stalls_until_the_credit_timeout() {
        let (plan, mut p) = (plan(), Pacing::new());
        p.started(5);
        assert_eq!(p.due(&plan), Some(5));
        let timeout = 2_000_000_000;
        assert_eq!(p.step(&plan, 0, 10).unwrap(), Step::Stalled(10 + timeout));
        assert_eq!(p.step(&plan, 0, 20).unwrap(), Step::Stalled(10 + timeout));
        assert_eq!(p.credit_stalls(), 1, "one stall, however long");
        let held = p.step(&plan, 8, 30).unwrap();
        assert_eq!(held, Step::Write { n: 8, paced: false });
        assert_eq!(
            p.step(&plan, 100, 40).unwrap(),
            Step::Write { n: 32, paced: true }
        );
        p.step(&plan, 0, 50).unwrap();
        let err = p.step(&plan, 0, 50 + timeout).unwrap_err();
        assert!(
            matches!(err, StreamError::CreditTimeout { index: 0, .. }),
            "{err}"
        );
    }

    #[test]
    fn paced_batches_keep_how_late_they_were_written() {
        let (plan, mut p) = (plan(), Pacing::new());
        p.started(0);
        assert_eq!(p.written(32, Some(100), true, 150, 400), Some(300));
        assert_eq!(p.written(32, Some(200), false, 900, 1000), Some(800));
        let j = p.jitter();
        assert_eq!((j.batches, j.max_ns, p.max_late_ns()), (1, 50, 50));
        assert_eq!(p.written_jitter().max_ns, 300);
        assert_eq!((p.next(), p.sent(), p.has_next(&plan)), (64, 64, true));
    }
}
