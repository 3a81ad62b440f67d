//! SPI controller adapters over an [`SpiTarget`]: a whole-transaction [`SpiDevice`], and a
//! [`SpiBus`] whose chip select is a separate [`ChipSelect`] pin.
//!
//! MOSI filler for reads is `0x00`. While chip select is released, the target sees nothing and
//! MISO floats high, so the controller reads `0xFF` (as with a pull-up on real boards,
//! [`RELEASED`]).
//!
//! **Bus faults.** Given the device's faults ([`SpiDevice::with_faults`], or later through
//! the adapter's [`BusFaultsHandle`]), the adapters drive the target through
//! [`margemu_firmware::bus_fault`], at the chip's scene clock ([`Chip::now_ns`]) when the
//! transaction (or bus call) begins: a `nak` window makes the chip dead (MISO `0xFF`, the chip
//! sees nothing), `corrupt` flips bits of MISO bytes, `clock_stretch` does nothing (SPI has no
//! clock stretching).

use super::faults::BusFaultsHandle;
use super::{Clock, Shared};
use embedded_hal::digital::{self, OutputPin, StatefulOutputPin};
use embedded_hal::spi::{self, ErrorKind, Operation};
use margemu_firmware::bus_fault::{BusFaults, RELEASED};
use margemu_firmware::chip::{Chip, SpiTarget};
use std::cell::{Cell, RefMut};
use std::rc::Rc;

/// MOSI byte clocked out while the controller only reads.
const FILLER: u8 = 0x00;
/// MISO seen while no target drives the line.
const FLOATING: u8 = RELEASED;

/// An SPI access that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error, docsplay::Display)]
#[non_exhaustive]
pub enum SpiError {
    /// the target is borrowed elsewhere (re-entrant access through another handle)
    TargetBusy,
}

impl spi::Error for SpiError {
    fn kind(&self) -> ErrorKind {
        match self {
            Self::TargetBusy => ErrorKind::Other,
        }
    }
}

impl digital::Error for SpiError {
    fn kind(&self) -> digital::ErrorKind {
        digital::ErrorKind::Other
    }
}

fn borrow<T>(target: &Shared<T>) -> Result<RefMut<'_, T>, SpiError> {
    target.try_borrow_mut().map_err(|_| SpiError::TargetBusy)
}

/// One byte time: returns the MISO byte prepared before `mosi`, and keeps the one the target
/// prepares for the next byte in `next`.
fn shift<T: SpiTarget + ?Sized>(target: &mut T, next: &mut u8, mosi: u8) -> u8 {
    let miso = *next;
    *next = target.exchange(mosi);
    miso
}

/// `SpiBus::transfer` semantics: `max(read.len(), write.len())` bytes; a short `write` is padded
/// with [`FILLER`], MISO bytes beyond `read` are dropped.
fn transfer<T: SpiTarget + ?Sized>(target: &mut T, next: &mut u8, read: &mut [u8], write: &[u8]) {
    for i in 0..read.len().max(write.len()) {
        let miso = shift(target, next, write.get(i).copied().unwrap_or(FILLER));
        if let Some(slot) = read.get_mut(i) {
            *slot = miso;
        }
    }
}

fn transfer_in_place<T: SpiTarget + ?Sized>(target: &mut T, next: &mut u8, words: &mut [u8]) {
    for word in words {
        *word = shift(target, next, *word);
    }
}

/// `embedded_hal::spi::SpiDevice` over a target: chip select is asserted before the first
/// operation and released after the last, whatever happens in between.
pub struct SpiDevice<T> {
    target: Shared<T>,
    clock: Option<Clock>,
    faults: BusFaultsHandle<T>,
}

impl<T> SpiDevice<T> {
    /// A device on `target`; `Operation::DelayNs` returns at once.
    pub fn new(target: Shared<T>) -> Self {
        Self {
            target,
            clock: None,
            faults: BusFaultsHandle::default(),
        }
    }

    /// Makes `Operation::DelayNs` advance `clock`.
    pub fn with_clock(mut self, clock: Clock) -> Self {
        self.clock = Some(clock);
        self
    }

    /// The target.
    pub fn target(&self) -> &Shared<T> {
        &self.target
    }

    /// Its bus faults (a handle that shares them).
    pub fn faults(&self) -> BusFaultsHandle<T> {
        self.faults.clone()
    }
}

impl<T: Chip> SpiDevice<T> {
    /// Drives the chip through its device's bus `faults` (module docs).
    pub fn with_faults(self, faults: BusFaults) -> Self {
        self.faults.set(faults);
        self
    }
}

impl<T> SpiDevice<T> {
    /// Applies the faults `handle` shares with another adapter on the same chip (so the two
    /// draw from one stream, as the chip's one bus target does).
    pub fn sharing_faults(mut self, handle: BusFaultsHandle<T>) -> Self {
        self.faults = handle;
        self
    }
}

impl<T> spi::ErrorType for SpiDevice<T> {
    type Error = SpiError;
}

impl<T: SpiTarget> spi::SpiDevice<u8> for SpiDevice<T> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), SpiError> {
        let mut target = borrow(&self.target)?;
        let clock = self.clock.as_ref();
        let mut faults = self.faults.borrow().ok_or(SpiError::TargetBusy)?;
        match &mut *faults {
            Some(faults) => selection(&mut faults.on(&mut target), operations, clock),
            None => selection(&mut *target, operations, clock),
        }
        Ok(())
    }
}

/// One whole selection of `target`: select, the operations, deselect.
fn selection<T: SpiTarget + ?Sized>(
    target: &mut T,
    operations: &mut [Operation<'_, u8>],
    clock: Option<&Clock>,
) {
    let mut next = target.select();
    for op in operations {
        match op {
            Operation::Read(words) => transfer(target, &mut next, words, &[]),
            Operation::Write(words) => transfer(target, &mut next, &mut [], words),
            Operation::Transfer(read, write) => transfer(target, &mut next, read, write),
            Operation::TransferInPlace(words) => transfer_in_place(target, &mut next, words),
            Operation::DelayNs(ns) => {
                if let Some(clock) = clock {
                    clock.advance_ns(u64::from(*ns));
                }
            }
        }
    }
    target.deselect();
}

/// The selection state shared by an [`SpiBus`] and its [`ChipSelect`]: `None` while released,
/// else the MISO byte the target prepared for the next byte.
type Line = Rc<Cell<Option<u8>>>;

/// `embedded_hal::spi::SpiBus` over a target whose chip select is the paired [`ChipSelect`].
/// The bytes of one selection may be spread over any number of bus calls.
pub struct SpiBus<T> {
    target: Shared<T>,
    line: Line,
    faults: BusFaultsHandle<T>,
}

/// The chip-select pin of an [`SpiBus`] (active low): `set_low` selects the target,
/// `set_high` releases it; setting the level it already has does nothing.
pub struct ChipSelect<T> {
    target: Shared<T>,
    line: Line,
    faults: BusFaultsHandle<T>,
}

impl<T> SpiBus<T> {
    /// A bus on `target` and its chip-select pin, released.
    pub fn new(target: Shared<T>) -> (Self, ChipSelect<T>) {
        let line = Line::default();
        let faults = BusFaultsHandle::default();
        let cs = ChipSelect {
            target: target.clone(),
            line: line.clone(),
            faults: faults.clone(),
        };
        let bus = Self {
            target,
            line,
            faults,
        };
        (bus, cs)
    }

    /// The target.
    pub fn target(&self) -> &Shared<T> {
        &self.target
    }

    /// Its bus faults, shared with its chip select (module docs).
    pub fn faults(&self) -> BusFaultsHandle<T> {
        self.faults.clone()
    }
}

impl<T: SpiTarget> SpiBus<T> {
    /// Runs `f` with the target (through its faults, if any) and its pending MISO byte while
    /// selected, or with `None` while released (then the target sees nothing).
    fn clocked(
        &mut self,
        f: impl FnOnce(Option<(&mut dyn SpiTarget, &mut u8)>),
    ) -> Result<(), SpiError> {
        match self.line.get() {
            None => f(None),
            Some(mut next) => {
                let mut target = borrow(&self.target)?;
                match &mut *self.faults.borrow().ok_or(SpiError::TargetBusy)? {
                    Some(faults) => f(Some((&mut faults.on(&mut target), &mut next))),
                    None => f(Some((&mut *target, &mut next))),
                }
                self.line.set(Some(next));
            }
        }
        Ok(())
    }
}

impl<T> spi::ErrorType for SpiBus<T> {
    type Error = SpiError;
}

impl<T: SpiTarget> spi::SpiBus<u8> for SpiBus<T> {
    fn read(&mut self, words: &mut [u8]) -> Result<(), SpiError> {
        self.clocked(|line| match line {
            Some((target, next)) => transfer(target, next, words, &[]),
            None => words.fill(FLOATING),
        })
    }

    fn write(&mut self, words: &[u8]) -> Result<(), SpiError> {
        self.clocked(|line| {
            if let Some((target, next)) = line {
                transfer(target, next, &mut [], words);
            }
        })
    }

    fn transfer(&mut self, read: &mut [u8], write: &[u8]) -> Result<(), SpiError> {
        self.clocked(|line| match line {
            Some((target, next)) => transfer(target, next, read, write),
            None => read.fill(FLOATING),
        })
    }

    fn transfer_in_place(&mut self, words: &mut [u8]) -> Result<(), SpiError> {
        self.clocked(|line| match line {
            Some((target, next)) => transfer_in_place(target, next, words),
            None => words.fill(FLOATING),
        })
    }

    fn flush(&mut self) -> Result<(), SpiError> {
        Ok(())
    }
}

impl<T> digital::ErrorType for ChipSelect<T> {
    type Error = SpiError;
}

impl<T: SpiTarget> ChipSelect<T> {
    /// Runs `f` on the target, through its faults if any.
    fn edge<R>(&mut self, f: impl FnOnce(&mut dyn SpiTarget) -> R) -> Result<R, SpiError> {
        let mut target = borrow(&self.target)?;
        Ok(
            match &mut *self.faults.borrow().ok_or(SpiError::TargetBusy)? {
                Some(faults) => f(&mut faults.on(&mut target)),
                None => f(&mut *target),
            },
        )
    }
}

impl<T: SpiTarget> OutputPin for ChipSelect<T> {
    fn set_low(&mut self) -> Result<(), SpiError> {
        if self.line.get().is_none() {
            let first = self.edge(|t| t.select())?;
            self.line.set(Some(first));
        }
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), SpiError> {
        if self.line.get().is_some() {
            self.edge(|t| t.deselect())?;
            self.line.set(None);
        }
        Ok(())
    }
}

impl<T: SpiTarget> StatefulOutputPin for ChipSelect<T> {
    fn is_set_high(&mut self) -> Result<bool, SpiError> {
        Ok(self.line.get().is_none())
    }

    fn is_set_low(&mut self) -> Result<bool, SpiError> {
        Ok(self.line.get().is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::super::fake::{Echo, Event, Regs};
    use super::super::{shared, Clock};
    use super::*;
    use embedded_hal::spi::{Error as _, SpiBus as _, SpiDevice as _};
    use Event::{Deselect, Exchange, Select};

    #[test]
    fn device_miso_is_one_byte_ahead() {
        let echo = shared(Echo::default());
        let mut spi = SpiDevice::new(echo.clone());
        let mut buf = [0x01, 0x02, 0x03];
        spi.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf, [Echo::FIRST, 0x01, 0x02]);
        let log = &echo.borrow().log;
        let expected = [
            Select,
            Exchange(0x01),
            Exchange(0x02),
            Exchange(0x03),
            Deselect,
        ];
        assert_eq!(log[..], expected);
    }

    #[test]
    fn device_keeps_chip_select_over_all_operations() {
        let echo = shared(Echo::default());
        let clock = Clock::new();
        let mut spi = SpiDevice::new(echo.clone()).with_clock(clock.clone());
        let (mut read, mut transfer, mut in_place) = ([0u8; 2], [0u8; 1], [0x30u8]);
        spi.transaction(&mut [
            Operation::Write(&[0x10, 0x11]),
            Operation::Read(&mut read),
            Operation::DelayNs(1_500),
            Operation::Transfer(&mut transfer, &[0x20, 0x21]),
            Operation::TransferInPlace(&mut in_place),
        ])
        .unwrap();
        // The MISO of each byte is the MOSI before it, across operation boundaries.
        assert_eq!(read, [0x11, FILLER]);
        assert_eq!(transfer, [FILLER]);
        assert_eq!(in_place, [0x21]);
        assert_eq!(clock.now_ns(), 1_500);
        let log = &echo.borrow().log;
        let mosi = [0x10, 0x11, FILLER, FILLER, 0x20, 0x21, 0x30].map(Exchange);
        assert_eq!(log[0], Select);
        assert_eq!(log[1..8], mosi);
        assert_eq!(log[8..], [Deselect]);
    }

    #[test]
    fn device_transfer_pads_short_write_and_drops_extra_miso() {
        let echo = shared(Echo::default());
        let mut spi = SpiDevice::new(echo.clone());
        let mut read = [0u8; 4];
        spi.transfer(&mut read, &[0x01, 0x02]).unwrap();
        assert_eq!(read, [Echo::FIRST, 0x01, 0x02, FILLER]);
        let mut short = [0u8; 1];
        spi.transfer(&mut short, &[0x07, 0x08, 0x09]).unwrap();
        assert_eq!(short, [Echo::FIRST]);
        let clocked = echo.borrow().log.iter().filter(|e| **e != Select).count();
        assert_eq!(clocked, 4 + 1 + 3 + 1);
    }

    #[test]
    fn device_reads_and_writes_registers() {
        let regs = shared(Regs::counting());
        let mut spi = SpiDevice::new(regs.clone());
        // Command byte, then a burst: the first MISO byte is the filler under the command.
        let mut buf = [0x82, 0, 0, 0];
        spi.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf, [0x00, 0x12, 0x13, 0x14]);
        spi.write(&[0x03, 0xAB, 0xCD]).unwrap();
        let mut read = [0u8; 3];
        spi.transaction(&mut [Operation::Write(&[0x83]), Operation::Read(&mut read)])
            .unwrap();
        assert_eq!(read, [0xAB, 0xCD, 0x15]);
        assert_eq!(regs.borrow().regs[2..6], [0x12, 0xAB, 0xCD, 0x15]);
    }

    #[test]
    fn device_reports_a_busy_target() {
        let regs = shared(Regs::counting());
        let mut spi = SpiDevice::new(regs.clone());
        let _held = regs.borrow_mut();
        let err = spi.write(&[0x00]).unwrap_err();
        assert_eq!(err, SpiError::TargetBusy);
        assert_eq!(err.kind(), ErrorKind::Other);
    }

    #[test]
    fn bus_keeps_miso_pending_across_calls() {
        let regs = shared(Regs::counting());
        let (mut bus, mut cs) = SpiBus::new(regs.clone());
        cs.set_low().unwrap();
        bus.write(&[0x85]).unwrap();
        let mut first = [0u8; 1];
        bus.read(&mut first).unwrap();
        let mut rest = [0u8; 2];
        bus.transfer(&mut rest, &[]).unwrap();
        bus.flush().unwrap();
        cs.set_high().unwrap();
        assert_eq!(first, [0x15]);
        assert_eq!(rest, [0x16, 0x17]);
        let log = &regs.borrow().log;
        let expected = [
            Select,
            Exchange(0x85),
            Exchange(FILLER),
            Exchange(FILLER),
            Exchange(FILLER),
            Deselect,
        ];
        assert_eq!(log[..], expected);
    }

    #[test]
    fn bus_writes_split_over_calls() {
        let regs = shared(Regs::counting());
        let (mut bus, mut cs) = SpiBus::new(regs.clone());
        cs.set_low().unwrap();
        bus.write(&[0x01]).unwrap();
        bus.write(&[0xEE, 0xDD]).unwrap();
        cs.set_high().unwrap();
        assert_eq!(regs.borrow().regs[1..4], [0xEE, 0xDD, 0x13]);
    }

    #[test]
    fn bus_without_chip_select_reads_floating_line() {
        let echo = shared(Echo::default());
        let (mut bus, mut cs) = SpiBus::new(echo.clone());
        let mut buf = [0x01, 0x02];
        bus.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf, [FLOATING; 2]);
        let mut read = [0u8; 2];
        bus.transfer(&mut read, &[0x03]).unwrap();
        assert_eq!(read, [FLOATING; 2]);
        bus.write(&[0x04]).unwrap();
        assert!(echo.borrow().log.is_empty());
        assert!(cs.is_set_high().unwrap());
    }

    #[test]
    fn chip_select_acts_on_edges_only() {
        let echo = shared(Echo::default());
        let (mut bus, mut cs) = SpiBus::new(echo.clone());
        cs.set_high().unwrap();
        cs.set_low().unwrap();
        cs.set_low().unwrap();
        assert!(cs.is_set_low().unwrap());
        let mut buf = [0x42, 0x43];
        bus.transfer_in_place(&mut buf).unwrap();
        assert_eq!(buf, [Echo::FIRST, 0x42]);
        cs.set_high().unwrap();
        cs.set_high().unwrap();
        let log = &echo.borrow().log;
        assert_eq!(log[..], [Select, Exchange(0x42), Exchange(0x43), Deselect]);
    }
}
