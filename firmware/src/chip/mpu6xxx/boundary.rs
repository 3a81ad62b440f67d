//! The InvenSense 6xxx family behind the chip boundary ([`Chip`]): model and identity, the
//! conversion settings, register overrides through the chip's own buses, and what the SPI
//! shadow needs to know about reads and writes.

use margemu_protocol::chip::{ChipModel, ChipSettings, Conversion, PhysicalSample};
use margemu_protocol::regmap::ak8963;
use margemu_protocol::regmap::mpu6xxx::{bits, is_read_only, next_address, reg, write_mask};

use super::super::{spi_read_burst_on_copy, Chip, I2cTarget, RegisterWrite, SpiTarget};
use super::Mpu6xxx;

/// Registers whose SPI write does more than store `value & write_mask` (resets, FIFO pushes,
/// transfers, registers a read does not return as stored).
const WRITE_SIDE_EFFECTS: [u8; 5] = [
    reg::PWR_MGMT_1,
    reg::USER_CTRL,
    reg::I2C_SLV4_CTRL,
    reg::FIFO_R_W,
    reg::MEM_R_W,
];

fn spi_write(chip: &mut Mpu6xxx, register: u8, value: u8) {
    chip.select();
    chip.exchange(register & 0x7F);
    chip.exchange(value);
    chip.deselect();
}

impl Mpu6xxx {
    /// Writes the AK8963's `register` through I2C bypass, INT_PIN_CFG and USER_CTRL restored
    /// afterwards (I2C_MST_EN last: it may start the auxiliary master).
    fn write_ak8963(&mut self, register: u8, value: u8) {
        let (pin_cfg, user_ctrl) = (self.peek(reg::INT_PIN_CFG), self.peek(reg::USER_CTRL));
        spi_write(self, reg::INT_PIN_CFG, pin_cfg | bits::INT_BYPASS_EN);
        spi_write(self, reg::USER_CTRL, user_ctrl & !bits::USER_I2C_MST_EN);
        if self.start(ak8963::I2C_ADDRESS, false) {
            I2cTarget::write(self, register);
            I2cTarget::write(self, value);
        }
        self.stop();
        spi_write(self, reg::USER_CTRL, user_ctrl & !bits::USER_I2C_MST_EN);
        spi_write(self, reg::INT_PIN_CFG, pin_cfg);
        if user_ctrl & bits::USER_I2C_MST_EN != 0 {
            spi_write(self, reg::USER_CTRL, user_ctrl);
        }
    }
}

impl Chip for Mpu6xxx {
    fn model(&self) -> ChipModel {
        self.config().variant.model()
    }
    fn settings(&self) -> ChipSettings {
        ChipSettings {
            model: Chip::model(self),
            conversion: Conversion::Mpu6xxx(self.image_config()),
        }
    }
    fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        Mpu6xxx::latch_image_at(self, image, now_ns);
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Mpu6xxx::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Mpu6xxx::advance(self, now_ns);
    }
    fn now_ns(&self) -> u64 {
        Mpu6xxx::now_ns(self)
    }
    fn sample_period_ns(&self) -> u64 {
        Mpu6xxx::sample_period_ns(self)
    }
    fn int_pin_at(&self, now_ns: u64) -> bool {
        Mpu6xxx::int_pin_at(self, now_ns)
    }
    fn int_open_drain(&self) -> bool {
        Mpu6xxx::int_open_drain(self)
    }
    fn int_pulse_end_ns(&self) -> Option<u64> {
        Mpu6xxx::int_pulse_end_ns(self)
    }
    fn pop_write(&mut self) -> Option<RegisterWrite> {
        Mpu6xxx::pop_write(self)
    }
    fn writes_dropped(&self) -> u32 {
        self.write_log().dropped()
    }
    /// File 0: the accel/gyro die over SPI; file 1: the AK8963 through I2C bypass (parts with
    /// the magnetometer only).
    fn write_register(&mut self, file: u8, register: u8, value: u8) -> bool {
        match file {
            0 => spi_write(self, register, value),
            1 if self.ak8963().is_some() => self.write_ak8963(register, value),
            _ => return false,
        }
        true
    }
    fn i2c_address(&self) -> u8 {
        Mpu6xxx::i2c_address(self)
    }
    fn spi_peek(&self, addr: u8) -> u8 {
        self.peek(addr)
    }
    fn spi_next_address(&self, addr: u8) -> u8 {
        next_address(addr & 0x7F)
    }
    fn spi_plain_write(&self, addr: u8, value: u8) -> Option<u8> {
        let addr = addr & 0x7F;
        (!is_read_only(addr) && !WRITE_SIDE_EFFECTS.contains(&addr))
            .then_some(value & write_mask(addr))
    }
    fn burst_start(&self) -> u8 {
        reg::ACCEL_XOUT_H
    }
    /// On a copy: FIFO_R_W pops, FIFO_COUNTH latches FIFO_COUNTL, status registers clear.
    fn spi_read_burst(&self, start: u8, out: &mut [u8]) {
        spi_read_burst_on_copy(self, start, out);
    }
    fn fault_reset(&mut self) -> bool {
        Mpu6xxx::fault_reset(self);
        true
    }
    fn fault_identity(&mut self, value: Option<u8>) -> bool {
        Mpu6xxx::fault_identity(self, value);
        true
    }
    fn fault_fifo_overflow(&mut self, on: bool) -> bool {
        Mpu6xxx::fault_fifo_overflow(self, on);
        true
    }
    /// The own address unless USER_CTRL.I2C_IF_DIS; the AK8963's in bypass mode.
    fn i2c_addresses_now(&self) -> [Option<u8>; 2] {
        let interface_on = self.peek(reg::USER_CTRL) & bits::USER_I2C_IF_DIS == 0;
        [
            interface_on.then(|| Mpu6xxx::i2c_address(self)),
            self.bypass_active().then_some(ak8963::I2C_ADDRESS),
        ]
    }
}
