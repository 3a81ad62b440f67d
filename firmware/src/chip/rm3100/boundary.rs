//! The RM3100 behind the chip boundary ([`Chip`]): an image is its result registers MX..=MZ
//! ([`map::IMAGE_LEN`] bytes, at the cycle counts the host predicted), held until the next
//! latch and copied into the results by each measurement; the conversion settings are the cycle
//! counts in force. SPI reads have side effects (DRDY clears on the results), so the SPI shadow's
//! burst runs on a copy; the DRDY pin is not emulated (the INT level reads low).

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::rm3100::{self as map, reg};

use super::super::{spi_read_burst_on_copy, Chip, I2cTarget, RegisterWrite};
use super::Rm3100;

impl Chip for Rm3100 {
    fn fault_reset(&mut self) -> bool {
        Rm3100::fault_reset(self);
        true
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        Rm3100::fault_identity(self, value);
        true
    }
    /// The RM3100 has no FIFO (one result set in its registers): nothing can overflow.
    fn fault_fifo_overflow(&mut self, _on: bool) -> bool {
        false
    }
    fn model(&self) -> ChipModel {
        ChipModel::Rm3100
    }
    fn settings(&self) -> ChipSettings {
        ChipSettings {
            model: ChipModel::Rm3100,
            conversion: Conversion::Rm3100(self.cycle_counts()),
        }
    }
    /// An image of another length only moves the clock.
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        match image.try_into() {
            Ok(image) => self.latch_raw_at(map::parse_image(image), now_ns),
            Err(_) => Rm3100::advance(self, now_ns),
        }
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Rm3100::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Rm3100::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Rm3100::now_ns(self)
    }
    /// The continuous-mode period (TMRC or the measurement, the longer), else one measurement
    /// of every axis.
    fn sample_period_ns(&self) -> u64 {
        let axes = map::axes(self.peek(reg::CMM));
        if self.is_continuous() {
            map::continuous_period_ns(self.peek(reg::TMRC), axes, self.cycle_counts())
        } else {
            map::measurement_ns(map::bits::AXES, self.cycle_counts())
        }
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
        if file != 0 {
            return false;
        }
        let address = self.i2c_address();
        let acked = self.start(address, false) && self.write(register) && self.write(value);
        self.stop();
        acked
    }
    fn i2c_address(&self) -> u8 {
        Rm3100::i2c_address(self)
    }
    fn spi_peek(&self, addr: u8) -> u8 {
        self.peek(addr & 0x7F)
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        map::next_address(addr & 0x7F)
    }
    /// Writes clear DRDY and may start measurements: never plain.
    fn spi_plain_write(&self, _addr: u8, _value: u8) -> Option<u8> {
        None
    }
    fn burst_start(&self) -> u8 {
        reg::MX
    }
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        spi_read_burst_on_copy(self, start, out);
    }
}
