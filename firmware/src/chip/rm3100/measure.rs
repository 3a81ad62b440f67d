//! The measurement schedule (DS §5.2, §5.3, §5.6.1): single measurements, continuous sequences
//! and the self test, completed axis by axis as the clock moves.

use margemu_protocol::regmap::rm3100::{self as map, bits};

use super::{Held, Rm3100};

/// What the chip is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Run {
    /// Nothing: idle mode.
    Idle,
    /// A single measurement (POLL).
    Single(Sequence),
    /// A self test (POLL with BIST.STE) of `axes`, done at `done_at`.
    SelfTest { done_at: u64, axes: u8 },
    /// Continuous measurements: `seq` is the current sequence, one every `period`.
    Continuous { seq: Sequence, period: u64 },
}

impl Run {
    /// Whether a POLL-started measurement or self test is in progress.
    pub(super) fn is_single(&self) -> bool {
        matches!(self, Self::Single(_) | Self::SelfTest { .. })
    }
}

/// One measurement of the axes in turn (x, then y, then z), with the cycle counts it started
/// with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Sequence {
    start: u64,
    axes: u8,
    done: u8,
    cycle_counts: [u16; 3],
}

impl Sequence {
    fn new(start: u64, axes: u8, cycle_counts: [u16; 3]) -> Self {
        Self {
            start,
            axes,
            done: 0,
            cycle_counts,
        }
    }

    /// The next axis to complete and when it completes.
    fn next(&self) -> Option<(usize, u64)> {
        let mut t = self.start;
        for (i, &cc) in self.cycle_counts.iter().enumerate() {
            if self.axes & (1 << i) == 0 {
                continue;
            }
            t = t.saturating_add(map::axis_measurement_ns(cc));
            if self.done & (1 << i) == 0 {
                return Some((i, t));
            }
        }
        None
    }

    fn complete(&self) -> bool {
        self.done == self.axes
    }

    /// The same measurement started `periods` × `period` later.
    fn later(&self, periods: u64, period: u64) -> Self {
        let start = self.start.saturating_add(periods.saturating_mul(period));
        Self::new(start, self.axes, self.cycle_counts)
    }
}

impl Rm3100 {
    /// Completes every axis measurement and self test due at or before `limit`.
    pub(super) fn run_until(&mut self, limit: u64) {
        // Each pass completes one axis or returns; continuous mode skips whole sequences first,
        // so a long step costs a few passes.
        loop {
            match self.run {
                Run::Idle => return,
                Run::SelfTest { done_at, axes } => {
                    if done_at <= limit {
                        self.bist_ok = (axes << 4) & bits::BIST_OK;
                        self.drdy = true; // the results stay as they were
                        self.run = Run::Idle;
                    }
                    return;
                }
                Run::Single(mut seq) => {
                    let Some((axis, t)) = seq.next() else {
                        self.run = Run::Idle;
                        return;
                    };
                    if t > limit {
                        return;
                    }
                    self.latch_axis(axis, &seq);
                    seq.done |= 1 << axis;
                    self.run = if seq.complete() {
                        self.publish();
                        Run::Idle
                    } else {
                        Run::Single(seq)
                    };
                }
                Run::Continuous { mut seq, period } => {
                    let behind = limit.saturating_sub(seq.start) / period.max(1);
                    if behind >= 2 {
                        // Sequences before the last complete one would be overwritten unread.
                        seq = seq.later(behind - 1, period);
                    }
                    let Some((axis, t)) = seq.next() else {
                        self.run = Run::Idle;
                        return;
                    };
                    if t > limit {
                        self.run = Run::Continuous { seq, period };
                        return;
                    }
                    self.latch_axis(axis, &seq);
                    seq.done |= 1 << axis;
                    if seq.complete() || self.cmm & bits::CMM_DRDM != 0 {
                        self.publish();
                    }
                    if seq.complete() {
                        let next = seq.later(1, period);
                        if next.start == seq.start {
                            self.run = Run::Idle; // the end of time
                            return;
                        }
                        seq = next;
                    }
                    self.run = Run::Continuous { seq, period };
                }
            }
        }
    }

    /// Starts what a POLL write asks for: the self test with BIST.STE, else a measurement of the
    /// polled axes (none polled: nothing).
    pub(super) fn start_single(&mut self) {
        let axes = map::axes(self.poll);
        self.run = if axes == 0 {
            Run::Idle
        } else if self.bist & bits::BIST_STE != 0 {
            Run::SelfTest {
                done_at: self
                    .now_ns
                    .saturating_add(map::self_test_ns(self.bist, axes)),
                axes,
            }
        } else {
            Run::Single(Sequence::new(self.now_ns, axes, self.cycle_counts))
        };
    }

    /// Starts (or stops) continuous measurements as CMM says, the first sequence now.
    pub(super) fn start_continuous(&mut self) {
        let axes = map::axes(self.cmm);
        self.run = if self.cmm & bits::CMM_START != 0 && axes != 0 {
            Run::Continuous {
                seq: Sequence::new(self.now_ns, axes, self.cycle_counts),
                period: map::continuous_period_ns(self.tmrc, axes, self.cycle_counts),
            }
        } else {
            Run::Idle
        };
    }

    /// Restarts continuous measurements with the current timing, if they are running.
    pub(super) fn reschedule(&mut self) {
        if self.is_continuous() {
            self.start_continuous();
        }
    }

    /// Ends continuous mode (CMM.START reads 0).
    pub(super) fn stop_continuous(&mut self) {
        if self.cmm & bits::CMM_START != 0 {
            self.cmm &= !bits::CMM_START;
            self.start_continuous();
        }
    }

    /// Converts the held field on `axis` into its three result bytes, kept until [`Self::publish`].
    fn latch_axis(&mut self, axis: usize, seq: &Sequence) {
        let cc = seq.cycle_counts.get(axis).copied().unwrap_or(0);
        let raw = match self.held {
            Held::Field(field) => map::axis_to_raw(field.get(axis).copied().unwrap_or(0.0), cc),
            Held::Raw(raw) => raw.get(axis).copied().unwrap_or(0),
        };
        let bytes = map::data_bytes(raw);
        if let Some(slot) = self.pending.get_mut(3 * axis..3 * axis + 3) {
            for (d, b) in slot.iter_mut().zip(bytes) {
                *d = b;
            }
        }
    }
}

impl Rm3100 {
    /// The measured axes reach the result registers together, and DRDY rises.
    fn publish(&mut self) {
        self.data = self.pending;
        self.drdy = true;
    }
}

#[cfg(test)]
mod tests {
    use super::super::PhysicalSample;
    use super::super::Rm3100;

    const MS: u64 = 1_000_000;

    fn field(x: f32, y: f32, z: f32) -> PhysicalSample {
        PhysicalSample {
            mag: [x, y, z],
            ..Default::default()
        }
    }

    #[test]
    fn axes_latch_one_after_the_other() {
        let mut mag = Rm3100::new();
        mag.latch_at(&field(1.0, 2.0, 3.0), 0);
        mag.write_register(0x00, 0x70);
        mag.latch_at(&field(10.0, 20.0, 30.0), 2 * MS); // x done at 2.28 ms
        mag.latch_at(&field(100.0, 200.0, 300.0), 4 * MS); // y done at 4.56 ms
        mag.advance(7 * MS);
        assert_eq!(mag.peek(0x34), 0x80);
        let raw =
            |i: u8| (u32::from(mag.peek(0x25 + 3 * i)) << 8) | u32::from(mag.peek(0x26 + 3 * i));
        assert_eq!([raw(0), raw(1), raw(2)], [750, 15_000, 22_500]);
    }

    #[test]
    fn a_long_step_in_continuous_mode_costs_few_passes() {
        let mut mag = Rm3100::new();
        mag.write_register(0x0B, 0x92);
        mag.write_register(0x01, 0x11); // x only: 600 Hz
        mag.latch_at(&field(1.0, 0.0, 0.0), 1);
        mag.advance(u64::MAX / 2);
        assert_eq!([mag.peek(0x34), mag.peek(0x26)], [0x80, 75]);
        mag.latch_at(&field(-1.0, 0.0, 0.0), u64::MAX - 1);
        mag.advance(u64::MAX); // returns, at the end of time
        assert_eq!(
            [mag.peek(0x34), mag.peek(0x24), mag.peek(0x26)],
            [0x80, 0xFF, 0xB5]
        );
    }
}
