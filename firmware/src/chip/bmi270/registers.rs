//! Register-file semantics (DS: register description): what a read returns and changes, what a
//! write stores and triggers.
//!
//! As for the other chips a bus read is split in two so the SPI target can prefetch one byte
//! ahead: [`Bmi270::read_register`] returns the value (and holds SENSORTIME when SENSORTIME_0
//! is read); [`Bmi270::commit_read`] applies what clocking the byte out does: clearing STATUS
//! drdy_acc / drdy_gyr on a data read, EVENT on its read, popping a FIFO_DATA byte.
//!
//! - CMD 0xB6: soft reset, every register to its power-on value and the interface back to I2C;
//!   the write log is kept. CMD 0xB0: FIFO flush. Other commands are ignored.
//! - INT_STATUS_1 reads the data-ready flags (`interrupts.rs`) and clears them.
//! - A write to a register that sets a rate or a source (ACC_CONF, GYR_CONF, FIFO_DOWNS,
//!   FIFO_CONFIG_1, PWR_CTRL) restarts the slower sensors' and the FIFO's dividers: the next
//!   latch takes every enabled sensor.
//! - Read-only and reserved registers ignore writes; listed registers keep the bits outside
//!   their fields at 0 ([`write_mask`]); CMD reads 0.

use margemu_protocol::regmap::bmi270::convert::{sensortime, sensortime_bytes};
use margemu_protocol::regmap::bmi270::{bits, reg, reset_value, write_mask};

use super::super::{Bus, RegisterWrite};
use super::sample::Ticks;
use super::upload::Upload;
use super::Bmi270;

/// Registers whose write restarts the rate dividers.
const RATE_REGISTERS: [u8; 5] = [
    reg::ACC_CONF,
    reg::GYR_CONF,
    reg::FIFO_DOWNS,
    reg::FIFO_CONFIG_1,
    reg::PWR_CTRL,
];

impl Bmi270 {
    /// Soft reset (and power-on): registers to their reset values, upload and latches cleared.
    /// A reset commanded over the bus also sets `soft_reset_seen`, which the SPI front end takes
    /// to go back to I2C mode (and the I2C target to end its transaction).
    pub(super) fn soft_reset(&mut self) {
        for (addr, value) in (0u8..).zip(self.regs.iter_mut()) {
            *value = reset_value(addr);
        }
        self.pending = None;
        self.upload = Upload::default();
        self.fifo.flush();
        self.sensortime_hold = None;
        self.ticks = Ticks::default();
        self.int_reset();
    }

    /// What a read of `addr` returns now, without side effects.
    pub(super) fn value_of(&self, addr: u8) -> u8 {
        match addr {
            reg::SENSORTIME_0..=reg::SENSORTIME_2 => {
                let ticks = self.sensortime_hold.unwrap_or(sensortime(self.now_ns));
                let bytes = sensortime_bytes(ticks);
                bytes
                    .get(usize::from(addr - reg::SENSORTIME_0))
                    .copied()
                    .unwrap_or(0)
            }
            reg::FIFO_LENGTH_0 | reg::FIFO_LENGTH_1 => self.fifo_length_byte(addr),
            reg::INT_STATUS_1 => self.int_status_1(),
            reg::FIFO_DATA => self.fifo.peek().unwrap_or(bits::FIFO_EMPTY),
            reg::CMD | reg::INIT_DATA => 0,
            reg::CHIP_ID => self.fault.chip_id.unwrap_or(self.stored(addr)),
            _ => self.stored(addr),
        }
    }

    /// The value a bus read of `addr` clocks out; a read of SENSORTIME_0 holds the time.
    pub(super) fn read_register(&mut self, addr: u8) -> u8 {
        if addr == reg::SENSORTIME_0 {
            self.sensortime_hold = Some(sensortime(self.now_ns));
        }
        self.value_of(addr)
    }

    /// `addr` was read: its side effects apply.
    pub(super) fn commit_read(&mut self, addr: u8, _value: u8) {
        let clear = match addr {
            0x0C..=0x11 => bits::DRDY_ACC,
            0x12..=0x17 => bits::DRDY_GYR,
            reg::FIFO_DATA => {
                self.fifo.pop();
                return;
            }
            reg::EVENT => {
                self.set(reg::EVENT, 0);
                return;
            }
            reg::INT_STATUS_1 => {
                self.int_status_1_read();
                return;
            }
            _ => return,
        };
        let status = self.stored(reg::STATUS) & !clear;
        self.set(reg::STATUS, status);
    }

    /// A byte written to `addr` over `bus`.
    pub(super) fn write_register(&mut self, bus: Bus, addr: u8, value: u8) {
        if addr == reg::INIT_DATA {
            let init_ctrl = self.stored(reg::INIT_CTRL);
            let word = self.init_word_address();
            self.upload.store(word, init_ctrl);
            return;
        }
        self.log.push(RegisterWrite {
            bus,
            device: self.i2c_address(),
            register: addr,
            value,
        });
        match addr {
            reg::CMD => {
                if value == bits::CMD_SOFT_RESET {
                    self.soft_reset();
                    self.soft_reset_seen = true;
                } else if value == bits::CMD_FIFO_FLUSH {
                    self.fifo_flush();
                }
            }
            reg::INIT_CTRL => {
                let old = self.stored(reg::INIT_CTRL);
                self.set(reg::INIT_CTRL, value);
                self.init_ctrl_written(old, value);
            }
            _ => {
                let mask = write_mask(addr);
                let stored = (self.stored(addr) & !mask) | (value & mask);
                self.set(addr, stored);
                if RATE_REGISTERS.contains(&addr) {
                    self.ticks = Ticks::default();
                }
            }
        }
    }

    /// The upload's word address, INIT_ADDR_1 << 4 | INIT_ADDR_0 bits 3:0.
    fn init_word_address(&self) -> u16 {
        u16::from(self.stored(reg::INIT_ADDR_1)) << 4
            | u16::from(self.stored(reg::INIT_ADDR_0) & 0x0F)
    }

    /// INIT_CTRL 0 begins a load; 0 → 1 ends it and reports in INTERNAL_STATUS.
    fn init_ctrl_written(&mut self, old: u8, new: u8) {
        let message = if new == 0 {
            self.upload = Upload::default();
            bits::MSG_NOT_INIT
        } else if old & 1 == 0 && new & 1 == 1 {
            if self.upload.is_complete() {
                bits::MSG_INIT_OK
            } else {
                bits::MSG_INIT_ERR
            }
        } else {
            return;
        };
        let status = (self.stored(reg::INTERNAL_STATUS) & !bits::MSG_MASK) | message;
        self.set(reg::INTERNAL_STATUS, status);
    }

    /// The transaction ended: bursts end, held values are released, a waiting sample appears.
    pub(super) fn bus_went_idle(&mut self) {
        self.upload.end_burst();
        self.fifo.end_burst();
        self.sensortime_hold = None;
        if let Some((latch, drdy)) = self.pending.take() {
            self.show(&latch, drdy);
        }
    }
}
