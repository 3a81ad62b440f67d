//! The Bosch BMI270 (accel + gyro + temperature), register by register (datasheet
//! BST-BMI270-DS000, "DS"; register map [`margemu_protocol::regmap::bmi270`]).
//!
//! [`Bmi270`] serves [`SpiTarget`](super::SpiTarget) (the first byte is `0x80 | address` to
//! read, `address` to write; bursts move to the next register except on the FIFO_DATA and
//! INIT_DATA ports) and [`I2cTarget`](super::I2cTarget) (0x68, or 0x69 with SDO high; see
//! `i2c.rs`), and stands behind the chip boundary as [`Chip`](super::Chip).
//!
//! **Interface selection** (DS: 4.4 primary interface). After power-on and after a soft reset
//! the chip listens on I2C; a rising edge of chip select switches it to SPI, which is why
//! drivers begin with a dummy read. Until that edge the SPI target ignores every byte and MISO
//! is not driven, which this crate reads as 0x00 (as it does for a deselected chip): the dummy
//! read returns 0x00 whatever the register, and a write is lost. The soft reset's own
//! transaction does not count as the switching edge: the chip is still resetting when chip
//! select rises, so a driver needs another dummy read after CMD = 0xB6, as Betaflight and
//! ArduPilot do. Once in SPI mode the chip no longer answers its I2C address (`i2c.rs`).
//!
//! **Dummy byte** (DS: 6.2 SPI). In SPI mode every read clocks out one dummy byte (0x00 here)
//! before the data of the addressed register; writes have none, and I2C reads have none.
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
//! **Before init_ok the sensors do not run.** The datasheet's bring-up (DS: 4.2) loads the
//! configuration file before any sensor is enabled, and users who skip it or whose upload fails
//! report data registers that stay 0 with the sensors enabled (Bosch community threads "BMI270
//! Config File" and "Reading Accelerometer/Gyroscope Registers BMI-270"). So
//! until INTERNAL_STATUS reads init_ok, latches change nothing a driver can see: the data
//! registers keep their reset value 0, TEMPERATURE its invalid 0x8000, STATUS raises no drdy,
//! the FIFO stays empty (FIFO_DATA reads 0x80) and no interrupt fires. SENSORTIME runs
//! regardless. A soft reset clears init_ok.
//!
//! **Samples.** The board calls [`Bmi270::latch_image_at`] (a finished
//! [register image](margemu_protocol::regmap::bmi270::image)) or [`Bmi270::latch_at`] (a
//! physical sample, converted at the configured ranges) once per sample period
//! ([`Bmi270::sample_period_ns`]: the gyro ODR, or the accel ODR when only the accel runs).
//! A latch writes the enabled sensors (PWR_CTRL acc_en, gyr_en) little-endian into
//! 0x0C..=0x17, and sets STATUS drdy_acc / drdy_gyr, which a read of that sensor's data clears.
//! Each sensor keeps its own rate, on the chip's clock (`sample.rs`): the gyro takes every
//! latch; the accelerometer, whose ODR stops at 1.6 kHz and may be set below the gyro's, takes
//! a latch only when one of its own periods (multiples of its ODR period from time 0) has
//! begun since its last sample, so at gyro 3.2 kHz / accel 800 Hz it takes every fourth image's
//! accel and keeps reading the older value in between; the temperature (when temp_en or a
//! sensor is on) is taken at most every 10 ms (ArduPilot's driver: "temperature sensor updated
//! every 10ms"). The registers swap in one step when the bus is idle: a burst in progress
//! completes with the old sample. SENSORTIME (0x18..=0x1A) counts the chip's time (moved by
//! latches and [`Bmi270::advance`]) at 39.0625 µs per LSB; reading SENSORTIME_0 holds the value
//! for the rest of the burst.
//!
//! **FIFO** (2 KB, `fifo.rs`): headered frames (0x8C gyro + accel, 0x88 gyro, 0x84 accel) or
//! headerless ones, pushed with the sensors that have a new sample in the FIFO's own rate
//! (FIFO_DOWNS), FIFO_LENGTH_0/1 in bytes, FIFO_DATA (a frame leaves once read whole), ERR_REG
//! fifo_err on a stream-mode overflow, CMD 0xB0 flush.
//!
//! **Faults** (`faults.rs`): the [`Chip`](super::Chip) fault hooks — a power cycle (the
//! upload lost), a wrong CHIP_ID, a FIFO forced to overflow.
//!
//! **Interrupts** (`interrupts.rs`): data ready sets INT_STATUS_1 acc_drdy / gyr_drdy and, mapped
//! by INT_MAP_DATA, drives INT1/INT2 as INTx_IO_CTRL says, pulsed or latched (INT_LATCH).
//!
//! **Not emulated yet**: the FIFO's special frames (sensor time, skip, configuration change),
//! pre-filtered FIFO data (FIFO_DOWNS filt bits are stored; the data is the filtered one) and
//! the watermark and full interrupts, the other ERR_REG bits, the features of the configuration
//! file (FEATURES pages are plain storage), the time the initialization takes (INTERNAL_STATUS
//! changes at once), the 450 µs write spacing of the low-power mode (PWR_CONF adv_power_save is
//! stored only), the auxiliary interface, self-test and the offsets. Reading INIT_DATA returns
//! 0. Bytes written to INIT_DATA are not put in the write log (an 8 KB upload would flush it).
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
//! spi(&mut chip, &[0x59, 0x00]); // INIT_CTRL 0: prepare the upload
//! let mut upload = vec![0x5E]; // INIT_DATA, then a 328-byte configuration file
//! upload.resize(1 + 328, 0xC8);
//! spi(&mut chip, &upload);
//! spi(&mut chip, &[0x59, 0x01]); // INIT_CTRL 1: INTERNAL_STATUS init_ok
//! assert_eq!(spi(&mut chip, &[0x80 | 0x21, 0, 0])[2], 0x01);
//! spi(&mut chip, &[0x7D, 0x0E]); // PWR_CTRL: accel, gyro, temperature
//! let sample = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 23.0, ..Default::default() };
//! chip.latch_at(&sample, 1_000_000);
//! assert_eq!(spi(&mut chip, &[0x80 | 0x10, 0, 0, 0])[2..], [0x00, 0x10]); // ACC_Z: 4096 (±8 g)
//! ```

mod boundary;
mod faults;
mod fifo;
mod i2c;
mod interrupts;
mod registers;
mod sample;
mod spi;
mod upload;

use margemu_protocol::regmap::bmi270::image::{ImageConfig, IMAGE_LEN};
use margemu_protocol::regmap::bmi270::{bits, reg, AccRange, GyrRange, Odr, I2C_ADDRESSES};

pub use margemu_protocol::regmap::bmi270::CONFIG_FILE_LENS;

use super::bosch_spi::BoschSpi;
use super::write_log::{RegisterWrite, WriteLog};
use super::PhysicalSample;
use faults::FaultState;
use fifo::Fifo;
use i2c::I2cState;
use interrupts::Interrupts;
use sample::Ticks;
use upload::Upload;

/// Capacity of the register write log (entries of 4 bytes).
pub const WRITE_LOG_LEN: usize = 128;

/// Data registers 0x0C..=0x17 and the temperature 0x22/0x23, as one latched sample (the
/// image's layout).
const LATCH_LEN: usize = IMAGE_LEN;

/// What makes one emulated part differ from another.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Config {
    /// The SDO pin: I2C address 0x69 when high, 0x68 when low.
    pub sdo: bool,
}

/// The emulated BMI270 (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Bmi270 {
    config: Config,
    regs: [u8; 128],
    /// A newer sample waiting for the bus to go idle: data registers, temperature, STATUS bits.
    pending: Option<([u8; LATCH_LEN], u8)>,
    /// A soft reset was commanded over the bus, for the SPI front end or the I2C target to take.
    soft_reset_seen: bool,
    /// A soft reset was written in the current I2C transaction: the chip answers no more START
    /// until the STOP.
    i2c_resetting: bool,
    /// SENSORTIME held by a read of SENSORTIME_0 until the transaction ends.
    sensortime_hold: Option<u32>,
    upload: Upload,
    fifo: Fifo,
    ticks: Ticks,
    int: Interrupts,
    now_ns: u64,
    spi: BoschSpi,
    i2c: I2cState,
    log: WriteLog<WRITE_LOG_LEN>,
    /// The fault hooks' overrides (`faults.rs`), kept across resets.
    fault: FaultState,
}

impl Default for Bmi270 {
    fn default() -> Self {
        Self::new()
    }
}

impl Bmi270 {
    /// A BMI270 just powered on, SDO low.
    pub fn new() -> Self {
        Self::with_config(Config::default())
    }

    /// A chip of the given configuration just powered on.
    pub fn with_config(config: Config) -> Self {
        let mut chip = Self {
            config,
            regs: [0; 128],
            pending: None,
            soft_reset_seen: false,
            i2c_resetting: false,
            sensortime_hold: None,
            upload: Upload::default(),
            fifo: Fifo::default(),
            ticks: Ticks::default(),
            int: Interrupts::default(),
            now_ns: 0,
            spi: BoschSpi::new(),
            i2c: I2cState::default(),
            log: WriteLog::new(),
            fault: FaultState::default(),
        };
        chip.soft_reset();
        chip
    }

    /// Power cycle: every register to its power-on value, back in I2C mode, time kept.
    pub fn power_cycle(&mut self) {
        self.soft_reset();
        self.spi = BoschSpi::new();
        self.i2c = I2cState::default();
    }

    /// The configuration the chip was built with.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The 7-bit I2C address (0x68, or 0x69 with SDO high).
    pub fn i2c_address(&self) -> u8 {
        let [low, high] = I2C_ADDRESSES;
        if self.config.sdo {
            high
        } else {
            low
        }
    }

    /// Whether a chip-select edge has switched the interface to SPI.
    pub fn is_spi_mode(&self) -> bool {
        self.spi.is_spi_mode()
    }

    /// Whether INTERNAL_STATUS reads init_ok: the sensors run.
    pub fn is_initialized(&self) -> bool {
        self.stored(reg::INTERNAL_STATUS) & bits::MSG_MASK == bits::MSG_INIT_OK
    }

    /// The value a bus read of `addr` would return, without side effects (and without the SPI
    /// dummy byte).
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
        if self.pwr_ctrl() & bits::GYR_EN != 0 {
            Some(self.gyro_period_ns())
        } else if self.pwr_ctrl() & bits::ACC_EN != 0 {
            Some(self.accel_period_ns())
        } else {
            None
        }
    }

    /// The ranges a physical sample is converted with right now: what the host needs to
    /// predict a register image.
    pub fn image_config(&self) -> ImageConfig {
        ImageConfig {
            acc_range: AccRange::from_reg(self.stored(reg::ACC_RANGE)),
            gyr_range: GyrRange::from_reg(self.stored(reg::GYR_RANGE)),
        }
    }

    /// Latches `sample` at chip time `now_ns` (see the [module docs](self)).
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_physical(sample, now_ns);
    }

    /// Latches a finished register image taken at `now_ns` (source mode (a)).
    pub fn latch_image_at(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        self.latch_image(image, now_ns);
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

    /// The gyro ODR period (a reserved code counts as the reset value's 200 Hz).
    fn gyro_period_ns(&self) -> u64 {
        Odr::from_conf(self.stored(reg::GYR_CONF)).map_or(Odr::HZ200.period_ns(), Odr::period_ns)
    }

    /// The accel ODR period (a reserved code, or one above 1.6 kHz, counts as 1.6 kHz).
    fn accel_period_ns(&self) -> u64 {
        let odr = Odr::from_conf(self.stored(reg::ACC_CONF)).unwrap_or(Odr::HZ1600);
        odr.period_ns().max(Odr::HZ1600.period_ns())
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
