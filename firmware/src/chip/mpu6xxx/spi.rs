//! The SPI target (PS-MPU-9250A-01 section 7.5) on the shared state machine
//! ([`SpiPhase`]): bursts move to the next register except on FIFO_R_W and MEM_R_W, which stay.

use margemu_protocol::regmap::mpu6xxx::next_address;

use super::super::spi_phase::{SpiPhase, SpiRegisters};
use super::super::{Bus, SpiTarget};
use super::Mpu6xxx;

impl SpiRegisters for Mpu6xxx {
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

impl SpiTarget for Mpu6xxx {
    fn select(&mut self) -> u8 {
        self.spi = SpiPhase::Address;
        0x00
    }

    fn exchange(&mut self, mosi: u8) -> u8 {
        let (phase, miso) = self.spi.step(mosi, self);
        self.spi = phase;
        miso
    }

    fn deselect(&mut self) {
        self.spi = SpiPhase::Idle;
        self.bus_went_idle();
    }
}
