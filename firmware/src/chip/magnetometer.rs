//! The chip boundary of the standalone magnetometers ([`Ist8310`], [`Qmc5883l`]): what they
//! share as [`Chip`]s.
//!
//! - **Samples.** A chip holds what it senses ([`Held`]) until the next latch and measures it
//!   on its own schedule (single-shot on the driver's trigger, or continuous at its rate). A
//!   physical sample ([`Chip::latch_at`]) holds the field, converted when a measurement
//!   completes, at the range in force then; an image ([`Chip::latch_image_at`], the 6 bytes of
//!   [`mag_image`], as the host computed them at the range it predicted) holds the raw values,
//!   which a measurement copies as they are. Both agree when the driver configures the range
//!   the scene declares.
//! - **Buses.** I2C only: the SPI side never drives MISO (reads 0x00) and ignores every byte.
//! - **Interrupts.** The DRDY pin is not emulated: the level reads low and never pulses.
//! - **Faults.** A reset fault is the chip's power-on state (each chip's `fault_reset`), a
//!   wrong identity replaces WAI / CHIP_ID; neither chip has a FIFO, so the FIFO-overflow fault
//!   does not apply (the hook returns `false`).
//! - **Writes.** Every data byte a controller writes over I2C lands in the write log; register
//!   overrides ([`Chip::write_register`], file 0) go through the same I2C target.
//!
//! ```
//! use margemu_firmware::chip::{Chip, EmulatedChip, I2cTarget};
//! use margemu_protocol::chip::ChipModel;
//! let mut mag = EmulatedChip::new(ChipModel::Ist8310, 0x10, 0x0C).unwrap();
//! assert!(mag.write_register(0, 0x0A, 0x01)); // CNTL1: one measurement
//! mag.latch_image_at(&[100, 0, 0xFF, 0xFF, 0, 0], 7_000_000);
//! assert!(mag.start(0x0C, false) && mag.write(0x03));
//! assert!(mag.start(0x0C, true));
//! assert_eq!([mag.read(), mag.read()], [100, 0]);
//! mag.stop();
//! assert!(!mag.start(0x0E, false)); // strapped to 0x0C only
//! ```

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::{ist8310, mag_image, qmc5883l};

use super::pointer_i2c::Step;
use super::{Bus, Chip, I2cTarget, Ist8310, Qmc5883l, RegisterWrite, SpiTarget};

/// Register writes a magnetometer keeps for the link (a driver writes a few per measurement).
pub const MAG_WRITE_LOG_LEN: usize = 32;

/// What a standalone magnetometer senses until the next latch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Held {
    /// A field in µT (chip axes), converted at the range in force when a measurement completes.
    Field([f32; 3]),
    /// Raw data register values, already at a range and clipped (an image's).
    Raw([i16; 3]),
}

/// `bit` if `set`.
pub(crate) fn flag(set: bool, bit: u8) -> u8 {
    if set {
        bit
    } else {
        0
    }
}

/// Writes `value` to `register` through the chip's own I2C target, as a driver would.
fn i2c_write<C: I2cTarget>(chip: &mut C, address: u8, register: u8, value: u8) -> bool {
    let acked = chip.start(address, false) && chip.write(register) && chip.write(value);
    chip.stop();
    acked
}

/// The magnetometer-specific parts of [`Chip`]: everything else is shared.
trait Magnetometer: I2cTarget + Clone {
    const MODEL: ChipModel;
    /// The register where drivers start their data burst.
    const BURST_START: u8;
    fn conversion(&self) -> Conversion;
    fn measurement_period_ns(&self) -> u64;
}

impl Magnetometer for Ist8310 {
    const MODEL: ChipModel = ChipModel::Ist8310;
    const BURST_START: u8 = ist8310::reg::STAT1;
    fn conversion(&self) -> Conversion {
        Conversion::Ist8310
    }
    /// The measurement time the averaging asks for (a driver triggers the next one).
    fn measurement_period_ns(&self) -> u64 {
        ist8310::measurement_ns(self.peek(ist8310::reg::AVGCNTL))
    }
}

impl Magnetometer for Qmc5883l {
    const MODEL: ChipModel = ChipModel::Qmc5883l;
    const BURST_START: u8 = qmc5883l::reg::XOUT_L;
    fn conversion(&self) -> Conversion {
        Conversion::Qmc5883l(self.range())
    }
    fn measurement_period_ns(&self) -> u64 {
        self.odr().period_ns()
    }
}

/// Implements [`I2cTarget`] (the shared register-pointer front end, every data byte logged),
/// [`SpiTarget`] (not driven) and [`Chip`] for a [`Magnetometer`].
macro_rules! magnetometer_chip {
    ($chip:ty) => {
        impl I2cTarget for $chip {
            fn start(&mut self, address: u8, read: bool) -> bool {
                let addressed = address == self.address();
                self.bus.start(addressed, read)
            }
            fn write(&mut self, byte: u8) -> bool {
                match self.bus.write(byte) {
                    Step::Pointer(addr) => self.set_pointer(addr),
                    Step::Data(value) => {
                        let register = self.write_next(value);
                        let device = self.address();
                        self.log.push(RegisterWrite {
                            bus: Bus::I2c,
                            device,
                            register,
                            value,
                        });
                    }
                    Step::Ignored => return false,
                }
                true
            }
            fn read(&mut self) -> u8 {
                if self.bus.may_read() {
                    self.read_next()
                } else {
                    0xFF
                }
            }
            fn stop(&mut self) {
                self.bus.stop();
            }
        }

        impl SpiTarget for $chip {
            fn select(&mut self) -> u8 {
                0x00
            }
            fn exchange(&mut self, _mosi: u8) -> u8 {
                0x00
            }
            fn deselect(&mut self) {}
        }

        impl Chip for $chip {
            fn model(&self) -> ChipModel {
                <$chip as Magnetometer>::MODEL
            }
            fn settings(&self) -> ChipSettings {
                ChipSettings {
                    model: <$chip as Magnetometer>::MODEL,
                    conversion: self.conversion(),
                }
            }
            /// An image of another length only moves the clock.
            fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
                match image.try_into() {
                    Ok(image) => self.sense_at(now_ns, Held::Raw(mag_image::parse(image))),
                    Err(_) => self.sense_at(now_ns, self.held()),
                }
            }
            fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
                self.sense_at(now_ns, Held::Field(sample.mag));
            }
            fn advance(&mut self, now_ns: u64) {
                self.sense_at(now_ns, self.held());
            }
            fn now_ns(&self) -> u64 {
                <$chip>::now_ns(self)
            }
            fn sample_period_ns(&self) -> u64 {
                self.measurement_period_ns()
            }
            fn int_pin_at(&self, _now_ns: u64) -> bool {
                false
            }
            fn int_open_drain(&self) -> bool {
                false
            }
            fn int_pulse_end_ns(&self) -> Option<u64> {
                None
            }
            fn pop_write(&mut self) -> Option<RegisterWrite> {
                self.log.pop()
            }
            fn writes_dropped(&self) -> u32 {
                self.log.dropped()
            }
            /// One register file (0), written over I2C.
            fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
                file == 0 && i2c_write(self, self.address(), register, value)
            }
            fn i2c_address(&self) -> u8 {
                self.address()
            }
            fn spi_peek(&self, _addr: u8) -> u8 {
                0x00
            }
            fn spi_next_address(&self, addr: u8) -> u8 {
                addr
            }
            fn spi_plain_write(&self, _addr: u8, _value: u8) -> Option<u8> {
                None
            }
            fn burst_start(&self) -> u8 {
                <$chip as Magnetometer>::BURST_START
            }
            fn spi_read_burst(&self, _start: u8, out: &mut [u8]) {
                out.fill(0x00);
            }
            fn fault_reset(&mut self) -> bool {
                <$chip>::fault_reset(self);
                true
            }
            fn fault_identity(&mut self, value: Option<u8>) -> bool {
                <$chip>::fault_identity(self, value);
                true
            }
            /// Neither chip has a FIFO: nothing can overflow.
            fn fault_fifo_overflow(&mut self, _on: bool) -> bool {
                false
            }
        }
    };
}

magnetometer_chip!(Ist8310);
magnetometer_chip!(Qmc5883l);
