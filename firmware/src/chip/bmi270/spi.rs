//! The SPI target (DS: 6.2 SPI interface, mode 0/3): the BMI270's registers behind the front
//! end it shares with the BMI088's accelerometer ([`BoschSpi`]: I2C until a chip-select rising
//! edge, one dummy byte before read data).

use margemu_protocol::regmap::bmi270::next_address;

use super::super::bosch_spi::BoschRegisters;
use super::super::spi_phase::SpiRegisters;
use super::super::{Bus, SpiTarget};
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

impl BoschRegisters for Bmi270 {
    fn take_soft_reset(&mut self) -> bool {
        core::mem::take(&mut self.soft_reset_seen)
    }
}

impl SpiTarget for Bmi270 {
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
