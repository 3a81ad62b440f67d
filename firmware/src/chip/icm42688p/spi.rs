//! The SPI target (DS: SPI interface, 4-wire mode 0/3) on the shared state machine
//! ([`SpiPhase`]): the address byte names a register of the bank REG_BANK_SEL selects, and
//! bursts move to the next register except on FIFO_DATA, which stays.

use margemu_protocol::regmap::icm42688p::next_address;

use super::super::spi_phase::{SpiPhase, SpiRegisters};
use super::super::{Bus, SpiTarget};
use super::Icm42688p;

impl SpiRegisters for Icm42688p {
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
        next_address(self.bank(), addr)
    }
}

impl SpiTarget for Icm42688p {
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
