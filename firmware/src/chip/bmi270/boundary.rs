//! The BMI270 behind the chip boundary ([`Chip`]): register overrides through its own bus, and
//! what the SPI shadow needs to know about reads (the dummy byte, the FIFO port) and writes.
//!
//! Register overrides are written as a driver would, over I2C at the chip's own address while
//! the chip is in I2C mode, so a fresh chip stays in it (an SPI write would switch it to SPI,
//! and the device under test's own first dummy read must still find it in I2C mode, as after
//! power-on); over SPI once it has switched. Before the
//! switch to SPI an SPI read returns 0x00 on every byte and an SPI write does nothing, which
//! [`Chip::spi_peek`] and [`Chip::spi_plain_write`] say too.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::bmi270::{is_read_only, next_address, reg, write_mask};

use super::super::{spi_read_burst_on_copy, Chip, I2cTarget, RegisterWrite, SpiTarget};
use super::Bmi270;

/// Registers whose write does more than store the masked value: commands, the upload, the
/// power and interrupt modes (they change what later reads return).
const WRITE_SIDE_EFFECTS: [u8; 5] = [
    reg::CMD,
    reg::INIT_CTRL,
    reg::INIT_DATA,
    reg::PWR_CTRL,
    reg::INT_LATCH,
];

impl Chip for Bmi270 {
    fn fault_reset(&mut self) -> bool {
        Bmi270::fault_reset(self);
        true
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        Bmi270::fault_identity(self, value);
        true
    }
    fn fault_fifo_overflow(&mut self, on: bool) -> bool {
        Bmi270::fault_fifo_overflow(self, on);
        true
    }
    fn model(&self) -> ChipModel {
        ChipModel::Bmi270
    }
    fn settings(&self) -> ChipSettings {
        ChipSettings {
            model: ChipModel::Bmi270,
            conversion: Conversion::Bmi270(self.image_config()),
        }
    }
    /// An image shorter than the model's is refused (nothing latched, the clock moves on).
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        match image.try_into() {
            Ok(image) => Bmi270::latch_image_at(self, image, now_ns),
            Err(_) => Bmi270::advance(self, now_ns),
        }
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Bmi270::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Bmi270::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Bmi270::now_ns(self)
    }
    /// The gyro ODR, or the accel ODR while only the accel runs; the gyro ODR while both are
    /// off.
    fn sample_period_ns(&self) -> u64 {
        Bmi270::sample_period_ns(self).unwrap_or_else(|| self.gyro_period_ns())
    }
    fn int_pin_at(&self, now_ns: u64) -> bool {
        Bmi270::int_pin_at(self, now_ns)
    }
    fn int_open_drain(&self) -> bool {
        Bmi270::int_open_drain(self)
    }
    fn int_pulse_end_ns(&self) -> Option<u64> {
        Bmi270::int_pulse_end_ns(self)
    }
    fn pop_write(&mut self) -> Option<RegisterWrite> {
        Bmi270::pop_write(self)
    }
    fn writes_dropped(&self) -> u32 {
        self.write_log().dropped()
    }
    /// File 0, the one register page, written over I2C while the chip is in I2C mode (see the
    /// module docs), over SPI once it has switched; `false` for any other file.
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
        if file != 0 {
            return false;
        }
        if self.is_spi_mode() {
            self.select();
            self.exchange(register & 0x7F);
            self.exchange(value);
            self.deselect();
            return true;
        }
        let address = Bmi270::i2c_address(self);
        let acked = self.start(address, false)
            && I2cTarget::write(self, register & 0x7F)
            && I2cTarget::write(self, value);
        self.stop();
        acked
    }
    fn i2c_address(&self) -> u8 {
        Bmi270::i2c_address(self)
    }
    /// The register's value (without the dummy byte that precedes it on MISO); 0x00 before
    /// the switch to SPI.
    fn spi_peek(&self, addr: u8) -> u8 {
        if self.is_spi_mode() {
            self.peek(addr & 0x7F)
        } else {
            0x00
        }
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        next_address(addr & 0x7F)
    }
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        let addr = addr & 0x7F;
        let mask = write_mask(addr);
        let plain = self.is_spi_mode()
            && mask != 0
            && !is_read_only(addr)
            && !WRITE_SIDE_EFFECTS.contains(&addr);
        plain.then(|| (self.peek(addr) & !mask) | (value & mask))
    }
    /// ACC_X_LSB: Betaflight reads 0x0C..=0x17 (behind the dummy byte) on every data-ready.
    fn burst_start(&self) -> u8 {
        reg::ACC_X_LSB
    }
    /// The dummy byte, FIFO_DATA pops and the SENSORTIME hold: the burst runs on a copy (its
    /// first byte is the dummy byte, as on MISO).
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        spi_read_burst_on_copy(self, start, out);
    }
    fn spi_read_dummy(&self) -> Option<u8> {
        self.is_spi_mode().then_some(super::super::bosch_spi::DUMMY)
    }
}
