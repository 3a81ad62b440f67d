//! Serving the SPI target from a shadow of the register file, for boards whose SPI peripheral
//! cannot turn the address byte around in time.
//!
//! Nothing here names a register or a chip: everything comes through the chip boundary
//! ([`Chip`]), so the same code serves every emulated chip.
//!
//! **The problem.** An MPU-9250 read puts the first data byte on MISO in the byte right after
//! the address byte. A microcontroller in SPI target mode without a FIFO must have that byte in
//! its TX register before the first SCK edge of the data byte, but learns the address only at the
//! last edge of the address byte: half an SCK period later (mode 3, bytes back to back) is all
//! the time there is, 500 ns at 1 MHz and 25 ns at 20 MHz. The chip model
//! ([`SpiTarget`](crate::chip::SpiTarget)) cannot run in that window, and the board's interrupt
//! handler cannot share the chip with the main loop's link handler without a lock the bus may
//! not wait for.
//!
//! **The design.** The main loop, which owns the chip, keeps a [`Shadow`]
//! ([`Shadow::capture`]): every register as a bus read would see it ([`Chip::spi_peek`]), the
//! burst order ([`Chip::spi_next_address`]), what a write stores ([`Chip::spi_plain_write`]), and
//! the MISO stream of the burst read the controller most likely makes next, exactly as the chip
//! would send it ([`Chip::spi_read_burst`]: FIFO ports pop, counters latch), from the start the
//! [`Speculator`] predicts (the successor of the last transaction's start, else the chip's
//! [`Chip::burst_start`], where flight-controller drivers start their sensor burst). The board
//! preloads that stream into its TX DMA while chip select is high, so the predicted burst is
//! served by hardware at any clock.
//! Its highest-priority handler, [`serve`], watches the address byte arrive: a write, or a read
//! at the predicted address, is left to the DMA; any other read is taken over by the CPU
//! ([`SpiPort::stop_stream`]), which serves the rest of the burst from the shadow, and whose
//! first byte is right only if the takeover beat the data byte (slow clocks, or a controller
//! that leaves a gap after the address byte). On a chip whose reads clock out a dummy byte
//! before the data (the BMI270, [`Chip::spi_read_dummy`]) the stream and the takeover both
//! begin with it. Writes are applied to the shadow at once
//! ([`Shadow::write_through`]) so a read-back sees them.
//!
//! Every transaction is recorded as a [`Capture`] (MOSI bytes and the MISO bytes actually
//! sent) and handed to the main loop, which replays it into the real chip ([`replay`]): the
//! chip applies the writes and the read side effects (status clears, FIFO pops), and the
//! MISO the chip would have sent is compared with what the board sent. The [`Outcome`] says
//! whether the board served the controller correctly, and is counted in [`Stats`]; the
//! [`Speculator`] learns which transaction follows which ([`Speculator::observe`]). A write the
//! shadow cannot apply by itself (`spi_plain_write` is `None`: resets, FIFO pushes, bank
//! switches) waits for that replay; the main loop then captures the shadow again, so after a
//! bank switch the shadow shows the new bank.
//!
//! The board's SPI peripheral is reached through the narrow [`SpiPort`] trait; the tests drive
//! the same [`serve`] through a simulated port clocked at chosen speeds ([`sim`]), and
//! [`sim::ShadowTarget`] puts the whole path (serve, replay, speculation, capture) behind an
//! [`SpiTarget`](crate::chip::SpiTarget), so register sequences written for a chip run through it.
//!
//! ```
//! use margemu_firmware::chip::{Chip, EmulatedChip};
//! use margemu_firmware::spi_shadow::{replay, Capture, Outcome, Shadow, Speculator};
//! let mut chip = EmulatedChip::default(); // an MPU-9250
//! let speculator = Speculator::new();
//! let mut shadow = Shadow::new();
//! shadow.capture(&chip, speculator.predict(chip.burst_start()), 0);
//! assert_eq!(shadow.read(0x75), 0x71); // WHO_AM_I, as a bus read would return it
//! // A board served a one-byte read of WHO_AM_I from the shadow (CPU takeover in time):
//! let capture = Capture::from_bytes(&[0x80 | 0x75, 0x00], &[0x00, 0x71], 0, Some(1));
//! assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
//! ```

mod serve;
pub mod sim;
mod verify;

#[cfg(test)]
mod fault_tests;
#[cfg(test)]
mod tests;

pub use serve::{serve, Capture, SpiPort};
pub use verify::{replay, Outcome, Speculator, Stats, MAX_CONFIDENCE, SUCCESSORS, SWITCH_AFTER};

use crate::bus_fault::{BusFaults, RELEASED};
use crate::chip::Chip;

/// MISO bytes the preloaded stream covers, and MOSI bytes a [`Capture`] keeps: the address
/// byte and 256 data bytes (every register twice; the longest FIFO bursts of the drivers
/// measured: PX4's 8 high-resolution ICM-42688-P packets behind INT_STATUS and the count are
/// 163 bytes, its ICM-20602 transfers 3 + 14 × 9 and more). A longer transaction is truncated:
/// the bytes beyond are neither served nor replayed.
pub const STREAM_LEN: usize = 1 + 256;

/// MISO during the address byte (what the chip models send there).
pub const ADDRESS_PHASE_MISO: u8 = 0x00;

/// What an SPI read returns after a write of `value`, bit by bit, taken from
/// [`Chip::spi_plain_write`] of 0x00 and 0xFF: each bit stays fixed, follows the value, or
/// follows it inverted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct WriteRule {
    /// The write only stores a value (else it waits for the replay).
    plain: bool,
    /// Read-back after writing 0x00.
    zero: u8,
    /// Bits that depend on the value written.
    follows: u8,
}

impl WriteRule {
    const NONE: Self = Self {
        plain: false,
        zero: 0,
        follows: 0,
    };

    fn of(chip: &impl Chip, addr: u8) -> Self {
        match (
            chip.spi_plain_write(addr, 0x00),
            chip.spi_plain_write(addr, 0xFF),
        ) {
            (Some(zero), Some(ones)) => Self {
                plain: true,
                zero,
                follows: zero ^ ones,
            },
            _ => Self::NONE,
        }
    }

    fn stored(self, value: u8) -> u8 {
        (self.zero & !self.follows) | ((value ^ self.zero) & self.follows)
    }
}

/// What a bus read of each register returns, the burst order, what writes store, and the MISO
/// stream of the predicted burst: everything the board's SPI handler needs, taken from the
/// chip by [`Shadow::capture`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shadow {
    regs: [u8; 128],
    next: [u8; 128],
    rules: [WriteRule; 128],
    stream: [u8; STREAM_LEN],
    start: u8,
    generation: u32,
    /// The chip's dummy byte ahead of a read's data ([`Chip::spi_read_dummy`]).
    dummy: Option<u8>,
}

impl Default for Shadow {
    fn default() -> Self {
        Self::new()
    }
}

impl Shadow {
    /// An all-zero shadow (what a board serves before its first [`Shadow::capture`]: zeros;
    /// all zero, so a board's static shadows cost no flash).
    pub const fn new() -> Self {
        Self {
            regs: [0; 128],
            next: [0; 128],
            rules: [WriteRule::NONE; 128],
            stream: [0; STREAM_LEN],
            start: 0,
            generation: 0,
            dummy: None,
        }
    }

    /// Takes every register of `chip` as a read would see it (without read side effects), its
    /// burst order and write rules, and the stream of a burst read from `start` exactly as the
    /// chip would send it; `generation` numbers the chip state it was taken from.
    pub fn capture(&mut self, chip: &impl Chip, start: u8, generation: u32) {
        for addr in 0..128u8 {
            let i = usize::from(addr);
            self.regs[i] = chip.spi_peek(addr);
            self.next[i] = chip.spi_next_address(addr) & 0x7F;
            self.rules[i] = WriteRule::of(chip, addr);
        }
        self.start = start & 0x7F;
        self.generation = generation;
        self.dummy = chip.spi_read_dummy();
        self.stream[0] = ADDRESS_PHASE_MISO;
        chip.spi_read_burst(self.start, &mut self.stream[1..]);
    }

    /// Applies the chip's bus faults at `t_ns` (`crate::bus_fault`): in a `nak` window the
    /// shadow is a dead chip (every byte [`RELEASED`], no write stored, so the replay through
    /// the same faults, which keeps the chip out of the transaction, agrees with what was
    /// served); in a `corrupt` window the stream carries the flips the faults' stream will
    /// draw for its bytes ([`BusFaults::preview`]; the address-phase byte is the first one the
    /// chip drives). A CPU takeover serves the registers uncorrupted: its replay then counts
    /// as a miss. The window is the one at the capture's instant, not the transaction's.
    pub fn apply_bus_faults(&mut self, faults: &BusFaults, t_ns: u64) {
        if faults.nak(t_ns) {
            self.regs = [RELEASED; 128];
            self.rules = [WriteRule::NONE; 128];
            self.stream = [RELEASED; STREAM_LEN];
            self.dummy = None;
            return;
        }
        faults.preview(t_ns, &mut self.stream);
    }

    /// The value a read of `addr` returns (7 bits of address), behind the dummy byte on chips
    /// with one ([`Shadow::dummy`]).
    pub fn read(&self, addr: u8) -> u8 {
        self.regs[usize::from(addr & 0x7F)]
    }

    /// The address a burst moves to after `addr` (the same one on FIFO ports).
    pub fn next_address(&self, addr: u8) -> u8 {
        self.next[usize::from(addr & 0x7F)]
    }

    /// The register the `n`-th register byte (`n ≥ 1`) of a burst from `start` reads (on a
    /// chip with a dummy byte, the data byte after it is the first register byte).
    pub fn burst_address(&self, start: u8, n: usize) -> u8 {
        let mut addr = start & 0x7F;
        for _ in 1..n.min(STREAM_LEN) {
            addr = self.next_address(addr);
        }
        addr
    }

    /// The byte a read clocks out ahead of the addressed register's value, if the chip's reads
    /// have one ([`Chip::spi_read_dummy`]).
    pub fn dummy(&self) -> Option<u8> {
        self.dummy
    }

    /// The MISO bytes of a read burst from `start`, after the address byte, one by one: the
    /// dummy byte first on chips with one, then the registers in burst order.
    pub fn burst_bytes(&self, start: u8) -> BurstBytes<'_> {
        BurstBytes {
            shadow: self,
            addr: start & 0x7F,
            dummy: self.dummy,
        }
    }

    /// The predicted burst's start address.
    pub fn start(&self) -> u8 {
        self.start
    }

    /// The generation given to [`Shadow::capture`].
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// The MISO stream of a read burst from [`Shadow::start`]: the address-phase byte, then the
    /// data bytes as the chip would send them (FIFO ports give successive FIFO bytes).
    pub fn stream(&self) -> &[u8; STREAM_LEN] {
        &self.stream
    }

    /// Applies the write transaction `mosi` (address byte, then data) to the registers whose
    /// write only stores a value, in the registers and in the stream, up to the first register
    /// whose write does more. Reads are ignored; other writes (resets, FIFO pushes, bank
    /// switches, transfers, read-only registers), and the rest of their burst, wait for the
    /// main loop's replay and fresh capture.
    pub fn write_through(&mut self, mosi: &[u8]) {
        let Some((&first, data)) = mosi.split_first() else {
            return;
        };
        if first & 0x80 != 0 {
            return;
        }
        let mut addr = first & 0x7F;
        let mut changed = [0u32; 4];
        for &value in data {
            let i = usize::from(addr);
            let rule = self.rules[i];
            if !rule.plain {
                // It may change what the next bytes write to (a bank select): the rest of the
                // burst waits for the replay too.
                break;
            }
            let stored = rule.stored(value);
            if self.regs[i] != stored {
                self.regs[i] = stored;
                changed[i / 32] |= 1 << (i % 32);
            }
            addr = self.next_address(addr);
        }
        if changed != [0; 4] {
            let mut addr = self.start;
            let data = 1 + usize::from(self.dummy.is_some());
            for slot in self.stream.iter_mut().skip(data) {
                let i = usize::from(addr);
                if changed[i / 32] & (1 << (i % 32)) != 0 {
                    *slot = self.regs[i];
                }
                addr = self.next[i];
            }
        }
    }
}

/// The MISO bytes of a read burst served from a [`Shadow`] ([`Shadow::burst_bytes`]).
#[derive(Clone, Debug)]
pub struct BurstBytes<'a> {
    shadow: &'a Shadow,
    addr: u8,
    dummy: Option<u8>,
}

impl BurstBytes<'_> {
    /// The next byte.
    pub fn next_byte(&mut self) -> u8 {
        if let Some(dummy) = self.dummy.take() {
            return dummy;
        }
        let byte = self.shadow.read(self.addr);
        self.addr = self.shadow.next_address(self.addr);
        byte
    }
}
