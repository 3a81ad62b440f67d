//! The BMI088 behind the chip boundary ([`Chip`]): register overrides through each die's own
//! bus, and what the SPI shadow needs to know about the accelerometer die, the one on the
//! package's own chip select (the dummy byte, the FIFO port, plain writes).
//!
//! Register file 0 is the accelerometer die, file 1 the gyroscope die. Overrides are written
//! as a driver would, over I2C at the die's address while the accelerometer is in I2C mode, so
//! a fresh chip stays in it (an SPI write would switch it, and the device under test's own
//! first dummy read must still find it in I2C mode, as after power-on); the accelerometer over
//! SPI once it has switched. Before the switch an SPI read of the accelerometer returns 0x00 on
//! every byte and an SPI write does nothing, which [`Chip::spi_peek`] and
//! [`Chip::spi_plain_write`] say too.
//!
//! The interrupt pin a board drives is INT1, the accelerometer's (the package's first pin): high
//! while not an output (the pull-up), else asserted while a mapped source is, at the level and
//! drive INT1_IO_CONF sets. INT2 and the gyroscope's INT3/INT4 are not brought out.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::bmi088::accel::{bits, reg};
use margemu_protocol::regmap::bmi088::Die;

use super::super::bosch_spi::DUMMY;
use super::super::{spi_read_burst_on_copy, Chip, I2cTarget, RegisterWrite, SpiTarget};
use super::Bmi088;

/// Writes `value` to `register` of the die at I2C `address`, as one transaction.
fn i2c_write(die: &mut impl I2cTarget, address: u8, register: u8, value: u8) -> bool {
    let acked = die.start(address, false) && die.write(register & 0x7F) && die.write(value);
    die.stop();
    acked
}

impl Chip for Bmi088 {
    fn fault_reset(&mut self) -> bool {
        Bmi088::fault_reset(self);
        true
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        Bmi088::fault_identity(self, value);
        true
    }
    fn fault_fifo_overflow(&mut self, on: bool) -> bool {
        Bmi088::fault_fifo_overflow(self, on);
        true
    }
    fn model(&self) -> ChipModel {
        ChipModel::Bmi088
    }
    fn settings(&self) -> ChipSettings {
        ChipSettings {
            model: ChipModel::Bmi088,
            conversion: Conversion::Bmi088(self.image_config()),
        }
    }
    /// An image of another length than the model's is refused (nothing latched, the clock
    /// moves on).
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        match image.try_into() {
            Ok(image) => Bmi088::latch_image_at(self, image, now_ns),
            Err(_) => Bmi088::advance(self, now_ns),
        }
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Bmi088::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Bmi088::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Bmi088::now_ns(self)
    }
    fn sample_period_ns(&self) -> u64 {
        Bmi088::sample_period_ns(self)
    }
    fn int_pin_at(&self, _now_ns: u64) -> bool {
        self.accel.int1_pin().unwrap_or(true)
    }
    fn int_open_drain(&self) -> bool {
        let conf = self.accel.peek(reg::INT1_IO_CONF);
        conf & bits::INT_OD != 0 || conf & bits::INT_OUT == 0
    }
    /// INT1 is a level (data ready until the data is read, FIFO levels): no pulse.
    fn int_pulse_end_ns(&self) -> Option<u64> {
        None
    }
    /// The accelerometer's writes first, then the gyroscope's (each names its die's I2C
    /// address in [`RegisterWrite::device`]).
    fn pop_write(&mut self) -> Option<RegisterWrite> {
        self.accel.pop_write().or_else(|| self.gyro.pop_write())
    }
    fn writes_dropped(&self) -> u32 {
        let accel = self.accel.write_log().dropped();
        accel.wrapping_add(self.gyro.write_log().dropped())
    }
    /// File 0 the accelerometer, file 1 the gyroscope (see the module docs); `false` for any
    /// other file.
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
        match file {
            0 if self.accel.is_spi_mode() => {
                self.accel.select();
                self.accel.exchange(register & 0x7F);
                self.accel.exchange(value);
                self.accel.deselect();
                true
            }
            0 => {
                let address = self.accel.i2c_address();
                i2c_write(&mut self.accel, address, register, value)
            }
            1 => {
                let address = self.gyro.i2c_address();
                i2c_write(&mut self.gyro, address, register, value)
            }
            _ => false,
        }
    }
    /// The accelerometer's address (the one Configure names).
    fn i2c_address(&self) -> u8 {
        self.accel.i2c_address()
    }
    /// The accelerometer's while it listens on I2C, and the gyroscope's.
    fn i2c_addresses_now(&self) -> [Option<u8>; 2] {
        let accel = (!self.accel.is_spi_mode()).then_some(self.accel.i2c_address());
        [accel, Some(self.gyro.i2c_address())]
    }
    /// The accelerometer's register (without the dummy byte that precedes it on MISO); 0x00
    /// before the switch to SPI.
    fn spi_peek(&self, addr: u8) -> u8 {
        if self.accel.is_spi_mode() {
            self.accel.peek(addr & 0x7F)
        } else {
            0x00
        }
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        Die::Accel.next_address(addr & 0x7F)
    }
    /// ACC_SOFTRESET (commands), ACC_CONF (it also sets ERR_REG) and ACC_PWR_CTRL (it starts
    /// and stops the samples) do more than store.
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        let addr = addr & 0x7F;
        let mask = Die::Accel.write_mask(addr);
        let plain = self.accel.is_spi_mode()
            && mask != 0
            && !matches!(addr, reg::ACC_SOFTRESET | reg::ACC_CONF | reg::ACC_PWR_CTRL);
        plain.then(|| (self.accel.peek(addr) & !mask) | (value & mask))
    }
    /// ACC_X_LSB: PX4 and ArduPilot read the accelerometer's data (or FIFO) behind the dummy
    /// byte.
    fn burst_start(&self) -> u8 {
        reg::ACC_X_LSB
    }
    /// The dummy byte, FIFO_DATA pops and the SENSORTIME hold: the burst runs on a copy of the
    /// accelerometer die (its first byte is the dummy byte, as on MISO).
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        spi_read_burst_on_copy(&self.accel, start, out);
    }
    fn spi_read_dummy(&self) -> Option<u8> {
        self.accel.is_spi_mode().then_some(DUMMY)
    }
}
