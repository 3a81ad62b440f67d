//! Emulated MARG chips, seen from the bus as a target (peripheral) device.
//!
//! A chip is driven byte by byte, the way a microcontroller's SPI or I2C peripheral in target
//! mode sees a transaction, so the same code serves a real board (from its interrupts) and the
//! host (behind embedded-hal adapters, so third-party drivers run against it unmodified).
//!
//! **SPI timing contract.** SPI is full duplex: while the controller clocks byte *i* in on MOSI,
//! the target shifts out the byte it loaded *before* byte *i* began. So [`SpiTarget::select`]
//! returns the MISO byte of the first byte, and [`SpiTarget::exchange`] takes the MOSI byte just
//! received and returns the MISO byte for the *next* byte, which a board must load into its TX
//! register within one byte time (the response-time budget). Implementations never panic, on any
//! sequence of calls.
//!
//! **I2C contract.** [`I2cTarget::start`] is a START or repeated START with a 7-bit address and
//! direction; it returns whether the target acknowledges. Writes return ACK/NACK; reads return
//! the byte the target drives; [`I2cTarget::stop`] ends the transaction. A target that did not
//! acknowledge its address ignores the following bytes until the next START.
//!
//! **The boundary.** [`Chip`] is what the link handler, the SPI shadow, the boards and the host
//! use of any chip; [`EmulatedChip`] is the chip a device runs, chosen by the host's Configure.
//!
//! Chips:
//! - [`Mpu6xxx`]: the InvenSense 6xxx family ([`Variant`]: the MPU-9250 and its WHO_AM_I
//!   variants with the [`Ak8963`] magnetometer behind the auxiliary I2C master or in bypass
//!   mode, the MPU-6500, the MPU-6000 and the ICM-20602);
//! - [`Ak8963`] on its own, as an [`I2cTarget`];
//! - [`Icm42688p`]: the TDK InvenSense ICM-42688-P (banks 0–4, 2 KB FIFO with 16- and 20-bit
//!   packets, INT1/INT2);
//! - [`Bmi270`]: the Bosch BMI270 (SPI with its dummy byte and I2C-to-SPI switch, I2C, the
//!   configuration upload, data registers at the sensors' own rates, sensor time, the FIFO,
//!   INT1/INT2 data ready);
//! - [`Bmi088`]: the Bosch BMI088, its two dies ([`bmi088::Bmi088Accel`],
//!   [`bmi088::Bmi088Gyro`]) each on its own chip select (or I2C address), each with its FIFO,
//!   behind one [`Chip`] (the accelerometer's SPI front end shared with the BMI270);
//! - [`Ist8310`]: the iSentek IST8310 standalone magnetometer (I2C only);
//! - [`Qmc5883l`]: the QST QMC5883L standalone magnetometer (I2C only); both share their
//!   [`Chip`] boundary ([`magnetometer`]) and I2C front end ([`pointer_i2c`]).
//! - [`Rm3100`]: the PNI RM3100 magnetometer, on I2C and SPI.
//!
//! Register writes the device under test makes are kept in a [`WriteLog`] for telemetry.
//!
//! **Faults.** Every chip implements the [`Chip`] fault hooks (`fault_reset`,
//! `fault_identity`, `fault_fifo_overflow`; no defaults), with the datasheet behaviour and the
//! drivers that check it (a `faults` module in each IMU family, the magnetometers' own
//! `fault_reset`; they have no FIFO to overflow); the ICM-42688-P also
//! models its AFSR stall while a driver leaves AFSR on (`icm42688p::afsr`).

mod ak8963;
pub mod bmi088;
pub mod bmi270;
mod bosch_spi;
mod emulated;
mod i2c_pointer;
pub mod icm42688p;
pub mod ist8310;
pub mod magnetometer;
pub mod mpu6xxx;
pub mod pointer_i2c;
pub mod qmc5883l;
pub mod rm3100;
mod spi_phase;
mod tick;
mod write_log;

pub use ak8963::{Ak8963, MagSource};
pub use bmi088::Bmi088;
pub use bmi270::Bmi270;
pub use emulated::{spi_read_burst_on_copy, Chip, EmulatedChip};
pub use icm42688p::Icm42688p;
pub use ist8310::Ist8310;
pub use mpu6xxx::{Config, Mpu6xxx, Variant};
pub use qmc5883l::Qmc5883l;
pub use rm3100::Rm3100;
pub use write_log::{Bus, RegisterWrite, WriteLog};

/// The SPI target side of a chip (mode 0/3, MSB first), byte by byte.
pub trait SpiTarget {
    /// Chip select asserted: a transaction begins. Returns the MISO byte of its first byte.
    fn select(&mut self) -> u8;
    /// `mosi` was clocked in; returns the MISO byte for the next byte of the transaction.
    fn exchange(&mut self, mosi: u8) -> u8;
    /// Chip select released: the transaction ends.
    fn deselect(&mut self);
}

/// The I2C target side of a chip (possibly answering several addresses, as the MPU-9250 does
/// with the AK8963 in bypass mode).
pub trait I2cTarget {
    /// START or repeated START to 7-bit `address`, reading if `read`; returns ACK.
    fn start(&mut self, address: u8, read: bool) -> bool;
    /// A byte written by the controller; returns ACK.
    fn write(&mut self, byte: u8) -> bool;
    /// The next byte read by the controller.
    fn read(&mut self) -> u8;
    /// STOP.
    fn stop(&mut self);
}

/// One physical sample as the chip's sensors would see it (defined by the chip boundary).
pub use margemu_protocol::chip::PhysicalSample;
