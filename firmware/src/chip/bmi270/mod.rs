//! The Bosch BMI270 (accel + gyro + temperature), register by register (datasheet
//! BST-BMI270-DS000, "DS"; register map [`margemu_protocol::regmap::bmi270`]).
//!
//! [`Bmi270`] serves [`SpiTarget`](super::SpiTarget): the first byte is `0x80 | address` to
//! read, `address` to write; bursts move to the next register except on the FIFO_DATA and
//! INIT_DATA ports.
//!
//! **Interface selection** (DS: 4.4 primary interface). After power-on and after a soft reset
//! the chip listens on I2C; a rising edge of chip select switches it to SPI, which is why
//! drivers begin with a dummy read. Until that edge the SPI target ignores every byte and MISO
//! is not driven, which this crate reads as 0x00 (as it does for a deselected chip): the dummy
//! read returns 0x00 whatever the register, and a write is lost. The soft reset's own
//! transaction does not count as the switching edge: the chip is still resetting when chip
//! select rises, so a driver needs another dummy read after CMD = 0xB6, as Betaflight and
//! ArduPilot do.
//!
//! **Dummy byte** (DS: 6.2 SPI). In SPI mode every read clocks out one dummy byte (0x00 here)
//! before the data of the addressed register; writes have none.
//!
//! **Configuration upload** (DS: 4.2 initialization). INIT_CTRL = 0 prepares a load (INTERNAL_STATUS
//! message 0x00, not_init); each burst written to INIT_DATA lands at the byte offset
//! 2 · (INIT_ADDR_1 << 4 | INIT_ADDR_0) of the 8 KB configuration RAM, read when the burst
//! begins, so a single burst from offset 0 (the 328-byte file of ArduPilot and Betaflight) and
//! chunks addressed through INIT_ADDR (the `bmi2` crate's 8 KB file) both work. INIT_CTRL 0 → 1
//! ends the load: INTERNAL_STATUS reads 0x01 (init_ok) when the bytes written cover offset 0 up
//! to one of the known file lengths ([`CONFIG_FILE_LENS`]) without gap, 0x02 (init_err)
//! otherwise (absent, truncated, or past the RAM).
//!
//! **Samples.** The board calls [`Bmi270::latch_at`] once per sample period
//! ([`Bmi270::sample_period_ns`]). A latch converts through the shared `regmap` conversions at
//! the configured ranges, writes the enabled sensors (PWR_CTRL acc_en, gyr_en; the temperature
//! when temp_en or a sensor is on) little-endian into 0x0C..=0x17 and 0x22/0x23, and sets
//! STATUS drdy_acc / drdy_gyr, which a read of that sensor's data clears. The registers swap in
//! one step when the bus is idle: a burst in progress completes with the old sample. SENSORTIME
//! (0x18..=0x1A) counts the chip's time (moved by latches and [`Bmi270::advance`]) at 39.0625 µs
//! per LSB; reading SENSORTIME_0 holds the value for the rest of the burst.
//!
//! **FIFO** (2 KB): headered (0x8C + gyro + accel) or headerless frames pushed
//! at each latch, FIFO_LENGTH_0/1 in bytes, FIFO_DATA (a frame leaves once read whole), ERR_REG
//! fifo_err on a stream-mode overflow, CMD 0xB0 flush.
//!
//! **Not emulated yet**: the FIFO's special frames (sensor time, skip, configuration change),
//! FIFO_DOWNS and the watermark, the other ERR_REG bits, interrupts and the INT pins,
//! the features of the configuration file (FEATURES pages are plain storage), the time the
//! initialization takes (INTERNAL_STATUS changes at once), the 450 µs write spacing of the
//! low-power mode (PWR_CONF adv_power_save is stored only), the I2C target, the auxiliary
//! interface, self-test and the offsets. Reading INIT_DATA returns 0. Gating the data on a
//! successful initialization is not modelled: the sensors run once PWR_CTRL enables them.
//! Bytes written to INIT_DATA are not put in the write log (an 8 KB upload would flush it).
//!
//! Driver sequences read (no code taken): ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_BMI270.cpp`, Betaflight
//! `src/main/drivers/accgyro/accgyro_spi_bmi270.c`, the Rust `bmi2` crate.
//!
//! ```
//! use margemu_firmware::chip::bmi270::Bmi270;
//! use margemu_firmware::chip::{PhysicalSample, SpiTarget};
//! let mut chip = Bmi270::new();
//! let mut spi = |chip: &mut Bmi270, bytes: &[u8]| -> Vec<u8> {
//!     let mut miso = vec![chip.select()];
//!     for b in bytes {
//!         miso.push(chip.exchange(*b));
//!     }
//!     chip.deselect();
//!     miso.truncate(bytes.len());
//!     miso
//! };
//! assert_eq!(spi(&mut chip, &[0x80, 0x00, 0x00]), [0, 0, 0]); // I2C mode: nothing driven
//! assert_eq!(spi(&mut chip, &[0x80, 0x00, 0x00]), [0, 0, 0x24]); // dummy byte, CHIP_ID
//! spi(&mut chip, &[0x7D, 0x0E]); // PWR_CTRL: accel, gyro, temperature
//! let sample = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 23.0, ..Default::default() };
//! chip.latch_at(&sample, 1_000_000);
//! assert_eq!(spi(&mut chip, &[0x80 | 0x10, 0, 0, 0])[2..], [0x00, 0x10]); // ACC_Z: 4096 (±8 g)
//! ```

mod fifo;
mod registers;
mod sample;
mod spi;
mod upload;

use margemu_protocol::regmap::bmi270::{bits, reg, Odr, DATA_LEN, I2C_ADDRESS};

pub use margemu_protocol::regmap::bmi270::CONFIG_FILE_LENS;

use super::bosch_spi::BoschSpi;
use super::write_log::{RegisterWrite, WriteLog};
use super::PhysicalSample;
use fifo::Fifo;
use upload::Upload;

/// Capacity of the register write log (entries of 4 bytes).
pub const WRITE_LOG_LEN: usize = 128;

/// Data registers 0x0C..=0x17 and the temperature 0x22/0x23, as one latched sample.
const LATCH_LEN: usize = DATA_LEN + 2;

/// The emulated BMI270 (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Bmi270 {
    regs: [u8; 128],
    /// A newer sample waiting for the bus to go idle: data registers, temperature, STATUS bits.
    pending: Option<([u8; LATCH_LEN], u8)>,
    /// A soft reset was commanded over the bus, for the SPI front end to take.
    soft_reset_seen: bool,
    /// SENSORTIME held by a read of SENSORTIME_0 until the transaction ends.
    sensortime_hold: Option<u32>,
    upload: Upload,
    fifo: Fifo,
    now_ns: u64,
    spi: BoschSpi,
    log: WriteLog<WRITE_LOG_LEN>,
}

impl Default for Bmi270 {
    fn default() -> Self {
        Self::new()
    }
}

impl Bmi270 {
    /// A BMI270 just powered on.
    pub fn new() -> Self {
        let mut chip = Self {
            regs: [0; 128],
            pending: None,
            soft_reset_seen: false,
            sensortime_hold: None,
            upload: Upload::default(),
            fifo: Fifo::default(),
            now_ns: 0,
            spi: BoschSpi::new(),
            log: WriteLog::new(),
        };
        chip.soft_reset();
        chip
    }

    /// Power cycle: every register to its power-on value, back in I2C mode, time kept.
    pub fn power_cycle(&mut self) {
        self.soft_reset();
        self.spi = BoschSpi::new();
    }

    /// The 7-bit I2C address (SDO low).
    pub fn i2c_address(&self) -> u8 {
        I2C_ADDRESS
    }

    /// Whether a chip-select edge has switched the interface to SPI.
    pub fn is_spi_mode(&self) -> bool {
        self.spi.is_spi_mode()
    }

    /// The value a bus read of `addr` would return, without side effects.
    pub fn peek(&self, addr: u8) -> u8 {
        self.value_of(addr)
    }

    /// The chip's time, ns since power-on.
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The sample period: the gyro ODR when the gyro is on, else the accel ODR when the
    /// accel is on; `None` when both are off.
    pub fn sample_period_ns(&self) -> Option<u64> {
        let conf = if self.pwr_ctrl() & bits::GYR_EN != 0 {
            reg::GYR_CONF
        } else if self.pwr_ctrl() & bits::ACC_EN != 0 {
            reg::ACC_CONF
        } else {
            return None;
        };
        Odr::from_conf(self.stored(conf)).map(Odr::period_ns)
    }

    /// Latches `sample` at chip time `now_ns` (see the [module docs](self)).
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_physical(sample, now_ns);
    }

    /// Moves the chip's time to `now_ns` (never backwards).
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
    }

    /// The oldest register write not yet drained.
    pub fn pop_write(&mut self) -> Option<RegisterWrite> {
        self.log.pop()
    }

    /// The register write log.
    pub fn write_log(&self) -> &WriteLog<WRITE_LOG_LEN> {
        &self.log
    }

    fn pwr_ctrl(&self) -> u8 {
        self.stored(reg::PWR_CTRL)
    }

    fn stored(&self, addr: u8) -> u8 {
        self.regs.get(usize::from(addr)).copied().unwrap_or(0)
    }

    fn set(&mut self, addr: u8, value: u8) {
        if let Some(r) = self.regs.get_mut(usize::from(addr)) {
            *r = value;
        }
    }
}
