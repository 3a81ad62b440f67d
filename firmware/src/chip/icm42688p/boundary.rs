//! The ICM-42688-P behind the chip boundary ([`Chip`]): register overrides by bank through its
//! own SPI target, and what the SPI shadow needs to know about reads and writes.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::icm42688p::{
    bank0, is_read_only, next_address, self_clearing_mask, write_mask, REG_BANK_SEL,
};

use super::super::{spi_read_burst_on_copy, Chip, RegisterWrite, SpiTarget};
use super::Icm42688p;

/// Bank 0 registers whose write does more than store the masked value: resets, power-mode
/// changes, FIFO and interface reconfiguration, interrupt routing.
const WRITE_SIDE_EFFECTS: [u8; 8] = [
    bank0::DEVICE_CONFIG,
    bank0::SIGNAL_PATH_RESET,
    bank0::PWR_MGMT0,
    bank0::FIFO_CONFIG,
    bank0::FIFO_CONFIG1,
    bank0::INTF_CONFIG0,
    bank0::INT_CONFIG,
    bank0::TMST_CONFIG,
];

fn spi_write(chip: &mut Icm42688p, register: u8, value: u8) {
    chip.select();
    chip.exchange(register & 0x7F);
    chip.exchange(value);
    chip.deselect();
}

impl Chip for Icm42688p {
    fn model(&self) -> ChipModel {
        ChipModel::Icm42688p
    }
    fn settings(&self) -> ChipSettings {
        ChipSettings {
            model: ChipModel::Icm42688p,
            conversion: Conversion::Icm42688p(self.image_config()),
        }
    }
    /// An image shorter than the model's is refused (nothing latched, the clock moves on).
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        match image.try_into() {
            Ok(image) => Icm42688p::latch_image_at(self, image, now_ns),
            Err(_) => Icm42688p::advance(self, now_ns),
        }
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Icm42688p::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Icm42688p::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Icm42688p::now_ns(self)
    }
    fn sample_period_ns(&self) -> u64 {
        Icm42688p::sample_period_ns(self)
    }
    fn int_pin_at(&self, now_ns: u64) -> bool {
        Icm42688p::int_pin_at(self, now_ns)
    }
    fn int_open_drain(&self) -> bool {
        Icm42688p::int_open_drain(self)
    }
    fn int_pulse_end_ns(&self) -> Option<u64> {
        Icm42688p::int_pulse_end_ns(self)
    }
    fn pop_write(&mut self) -> Option<RegisterWrite> {
        Icm42688p::pop_write(self)
    }
    fn writes_dropped(&self) -> u32 {
        self.write_log().dropped()
    }
    /// File `n` is bank `n` (0–4): REG_BANK_SEL is switched for the write and restored.
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
        if file > 4 {
            return false;
        }
        let bank = self.bank();
        spi_write(self, REG_BANK_SEL, file);
        spi_write(self, register, value);
        spi_write(self, REG_BANK_SEL, bank);
        true
    }
    fn i2c_address(&self) -> u8 {
        Icm42688p::i2c_address(self)
    }
    fn spi_peek(&self, addr: u8) -> u8 {
        self.peek(self.bank(), addr & 0x7F)
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        next_address(self.bank(), addr & 0x7F)
    }
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        let (bank, addr) = (self.bank(), addr & 0x7F);
        let mask = write_mask(bank, addr);
        let plain = addr != REG_BANK_SEL
            && bank <= 4
            && mask != 0
            && self_clearing_mask(bank, addr) == 0
            && !is_read_only(bank, addr)
            && !(bank == 0 && WRITE_SIDE_EFFECTS.contains(&addr));
        plain.then(|| (self.peek(bank, addr) & !mask) | (value & mask))
    }
    fn burst_start(&self) -> u8 {
        bank0::TEMP_DATA1
    }
    fn fault_reset(&mut self) -> bool {
        Icm42688p::fault_reset(self);
        true
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        Icm42688p::fault_identity(self, value);
        true
    }
    fn fault_fifo_overflow(&mut self, on: bool) -> bool {
        Icm42688p::fault_fifo_overflow(self, on);
        true
    }
    /// FIFO_DATA pops and FIFO_COUNTH latches the count: the burst runs on a copy.
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        spi_read_burst_on_copy(self, start, out);
    }
}
