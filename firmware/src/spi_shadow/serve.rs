//! The board's highest-priority SPI handler: [`serve`] one transaction from the [`Shadow`]
//! through an [`SpiPort`], recording it as a [`Capture`].

use super::{Shadow, STREAM_LEN};

/// The board's SPI peripheral in target mode, as [`serve`] needs it.
///
/// Before chip select falls, the board has armed a TX stream over [`Shadow::stream`] (the
/// peripheral holds stream byte 0 and fetches each next byte as the previous one starts to
/// shift out) and an RX stream that stores every MOSI byte. Byte `i` of the transaction is
/// the `i`-th byte clocked since chip select fell.
pub trait SpiPort {
    /// Whether chip select is still asserted.
    fn selected(&mut self) -> bool;
    /// MOSI bytes stored so far (at most [`STREAM_LEN`]; later bytes are lost).
    fn received(&mut self) -> usize;
    /// MOSI byte `i` (for `i < received()`).
    fn mosi(&mut self, i: usize) -> u8;
    /// Stops the TX stream; returns whether a stream byte still waits in the TX register (the
    /// next [`SpiPort::write_tx`] replaces it).
    fn stop_stream(&mut self) -> bool;
    /// Stream bytes the TX register took before [`SpiPort::stop_stream`].
    fn stream_taken(&mut self) -> usize;
    /// Whether the TX register is empty (the byte written last has started to shift out).
    fn tx_empty(&mut self) -> bool;
    /// Puts `byte` in the TX register, replacing what waits there.
    fn write_tx(&mut self, byte: u8);
    /// Chip select was released: stops both streams. The board may re-arm the peripheral for
    /// the next transaction here (it should: the sooner, the shorter chip select may stay
    /// high), as long as [`SpiPort::received`] and [`SpiPort::mosi`] keep returning this
    /// transaction's bytes.
    fn end(&mut self);
}

/// One transaction as the board served it: the MOSI bytes stored and the MISO bytes sent.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Capture {
    mosi: [u8; STREAM_LEN],
    sent: [u8; STREAM_LEN],
    len: usize,
    generation: u32,
    takeover: Option<usize>,
}

impl Default for Capture {
    fn default() -> Self {
        Self::new()
    }
}

impl Capture {
    /// An empty capture.
    pub const fn new() -> Self {
        Self {
            mosi: [0; STREAM_LEN],
            sent: [0; STREAM_LEN],
            len: 0,
            generation: 0,
            takeover: None,
        }
    }

    /// A capture of `mosi` answered with `sent` (the shorter length counts), from a shadow of
    /// `generation`, with the CPU taking over at byte `takeover` (for tests and host tools).
    pub fn from_bytes(mosi: &[u8], sent: &[u8], generation: u32, takeover: Option<usize>) -> Self {
        let mut c = Self::new();
        let len = mosi.len().min(sent.len()).min(STREAM_LEN);
        c.mosi[..len].copy_from_slice(&mosi[..len]);
        c.sent[..len].copy_from_slice(&sent[..len]);
        c.len = len;
        c.generation = generation;
        c.takeover = takeover;
        c
    }

    /// The MOSI bytes stored.
    pub fn mosi(&self) -> &[u8] {
        &self.mosi[..self.len]
    }

    /// The MISO bytes sent, one per MOSI byte stored.
    pub fn sent(&self) -> &[u8] {
        &self.sent[..self.len]
    }

    /// Whether the transaction may have been longer than what was stored.
    pub fn truncated(&self) -> bool {
        self.len >= STREAM_LEN
    }

    /// The generation of the shadow the transaction was served from.
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// The byte from which the CPU served the transaction instead of the preloaded stream.
    pub fn takeover(&self) -> Option<usize> {
        self.takeover
    }

    fn set_sent(&mut self, i: usize, byte: u8) {
        if let Some(slot) = self.sent.get_mut(i) {
            *slot = byte;
        }
    }
}

/// Serves one transaction, from chip select falling to its release, and records it in
/// `capture`. A write transaction is then applied to `shadow` ([`Shadow::write_through`]).
///
/// Runs in the board's highest-priority handler, entered when chip select falls.
pub fn serve(port: &mut impl SpiPort, shadow: &mut Shadow, capture: &mut Capture) {
    capture.generation = shadow.generation();
    capture.takeover = None;
    let started = loop {
        if port.received() > 0 {
            break true;
        }
        if !port.selected() {
            break port.received() > 0;
        }
    };
    if started {
        let first = port.mosi(0);
        let (read, addr) = (first & 0x80 != 0, first & 0x7F);
        if read && addr != shadow.start() {
            take_over(port, shadow, capture, addr);
        }
    }
    while port.selected() {}
    port.end();
    let len = port.received().min(STREAM_LEN);
    for i in 0..len {
        capture.mosi[i] = port.mosi(i);
    }
    let from = capture.takeover.unwrap_or(len).min(len);
    capture.sent[..from].copy_from_slice(&shadow.stream()[..from]);
    capture.len = len;
    shadow.write_through(capture.mosi());
}

/// A read the stream does not serve: stop it and feed the TX register from the shadow.
///
/// The first data byte (the dummy byte on chips with one) is written before anything else is
/// worked out (the fewer instructions between the address byte and this write, the slower a
/// clock the takeover beats); then the stream's progress says which byte that write actually
/// feeds, and a late write is corrected so that the rest of the burst is right.
fn take_over(port: &mut impl SpiPort, shadow: &Shadow, capture: &mut Capture, start: u8) {
    let waiting = port.stop_stream();
    let mut bytes = shadow.burst_bytes(start);
    let mut byte = bytes.next_byte();
    port.write_tx(byte);
    let mut next = port
        .stream_taken()
        .saturating_sub(usize::from(waiting))
        .max(1);
    if next > 1 {
        for _ in 2..next {
            bytes.next_byte();
        }
        byte = bytes.next_byte();
        port.write_tx(byte);
    }
    capture.takeover = Some(next);
    capture.set_sent(next, byte);
    while port.selected() {
        if port.tx_empty() {
            next += 1;
            let byte = bytes.next_byte();
            port.write_tx(byte);
            capture.set_sent(next, byte);
        }
    }
}
