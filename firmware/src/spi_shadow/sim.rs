//! A simulated SPI target peripheral (test double) behind [`SpiPort`], with a controller that
//! clocks one transaction through it.
//!
//! Time is counted in ticks: every [`SpiPort`] call costs one tick, as each costs the real
//! handler a few CPU cycles. Byte `i` takes `byte_ticks`; its MOSI byte is stored when it ends,
//! and byte `i + 1` starts `turnaround` ticks later (the half SCK period of mode 3 plus any gap
//! the controller leaves). When a byte starts, the TX register moves to the shift register (an
//! empty register sends [`UNDERRUN`]) and a running TX stream refills it at once, as DMA does.

use super::{SpiPort, STREAM_LEN};

/// MISO when the TX register was empty as a byte started.
pub(super) const UNDERRUN: u8 = 0xEE;

/// Bus timing of the simulated controller, in ticks.
#[derive(Clone, Copy, Debug)]
pub(super) struct Timing {
    /// From chip select falling to the first byte.
    pub setup: u64,
    /// One byte.
    pub byte: u64,
    /// From the end of one byte to the start of the next.
    pub turnaround: u64,
}

/// A fast controller: the takeover always comes too late for the first data byte.
pub(super) const FAST: Timing = Timing {
    setup: 1,
    byte: 8,
    turnaround: 1,
};

/// A slow controller: plenty of time after the address byte.
pub(super) const SLOW: Timing = Timing {
    setup: 4,
    byte: 80,
    turnaround: 40,
};

pub(super) struct SimPort {
    timing: Timing,
    mosi: [u8; 256],
    len: usize,
    stream: [u8; STREAM_LEN],
    dma_on: bool,
    dma_next: usize,
    tx: Option<u8>,
    /// MISO of every byte clocked.
    pub shifted: [u8; 256],
    started: usize,
    rx: [u8; STREAM_LEN],
    received: usize,
    tick: u64,
}

impl SimPort {
    /// Arms a transaction of `mosi` (at most 256 bytes) against the preloaded `stream`.
    pub(super) fn new(timing: Timing, mosi: &[u8], stream: &[u8; STREAM_LEN]) -> Self {
        let len = mosi.len().min(256);
        let mut m = [0; 256];
        m[..len].copy_from_slice(&mosi[..len]);
        Self {
            timing,
            mosi: m,
            len,
            stream: *stream,
            dma_on: true,
            dma_next: 1,
            tx: Some(stream[0]),
            shifted: [0; 256],
            started: 0,
            rx: [0; STREAM_LEN],
            received: 0,
            tick: 0,
        }
    }

    /// The MISO bytes the controller saw.
    pub(super) fn miso(&self) -> &[u8] {
        &self.shifted[..self.started]
    }

    fn start_of(&self, i: usize) -> u64 {
        let t = self.timing;
        t.setup + i as u64 * (t.byte + t.turnaround)
    }

    fn advance(&mut self) {
        self.tick += 1;
        loop {
            let i = self.started;
            // Bytes end in order; byte `received` ends before byte `received + 1` starts.
            let end = self.start_of(self.received) + self.timing.byte;
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
