//! The accelerometer die (DS 5.2, 5.3; AN 3), register by register.
//!
//! - **Interface** (the SPI front end shared with the BMI270): I2C after power-on and after a soft reset, SPI from the next
//!   chip-select rising edge (DS 3, 6.1; Bosch's API reads CHIP_ID once after each soft reset for
//!   this); every SPI read clocks out one dummy byte first (DS 6.1.2).
//! - **Power** (DS 3, 4.1.1): the accelerometer and the temperature sensor run while
//!   ACC_PWR_CTRL = 0x04; otherwise a latch changes nothing and the data registers keep their
//!   last values. ACC_PWR_CONF (0x03 "suspend" at reset, 0x00 active) is stored only: DS 5.3.14
//!   says suspend stops acquisition, but DS 3 and 4.1.1 name ACC_PWR_CTRL = 4 alone as the step
//!   into normal mode, which is what this follows.
//! - **Data**: ACC_X..Z at 0x12–0x17 little-endian at ACC_RANGE; ACC_STATUS.acc_drdy set by a
//!   sample and cleared by reading a data register; ACC_INT_STAT_1.acc_drdy cleared by reading
//!   ACC_INT_STAT_1; SENSORTIME 0x18–0x1A counts the die's clock (39.0625 µs), held from a read
//!   of SENSORTIME_0 to the end of the burst; TEMP_MSB/LSB (11 bits, 0.125 K) updated by a sample
//!   at most every 1.28 s (DS 5.3.7), 0x0000 (23 °C) before the first.
//! - **ACC_ERR_REG.error_code** = 1 after a write of an invalid ACC_CONF (reserved acc_bwp or
//!   acc_odr; DS 5.3.2), 0 after a valid one; the invalid value is kept and the ODR of a reserved
//!   code stops the samples ([`Bmi088Accel::sample_period_ns`] is `None`).
//! - **ACC_SOFTRESET**: 0xB6 resets every register (the write log is kept) and the interface to
//!   I2C; 0xB0 resets the FIFO; other values are ignored. It reads 0.
//! - **FIFO**: see [`accel_fifo`](super::accel_fifo).
//! - **INT1/INT2** ([`Bmi088Accel::int1_pin`]): an output pin (intx_out) is asserted while a
//!   mapped source is: data ready while ACC_STATUS.acc_drdy is set (until a data register is
//!   read), FIFO watermark while FIFO_LENGTH ≥ FIFO_WTM, FIFO full while no frame fits.
//!
//! Not emulated: self-test offsets, the 1 ms boot and 5 ms power-mode settling, the 2 µs write
//! spacing, fatal_err, input pins and the FIFO tags.

use margemu_protocol::regmap::bmi088::accel::{
    bits, conf_is_valid, reg, AccRange, Odr, DATA_LEN, I2C_ADDRESS,
};
use margemu_protocol::regmap::bmi088::convert::{
    accel_to_raw, sensortime, sensortime_bytes, temp_bytes, temp_to_raw, TEMP_UPDATE_NS,
};
use margemu_protocol::regmap::bmi088::Die;

use super::super::bosch_spi::{bosch_spi_target, BoschSpi};
use super::super::spi_phase::SpiRegisters;
use super::super::write_log::{Bus, RegisterWrite, WriteLog};
use super::super::PhysicalSample;
use super::accel_fifo::AccelFifo;
use super::faults::DieFaults;
use super::i2c::{I2cPort, I2cRegisters};
use super::{pin_level, put_le, Regs, WRITE_LOG_LEN};

const DIE: Die = Die::Accel;

/// One sample as it reaches the registers: data, and the temperature when it was due.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Latch {
    data: [u8; DATA_LEN],
    temp: Option<[u8; 2]>,
}

/// The emulated BMI088 accelerometer die (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Bmi088Accel {
    regs: Regs,
    /// A newer sample waiting for the bus to go idle.
    pending: Option<Latch>,
    spi: BoschSpi,
    /// A soft reset was commanded over SPI, for the front end to take.
    soft_reset_seen: bool,
    i2c: I2cPort,
    pointer: u8,
    i2c_address: u8,
    fifo: AccelFifo,
    sensortime_hold: Option<u32>,
    /// When the temperature registers were last updated.
    temp_at: Option<u64>,
    now_ns: u64,
    log: WriteLog<WRITE_LOG_LEN>,
    /// The fault hooks' overrides (`faults.rs`), kept across resets.
    pub(super) fault: DieFaults,
}

impl Default for Bmi088Accel {
    fn default() -> Self {
        Self::new()
    }
}

impl Bmi088Accel {
    /// A die just powered on, SDO1 at GND (I2C 0x18).
    pub fn new() -> Self {
        Self::with_sdo(false)
    }

    /// A die just powered on, SDO1 at VDDIO (`true`, I2C 0x19) or GND.
    pub fn with_sdo(sdo_high: bool) -> Self {
        Self {
            regs: Regs::power_on(DIE),
            pending: None,
            spi: BoschSpi::new(),
            soft_reset_seen: false,
            i2c: I2cPort::Idle,
            pointer: 0,
            i2c_address: I2C_ADDRESS | u8::from(sdo_high),
            fifo: AccelFifo::default(),
            sensortime_hold: None,
            temp_at: None,
            now_ns: 0,
            log: WriteLog::new(),
            fault: DieFaults::default(),
        }
    }

    /// Power cycle: every register to its power-on value, back in I2C mode, time kept.
    pub fn power_cycle(&mut self) {
        self.soft_reset();
        self.spi = BoschSpi::new();
        self.i2c = I2cPort::Idle;
    }

    /// The 7-bit I2C address.
    pub fn i2c_address(&self) -> u8 {
        self.i2c_address
    }

    /// Whether a chip-select edge has switched the interface to SPI.
    pub fn is_spi_mode(&self) -> bool {
        self.spi.is_spi_mode()
    }

    /// Whether the accelerometer is on (ACC_PWR_CTRL = 0x04).
    pub fn is_on(&self) -> bool {
        self.regs.get(reg::ACC_PWR_CTRL) == bits::ACC_ENABLE
    }

    /// The value a bus read of `addr` would return now, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        if addr == reg::FIFO_DATA {
            return self.fifo.clone().peek(self.ticks());
        }
        self.value_of(addr)
    }

    /// The die's time, ns since power-on.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The sample period at ACC_CONF's ODR while the accelerometer is on; `None` when it is off
    /// or the ODR code is reserved.
    pub fn sample_period_ns(&self) -> Option<u64> {
        if !self.is_on() {
            return None;
        }
        Odr::from_conf(self.regs.get(reg::ACC_CONF)).map(Odr::period_ns)
    }

    /// Latches `sample` at die time `now_ns` (see the [module docs](self)).
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        let range = AccRange::from_reg(self.regs.get(reg::ACC_RANGE));
        let mut data = [0; DATA_LEN];
        put_le(&mut data, sample.acc.map(|a| accel_to_raw(a, range)));
        self.latch_data(data, temp_bytes(temp_to_raw(sample.temp_c)), now_ns);
    }

    /// Latches register values at die time `now_ns`: ACC_X..Z (`data`, as the registers hold
    /// them) and TEMP_MSB, TEMP_LSB (`temp`, taken only when the temperature is due), as
    /// [`Bmi088Accel::latch_at`] does with the values it converts.
    pub fn latch_data(&mut self, data: [u8; DATA_LEN], temp: [u8; 2], now_ns: u64) {
        self.advance(now_ns);
        if !self.is_on() {
            return;
        }
        let temp_due = self
            .temp_at
            .is_none_or(|t| self.now_ns >= t.saturating_add(TEMP_UPDATE_NS));
        let temp = temp_due.then(|| {
            self.temp_at = Some(self.now_ns);
            temp
        });
        if self.regs.get(reg::FIFO_CONFIG_1) & bits::FIFO_ACC_EN != 0 {
            let downs = (self.regs.get(reg::FIFO_DOWNS) >> 4) & 0x07;
            let stop = self.regs.get(reg::FIFO_CONFIG_0) & bits::FIFO_MODE_STOP != 0;
            self.fifo.push_sample(&data, downs, stop);
            if self.fault.fifo_overflow {
                self.fifo.overflow_with(&data, stop);
            }
        }
        let latch = Latch { data, temp };
        if self.spi.is_active() || self.i2c != I2cPort::Idle {
            let older_temp = self.pending.and_then(|p| p.temp);
            self.pending = Some(Latch {
                temp: temp.or(older_temp),
                ..latch
            });
        } else {
            self.show(latch);
        }
    }

    /// Moves the die's time to `now_ns` (never backwards).
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
    }

    /// The level of INT1 (`true` = high), `None` while it is not an output (INT1_IO_CONF).
    pub fn int1_pin(&self) -> Option<bool> {
        self.int_pin(reg::INT1_IO_CONF, 0)
    }

    /// The level of INT2, as [`Bmi088Accel::int1_pin`].
    pub fn int2_pin(&self) -> Option<bool> {
        self.int_pin(reg::INT2_IO_CONF, 4)
    }

    /// The oldest register write not yet drained.
    pub fn pop_write(&mut self) -> Option<RegisterWrite> {
        self.log.pop()
    }

    /// The register write log.
    pub fn write_log(&self) -> &WriteLog<WRITE_LOG_LEN> {
        &self.log
    }

    fn int_pin(&self, io_conf: u8, shift: u8) -> Option<bool> {
        let conf = self.regs.get(io_conf);
        if conf & bits::INT_OUT == 0 {
            return None;
        }
        let map = self.regs.get(reg::INT1_INT2_MAP_DATA) >> shift;
        let wtm = u16::from(self.regs.get(reg::FIFO_WTM_1)) << 8
            | u16::from(self.regs.get(reg::FIFO_WTM_0));
        let asserted = (map & bits::INT1_DRDY != 0 && self.regs.get(reg::STATUS) & bits::DRDY != 0)
            || (map & bits::INT1_FWM != 0 && self.fifo.len() >= usize::from(wtm))
            || (map & bits::INT1_FFULL != 0 && self.fifo.is_full());
        Some(pin_level(asserted, conf & bits::INT_LVL != 0))
    }

    fn ticks(&self) -> u32 {
        sensortime(self.now_ns)
    }

    /// Soft reset (and power-on): registers to their reset values, FIFO and latches cleared.
    fn soft_reset(&mut self) {
        self.regs.reset(DIE);
        self.pending = None;
        self.fifo.reset();
        self.sensortime_hold = None;
        self.temp_at = None;
    }

    /// Writes a sample into the registers and raises the data-ready flags.
    fn show(&mut self, latch: Latch) {
        for (addr, byte) in (reg::ACC_X_LSB..).zip(latch.data) {
            self.regs.set(addr, byte);
        }
        if let Some([msb, lsb]) = latch.temp {
            self.regs.set(reg::TEMP_MSB, msb);
            self.regs.set(reg::TEMP_LSB, lsb);
        }
        for addr in [reg::STATUS, reg::INT_STAT_1] {
            self.regs.set(addr, self.regs.get(addr) | bits::DRDY);
        }
    }

    /// What a read of `addr` returns now, without side effects (FIFO_DATA aside).
    fn value_of(&self, addr: u8) -> u8 {
        match addr {
            reg::SENSORTIME_0..=reg::SENSORTIME_2 => {
                let ticks = self.sensortime_hold.unwrap_or(self.ticks());
                let bytes = sensortime_bytes(ticks);
                bytes
                    .get(usize::from(addr - reg::SENSORTIME_0))
                    .copied()
                    .unwrap_or(0)
            }
            reg::FIFO_LENGTH_0 | reg::FIFO_LENGTH_1 => {
                let [lo, hi] = (self.fifo.len() as u16 & 0x3FFF).to_le_bytes();
                if addr == reg::FIFO_LENGTH_0 {
                    lo
                } else {
                    hi
                }
            }
            reg::ACC_SOFTRESET => 0,
            reg::CHIP_ID => self.fault.chip_id.unwrap_or(self.regs.get(addr)),
            _ => self.regs.get(addr),
        }
    }

    /// The value a bus read of `addr` clocks out (holding SENSORTIME, taking FIFO bytes' place).
    fn read_register(&mut self, addr: u8) -> u8 {
        match addr {
            reg::SENSORTIME_0 => {
                self.sensortime_hold = Some(self.ticks());
                self.value_of(addr)
            }
            reg::FIFO_DATA => self.fifo.peek(self.ticks()),
            _ => self.value_of(addr),
        }
    }

    /// `addr` was read: its side effects apply.
    fn commit_read(&mut self, addr: u8) {
        match addr {
            reg::ACC_X_LSB..=reg::ACC_Z_MSB => {
                self.regs
                    .set(reg::STATUS, self.regs.get(reg::STATUS) & !bits::DRDY);
            }
            reg::INT_STAT_1 => self.regs.set(reg::INT_STAT_1, 0),
            reg::FIFO_DATA => self.fifo.pop(self.ticks()),
            _ => {}
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
        match (addr, value) {
            (reg::ACC_SOFTRESET, bits::CMD_SOFT_RESET) => {
                self.soft_reset();
                self.soft_reset_seen = bus == Bus::Spi;
            }
            (reg::ACC_SOFTRESET, bits::CMD_FIFO_RESET) => self.fifo.reset(),
            (reg::ACC_CONF, _) => {
                self.regs.write_masked(DIE, addr, value);
                let code = if conf_is_valid(value) {
                    0
                } else {
                    bits::ERROR_CODE_CONF
                };
                let err = self.regs.get(reg::ERR_REG) & !0x1C;
                self.regs.set(reg::ERR_REG, err | code);
            }
            _ => self.regs.write_masked(DIE, addr, value),
        }
    }

    /// The transaction ended: bursts end, held values are released, a waiting sample appears.
    fn bus_went_idle(&mut self) {
        self.fifo.end_burst();
        self.sensortime_hold = None;
        if let Some(latch) = self.pending.take() {
            self.show(latch);
        }
    }
}

impl SpiRegisters for Bmi088Accel {
    fn prefetch(&mut self, addr: u8) -> u8 {
        self.read_register(addr)
    }
    fn commit(&mut self, addr: u8, _value: u8) {
        self.commit_read(addr);
    }
    fn store(&mut self, addr: u8, value: u8) {
        self.write_register(Bus::Spi, addr, value);
    }
    fn burst_next(&self, addr: u8) -> u8 {
        DIE.next_address(addr)
    }
}

bosch_spi_target!(Bmi088Accel);

impl I2cRegisters for Bmi088Accel {
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
        !self.spi.is_spi_mode() && address == self.i2c_address
    }
    fn read_now(&mut self, addr: u8) -> u8 {
        let value = self.read_register(addr);
        self.commit_read(addr);
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
