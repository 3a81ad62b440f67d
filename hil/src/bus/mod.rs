//! embedded-hal 1.0 adapters over the emulated chips' bus-target side, so third-party drivers
//! run unmodified against [`margemu_firmware::chip`] on the host.
//!
//! The chips are driven byte by byte through [`SpiTarget`] and [`I2cTarget`]; these adapters
//! play the controller:
//!
//! - [`SpiDevice`]: `embedded_hal::spi::SpiDevice`, chip select asserted for the whole
//!   transaction (every [`Operation`](embedded_hal::spi::Operation) kind, `DelayNs` included);
//! - [`SpiBus`] with its [`ChipSelect`] pin: `embedded_hal::spi::SpiBus` plus a
//!   `digital::OutputPin`, for drivers that drive chip select themselves (or an
//!   `ExclusiveDevice`-style pairing); MISO stays one byte ahead across separate bus calls;
//! - [`I2c`]: `embedded_hal::i2c::I2c` with START, repeated START between operations of
//!   different direction, STOP at the end, and NACKs reported as
//!   [`NoAcknowledge`](embedded_hal::i2c::ErrorKind::NoAcknowledge) of the address or the data;
//! - [`I2cBus`]: several [`I2cTarget`]s on one bus, itself a target for [`I2c`]: every target
//!   sees every START and STOP and answers its own addresses, the bytes go to those that
//!   acknowledged, an address nobody acknowledges is NACKed;
//! - [`Delay`] and [`Clock`]: a `DelayNs` that never sleeps but, if given a clock, advances it
//!   (drivers wait during their initialisation; the emulation decides what time means).
//!
//! **Bus faults.** Each adapter applies its device's `nak`, `corrupt` and `clock_stretch`
//! faults when given them ([`SpiDevice::with_faults`], [`I2c::with_faults`], or later through
//! its [`BusFaultsHandle`], e.g. [`BusFaultsHandle::sync`] from the firmware device's schedule;
//! on an [`I2cBus`], per chip: [`I2cBus::with_shared_faulted`]),
//! through the firmware's own application ([`margemu_firmware::bus_fault`]), so a third-party
//! driver on the host sees what it would see on a board; see each adapter's docs.
//!
//! **MISO one byte ahead.** [`SpiTarget::select`] returns the MISO byte of the first byte and
//! [`SpiTarget::exchange`] the MISO byte of the *next* one, exactly as a target's shift
//! register works; the adapters keep that pending byte, so byte *i* read by the controller is
//! the one the target prepared while byte *i − 1* was clocked in.
//!
//! **Sharing.** Every adapter holds a [`Shared`] handle to its target (`Rc<RefCell<T>>`), so one
//! chip can sit behind an SPI and an I2C adapter at once and the test bench can latch samples
//! into it between driver calls. A handle already borrowed elsewhere makes the access fail
//! with [`SpiError::TargetBusy`] or [`I2cError::TargetBusy`] instead of panicking.
//!
//! ```
//! use embedded_hal::spi::SpiDevice as _;
//! use margemu_hil::bus::{self, SpiDevice};
//! use margemu_firmware::chip::SpiTarget;
//!
//! /// Echoes every MOSI byte on the following byte.
//! struct Echo;
//! impl SpiTarget for Echo {
//!     fn select(&mut self) -> u8 { 0xA5 }
//!     fn exchange(&mut self, mosi: u8) -> u8 { mosi }
//!     fn deselect(&mut self) {}
//! }
//!
//! let mut spi = SpiDevice::new(bus::shared(Echo));
//! let mut buf = [1, 2, 3];
//! spi.transfer_in_place(&mut buf).unwrap();
//! assert_eq!(buf, [0xA5, 1, 2]);
//! ```
//!
//! [`SpiTarget`]: margemu_firmware::chip::SpiTarget
//! [`SpiTarget::select`]: margemu_firmware::chip::SpiTarget::select
//! [`SpiTarget::exchange`]: margemu_firmware::chip::SpiTarget::exchange
//! [`I2cTarget`]: margemu_firmware::chip::I2cTarget

mod delay;
mod faults;
mod i2c;
mod i2c_bus;
mod spi;

#[cfg(test)]
mod fake;

pub use delay::{Clock, Delay};
pub use faults::BusFaultsHandle;
pub use i2c::{I2c, I2cError};
pub use i2c_bus::I2cBus;
pub use spi::{ChipSelect, SpiBus, SpiDevice, SpiError};

use std::cell::RefCell;
use std::rc::Rc;

/// A target shared between adapters and the test bench (host only, single-threaded).
pub type Shared<T> = Rc<RefCell<T>>;

/// Wraps `target` for sharing.
pub fn shared<T>(target: T) -> Shared<T> {
    Rc::new(RefCell::new(target))
}
