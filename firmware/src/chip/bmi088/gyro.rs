//! The gyroscope die (DS 5.4, 5.5; AN 4), register by register.
//!
//! - **Interface**: SPI as the other chips (read flag 0x80, no dummy byte, bursts increment
//!   except on FIFO_DATA), or I2C; the PS pin, not modelled, decides which on a real board.
//! - **Power** (DS 4.1.2, 5.5.6): samples are taken in normal mode (GYRO_LPM1 = 0x00). Suspend
//!   (0x80) keeps the registers and the last data; deep suspend (0x20) loses the configuration
//!   (every register back to its reset value); switching between the two suspend modes is not
//!   allowed and such a write is ignored. Other values stop the samples too.
//! - **Data**: RATE_X..Z at 0x02–0x07 little-endian at GYRO_RANGE (bits 2:0).
//!   GYRO_INT_STAT_1.data_int is set by a sample while GYRO_INT_CTRL.data_en is set and clears
//!   280 µs later (DS 4.7.2: 280–400 µs); bit 4 fifo_int while GYRO_INT_CTRL.fifo_en and either
//!   the watermark (FIFO_WM_ENABLE bit 7, level FIFO_CONFIG_0 bits 6:0 ≥ 1) is reached or the
//!   FIFO is full (AN 4.4).
//! - **GYRO_BANDWIDTH** bit 7 always reads 1; bits 3:0 choose ODR and filter (DS 5.5.5).
//! - **GYRO_SOFTRESET** = 0xB6 resets every register (other values are ignored); it reads 0.
//! - **GYRO_SELF_TEST**: rate_ok (bit 4) reads 1 in normal mode; writing trig_bist makes
//!   bist_rdy read 1 with bist_fail 0 (the test passes at once).
//! - **FIFO**: see [`gyro_fifo`](super::gyro_fifo); on only in FIFO (0x40) or stream
//!   (0x80) mode; writing FIFO_CONFIG_0 or FIFO_CONFIG_1 empties it and clears the overrun flag
//!   (AN 4.3, 4.4, 4.5.9).
//! - **INT3/INT4** ([`Bmi088Gyro::int3_pin`]): asserted while a mapped source is (the
//!   data-ready pulse, fifo_int), at the level INT3_INT4_IO_CONF sets (reset 0x0F: active high,
//!   open drain).
//!
//! Not emulated: the 30 ms reset and mode-change times, the suspend-mode write spacing, the
//! external FIFO synchronisation (FIFO_EXT_INT_S and the FIFO_CONFIG_0 tag bit are stored only),
//! the MSB lock between separate transactions.

use margemu_protocol::regmap::bmi088::convert::gyro_to_raw;
use margemu_protocol::regmap::bmi088::gyro::{
    bits, reg, Bandwidth, GyroRange, DATA_LEN, I2C_ADDRESS,
};
use margemu_protocol::regmap::bmi088::Die;

use super::super::spi_phase::{SpiPhase, SpiRegisters};
use super::super::write_log::{Bus, RegisterWrite, WriteLog};
use super::super::{PhysicalSample, SpiTarget};
use super::faults::DieFaults;
use super::gyro_fifo::GyroFifo;
use super::i2c::{I2cPort, I2cRegisters};
use super::{pin_level, put_le, Regs, WRITE_LOG_LEN};

const DIE: Die = Die::Gyro;

/// How long GYRO_INT_STAT_1.data_int and a mapped data-ready pin stay asserted, ns.
pub const DRDY_PULSE_NS: u64 = 280_000;

/// The emulated BMI088 gyroscope die (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Bmi088Gyro {
    regs: Regs,
    /// A newer sample waiting for the bus to go idle.
    pending: Option<[u8; 6]>,
    spi: SpiPhase,
    i2c: I2cPort,
    pointer: u8,
    i2c_address: u8,
    fifo: GyroFifo,
    /// When the last sample was taken (the data-ready pulse starts there).
    drdy_at: Option<u64>,
    bist_done: bool,
    now_ns: u64,
    log: WriteLog<WRITE_LOG_LEN>,
    /// The fault hooks' overrides (`faults.rs`), kept across resets.
    pub(super) fault: DieFaults,
}

impl Default for Bmi088Gyro {
    fn default() -> Self {
        Self::new()
    }
}

impl Bmi088Gyro {
    /// A die just powered on (normal mode), SDO2 at GND (I2C 0x68).
    pub fn new() -> Self {
        Self::with_sdo(false)
    }

    /// A die just powered on, SDO2 at VDDIO (`true`, I2C 0x69) or GND.
    pub fn with_sdo(sdo_high: bool) -> Self {
        Self {
            regs: Regs::power_on(DIE),
            pending: None,
            spi: SpiPhase::Idle,
            i2c: I2cPort::Idle,
            pointer: 0,
            i2c_address: I2C_ADDRESS | u8::from(sdo_high),
            fifo: GyroFifo::default(),
            drdy_at: None,
            bist_done: false,
            now_ns: 0,
            log: WriteLog::new(),
            fault: DieFaults::default(),
        }
    }

    /// Power cycle: every register to its power-on value, time kept.
    pub fn power_cycle(&mut self) {
        self.soft_reset();
        self.spi = SpiPhase::Idle;
        self.i2c = I2cPort::Idle;
    }

    /// The 7-bit I2C address.
    pub fn i2c_address(&self) -> u8 {
        self.i2c_address
    }

    /// Whether the die is in normal mode (GYRO_LPM1 = 0x00), taking samples.
    pub fn is_normal(&self) -> bool {
        self.regs.get(reg::LPM1) == bits::PM_NORMAL
    }

    /// The value a bus read of `addr` would return now, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        self.value_of(addr)
    }

    /// The die's time, ns since power-on.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The sample period at GYRO_BANDWIDTH's ODR in normal mode; `None` otherwise.
    pub fn sample_period_ns(&self) -> Option<u64> {
        self.is_normal()
            .then(|| Bandwidth::from_reg(self.regs.get(reg::BANDWIDTH)).period_ns())
    }

    /// Latches `sample` at die time `now_ns` (see the [module docs](self)).
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let range = GyroRange::from_reg(self.regs.get(reg::RANGE));
        let mut data = [0; DATA_LEN];
        put_le(&mut data, sample.gyr.map(|w| gyro_to_raw(w, range)));
        self.latch_data(data, now_ns);
    }

    /// Latches RATE_X..Z as the registers hold them (`data`) at die time `now_ns`, as
    /// [`Bmi088Gyro::latch_at`] does with the values it converts.
    pub fn latch_data(&mut self, data: [u8; DATA_LEN], now_ns: u64) {
        self.advance(now_ns);
        if !self.is_normal() {
            return;
        }
        self.drdy_at = Some(self.now_ns);
        self.fifo_push(data);
        if self.spi.is_active() || self.i2c != I2cPort::Idle {
            self.pending = Some(data);
        } else {
            self.show(data);
        }
    }

    /// Moves the die's time to `now_ns` (never backwards).
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
    }

    /// The level of INT3 (`true` = high; open drain shows the inactive level as high).
    pub fn int3_pin(&self) -> bool {
        let map = self.regs.get(reg::INT3_INT4_IO_MAP);
        let asserted = (map & bits::INT3_DATA != 0 && self.data_int())
            || (map & bits::INT3_FIFO != 0 && self.fifo_int());
        let conf = self.regs.get(reg::INT3_INT4_IO_CONF);
        pin_level(asserted, conf & bits::INT3_LVL != 0)
    }

    /// The level of INT4, as [`Bmi088Gyro::int3_pin`].
    pub fn int4_pin(&self) -> bool {
        let map = self.regs.get(reg::INT3_INT4_IO_MAP);
        let asserted = (map & bits::INT4_DATA != 0 && self.data_int())
            || (map & bits::INT4_FIFO != 0 && self.fifo_int());
        let conf = self.regs.get(reg::INT3_INT4_IO_CONF);
        pin_level(asserted, conf & (bits::INT3_LVL << 2) != 0)
    }

    /// The oldest register write not yet drained.
    pub fn pop_write(&mut self) -> Option<RegisterWrite> {
        self.log.pop()
    }

    /// The register write log.
    pub fn write_log(&self) -> &WriteLog<WRITE_LOG_LEN> {
        &self.log
    }

    fn fifo_push(&mut self, data: [u8; 6]) {
        let config = self.regs.get(reg::FIFO_CONFIG_1);
        let stream = match config & bits::FIFO_MODE_MASK {
            bits::FIFO_MODE_FIFO => false,
            bits::FIFO_MODE_STREAM => true,
            _ => return,
        };
        let (frame, len) = match config & bits::FIFO_DATA_SELECT {
            0 => (data, 6),
            axis => {
                let at = usize::from(axis - 1) * 2;
                let word = [data.get(at).copied(), data.get(at + 1).copied()];
                let [lo, hi] = word.map(|b| b.unwrap_or(0));
                ([lo, hi, 0, 0, 0, 0], 2)
            }
        };
        self.fifo.push(frame, len, stream);
        if self.fault.fifo_overflow {
            self.fifo.overflow_with(frame, len, stream);
        }
    }

    fn data_int(&self) -> bool {
        self.regs.get(reg::INT_CTRL) & bits::DATA_EN != 0
            && self
                .drdy_at
                .is_some_and(|t| self.now_ns < t.saturating_add(DRDY_PULSE_NS))
    }

    fn fifo_int(&self) -> bool {
        if self.regs.get(reg::INT_CTRL) & bits::FIFO_EN == 0 {
            return false;
        }
        let level = usize::from(self.regs.get(reg::FIFO_CONFIG_0) & bits::FIFO_WATERMARK);
        let wm_on = self.regs.get(reg::FIFO_WM_ENABLE) & bits::FIFO_WM_EN != 0;
        let stream =
            self.regs.get(reg::FIFO_CONFIG_1) & bits::FIFO_MODE_MASK == bits::FIFO_MODE_STREAM;
        (wm_on && level > 0 && self.fifo.count() >= level)
            || self.fifo.count() >= GyroFifo::capacity(stream)
    }

    fn soft_reset(&mut self) {
        self.regs.reset(DIE);
        self.pending = None;
        self.fifo.reset();
        self.drdy_at = None;
        self.bist_done = false;
    }

    fn show(&mut self, data: [u8; 6]) {
        for (addr, byte) in (reg::RATE_X_LSB..).zip(data) {
            self.regs.set(addr, byte);
        }
    }

    /// What a read of `addr` returns now, without side effects.
    fn value_of(&self, addr: u8) -> u8 {
        match addr {
            reg::INT_STAT_1 => {
                let data = if self.data_int() { bits::DATA_INT } else { 0 };
                let fifo = if self.fifo_int() { bits::FIFO_INT } else { 0 };
                data | fifo
            }
            reg::FIFO_STATUS => {
                let overrun = if self.fifo.overrun() {
                    bits::FIFO_OVERRUN
                } else {
                    0
                };
                overrun | (self.fifo.count() as u8 & bits::FIFO_FRAME_COUNT)
            }
            reg::BANDWIDTH => self.regs.get(addr) | bits::BANDWIDTH_FIXED,
            reg::SOFTRESET => 0,
            reg::SELF_TEST => {
                let ok = if self.is_normal() { bits::RATE_OK } else { 0 };
                let rdy = if self.bist_done { bits::BIST_RDY } else { 0 };
                ok | rdy
            }
            reg::FIFO_DATA => self.fifo.peek(),
            reg::CHIP_ID => self.fault.chip_id.unwrap_or(self.regs.get(addr)),
            _ => self.regs.get(addr),
        }
    }

    /// A byte written to `addr` over `bus`.
    fn write_register(&mut self, bus: Bus, addr: u8, value: u8) {
        self.log.push(RegisterWrite {
            bus,
            device: self.i2c_address,
            register: addr,
            value,
        });
        match addr {
            reg::SOFTRESET if value == bits::CMD_SOFT_RESET => self.soft_reset(),
            reg::LPM1 => self.write_lpm1(value),
            reg::FIFO_CONFIG_0 | reg::FIFO_CONFIG_1 => {
                self.regs.write_masked(DIE, addr, value);
                self.fifo.reset();
            }
            reg::SELF_TEST => self.bist_done |= value & bits::TRIG_BIST != 0,
            _ => self.regs.write_masked(DIE, addr, value),
        }
    }

    /// GYRO_LPM1: no direct switch between the suspend modes; deep suspend loses the
    /// configuration.
    fn write_lpm1(&mut self, value: u8) {
        let (from, to) = (self.regs.get(reg::LPM1), value);
        let suspends = [bits::PM_SUSPEND, bits::PM_DEEP_SUSPEND];
        if from != to && suspends.contains(&from) && suspends.contains(&to) {
            return;
        }
        if to == bits::PM_DEEP_SUSPEND {
            self.soft_reset();
        }
        self.regs.write_masked(DIE, reg::LPM1, to);
    }

    /// The transaction ended: a partly read FIFO frame is lost, a waiting sample appears.
    fn bus_went_idle(&mut self) {
        self.fifo.end_burst();
        if let Some(data) = self.pending.take() {
            self.show(data);
        }
    }
}

impl SpiRegisters for Bmi088Gyro {
    fn prefetch(&mut self, addr: u8) -> u8 {
        self.value_of(addr)
    }
    fn commit(&mut self, addr: u8, _value: u8) {
        if addr == reg::FIFO_DATA {
            self.fifo.pop();
        }
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.write_register(Bus::Spi, addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        DIE.next_address(addr)
    }
}

impl SpiTarget for Bmi088Gyro {
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

impl I2cRegisters for Bmi088Gyro {
    fn port(&mut self) -> &mut I2cPort {
        &mut self.i2c
    }
    fn pointer(&self) -> u8 {
        self.pointer
    }
    fn set_pointer(&mut self, addr: u8) {
        self.pointer = addr;
    }
    fn answers(&self, address: u8) -> bool {
        address == self.i2c_address
    }
    fn read_now(&mut self, addr: u8) -> u8 {
        let value = self.value_of(addr);
        self.commit(addr, value);
        value
    }
    fn write_now(&mut self, addr: u8, value: u8) {
        self.write_register(Bus::I2c, addr, value);
    }
    fn next(&self, addr: u8) -> u8 {
        DIE.next_address(addr)
    }
    fn i2c_idle(&mut self) {
        self.bus_went_idle();
    }
}
