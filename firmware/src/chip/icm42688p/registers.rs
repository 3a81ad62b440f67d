//! Register-file semantics shared by the SPI and I2C targets (DS register map and
//! descriptions): what a read
//! returns and changes, what a write stores and triggers.
//!
//! As in the 6xxx family a bus read is split in two so the SPI target can prefetch one byte
//! ahead: [`Icm42688p::read_register`] returns the value (and latches the FIFO count when
//! FIFO_COUNTH is read); [`Icm42688p::commit_read`] applies what clocking the byte out does —
//! popping the FIFO, clearing INT_STATUS bits.
//!
//! - Data registers (0x1D..=0x2A) are stored big-endian and read in the order
//!   INTF_CONFIG0.SENSOR_DATA_ENDIAN selects; FIFO_COUNTH/L in FIFO_COUNT_ENDIAN order, counting
//!   bytes or records (FIFO_COUNT_REC).
//! - INT_STATUS clears on read, except the bits INT_CONFIG0 sets to clear on a sensor-register
//!   read (DATA_RDY) or on a FIFO byte read (FIFO_THS, FIFO_FULL) (DS: INT_CONFIG0).
//! - DEVICE_CONFIG.SOFT_RESET_CONFIG: every bank to its reset values, RESET_DONE_INT set; the
//!   write log is kept. SIGNAL_PATH_RESET.FIFO_FLUSH (and ABORT_AND_RESET) empty the FIFO.
//! - Reserved addresses read 0 and ignore writes; reserved bits keep their reset value.

use margemu_protocol::regmap::icm42688p::{
    bank0, bits, reset_value, write_mask, BANKS, DATA_LEN, REG_BANK_SEL,
};

use super::super::Bus;
use super::Icm42688p;

/// Bank 0 data registers TEMP_DATA1..=GYRO_DATA_Z0.
pub(super) const DATA: core::ops::RangeInclusive<usize> =
    bank0::TEMP_DATA1 as usize..=bank0::GYRO_DATA_Z0 as usize;

impl Icm42688p {
    /// Soft reset (and power-on): every register to its reset value, FIFO and interrupts
    /// cleared, then RESET_DONE_INT.
    pub(super) fn soft_reset(&mut self) {
        for (bank, regs) in (0u8..).zip(self.banks.iter_mut()) {
            for (addr, value) in (0u8..).zip(regs.iter_mut()) {
                *value = reset_value(bank, addr);
            }
        }
        self.bank_sel = 0;
        self.pending = None;
        self.int_status = 0;
        self.int1 = Default::default();
        self.int2 = Default::default();
        self.fifo.flush();
        self.fifo_count_latch = [0; 2];
        self.afsr = Default::default();
        self.raise_interrupt(bits::RESET_DONE_INT);
    }

    /// The bank addresses currently reach (REG_BANK_SEL; 5–7 reach only REG_BANK_SEL).
    pub(super) fn bank(&self) -> u8 {
        self.bank_sel
    }

    fn stored(&self, bank: u8, addr: u8) -> u8 {
        self.banks
            .get(usize::from(bank))
            .and_then(|regs| regs.get(usize::from(addr & 0x7F)))
            .copied()
            .unwrap_or(0)
    }

    fn little_endian_data(&self) -> bool {
        self.reg0(bank0::INTF_CONFIG0) & bits::SENSOR_DATA_ENDIAN == 0
    }

    /// The FIFO count in the unit and byte order INTF_CONFIG0 selects, as (0x2E, 0x2F).
    fn fifo_count_bytes(&self) -> [u8; 2] {
        let cfg = self.reg0(bank0::INTF_CONFIG0);
        let count = self.fifo_count(cfg & bits::FIFO_COUNT_REC != 0);
        if cfg & bits::FIFO_COUNT_ENDIAN != 0 {
            count.to_be_bytes()
        } else {
            count.to_le_bytes()
        }
    }

    /// The value a read of `addr` in `bank` returns, without side effects.
    pub(super) fn peek_register(&self, bank: u8, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        if addr == REG_BANK_SEL {
            return self.bank_sel;
        }
        if bank != 0 {
            return self.stored(bank, addr);
        }
        match addr {
            a if DATA.contains(&usize::from(a)) => {
                let offset = usize::from(a) - DATA.start();
                let swapped = if self.little_endian_data() {
                    offset ^ 1
                } else {
                    offset
                };
                self.stored(0, (DATA.start() + swapped) as u8)
            }
            bank0::INT_STATUS => self.int_status,
            bank0::FIFO_COUNTH => self.fifo_count_bytes()[0],
            bank0::FIFO_COUNTL => self.fifo_count_latch[1],
            bank0::FIFO_DATA => self.fifo.peek().unwrap_or(0xFF),
            bank0::FIFO_LOST_PKT0 => self.fifo.lost().to_le_bytes()[0],
            bank0::FIFO_LOST_PKT1 => self.fifo.lost().to_le_bytes()[1],
            bank0::WHO_AM_I => self.fault.who_am_i.unwrap_or(self.config.who_am_i),
            _ => self.stored(0, addr),
        }
    }

    /// A bus read of `addr` in the selected bank: the value, latching the FIFO count when
    /// FIFO_COUNTH is read.
    pub(super) fn read_register(&mut self, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        if self.bank() == 0 && addr == bank0::FIFO_COUNTH {
            self.fifo_count_latch = self.fifo_count_bytes();
        }
        self.peek_register(self.bank(), addr)
    }

    /// The byte `value` read from `addr` was clocked out: apply the read's side effects.
    pub(super) fn commit_read(&mut self, addr: u8, value: u8) {
        if self.bank() != 0 {
            return;
        }
        match addr & 0x7F {
            bank0::INT_STATUS => {
                self.int_status &= !(value & self.cleared_by_status_read());
            }
            bank0::FIFO_DATA => {
                self.fifo.pop();
                let clear = self.cleared_by_fifo_read();
                self.int_status &= !clear;
            }
            // UI_DRDY_INT_CLEAR = 1x: a sensor-register read clears DATA_RDY.
            a if DATA.contains(&usize::from(a)) && self.reg0(bank0::INT_CONFIG0) & 0x20 != 0 => {
                self.int_status &= !bits::DATA_RDY_INT;
            }
            _ => {}
        }
    }

    /// INT_STATUS bits a status read clears: all but those INT_CONFIG0 sets to 10 (clear only
    /// by a data or FIFO read).
    fn cleared_by_status_read(&self) -> u8 {
        let cfg = self.reg0(bank0::INT_CONFIG0);
        let mut keep = 0;
        for (field, bit) in [
            (cfg >> 4, bits::DATA_RDY_INT),
            (cfg >> 2, bits::FIFO_THS_INT),
            (cfg, bits::FIFO_FULL_INT),
        ] {
            if field & 0x03 == 0x02 {
                keep |= bit;
            }
        }
        !keep
    }

    /// INT_STATUS bits a FIFO byte read clears (INT_CONFIG0 fields set to 1x).
    fn cleared_by_fifo_read(&self) -> u8 {
        let cfg = self.reg0(bank0::INT_CONFIG0);
        let mut clear = 0;
        if cfg & 0x08 != 0 {
            clear |= bits::FIFO_THS_INT;
        }
        if cfg & 0x02 != 0 {
            clear |= bits::FIFO_FULL_INT;
        }
        clear
    }

    /// A bus write of `value` to `addr` in the selected bank, logged.
    pub(super) fn write_register(&mut self, bus: Bus, addr: u8, value: u8) {
        let addr = addr & 0x7F;
        self.log_write(bus, addr, value);
        if addr == REG_BANK_SEL {
            self.bank_sel = value & 0x07;
            return;
        }
        let bank = self.bank();
        if bank >= BANKS {
            return;
        }
        match (bank, addr) {
            (0, bank0::DEVICE_CONFIG) if value & bits::SOFT_RESET_CONFIG != 0 => {
                self.soft_reset();
            }
            (0, bank0::SIGNAL_PATH_RESET) => {
                if value & (bits::FIFO_FLUSH | 0x08) != 0 {
                    self.fifo.flush();
                }
            }
            _ => {
                let mask = write_mask(bank, addr);
                if let Some(slot) = self
                    .banks
                    .get_mut(usize::from(bank))
                    .and_then(|regs| regs.get_mut(usize::from(addr)))
                {
                    *slot = (*slot & !mask) | (value & mask);
                }
                if (bank, addr) == (0, bank0::PWR_MGMT0) {
                    self.power_changed();
                }
            }
        }
    }

    /// The data registers the next sample builds on: the pending image, else the visible one.
    pub(super) fn latest_data(&self) -> [u8; DATA_LEN] {
        match &self.pending {
            Some(pending) => *pending,
            None => {
                let mut data = [0; DATA_LEN];
                data.copy_from_slice(&self.banks[0][DATA]);
                data
            }
        }
    }

    /// Makes `data` the data registers: at once if the bus is idle, else when it goes idle.
    pub(super) fn publish_data(&mut self, data: [u8; DATA_LEN]) {
        self.pending = Some(data);
        self.bus_went_idle();
    }

    /// Called when a transaction ends: a waiting sample becomes visible, and a partly read FIFO
    /// packet is rewound unless FIFO_RESUME_PARTIAL_RD.
    pub(super) fn bus_went_idle(&mut self) {
        if self.spi.is_active() || self.i2c.is_active() {
            return;
        }
        let resume = self.reg0(bank0::FIFO_CONFIG1) & bits::FIFO_RESUME_PARTIAL_RD != 0;
        self.fifo.end_transaction(resume);
        if let Some(data) = self.pending.take() {
            self.banks[0][DATA].copy_from_slice(&data);
        }
    }
}
