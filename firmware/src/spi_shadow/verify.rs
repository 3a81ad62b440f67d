//! The main loop's side: [`replay`] each [`Capture`] into the chip, judge it ([`Outcome`]),
//! count it ([`Stats`]) and learn the next burst start ([`Speculator`]).

use crate::chip::SpiTarget;

use super::{Capture, DEFAULT_START};

/// How the board served one transaction, judged against the chip's own answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Chip select fell and rose without a whole byte.
    Empty,
    /// A write (MISO is not looked at); the chip has applied it.
    Write,
    /// A read served by the preloaded stream, every byte as the chip would have sent it.
    Hit,
    /// A read the CPU took over in time: every byte right.
    Fixed,
    /// A read with at least one wrong byte, served from a shadow of the chip's current
    /// generation: the speculation was wrong and the takeover too late (or, rarely, a side
    /// effect of an earlier transaction not yet in the shadow).
    Miss {
        /// The register the read started at.
        start: u8,
    },
    /// A read with a wrong byte served from an older shadow (a sample was latched, or the host
    /// reconfigured the chip, before the board's shadow caught up): the controller got a
    /// consistent older state.
    Stale {
        /// The register the read started at.
        start: u8,
    },
    /// More bytes than a capture holds: the part beyond it was neither checked nor replayed.
    Truncated,
}

/// Replays `capture` into `chip` (select, every MOSI byte, deselect) and compares the MISO the
/// chip gives with what the board sent. `generation` is the generation of the chip state now.
pub fn replay(chip: &mut impl SpiTarget, capture: &Capture, generation: u32) -> Outcome {
    let (mosi, sent) = (capture.mosi(), capture.sent());
    let Some(&first) = mosi.first() else {
        return Outcome::Empty;
    };
    let mut expected = chip.select();
    let mut right = true;
    for (&m, &s) in mosi.iter().zip(sent) {
        right &= expected == s;
        expected = chip.exchange(m);
    }
    chip.deselect();
    let start = first & 0x7F;
    if capture.truncated() {
        Outcome::Truncated
    } else if first & 0x80 == 0 {
        Outcome::Write
    } else if right {
        match capture.takeover() {
            None => Outcome::Hit,
            Some(_) => Outcome::Fixed,
        }
    } else if capture.generation() == generation {
        Outcome::Miss { start }
    } else {
        Outcome::Stale { start }
    }
}

/// Transactions by [`Outcome`] (wrapping counters).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Transactions replayed.
    pub transactions: u32,
    /// [`Outcome::Empty`].
    pub empty: u32,
    /// [`Outcome::Write`].
    pub writes: u32,
    /// [`Outcome::Hit`].
    pub hits: u32,
    /// [`Outcome::Fixed`].
    pub fixed: u32,
    /// [`Outcome::Miss`].
    pub misses: u32,
    /// [`Outcome::Stale`].
    pub stale: u32,
    /// [`Outcome::Truncated`].
    pub truncated: u32,
    /// Captures the board had to drop because the main loop had not taken the earlier ones
    /// (counted by the board).
    pub dropped: u32,
}

impl Stats {
    /// Counts one outcome.
    pub fn record(&mut self, outcome: Outcome) {
        let counter = match outcome {
            Outcome::Empty => &mut self.empty,
            Outcome::Write => &mut self.writes,
            Outcome::Hit => &mut self.hits,
            Outcome::Fixed => &mut self.fixed,
            Outcome::Miss { .. } => &mut self.misses,
            Outcome::Stale { .. } => &mut self.stale,
            Outcome::Truncated => &mut self.truncated,
        };
        *counter = counter.wrapping_add(1);
        self.transactions = self.transactions.wrapping_add(1);
    }
}

/// Consecutive burst reads starting at the same other register after which the
/// [`Speculator`] moves its prediction there.
pub const SWITCH_AFTER: u8 = 4;

/// Predicts where the next burst read starts: [`DEFAULT_START`] until [`SWITCH_AFTER`]
/// consecutive bursts (reads of two data bytes or more) start at one other register.
/// Single-register reads (register setup, mostly at slow clocks, where the CPU takeover serves
/// them) and writes do not move it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Speculator {
    start: u8,
    candidate: u8,
    streak: u8,
}

impl Default for Speculator {
    fn default() -> Self {
        Self::new()
    }
}

impl Speculator {
    /// Predicting [`DEFAULT_START`].
    pub const fn new() -> Self {
        Self {
            start: DEFAULT_START,
            candidate: DEFAULT_START,
            streak: 0,
        }
    }

    /// The predicted start address.
    pub fn start(&self) -> u8 {
        self.start
    }

    /// Learns from one transaction; returns whether the prediction changed.
    pub fn observe(&mut self, capture: &Capture) -> bool {
        let mosi = capture.mosi();
        let burst = mosi.len() >= 3;
        let Some(&first) = mosi.first() else {
            return false;
        };
        if first & 0x80 == 0 || !burst {
            return false;
        }
        let start = first & 0x7F;
        if start == self.start {
            self.streak = 0;
            return false;
        }
        if start == self.candidate {
            self.streak = self.streak.saturating_add(1);
        } else {
            self.candidate = start;
            self.streak = 1;
        }
        if self.streak >= SWITCH_AFTER {
            self.start = start;
            self.streak = 0;
            return true;
        }
        false
    }
}
