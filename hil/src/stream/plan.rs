//! [`Plan`]: everything a streaming session keeps fixed once the device has answered Hello (the
//! scene's counts and rates, the batch size and lead the device's capabilities allow, the
//! windows of what the session keeps, the timeouts), set once by the run (`flow.rs`) and never
//! changed; the run's mutable state lives in its parts (`pacing.rs`, `reports.rs`,
//! `ending.rs`).
//!
//! Items are written in batches of up to `StreamConfig::batch`, capped by the frame, by the
//! device's `max_batch` and by a quarter of its buffer. The lead is `StreamConfig::lead` capped
//! at 3/8 of the device's buffer (so a due batch normally finds the credit it needs: the device
//! grants its window a quarter of its buffer at a time).
//!
//! What the session keeps is bounded by the device's buffer: the write times of the last
//! `buffer_capacity` items and a batch (a go-back starts no earlier than the credit window,
//! `limit − buffer_capacity`, and nothing was written at or beyond `limit`); the items
//! themselves, predicted up to [`PREDICT_AHEAD`] batches beyond the next to write (so a go-back
//! always finds them); the Served check's window ([`served_window`], the items predicted ahead
//! counted as buffered).

use super::served::{served_window, MAX_WINDOW};
use super::session::StreamConfig;
use super::source::Source;
use margemu_protocol::link::{HelloAck, Rate};
use std::time::Duration;

/// Batches predicted beyond the next one to write.
const PREDICT_AHEAD: u64 = 2;

/// The fixed parameters of a session (see the module docs). Times are ns.
#[derive(Clone, Copy, Debug)]
pub(super) struct Plan {
    /// Output samples in the scene.
    samples: u64,
    /// Items to stream (output samples, or kinematics samples in source model).
    stream_len: u64,
    /// The scene's output rate.
    rate: Rate,
    /// The rate of the items.
    item_rate: Rate,
    /// Output samples per item.
    hold: u64,
    /// The device stops at once on Stop (source model) rather than serving what it holds.
    stops_at_once: bool,
    /// Items per batch.
    batch: u64,
    /// How far ahead of its first item's instant a batch is due.
    lead_ns: u64,
    /// The device's buffer, items (0 before the handshake).
    capacity: u64,
    /// The last stretch before a due instant that is busy-waited.
    spin_ns: u64,
    /// The session number sent in Hello.
    session_id: u32,
    /// How long to wait for HelloAck and for the first credit window.
    hello_timeout: Duration,
    /// How long a due batch may wait for credit.
    credit_timeout: Duration,
    /// How long to wait for the last sample served and for the Stop confirmed.
    drain_ns: u64,
    /// How long after its last write an item the device reports lost may be written again.
    resend_after_ns: u64,
}

impl Plan {
    /// The plan before the device has answered: one item per batch, no lead, no buffer.
    pub(super) fn before_handshake(source: &Source, c: &StreamConfig) -> Self {
        let ns = |d: Duration| d.as_nanos() as u64;
        Self {
            samples: source.samples(),
            stream_len: source.stream_len(),
            rate: source.rate(),
            item_rate: source.item_rate(),
            hold: source.hold(),
            stops_at_once: source.stops_at_once(),
            batch: 1,
            lead_ns: 0,
            capacity: 0,
            spin_ns: ns(c.spin),
            session_id: c.session_id,
            hello_timeout: c.hello_timeout,
            credit_timeout: c.credit_timeout,
            drain_ns: ns(c.drain_timeout),
            resend_after_ns: ns(c.resend_after),
        }
    }

    /// The plan for a device that answered `ack` (a device without one is planned as one of
    /// batch 1 and buffer 4).
    pub(super) fn new(source: &Source, config: &StreamConfig, ack: Option<&HelloAck>) -> Self {
        let (max_batch, capacity) = ack.map_or((1, 4), |a| {
            let c = a.capabilities;
            (usize::from(c.max_batch), c.buffer_capacity as usize)
        });
        let batch = config
            .batch
            .min(max_batch)
            .min(source.max_per_frame())
            .min(capacity / 4)
            .max(1);
        let window = source.item_rate().sample_time_ns(3 * capacity as u64 / 8);
        let lead = config.lead.min(Duration::from_nanos(window));
        Self {
            batch: batch as u64,
            lead_ns: lead.as_nanos() as u64,
            capacity: capacity as u64,
            ..Self::before_handshake(source, config)
        }
    }

    /// Host time at which the batch starting at item `j` is due, for a Start written at host
    /// time `start`: `start + t_j − lead`, never before `start`.
    pub(super) fn due(&self, start: u64, j: u64) -> u64 {
        let t = self.item_rate.sample_time_ns(j);
        (start + t).saturating_sub(self.lead_ns).max(start)
    }

    /// Output samples in the scene.
    pub(super) fn samples(&self) -> u64 {
        self.samples
    }

    /// Items to stream (output samples, or kinematics samples in source model).
    pub(super) fn stream_len(&self) -> u64 {
        self.stream_len
    }

    /// The scene's output rate.
    pub(super) fn rate(&self) -> Rate {
        self.rate
    }

    /// Whether item `j` is due at Start: its instant is within the lead.
    pub(super) fn due_at_start(&self, j: u64) -> bool {
        self.item_rate.sample_time_ns(j) <= self.lead_ns
    }

    /// Whether the device stops at once on Stop (source model).
    pub(super) fn stops_at_once(&self) -> bool {
        self.stops_at_once
    }

    /// Items per batch.
    pub(super) fn batch(&self) -> u64 {
        self.batch
    }

    /// How far ahead of its first item's instant a batch is due.
    pub(super) fn lead(&self) -> Duration {
        Duration::from_nanos(self.lead_ns)
    }

    /// The device's buffer, items (0 before the handshake).
    pub(super) fn capacity(&self) -> u64 {
        self.capacity
    }

    /// The last stretch before a due instant that is busy-waited, ns.
    pub(super) fn spin_ns(&self) -> u64 {
        self.spin_ns
    }

    /// The session number sent in Hello.
    pub(super) fn session_id(&self) -> u32 {
        self.session_id
    }

    /// How long to wait for HelloAck and for the first credit window.
    pub(super) fn hello_timeout(&self) -> Duration {
        self.hello_timeout
    }

    /// How long a due batch may wait for credit.
    pub(super) fn credit_timeout(&self) -> Duration {
        self.credit_timeout
    }

    /// How long to wait for the last sample served and for the Stop confirmed, ns.
    pub(super) fn drain_ns(&self) -> u64 {
        self.drain_ns
    }

    /// How long after its last write an item the device reports lost may be written again, ns.
    pub(super) fn resend_after_ns(&self) -> u64 {
        self.resend_after_ns
    }

    /// Items predicted beyond the next one to write.
    pub(super) fn ahead(&self) -> u64 {
        PREDICT_AHEAD * self.batch
    }

    /// How many of the newest items' write times are kept (what a go-back can reach).
    pub(super) fn write_times_kept(&self) -> usize {
        let (batch, capacity) = (self.batch as usize, self.capacity as usize);
        capacity.saturating_add(batch).min(MAX_WINDOW)
    }

    /// How many of the newest items are kept: those a go-back can reach, those predicted ahead
    /// and a batch.
    pub(super) fn items_kept(&self) -> usize {
        let batch = self.batch as usize;
        self.write_times_kept() + PREDICT_AHEAD as usize * batch + batch
    }

    /// How many predictions the Served check keeps ([`served_window`]).
    pub(super) fn served_window(&self) -> usize {
        let buffered =
            (self.capacity as usize).saturating_add(PREDICT_AHEAD as usize * self.batch as usize);
        let buffered = u32::try_from(buffered).unwrap_or(u32::MAX);
        let hold = u32::try_from(self.hold).unwrap_or(u32::MAX);
        served_window(buffered, hold)
    }

    /// Host time at which Stop is due, for a Start written at host time `start`: half an output
    /// period after the last sample's instant (`None` for an empty scene).
    pub(super) fn stop_at(&self, start: u64) -> Option<u64> {
        let last = self.samples.checked_sub(1)?;
        let (t_last, t_next) = (
            self.rate.sample_time_ns(last),
            self.rate.sample_time_ns(self.samples),
        );
        Some(start + t_last + (t_next - t_last) / 2)
    }
}

#[cfg(test)]
impl Plan {
    /// A plan for unit tests: `samples` images at `rate`, batches of 32, a 96 ms lead, a
    /// buffer of 256, a credit timeout of 2 s, no spin and no resend margin.
    pub(super) fn example(samples: u64, rate: Rate) -> Self {
        Self {
            samples,
            stream_len: samples,
            rate,
            item_rate: rate,
            hold: 1,
            stops_at_once: false,
            batch: 32,
            lead_ns: 96_000_000,
            capacity: 256,
            spin_ns: 0,
            session_id: 0,
            hello_timeout: Duration::ZERO,
            credit_timeout: Duration::from_secs(2),
            drain_ns: 0,
            resend_after_ns: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(samples: u64, rate: Rate) -> Plan {
        Plan::example(samples, rate)
    }

    #[test]
    fn batches_are_due_a_lead_ahead_and_never_before_start() {
        let p = plan(1000, Rate::new(1000, 1).unwrap());
        assert_eq!(p.due(5, 0), 5);
        assert_eq!(p.due(5, 96), 5);
        assert_eq!(p.due(5, 97), 5 + 1_000_000);
        assert_eq!(p.due(5, 200), 5 + 104_000_000);
    }

    #[test]
    fn stop_is_due_half_a_period_after_the_last_instant() {
        assert_eq!(
            plan(1000, Rate::new(1000, 1).unwrap()).stop_at(5),
            Some(5 + 999_500_000)
        );
        // 3 Hz: instants 0, 333 333 333, 666 666 666 ns, then 1 s.
        assert_eq!(
            plan(3, Rate::new(3, 1).unwrap()).stop_at(0),
            Some(833_333_333)
        );
        assert_eq!(plan(0, Rate::new(3, 1).unwrap()).stop_at(0), None);
    }
}
