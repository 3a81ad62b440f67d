//! The main loop's side: [`replay`] each [`Capture`] into the chip, judge it ([`Outcome`]),
//! count it ([`Stats`]) and learn where the next read starts ([`Speculator`]).

use crate::chip::SpiTarget;

use super::Capture;

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

/// Replays `capture` into `chip` (select, every MOSI byte, deselect; an empty capture is a
/// bare chip-select toggle) and compares the MISO the chip gives with what the board sent. `generation` is the generation of the chip state now.
pub fn replay(chip: &mut impl SpiTarget, capture: &Capture, generation: u32) -> Outcome {
    let (mosi, sent) = (capture.mosi(), capture.sent());
    let Some(&first) = mosi.first() else {
        // Chip select fell and rose: the chip sees the edges (the BMI270 switches to SPI on
        // the rising one, which Betaflight's bare chip-select toggle relies on).
        chip.select();
        chip.deselect();
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
    /// Read transactions: [`Stats::hits`], [`Stats::fixed`], [`Stats::misses`],
    /// [`Stats::stale`] and [`Stats::truncated`] (truncated transactions are counted as reads).
    pub fn reads(&self) -> u32 {
        self.hits
            .wrapping_add(self.fixed)
            .wrapping_add(self.misses)
            .wrapping_add(self.stale)
            .wrapping_add(self.truncated)
    }

    /// Reads whose every byte was right: [`Stats::hits`] and [`Stats::fixed`].
    pub fn served_right(&self) -> u32 {
        self.hits.wrapping_add(self.fixed)
    }

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
/// [`Speculator`]'s fallback prediction moves there.
pub const SWITCH_AFTER: u8 = 4;

/// Transactions whose successor the [`Speculator`] remembers.
pub const SUCCESSORS: usize = 16;

/// Highest confidence of a remembered successor: a successor is replaced after this many
/// plus one consecutive transactions that followed otherwise.
pub const MAX_CONFIDENCE: u8 = 2;

/// What the speculator knows of a transaction: its first MOSI byte (`R/W̄ | address`), its
/// length (as stored: a truncated one counts as [`STREAM_LEN`](super::STREAM_LEN)), and a
/// byte of its data: for a write the first byte written (a bank select's bank), for a read
/// whether every data byte the controller got was zero (1 if so; drivers branch on that: an
/// empty FIFO count, a clear status). The length tells a driver's reads apart that start at
/// the same register but mean different things: a FIFO read of one record, followed by the
/// next poll, and the long read of a driver that got a wrong count, followed by its recovery.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Key {
    first: u8,
    len: u16,
    data: u8,
}

impl Key {
    fn of(capture: &Capture) -> Option<Self> {
        let (&first, written) = capture.mosi().split_first()?;
        let data = if first & 0x80 == 0 {
            written.first().copied().unwrap_or(0)
        } else {
            let sent = capture.sent().get(1..).unwrap_or(&[]);
            u8::from(sent.iter().all(|&b| b == 0))
        };
        let len = u16::try_from(capture.mosi().len()).unwrap_or(u16::MAX);
        Some(Self { first, len, data })
    }
}

/// Which read followed a transaction last time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Successor {
    /// The transaction.
    key: Key,
    /// The start address of the read that followed it.
    next: u8,
    /// How often in a row (saturating at [`MAX_CONFIDENCE`]) `next` was right, less the times
    /// it was wrong since.
    confidence: u8,
}

/// Predicts where the next read transaction starts, from the transaction before it.
///
/// Flight-controller drivers repeat fixed transactions: a burst from one register on every
/// data-ready, or a pair (FIFO count, then FIFO data), with writes and single-register checks
/// in between. The speculator remembers, for each of the [`SUCCESSORS`] transactions seen
/// last (keyed by their first MOSI byte: read or write, and address; their length; for writes
/// the first byte written, and for reads whether the controller got only zeros, since a driver
/// reads FIFO data only when the count it read is not zero), the start address of the read
/// that followed, with a small confidence so that one odd transaction does not unlearn a
/// pattern: a remembered successor is replaced only after it was wrong
/// [`MAX_CONFIDENCE`] + 1 times more than right. The least recently used entry makes room for a
/// new one. Without an entry for the last transaction, the prediction falls back to where
/// [`SWITCH_AFTER`] consecutive bursts (reads of two data bytes or more) started, else to the
/// chip's own burst start. Empty transactions are ignored; writes are keys but never
/// predicted (the board captures them at any clock). No allocation, fixed work per
/// transaction, and the same transactions always give the same predictions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Speculator {
    /// Most recently used first.
    table: [Successor; SUCCESSORS],
    len: usize,
    /// The last transaction.
    last: Option<Key>,
    fallback: Option<u8>,
    candidate: u8,
    streak: u8,
}

impl Default for Speculator {
    fn default() -> Self {
        Self::new()
    }
}

impl Speculator {
    /// Nothing learned: predicting the chip's burst start.
    pub const fn new() -> Self {
        Self {
            table: [Successor {
                key: Key {
                    first: 0,
                    len: 0,
                    data: 0,
                },
                next: 0,
                confidence: 0,
            }; SUCCESSORS],
            len: 0,
            last: None,
            fallback: None,
            candidate: 0,
            streak: 0,
        }
    }

    /// The start address of the next read: the successor of the last transaction if one is
    /// remembered, else the burst start learned from repeated bursts, else `burst_start` (the
    /// chip's [`Chip::burst_start`](crate::chip::Chip::burst_start)).
    pub fn predict(&self, burst_start: u8) -> u8 {
        self.last
            .and_then(|key| self.find(key))
            .map(|i| self.table[i].next)
            .or(self.fallback)
            .unwrap_or(burst_start)
            & 0x7F
    }

    /// The fallback learned from repeated bursts, if any.
    pub fn fallback(&self) -> Option<u8> {
        self.fallback
    }

    /// Learns from one transaction (in bus order); returns whether the successor remembered
    /// for the transaction before it, or the fallback, changed.
    pub fn observe(&mut self, capture: &Capture) -> bool {
        let mosi = capture.mosi();
        let Some(key) = Key::of(capture) else {
            return false;
        };
        let previous = self.last.replace(key);
        if key.first & 0x80 == 0 {
            return false;
        }
        let start = key.first & 0x7F;
        let mut changed = match previous {
            Some(key) => self.learn(key, start),
            None => false,
        };
        if mosi.len() >= 3 {
            changed |= self.learn_fallback(start);
        }
        changed
    }

    fn find(&self, key: Key) -> Option<usize> {
        self.table[..self.len].iter().position(|s| s.key == key)
    }

    /// `start` followed the transaction `key`; the entry moves to the front.
    fn learn(&mut self, key: Key, start: u8) -> bool {
        let (mut entry, at, changed) = match self.find(key) {
            Some(i) => {
                let mut e = self.table[i];
                let changed = if e.next == start {
                    e.confidence = (e.confidence + 1).min(MAX_CONFIDENCE);
                    false
                } else if e.confidence > 0 {
                    e.confidence -= 1;
                    false
                } else {
                    e.next = start;
                    true
                };
                (e, i, changed)
            }
            None => {
                let at = self.len.min(SUCCESSORS - 1);
                self.len = (self.len + 1).min(SUCCESSORS);
                let e = Successor {
                    key,
                    next: start,
                    confidence: 0,
                };
                (e, at, true)
            }
        };
        entry.next &= 0x7F;
        self.table.copy_within(0..at, 1);
        self.table[0] = entry;
        changed
    }

    fn learn_fallback(&mut self, start: u8) -> bool {
        if Some(start) == self.fallback {
            self.streak = 0;
            return false;
        }
        if start == self.candidate && self.streak > 0 {
            self.streak = self.streak.saturating_add(1);
        } else {
            self.candidate = start;
            self.streak = 1;
        }
        if self.streak >= SWITCH_AFTER {
            self.fallback = Some(start);
            self.streak = 0;
            return true;
        }
        false
    }
}
