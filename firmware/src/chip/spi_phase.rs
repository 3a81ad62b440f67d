//! The SPI target state machine every chip shares: the first byte after chip select is
//! `R/W̄ | address` (bit 7 set reads), the following bytes are data, and a burst moves along
//! the chip's own register order ([`SpiRegisters::burst_next`]: FIFO ports stay).
//!
//! Following the one-byte-ahead contract of [`SpiTarget`](super::SpiTarget), a step returns
//! the *next* MISO byte, so a read is prefetched one byte before it is clocked out. Its
//! destructive side effects (FIFO pop, status clear) are applied only when the next step
//! confirms the byte went out; the prefetch after the last byte of a burst is discarded by
//! deselect. MISO during the address byte and during writes is 0x00.

/// What the state machine asks of a chip's register file.
pub(crate) trait SpiRegisters {
    /// The value a read of `addr` clocks out, without its side effects.
    fn prefetch(&mut self, addr: u8) -> u8;
    /// `value`, read from `addr`, went out: the read's side effects apply.
    fn commit(&mut self, addr: u8, value: u8);
    /// A data byte written to `addr`.
    fn store(&mut self, addr: u8, value: u8);
    /// The register a burst moves to after `addr`; asked after a write to `addr` has been
    /// stored (a bank select changes it).
    fn burst_next(&self, addr: u8) -> u8;
}

/// Where the SPI transaction is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SpiPhase {
    /// Chip select released.
    Idle,
    /// Selected; the next byte is the address byte.
    Address,
    /// Reading; `value` of register `addr` was prefetched and is being clocked out.
    Read { addr: u8, value: u8 },
    /// Writing; the next byte goes to `addr`.
    Write { addr: u8 },
}

impl SpiPhase {
    pub(crate) fn is_active(self) -> bool {
        self != Self::Idle
    }

    /// `mosi` was clocked in: returns the phase after it and the MISO byte for the next byte.
    pub(crate) fn step(self, mosi: u8, chip: &mut impl SpiRegisters) -> (Self, u8) {
        match self {
            Self::Idle => (Self::Idle, 0x00), // not selected: MISO is not driven
            Self::Address => {
                let addr = mosi & 0x7F;
                if mosi & 0x80 != 0 {
                    let value = chip.prefetch(addr);
                    (Self::Read { addr, value }, value)
                } else {
                    (Self::Write { addr }, 0x00)
                }
            }
            Self::Read { addr, value } => {
                chip.commit(addr, value);
                let addr = chip.burst_next(addr);
                let value = chip.prefetch(addr);
                (Self::Read { addr, value }, value)
            }
            Self::Write { addr } => {
                chip.store(addr, mosi);
                let addr = chip.burst_next(addr);
                (Self::Write { addr }, 0x00)
            }
        }
    }
}
