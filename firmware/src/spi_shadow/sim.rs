//! A simulated SPI target peripheral (test double) behind [`SpiPort`], with a controller that
//! clocks one transaction through it, and [`ShadowTarget`]: a chip served the way a board
//! serves it (shadow, [`serve`], [`replay`], [`Speculator`]) behind an [`SpiTarget`], so that
//! register sequences written for a chip measure the shadow path (for tests and host tools).
//!
//! Time is counted in ticks: every [`SpiPort`] call costs one tick, as each costs the real
//! handler a few CPU cycles. Byte `i` takes `byte_ticks`; its MOSI byte is stored when it ends,
//! and byte `i + 1` starts `turnaround` ticks later (the half SCK period of mode 3 plus any gap
//! the controller leaves). When a byte starts, the TX register moves to the shift register (an
//! empty register sends [`UNDERRUN`]) and a running TX stream refills it at once, as DMA does.

use crate::chip::{Chip, SpiTarget};

use super::{replay, serve, Capture, Outcome, Shadow, Speculator, SpiPort, Stats, STREAM_LEN};

/// MISO when the TX register was empty as a byte started.
pub const UNDERRUN: u8 = 0xEE;

/// Longest transaction [`SimPort`] clocks; later bytes are not clocked.
pub const SIM_LEN: usize = 512;

/// Bus timing of the simulated controller, in ticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Timing {
    /// From chip select falling to the first byte.
    pub setup: u64,
    /// One byte.
    pub byte: u64,
    /// From the end of one byte to the start of the next.
    pub turnaround: u64,
}

/// A fast controller: the takeover always comes too late for the first data byte.
pub const FAST: Timing = Timing {
    setup: 1,
    byte: 8,
    turnaround: 1,
};

/// A slow controller: plenty of time after the address byte.
pub const SLOW: Timing = Timing {
    setup: 4,
    byte: 80,
    turnaround: 40,
};

/// The simulated peripheral with its controller, for one transaction.
#[derive(Clone, Debug)]
pub struct SimPort {
    timing: Timing,
    mosi: [u8; SIM_LEN],
    len: usize,
    stream: [u8; STREAM_LEN],
    dma_on: bool,
    dma_next: usize,
    tx: Option<u8>,
    /// MISO of every byte clocked.
    pub shifted: [u8; SIM_LEN],
    started: usize,
    rx: [u8; STREAM_LEN],
    received: usize,
    tick: u64,
}

impl SimPort {
    /// Arms a transaction of `mosi` (at most [`SIM_LEN`] bytes) against the preloaded `stream`.
    pub fn new(timing: Timing, mosi: &[u8], stream: &[u8; STREAM_LEN]) -> Self {
        let len = mosi.len().min(SIM_LEN);
        let mut m = [0; SIM_LEN];
        m[..len].copy_from_slice(&mosi[..len]);
        Self {
            timing,
            mosi: m,
            len,
            stream: *stream,
            dma_on: true,
            dma_next: 1,
            tx: Some(stream[0]),
            shifted: [0; SIM_LEN],
            started: 0,
            rx: [0; STREAM_LEN],
            received: 0,
            tick: 0,
        }
    }

    /// The MISO bytes the controller saw.
    pub fn miso(&self) -> &[u8] {
        &self.shifted[..self.started]
    }

    fn start_of(&self, i: usize) -> u64 {
        let t = self.timing;
        let per_byte = t.byte.saturating_add(t.turnaround);
        t.setup.saturating_add((i as u64).saturating_mul(per_byte))
    }

    fn advance(&mut self) {
        self.tick += 1;
        loop {
            let i = self.started;
            // Bytes end in order; byte `received` ends before byte `received + 1` starts.
            let end = self
                .start_of(self.received)
                .saturating_add(self.timing.byte);
            if self.received < self.started && end <= self.tick {
                if let Some(slot) = self.rx.get_mut(self.received) {
                    *slot = self.mosi[self.received];
                }
                self.received += 1;
            } else if i < self.len && self.start_of(i) <= self.tick {
                self.shifted[i] = self.tx.take().unwrap_or(UNDERRUN);
                self.started += 1;
                if self.dma_on {
                    self.tx = self.stream.get(self.dma_next).copied();
                    self.dma_next += 1;
                }
            } else {
                break;
            }
        }
    }
}

impl SpiPort for SimPort {
    fn selected(&mut self) -> bool {
        self.advance();
        self.received < self.len
    }

    fn received(&mut self) -> usize {
        self.advance();
        self.received.min(STREAM_LEN)
    }

    fn mosi(&mut self, i: usize) -> u8 {
        self.advance();
        self.rx.get(i).copied().unwrap_or(0)
    }

    fn stop_stream(&mut self) -> bool {
        self.advance();
        self.dma_on = false;
        self.tx.is_some()
    }

    fn stream_taken(&mut self) -> usize {
        self.advance();
        self.dma_next
    }

    fn tx_empty(&mut self) -> bool {
        self.advance();
        self.tx.is_none()
    }

    fn write_tx(&mut self, byte: u8) {
        self.advance();
        self.tx = Some(byte);
    }

    fn end(&mut self) {
        self.advance();
        self.dma_on = false;
    }
}

/// One SPI transaction on `target`: `mosi` out, the MISO of each byte into `miso` (as far as
/// both reach).
pub fn transfer(target: &mut impl SpiTarget, mosi: &[u8], miso: &mut [u8]) {
    let mut next = target.select();
    for (i, &m) in mosi.iter().enumerate() {
        if let Some(slot) = miso.get_mut(i) {
            *slot = next;
        }
        next = target.exchange(m);
    }
    target.deselect();
}

/// A chip behind the SPI shadow path, as an [`SpiTarget`]: each transaction is served by
/// [`serve`] from the [`Shadow`] through a [`SimPort`] at the chosen [`Timing`], then replayed
/// into the chip ([`replay`], counted in [`Stats`]) and shown to the [`Speculator`]; before
/// the next transaction the shadow is captured again with the speculator's prediction, as a
/// board's main loop does when it keeps up.
///
/// Byte by byte: chip select gives the preloaded stream's first byte; once the address byte
/// is in, the MISO of the whole transaction is known (it does not depend on later MOSI bytes,
/// only on timing), and is handed out byte by byte; at deselect the transaction is served for
/// real and every byte handed out is checked against the capture ([`ShadowTarget::divergences`]).
/// Bytes beyond [`SIM_LEN`] read 0x00 and are not served.
///
/// [`ShadowTarget::chip_mut`] (latching samples, reconfiguring) counts as a new chip
/// generation, as the board's link handler does.
#[derive(Clone, Debug)]
pub struct ShadowTarget<C> {
    chip: C,
    shadow: Shadow,
    speculator: Speculator,
    stats: Stats,
    timing: Timing,
    generation: u32,
    stale: bool,
    selected: bool,
    mosi: [u8; SIM_LEN],
    len: usize,
    miso: [u8; SIM_LEN],
    last: Option<Outcome>,
    divergences: u32,
}

impl<C: Chip> ShadowTarget<C> {
    /// `chip` served at `timing`, nothing learned yet.
    pub fn new(chip: C, timing: Timing) -> Self {
        Self {
            chip,
            shadow: Shadow::new(),
            speculator: Speculator::new(),
            stats: Stats::default(),
            timing,
            generation: 0,
            stale: true,
            selected: false,
            mosi: [0; SIM_LEN],
            len: 0,
            miso: [0; SIM_LEN],
            last: None,
            divergences: 0,
        }
    }

    /// The chip.
    pub fn chip(&self) -> &C {
        &self.chip
    }

    /// The chip, for changes outside SPI (a new chip generation: the shadow is captured
    /// again before the next transaction).
    pub fn chip_mut(&mut self) -> &mut C {
        self.generation = self.generation.wrapping_add(1);
        self.stale = true;
        &mut self.chip
    }

    /// The controller's timing from the next transaction on.
    pub fn set_timing(&mut self, timing: Timing) {
        self.timing = timing;
    }

    /// Transactions by outcome so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Clears the counters (after a driver's initialisation, say).
    pub fn reset_stats(&mut self) {
        self.stats = Stats::default();
    }

    /// The speculator.
    pub fn speculator(&self) -> &Speculator {
        &self.speculator
    }

    /// The outcome of the last transaction.
    pub fn last_outcome(&self) -> Option<Outcome> {
        self.last
    }

    /// Transactions where a byte handed out differed from what [`serve`] sent (never, unless
    /// the simulation is wrong).
    pub fn divergences(&self) -> u32 {
        self.divergences
    }

    fn refresh(&mut self) {
        if self.stale {
            let start = self.speculator.predict(self.chip.burst_start());
            self.shadow.capture(&self.chip, start, self.generation);
            self.stale = false;
        }
    }
}

impl<C: Chip> SpiTarget for ShadowTarget<C> {
    fn select(&mut self) -> u8 {
        self.refresh();
        self.selected = true;
        self.len = 0;
        self.miso = [0; SIM_LEN];
        self.miso[0] = self.shadow.stream()[0];
        self.miso[0]
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        if !self.selected {
            return 0x00;
        }
        if let Some(slot) = self.mosi.get_mut(self.len) {
            *slot = mosi;
        }
        self.len += 1;
        if self.len == 1 {
            // The address byte: serve a transaction as long as the simulation goes, on a copy.
            let mut probe = [0u8; SIM_LEN];
            probe[0] = mosi;
            let mut shadow = self.shadow.clone();
            let mut port = SimPort::new(self.timing, &probe, shadow.stream());
            serve(&mut port, &mut shadow, &mut Capture::new());
            self.miso = port.shifted;
        }
        self.miso.get(self.len).copied().unwrap_or(0x00)
    }

    fn deselect(&mut self) {
        if !self.selected {
            return;
        }
        self.selected = false;
        let len = self.len.min(SIM_LEN);
        let mut port = SimPort::new(self.timing, &self.mosi[..len], self.shadow.stream());
        let mut capture = Capture::new();
        serve(&mut port, &mut self.shadow, &mut capture);
        let sent = capture.sent();
        if port.miso() != &self.miso[..port.miso().len()] || sent != &port.miso()[..sent.len()] {
            self.divergences = self.divergences.wrapping_add(1);
        }
        let outcome = replay(&mut self.chip, &capture, self.generation);
        self.stats.record(outcome);
        self.last = Some(outcome);
        self.speculator.observe(&capture);
        self.stale = true;
    }
}
