//! The SPI target (DS: 6.2 SPI interface, mode 0/3): the BMI270's registers behind the front
//! end it shares with the BMI088's accelerometer (`bosch_spi.rs`: I2C until a chip-select rising
//! edge, one dummy byte before read data).

use margemu_protocol::regmap::bmi270::next_address;

use super::super::bosch_spi::bosch_spi_target;
use super::super::spi_phase::SpiRegisters;
use super::super::Bus;
use super::Bmi270;

impl SpiRegisters for Bmi270 {
    fn prefetch(&mut self, addr: u8) -> u8 {
        self.read_register(addr)
    }
    fn commit(&mut self, addr: u8, value: u8) {
        self.commit_read(addr, value);
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.write_register(Bus::Spi, addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        next_address(addr)
    }
}

bosch_spi_target!(Bmi270);
