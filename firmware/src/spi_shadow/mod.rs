//! Serving the SPI target from a shadow of the register file, for boards whose SPI peripheral
//! cannot turn the address byte around in time.
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
//! **The design.** The main loop, which owns the chip, keeps a [`Shadow`]: every register as a
//! bus read would see it ([`Mpu6xxx::peek`]), and the MISO stream of the burst read the
//! controller most likely makes next (from [`Speculator::start`], by default ACCEL_XOUT_H, where
//! flight-controller drivers start their sensor burst). The board preloads that stream into its
//! TX DMA while chip select is high, so the predicted burst is served by hardware at any clock.
//! Its highest-priority handler, [`serve`], watches the address byte arrive: a write, or a read
//! at the predicted address, is left to the DMA; any other read is taken over by the CPU
//! ([`SpiPort::stop_stream`]), which serves the rest of the burst from the shadow, and whose
//! first byte is right only if the takeover beat the data byte (slow clocks, or a controller
//! that leaves a gap after the address byte). Writes are applied to the shadow at once
//! ([`Shadow::write_through`]) so a read-back sees them.
//!
//! Every transaction is recorded as a [`Capture`] (MOSI bytes and the MISO bytes actually
//! sent) and handed to the main loop, which replays it into the real chip ([`replay`]): the
//! chip applies the writes and the read side effects (INT_STATUS clear, FIFO pops), and the
//! MISO the chip would have sent is compared with what the board sent. The [`Outcome`] says
//! whether the board served the controller correctly, and is counted in [`Stats`]; the
//! [`Speculator`] learns a new start address from repeated burst misses.
//!
//! The board's SPI peripheral is reached through the narrow [`SpiPort`] trait; the tests drive
//! the same [`serve`] through a simulated port clocked at chosen speeds.
//!
//! ```
//! use margemu_firmware::chip::Mpu6xxx;
//! use margemu_firmware::spi_shadow::{replay, Capture, Outcome, Shadow, DEFAULT_START};
//! let mut chip = Mpu6xxx::new();
//! let mut shadow = Shadow::new();
//! shadow.capture(&chip, DEFAULT_START, 0);
//! assert_eq!(shadow.read(0x75), 0x71); // WHO_AM_I, as a bus read would return it
//! // A board served a one-byte read of WHO_AM_I from the shadow (CPU takeover in time):
//! let capture = Capture::from_bytes(&[0x80 | 0x75, 0x00], &[0x00, 0x71], 0, Some(1));
//! assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
//! ```

mod serve;
mod verify;

#[cfg(test)]
mod sim;
#[cfg(test)]
mod tests;

pub use serve::{serve, Capture, SpiPort};
pub use verify::{replay, Outcome, Speculator, Stats, SWITCH_AFTER};

use margemu_protocol::regmap::mpu6xxx::{is_read_only, next_address, reg, write_mask};

use crate::chip::Mpu6xxx;

/// MISO bytes the preloaded stream covers, and MOSI bytes a [`Capture`] keeps: the address
/// byte and 128 data bytes (every register once).
pub const STREAM_LEN: usize = 1 + 128;

/// The burst start predicted until the [`Speculator`] learns another: ACCEL_XOUT_H (0x3B), where
/// drivers start the accel–temperature–gyro burst.
pub const DEFAULT_START: u8 = reg::ACCEL_XOUT_H;

/// MISO during the address byte (what the chip model sends there).
pub const ADDRESS_PHASE_MISO: u8 = 0x00;

/// Registers whose write does more than store `value & write_mask` in that register (resets,
/// FIFO pushes, transfers, registers a read does not return as stored): left to the replay.
const WRITE_SIDE_EFFECTS: [u8; 5] = [
    reg::PWR_MGMT_1,
    reg::USER_CTRL,
    reg::I2C_SLV4_CTRL,
    reg::FIFO_R_W,
    reg::MEM_R_W,
];

/// The register address the `n`-th data byte (`n ≥ 1`) of a burst from `start` reads.
pub fn burst_address(start: u8, n: usize) -> u8 {
    let mut addr = start & 0x7F;
    for _ in 1..n.min(STREAM_LEN) {
        addr = next_address(addr);
    }
    addr
}

/// What a bus read of each register returns, and the MISO stream of the predicted burst.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Shadow {
    regs: [u8; 128],
    stream: [u8; STREAM_LEN],
    start: u8,
    generation: u32,
}

impl Default for Shadow {
    fn default() -> Self {
        Self::new()
    }
}

impl Shadow {
    /// An all-zero shadow (what a board serves before its first [`Shadow::capture`]).
    pub const fn new() -> Self {
        Self {
            regs: [0; 128],
            stream: [0; STREAM_LEN],
            start: DEFAULT_START,
            generation: 0,
        }
    }

    /// Takes every register of `chip` (without read side effects) and builds the stream of a
    /// burst read from `start`; `generation` numbers the chip state it was taken from.
    pub fn capture(&mut self, chip: &Mpu6xxx, start: u8, generation: u32) {
        for (addr, slot) in (0u8..).zip(self.regs.iter_mut()) {
            *slot = chip.peek(addr);
        }
        self.start = start & 0x7F;
        self.generation = generation;
        self.rebuild_stream();
    }

    /// The value a read of `addr` returns (7 bits of address).
    pub fn read(&self, addr: u8) -> u8 {
        self.regs[usize::from(addr & 0x7F)]
    }

    /// The predicted burst's start address.
    pub fn start(&self) -> u8 {
        self.start
    }

    /// The generation given to [`Shadow::capture`].
    pub fn generation(&self) -> u32 {
        self.generation
    }

    /// The MISO stream of a read burst from [`Shadow::start`]: the address-phase byte, then one
    /// byte per register in burst order (FIFO_R_W and MEM_R_W repeat, as the chip does).
    pub fn stream(&self) -> &[u8; STREAM_LEN] {
        &self.stream
    }

    /// Applies the write transaction `mosi` (address byte, then data) to the registers that only
    /// store what is written. Reads are ignored; writes to registers with side effects (resets,
    /// FIFO, transfers) wait for the main loop's replay and fresh capture.
    pub fn write_through(&mut self, mosi: &[u8]) {
        let Some((&first, data)) = mosi.split_first() else {
            return;
        };
        if first & 0x80 != 0 {
            return;
        }
        let mut addr = first & 0x7F;
        let mut changed = false;
        for &value in data {
            if !is_read_only(addr) && !WRITE_SIDE_EFFECTS.contains(&addr) {
                let slot = &mut self.regs[usize::from(addr)];
                let stored = value & write_mask(addr);
                changed |= *slot != stored;
                *slot = stored;
            }
            addr = next_address(addr);
        }
        if changed {
            self.rebuild_stream();
        }
    }

    fn rebuild_stream(&mut self) {
        self.stream[0] = ADDRESS_PHASE_MISO;
        let mut addr = self.start;
        for slot in &mut self.stream[1..] {
            *slot = self.regs[usize::from(addr)];
            addr = next_address(addr);
        }
    }
}
