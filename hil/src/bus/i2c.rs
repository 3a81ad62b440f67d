//! I2C controller adapter over an [`I2cTarget`] (7-bit addresses).
//!
//! A transaction follows the embedded-hal contract: START and the address with the direction of
//! the first operation; adjacent operations of the same direction run back to back; a repeated
//! START and the address go before each change of direction; STOP ends it, also after a NACK,
//! which aborts the rest.
//!
//! **Bus faults.** Given the device's faults ([`I2c::with_faults`], or later through its
//! [`BusFaultsHandle`]), the
//! adapter drives the target through [`margemu_firmware::bus_fault`] at the chip's scene clock
//! ([`Chip::now_ns`]) when the transaction begins: in a `nak` window the address is not
//! acknowledged ([`I2cError::AddressNack`]); `corrupt` flips bits of the bytes read;
//! `clock_stretch` holds SCL low before each byte read, which advances the adapter's [`Clock`]
//! ([`I2c::with_clock`]) by the stretch, and a controller given a timeout
//! ([`I2c::with_timeout_ns`]) gives up once the target has held the transaction longer than
//! that: STOP, and [`I2cError::Timeout`]. Without a timeout the controller waits as long as the
//! target stretches (as the embedded-hal controllers of most HALs do; an SMBus controller
//! would use 25 ms, the SMBus clock-low timeout, and a Linux or ChibiOS controller its
//! transfer timeout).

use super::faults::BusFaultsHandle;
use super::{Clock, Shared};
use embedded_hal::i2c::{self, ErrorKind, NoAcknowledgeSource, Operation, SevenBitAddress};
use margemu_firmware::bus_fault::{BusFaults, Faulted};
use margemu_firmware::chip::{Chip, I2cTarget};

/// An I2C access that failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error, docsplay::Display)]
#[non_exhaustive]
pub enum I2cError {
    /// no target acknowledged address {0:#04x}
    AddressNack(u8),
    /// the target at {address:#04x} did not acknowledge written byte {index} of the transaction
    DataNack {
        /// The 7-bit address.
        address: u8,
        /// Position of the refused byte among the bytes written in the transaction.
        index: usize,
    },
    /// the target is borrowed elsewhere (re-entrant access through another handle)
    TargetBusy,
    /// the target at {address:#04x} held SCL low for longer than the controller's timeout ({timeout_ns} ns)
    Timeout {
        /// The 7-bit address.
        address: u8,
        /// The controller's timeout, ns.
        timeout_ns: u64,
    },
}

impl i2c::Error for I2cError {
    fn kind(&self) -> ErrorKind {
        match self {
            Self::AddressNack(_) => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address),
            Self::DataNack { .. } => ErrorKind::NoAcknowledge(NoAcknowledgeSource::Data),
            Self::TargetBusy | Self::Timeout { .. } => ErrorKind::Other,
        }
    }
}

/// `embedded_hal::i2c::I2c` over a target that may answer several addresses.
///
/// An address above `0x7F` is not a 7-bit address: it is refused as
/// [`I2cError::AddressNack`] without touching the bus.
pub struct I2c<T> {
    target: Shared<T>,
    faults: BusFaultsHandle<T>,
    clock: Option<Clock>,
    timeout_ns: Option<u64>,
}

impl<T> I2c<T> {
    /// A controller on `target`.
    pub fn new(target: Shared<T>) -> Self {
        Self {
            target,
            faults: BusFaultsHandle::default(),
            clock: None,
            timeout_ns: None,
        }
    }

    /// The target.
    pub fn target(&self) -> &Shared<T> {
        &self.target
    }

    /// Its bus faults (a handle that shares them).
    pub fn faults(&self) -> BusFaultsHandle<T> {
        self.faults.clone()
    }

    /// Makes the target's clock stretching advance `clock`.
    pub fn with_clock(mut self, clock: Clock) -> Self {
        self.clock = Some(clock);
        self
    }

    /// Gives up a transaction once the target has stretched it by more than `timeout_ns`.
    pub fn with_timeout_ns(mut self, timeout_ns: u64) -> Self {
        self.timeout_ns = Some(timeout_ns);
        self
    }
}

impl<T: Chip> I2c<T> {
    /// Drives the chip through its device's bus `faults` (module docs).
    pub fn with_faults(self, faults: BusFaults) -> Self {
        self.faults.set(faults);
        self
    }
}

impl<T> i2c::ErrorType for I2c<T> {
    type Error = I2cError;
}

impl<T: I2cTarget> i2c::I2c<SevenBitAddress> for I2c<T> {
    fn transaction(
        &mut self,
        address: SevenBitAddress,
        operations: &mut [Operation<'_>],
    ) -> Result<(), I2cError> {
        if operations.is_empty() {
            return Ok(());
        }
        if address > 0x7F {
            return Err(I2cError::AddressNack(address));
        }
        let mut target = self
            .target
            .try_borrow_mut()
            .map_err(|_| I2cError::TargetBusy)?;
        let mut waited = Waited {
            clock: self.clock.as_ref(),
            timeout_ns: self.timeout_ns,
            address,
            total_ns: 0,
        };
        let mut faults = self.faults.borrow().ok_or(I2cError::TargetBusy)?;
        let mut line = match &mut *faults {
            Some(faults) => Line::Faulted(faults.on(&mut target)),
            None => Line::Plain(&mut *target),
        };
        let result = run(&mut line, address, operations, &mut waited);
        line.target().stop();
        result
    }
}

/// The target as the controller drives it: as it is, or through its bus faults.
enum Line<'a, T> {
    Plain(&'a mut T),
    Faulted(Faulted<'a, T>),
}

impl<T: I2cTarget> Line<'_, T> {
    fn target(&mut self) -> &mut dyn I2cTarget {
        match self {
            Self::Plain(t) => *t,
            Self::Faulted(t) => t,
        }
    }

    /// The time the target held SCL low since the last call.
    fn take_stretch_ns(&mut self) -> u64 {
        match self {
            Self::Plain(_) => 0,
            Self::Faulted(t) => t.take_stretch_ns(),
        }
    }
}

/// The controller's waiting on a stretched clock, over one transaction.
struct Waited<'a> {
    clock: Option<&'a Clock>,
    timeout_ns: Option<u64>,
    address: u8,
    total_ns: u64,
}

impl Waited<'_> {
    /// Waits `ns` more (advancing the clock), or gives up at the timeout.
    fn wait(&mut self, ns: u64) -> Result<(), I2cError> {
        if ns == 0 {
            return Ok(());
        }
        let total = self.total_ns.saturating_add(ns);
        let (waited, result) = match self.timeout_ns {
            Some(timeout_ns) if total > timeout_ns => {
                let address = self.address;
                (
                    timeout_ns,
                    Err(I2cError::Timeout {
                        address,
                        timeout_ns,
                    }),
                )
            }
            _ => (total, Ok(())),
        };
        if let Some(clock) = self.clock {
            clock.advance_ns(waited.saturating_sub(self.total_ns));
        }
        self.total_ns = waited;
        result
    }
}

/// Everything between the first START and the STOP.
fn run<T: I2cTarget>(
    line: &mut Line<'_, T>,
    address: u8,
    operations: &mut [Operation<'_>],
    waited: &mut Waited<'_>,
) -> Result<(), I2cError> {
    let mut reading = None;
    let mut written = 0;
    for op in operations {
        let read = matches!(op, Operation::Read(_));
        if reading != Some(read) {
            if !line.target().start(address, read) {
                return Err(I2cError::AddressNack(address));
            }
            reading = Some(read);
        }
        match op {
            Operation::Read(words) => {
                for word in words.iter_mut() {
                    *word = line.target().read();
                    // The target stretched SCL before it drove the byte.
                    let stretch = line.take_stretch_ns();
                    waited.wait(stretch)?;
                }
            }
            Operation::Write(words) => {
                for &word in words.iter() {
                    if !line.target().write(word) {
                        let index = written;
                        return Err(I2cError::DataNack { address, index });
                    }
                    written += 1;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::fake::{Event, Regs};
    use super::super::shared;
    use super::*;
    use embedded_hal::i2c::{Error as _, I2c as _};
    use Event::{Read, Start, Stop, Write};

    const ADDR: u8 = Regs::ADDRESS;

    #[test]
    fn write_read_uses_a_repeated_start() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        let mut buf = [0u8; 3];
        i2c.write_read(ADDR, &[0x02], &mut buf).unwrap();
        assert_eq!(buf, [0x12, 0x13, 0x14]);
        let log = &regs.borrow().log;
        let expected = [
            Start(ADDR, false),
            Write(0x02),
            Start(ADDR, true),
            Read,
            Read,
            Read,
            Stop,
        ];
        assert_eq!(log[..], expected);
    }

    #[test]
    fn write_and_read_are_single_transactions() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        i2c.write(ADDR, &[0x04, 0xBE, 0xEF]).unwrap();
        let mut buf = [0u8; 2];
        i2c.read(ADDR, &mut buf).unwrap();
        // The pointer kept auto-incrementing past the written bytes.
        assert_eq!(buf, [0x16, 0x17]);
        assert_eq!(regs.borrow().regs[4..6], [0xBE, 0xEF]);
        let log = &regs.borrow().log;
        let expected = [
            Start(ADDR, false),
            Write(0x04),
            Write(0xBE),
            Write(0xEF),
            Stop,
            Start(ADDR, true),
            Read,
            Read,
            Stop,
        ];
        assert_eq!(log[..], expected);
    }

    #[test]
    fn adjacent_operations_of_one_direction_share_a_start() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        let (mut a, mut b) = ([0u8; 1], [0u8; 1]);
        i2c.transaction(
            ADDR,
            &mut [
                Operation::Write(&[0x01]),
                Operation::Write(&[0x77]),
                Operation::Write(&[0x00]),
                Operation::Read(&mut a),
                Operation::Read(&mut b),
                Operation::Write(&[0x01]),
            ],
        )
        .unwrap();
        assert_eq!(regs.borrow().regs[1..3], [0x77, 0x00]);
        assert_eq!((a, b), ([0x13], [0x14]));
        let log = &regs.borrow().log;
        let expected = [
            Start(ADDR, false),
            Write(0x01),
            Write(0x77),
            Write(0x00),
            Start(ADDR, true),
            Read,
            Read,
            Start(ADDR, false),
            Write(0x01),
            Stop,
        ];
        assert_eq!(log[..], expected);
    }

    #[test]
    fn address_nack_stops_at_once() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        let err = i2c.write(0x0C, &[0x00, 0x01]).unwrap_err();
        assert_eq!(err, I2cError::AddressNack(0x0C));
        let kind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
        assert_eq!(err.kind(), kind);
        assert_eq!(regs.borrow().log[..], [Start(0x0C, false), Stop]);
        assert_eq!(i2c.read(0x80, &mut [0]).unwrap_err().kind(), kind);
        assert_eq!(regs.borrow().log.len(), 2);
    }

    #[test]
    fn data_nack_stops_at_once() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        let mut buf = [0u8; 1];
        let err = i2c
            .write_read(ADDR, &[0x0E, 0x55, 0x66, 0x99], &mut buf)
            .unwrap_err();
        assert_eq!(
            err,
            I2cError::DataNack {
                address: ADDR,
                index: 2
            }
        );
        let kind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Data);
        assert_eq!(err.kind(), kind);
        let log = &regs.borrow().log;
        let expected = [
            Start(ADDR, false),
            Write(0x0E),
            Write(0x55),
            Write(0x66),
            Stop,
        ];
        assert_eq!(log[..], expected);
        assert_eq!(regs.borrow().regs[0x0E], 0x55);
    }

    #[test]
    fn empty_transaction_touches_nothing() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        i2c.transaction(ADDR, &mut []).unwrap();
        assert!(regs.borrow().log.is_empty());
    }

    #[test]
    fn busy_target_is_an_error() {
        let regs = shared(Regs::counting());
        let mut i2c = I2c::new(regs.clone());
        let _held = regs.borrow_mut();
        let err = i2c.write(ADDR, &[0]).unwrap_err();
        assert_eq!((err, err.kind()), (I2cError::TargetBusy, ErrorKind::Other));
    }
}
