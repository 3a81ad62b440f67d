//! The SPI front end of Bosch's accelerometer-side parts (the BMI270, the BMI088's
//! accelerometer die), on the shared state machine ([`SpiPhase`]):
//!
//! - **interface selection**: after power-on and after a soft reset the part listens on I2C; a
//!   chip-select rising edge switches it to SPI (which is why drivers begin with a dummy read).
//!   Until that edge the SPI bytes are not decoded and MISO is not driven (0x00 here, as for a
//!   deselected chip). The soft reset's own transaction does not count as the switching edge:
//!   the part is resetting when chip select rises, and the bytes after the reset command are
//!   not decoded;
//! - **dummy byte**: every read clocks out one dummy byte (0x00 here; "unpredictable" in the
//!   datasheets) before the data of the addressed register; writes have none.
//!
//! The dummy byte is threaded through [`SpiRegisters`] by [`DummyFirst`]: the first prefetch of
//! a read returns the dummy, its commit has no side effect and the burst stays on the addressed
//! register for the byte after it.

use super::spi_phase::{SpiPhase, SpiRegisters};

/// The MISO value of the dummy byte.
pub(crate) const DUMMY: u8 = 0x00;

/// A register file behind [`BoschSpi`].
pub(crate) trait BoschRegisters: SpiRegisters {
    /// Whether a soft reset was commanded since the last call (the flag is cleared).
    fn take_soft_reset(&mut self) -> bool;
}

/// Where a read is with respect to its dummy byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dummy {
    /// The next prefetch is the dummy byte.
    Due,
    /// The dummy was prefetched and is being clocked out.
    Out,
    /// The dummy went out: the burst stays on the addressed register once.
    Hold,
    /// Data bytes.
    None,
}

/// A register file whose reads begin with one dummy byte.
struct DummyFirst<'a, R> {
    regs: &'a mut R,
    state: Dummy,
}

impl<R: SpiRegisters> SpiRegisters for DummyFirst<'_, R> {
    fn prefetch(&mut self, addr: u8) -> u8 {
        if self.state == Dummy::Due {
            self.state = Dummy::Out;
            return DUMMY;
        }
        self.state = Dummy::None;
        self.regs.prefetch(addr)
    }
    fn commit(&mut self, addr: u8, value: u8) {
        if self.state == Dummy::Out {
            self.state = Dummy::Hold;
        } else {
            self.regs.commit(addr, value);
        }
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.regs.store(addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        match self.state {
            Dummy::Hold => addr,
            _ => self.regs.burst_next(addr),
        }
    }
}

/// The front end's state (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BoschSpi {
    phase: SpiPhase,
    dummy: Dummy,
    /// SPI selected by a chip-select rising edge (false: I2C mode).
    spi_mode: bool,
    /// A soft reset happened in the current transaction.
    resetting: bool,
}

impl BoschSpi {
    /// Power-on: I2C mode, idle.
    pub(crate) const fn new() -> Self {
        Self {
            phase: SpiPhase::Idle,
            dummy: Dummy::None,
            spi_mode: false,
            resetting: false,
        }
    }

    /// Whether a chip-select edge has switched the interface to SPI.
    pub(crate) fn is_spi_mode(&self) -> bool {
        self.spi_mode
    }

    /// Whether a transaction is in progress.
    pub(crate) fn is_active(&self) -> bool {
        self.phase.is_active()
    }

    /// Chip select asserted; returns the MISO byte of the first byte.
    pub(crate) fn select(&mut self) -> u8 {
        self.resetting = false;
        self.dummy = Dummy::Due;
        self.phase = if self.spi_mode {
            SpiPhase::Address
        } else {
            SpiPhase::Idle
        };
        0x00
    }

    /// `mosi` was clocked in; returns the MISO byte for the next byte.
    pub(crate) fn exchange(&mut self, mosi: u8, regs: &mut impl BoschRegisters) -> u8 {
        let mut with_dummy = DummyFirst {
            regs: &mut *regs,
            state: self.dummy,
        };
        let (phase, miso) = self.phase.step(mosi, &mut with_dummy);
        self.dummy = with_dummy.state;
        if regs.take_soft_reset() {
            self.resetting = true;
            self.spi_mode = false;
        }
        // A soft reset ends the transaction for the part: what follows is not decoded.
        self.phase = if self.resetting {
            SpiPhase::Idle
        } else {
            phase
        };
        miso
    }

    /// Chip select released: the rising edge selects SPI, unless the part was resetting.
    pub(crate) fn deselect(&mut self) {
        if !self.resetting {
            self.spi_mode = true;
        }
        *self = Self {
            spi_mode: self.spi_mode,
            ..Self::new()
        };
    }
}

/// Implements [`BoschRegisters`] and [`SpiTarget`](super::SpiTarget) for a chip behind
/// [`BoschSpi`]: one with the fields `spi: BoschSpi` and `soft_reset_seen: bool` (set when a
/// soft reset is commanded over SPI) and a method `bus_went_idle(&mut self)` (the transaction
/// ended: held values released, a waiting sample shown), besides its [`SpiRegisters`].
macro_rules! bosch_spi_target {
    ($chip:ty) => {
        impl $crate::chip::bosch_spi::BoschRegisters for $chip {
            fn take_soft_reset(&mut self) -> bool {
                core::mem::take(&mut self.soft_reset_seen)
            }
        }

        impl $crate::chip::SpiTarget for $chip {
            fn select(&mut self) -> u8 {
                self.spi.select()
            }

            fn exchange(&mut self, mosi: u8) -> u8 {
                let mut front = self.spi;
                let miso = front.exchange(mosi, self);
                self.spi = front;
                miso
            }

            fn deselect(&mut self) {
                self.spi.deselect();
                self.bus_went_idle();
            }
        }
    };
}
pub(crate) use bosch_spi_target;
