//! Register-file semantics shared by the SPI and I2C targets: what a read returns and changes,
//! what a write stores and triggers (RM-MPU-9250A-00 section 4; the other parts' differences,
//! reset values and missing registers come from `regmap::mpu6xxx::variant`).
//!
//! A register the part lacks reads 0x00 and ignores writes (they are still logged: the log is
//! what the device under test wrote). SIGNAL_PATH_RESET's bits self-clear; GYRO_RST (bit 2) and
//! ACCEL_RST (bit 1) restart that sensor's sample clock, so the next latch takes a fresh value;
//! the data registers keep their values (RM section 4.28: only USER_CTRL.SIG_COND_RST clears
//! them).
//!
//! A bus read is split in two so the SPI target can prefetch one byte ahead:
//! [`Mpu6xxx::read_register`] returns the value (and may latch FIFO_COUNT, which is harmless if
//! the byte is never clocked out); [`Mpu6xxx::commit_read`] applies what clocking the byte out
//! does — popping the FIFO, clearing INT_STATUS or I2C_MST_STATUS. The I2C target commits at once.

use margemu_protocol::regmap::mpu6xxx::variant::extra_reg;
use margemu_protocol::regmap::mpu6xxx::{bits, reg, DATA_LEN, SENSOR_LEN};

use super::super::Bus;
use super::Mpu6xxx;

const DATA: core::ops::RangeInclusive<usize> =
    reg::ACCEL_XOUT_H as usize..=reg::EXT_SENS_DATA_23 as usize;

impl Mpu6xxx {
    /// Device reset (PWR_MGMT_1.H_RESET, and power-on): every register to its reset value with
    /// the part's factory trim; FIFO, interrupt and master state cleared. The AK8963 is a
    /// separate die and keeps its state.
    pub(super) fn device_reset(&mut self) {
        let variant = self.config.variant;
        for (addr, value) in (0u8..).zip(self.regs.iter_mut()) {
            *value = variant.reset_value(addr);
        }
        let trim = &self.config;
        for (&addr, value) in variant.self_test_registers().iter().zip(trim.self_test) {
            self.regs[usize::from(addr & 0x7F)] = value;
        }
        let offsets = variant.accel_offset_registers();
        for (addr, value) in offsets.into_iter().zip(trim.accel_offset) {
            let addr = usize::from(addr.min(0x7E));
            self.regs[addr..addr + 2].copy_from_slice(&value.to_be_bytes());
        }
        self.pending = None;
        self.int_status = 0;
        self.int_pulse_ns = None;
        self.mst_status = 0;
        self.fifo.clear();
        self.fifo.forget_last_read();
        self.fifo_count_latch = 0;
        self.aux = Default::default();
        self.accel_clock.restart();
        self.gyro_clock.restart();
    }

    /// The value a read of `addr` returns, without side effects.
    pub(super) fn peek_register(&self, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        if !self.config.variant.has_register(addr) {
            return 0x00;
        }
        match addr {
            reg::INT_STATUS => self.int_status,
            reg::I2C_MST_STATUS => self.mst_status,
            reg::FIFO_COUNTH => (self.fifo.len() >> 8) as u8 & 0x1F,
            reg::FIFO_COUNTL => self.fifo_count_latch as u8,
            reg::FIFO_R_W => self.fifo.peek(),
            reg::WHO_AM_I => self
                .fault
                .who_am_i
                .unwrap_or(self.config.variant.who_am_i()),
            reg::MEM_R_W => 0x00, // DMP memory is not emulated
            _ => self.regs[usize::from(addr)],
        }
    }

    /// A bus read of `addr`: the value, latching FIFO_COUNT when FIFO_COUNTH is read.
    pub(super) fn read_register(&mut self, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        if addr == reg::FIFO_COUNTH {
            self.fifo_count_latch = self.fifo.len();
        }
        self.peek_register(addr)
    }

    /// The byte `value` read from `addr` was clocked out: apply the read's side effects.
    pub(super) fn commit_read(&mut self, addr: u8, value: u8) {
        let addr = addr & 0x7F;
        match addr {
            reg::FIFO_R_W => self.fifo.pop(),
            reg::INT_STATUS => self.int_status &= !value,
            reg::I2C_MST_STATUS => self.mst_status &= !value,
            _ => {}
        }
        if self.regs[usize::from(reg::INT_PIN_CFG)] & bits::INT_ANYRD_2CLEAR != 0 {
            self.int_status = 0;
        }
    }

    /// A bus write of `value` to `addr`, logged.
    pub(super) fn write_register(&mut self, bus: Bus, addr: u8, value: u8) {
        let addr = addr & 0x7F;
        self.log_write(bus, self.i2c_address(), addr, value);
        match addr {
            reg::FIFO_R_W => self.fifo_push(&[value]),
            reg::PWR_MGMT_1 if value & bits::PWR1_H_RESET != 0 => self.device_reset(),
            _ if self.config.variant.is_read_only(addr) => {}
            _ => {
                let slot = &mut self.regs[usize::from(addr)];
                *slot = value & self.config.variant.write_mask(addr);
                match addr {
                    reg::USER_CTRL => self.user_ctrl_actions(value),
                    reg::I2C_SLV4_CTRL => self.slv4_transfer(),
                    reg::SIGNAL_PATH_RESET => self.signal_path_reset(value),
                    _ => {}
                }
            }
        }
    }

    /// SIGNAL_PATH_RESET: GYRO_RST (bit 2, where the part has it) and ACCEL_RST (bit 1)
    /// restart that sensor's sample clock; TEMP_RST has nothing to restart (the temperature is
    /// taken at every latch).
    fn signal_path_reset(&mut self, value: u8) {
        let mask = self
            .config
            .variant
            .self_clearing_mask(reg::SIGNAL_PATH_RESET);
        if value & mask & 0x04 != 0 {
            self.gyro_clock.restart();
        }
        if value & mask & 0x02 != 0 {
            self.accel_clock.restart();
        }
    }

    /// Whether the primary I2C interface is disabled (USER_CTRL or, on the ICM-20602, I2C_IF).
    pub(super) fn i2c_interface_disabled(&self) -> bool {
        self.config.variant.i2c_disabled(
            self.regs[usize::from(reg::USER_CTRL)],
            self.regs[usize::from(extra_reg::ICM20602_I2C_IF)],
        )
    }

    fn user_ctrl_actions(&mut self, value: u8) {
        if value & bits::USER_FIFO_RST != 0 {
            self.fifo.clear();
        }
        if value & bits::USER_I2C_MST_RST != 0 {
            self.aux = Default::default();
            self.mst_status = 0;
        }
        if value & bits::USER_SIG_COND_RST != 0 {
            // "This bit also clears all the sensor registers" (accel, temperature, gyro).
            self.regs[DATA][..SENSOR_LEN].fill(0);
            if let Some(pending) = &mut self.pending {
                pending[..SENSOR_LEN].fill(0);
            }
            self.accel_clock.restart();
            self.gyro_clock.restart();
        }
        self.slv4_transfer(); // a transfer waiting for the master to be enabled
    }

    /// The data registers the next sample builds on: the pending image, else the visible one.
    pub(super) fn latest_data(&self) -> [u8; DATA_LEN] {
        match &self.pending {
            Some(pending) => *pending,
            None => {
                let mut data = [0; DATA_LEN];
                data.copy_from_slice(&self.regs[DATA]);
                data
            }
        }
    }

    /// Makes `data` the data registers: at once if the bus is idle, else when it goes idle.
    pub(super) fn publish_data(&mut self, data: [u8; DATA_LEN]) {
        self.pending = Some(data);
        self.bus_went_idle();
    }

    /// Called when a transaction ends: a waiting sample becomes visible.
    pub(super) fn bus_went_idle(&mut self) {
        if self.spi.is_active() || self.i2c.is_active() {
            return;
        }
        // Without an auxiliary master the bytes after the sensors are other registers (the
        // ICM-20602's FIFO_WM_TH1 at 0x60): only the sensor bytes are data there.
        let len = if self.config.variant.has_aux_master() {
            DATA_LEN
        } else {
            SENSOR_LEN
        };
        if let Some(data) = self.pending.take() {
            self.regs[DATA][..len].copy_from_slice(&data[..len]);
        }
    }
}
