//! The TDK InvenSense ICM-42688-P (accel + gyro + temperature), register by register
//! (datasheet DS-000347 rev. 1.7, "DS"; register map
//! [`margemu_protocol::regmap::icm42688p`]).
//!
//! [`Icm42688p`] serves [`SpiTarget`](super::SpiTarget) (first byte `0x80 | address` reads,
//! `address` writes; bursts move to the next register of the selected bank, except on
//! FIFO_DATA) and [`I2cTarget`](super::I2cTarget) (0x68, or 0x69 with AD0 high). REG_BANK_SEL
//! (0x76, in every bank) selects which of banks 0–4 the addresses reach.
//!
//! **Samples.** The board calls [`Icm42688p::latch_at`] once per sample period
//! ([`Icm42688p::sample_period_ns`]: the gyro ODR, or the accel ODR when only the accel runs).
//! A latch converts through the shared `regmap` conversions (or takes a finished
//! [register image](margemu_protocol::regmap::icm42688p::image) in
//! [`Icm42688p::latch_image_at`]), writes −32768 for a sensor that is off (PWR_MGMT0, TEMP_DIS),
//! pushes one FIFO packet when the FIFO is on, sets DATA_RDY_INT and swaps the data registers in
//! one step: a burst in progress completes with the old sample, the new one appears when the
//! bus goes idle. No latch happens while both sensors are off.
//!
//! **Interrupt pins.** [`Icm42688p::int_pin_at`] (INT1) and [`Icm42688p::int2_pin_at`] are the
//! levels a board drives: latched (held while an enabled INT_STATUS bit is set) or a 100/8 µs
//! pulse (INT_CONFIG1) per event, active high or low (INT_CONFIG). Time only moves with the
//! latches and [`Icm42688p::advance`].
//!
//! **AFSR** (`afsr.rs`): left on (INTF_CONFIG1 bits 7:6 ≠ 01, as at power-on), a gyro axis
//! whose rate crosses ±[`AFSR_THRESHOLD_DPS`] holds its output for [`AFSR_STALL_NS`], as the
//! silicon does; drivers that turn AFSR off never see it.
//!
//! **Faults** (`faults.rs`): the [`Chip`](super::Chip) fault hooks — a power cycle, a wrong
//! WHO_AM_I, a FIFO forced to overflow.
//!
//! **Stored only** (read back, no effect on the data yet): the anti-alias filters (bank 1
//! 0x0B–0x0E, bank 2 0x03–0x05), the notch filter, the UI filters (GYRO_CONFIG1,
//! GYRO_ACCEL_CONFIG0, ACCEL_CONFIG1), clock selection and the external clock, APEX, wake on motion, self-test, FSYNC and
//! the user offsets (bank 4). Register writes are logged with the register address only; the
//! REG_BANK_SEL writes in the log tell which bank they reached.
//!
//! ```
//! use margemu_firmware::chip::{Icm42688p, PhysicalSample, SpiTarget};
//! let mut chip = Icm42688p::new();
//! let mut spi = |chip: &mut Icm42688p, bytes: &[u8]| -> Vec<u8> {
//!     let mut miso = vec![chip.select()];
//!     for b in bytes {
//!         miso.push(chip.exchange(*b));
//!     }
//!     chip.deselect();
//!     miso.truncate(bytes.len());
//!     miso
//! };
//! assert_eq!(spi(&mut chip, &[0x80 | 0x75, 0x00])[1], 0x47); // WHO_AM_I
//! spi(&mut chip, &[0x4E, 0x0F]); // PWR_MGMT0: gyro and accel low noise
//! let sample = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 25.0, ..Default::default() };
//! chip.latch_at(&sample, 1_000_000);
//! assert_eq!(spi(&mut chip, &[0x80 | 0x23, 0x00, 0x00])[1..], [0x08, 0x00]); // ACCEL_DATA_Z: 2048
//! ```

mod afsr;
mod boundary;
mod faults;
mod fifo;
mod i2c;
mod interrupts;
mod registers;
mod sample;
mod spi;

use margemu_protocol::regmap::icm42688p::image::{ImageConfig, IMAGE_LEN};
use margemu_protocol::regmap::icm42688p::{bank0, bits, AccelFs, GyroFs, Odr, DATA_LEN};

use super::write_log::{RegisterWrite, WriteLog};
use super::PhysicalSample;

use super::spi_phase::SpiPhase;
use afsr::Afsr;
use faults::FaultState;
use fifo::Fifo;

pub use afsr::{AFSR_STALL_NS, AFSR_THRESHOLD_DPS};
use i2c::I2cState;
use interrupts::Pulse;

/// Capacity of the register write log (entries of 4 bytes).
pub const WRITE_LOG_LEN: usize = 128;

/// What makes one emulated part differ from another.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// The AD0 pin: I2C address 0x69 when high, 0x68 when low.
    pub ad0: bool,
    /// The WHO_AM_I value (0x47 for the ICM-42688-P).
    pub who_am_i: u8,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            ad0: false,
            who_am_i: 0x47,
        }
    }
}

/// The emulated ICM-42688-P (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Icm42688p {
    config: Config,
    /// Stored register values of banks 0–4 (bank 0 0x1D..=0x2A: the visible data, big-endian).
    banks: [[u8; 128]; 5],
    /// REG_BANK_SEL (the same register in every bank).
    bank_sel: u8,
    /// A newer sample waiting for the bus to go idle (data registers, big-endian).
    pending: Option<[u8; DATA_LEN]>,
    int_status: u8,
    int1: Pulse,
    int2: Pulse,
    fifo: Fifo,
    /// FIFO count latched by the last FIFO_COUNTH read, as the two bytes it reads.
    fifo_count_latch: [u8; 2],
    now_ns: u64,
    spi: SpiPhase,
    i2c: I2cState,
    log: WriteLog<WRITE_LOG_LEN>,
    /// The gyro's AFSR state (`afsr.rs`).
    afsr: Afsr,
    /// The fault hooks' overrides (`faults.rs`), kept across resets.
    fault: FaultState,
}

impl Default for Icm42688p {
    fn default() -> Self {
        Self::new()
    }
}

impl Icm42688p {
    /// An ICM-42688-P just powered on, with the default [`Config`].
    pub fn new() -> Self {
        Self::with_config(Config::default())
    }

    /// A chip of the given configuration just powered on.
    pub fn with_config(config: Config) -> Self {
        let mut chip = Self {
            config,
            banks: [[0; 128]; 5],
            bank_sel: 0,
            pending: None,
            int_status: 0,
            int1: Pulse::default(),
            int2: Pulse::default(),
            fifo: Fifo::new(),
            fifo_count_latch: [0; 2],
            now_ns: 0,
            spi: SpiPhase::Idle,
            i2c: I2cState::default(),
            log: WriteLog::new(),
            afsr: Afsr::default(),
            fault: FaultState::default(),
        };
        chip.soft_reset();
        chip
    }

    /// Power cycle: registers and bus state as from [`Icm42688p::with_config`]; the clock, the
    /// write log and the fault hooks' overrides are kept.
    pub fn power_cycle(&mut self) {
        let now_ns = self.now_ns;
        let log = core::mem::take(&mut self.log);
        let fault = self.fault;
        *self = Self::with_config(self.config);
        self.now_ns = now_ns;
        self.log = log;
        self.fault = fault;
    }

    /// The configuration the chip was built with.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The 7-bit I2C address (0x68, or 0x69 with AD0 high).
    pub fn i2c_address(&self) -> u8 {
        0x68 | u8::from(self.config.ad0)
    }

    /// The value a read of `addr` (7 bits) in `bank` returns, without the side effects of a
    /// bus read.
    pub fn peek(&self, bank: u8, addr: u8) -> u8 {
        self.peek_register(bank, addr)
    }

    /// The chip's clock: the latest instant given to a latch or [`Icm42688p::advance`].
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Nanoseconds between samples: the gyro ODR while the gyro runs, else the accel ODR while
    /// the accel runs, else the gyro ODR. A reserved ODR code counts as 1 kHz.
    pub fn sample_period_ns(&self) -> u64 {
        let gyro = Odr::from_gyro_config0(self.reg0(bank0::GYRO_CONFIG0));
        let accel = Odr::from_config0(self.reg0(bank0::ACCEL_CONFIG0));
        let odr = if !self.gyro_on() && self.accel_on() {
            accel
        } else {
            gyro
        };
        odr.map_or(1_000_000, Odr::period_ns)
    }

    /// Samples per second under the current configuration (`1e9 / sample_period_ns`).
    pub fn output_rate_hz(&self) -> f64 {
        1e9 / self.sample_period_ns() as f64
    }

    /// The settings a physical sample is converted with right now (the full scales): what the
    /// host needs to predict a register image.
    pub fn image_config(&self) -> ImageConfig {
        ImageConfig {
            accel_fs: AccelFs::from_accel_config0(self.reg0(bank0::ACCEL_CONFIG0)),
            gyro_fs: GyroFs::from_gyro_config0(self.reg0(bank0::GYRO_CONFIG0)),
        }
    }

    /// Latches one physical sample (in the chip's axes) taken at `now_ns`; the magnetic field
    /// is ignored.
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_physical(sample, now_ns);
    }

    /// Latches one physical sample at the next instant of the chip's sample clock.
    pub fn latch(&mut self, sample: &PhysicalSample) {
        self.latch_at(sample, self.next_sample_ns());
    }

    /// Latches one finished register image taken at `now_ns` (source mode (a)).
    pub fn latch_image_at(&mut self, image: &[u8; IMAGE_LEN], now_ns: u64) {
        self.latch_registers(image, now_ns);
    }

    /// Latches one register image at the next instant of the chip's sample clock.
    pub fn latch_image(&mut self, image: &[u8; IMAGE_LEN]) {
        self.latch_image_at(image, self.next_sample_ns());
    }

    /// The next instant of the chip's sample clock: its clock plus one sample period.
    pub fn next_sample_ns(&self) -> u64 {
        self.now_ns.saturating_add(self.sample_period_ns())
    }

    /// Moves the chip's clock to `now_ns` without a new sample (ends INT pulses).
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
    }

    /// Whether INT1 is asserted at `now_ns` (before polarity).
    pub fn int_asserted_at(&self, now_ns: u64) -> bool {
        self.int_line_asserted(1, now_ns)
    }

    /// The electrical level of INT1 at `now_ns` (`true` = high). Open drain only drives the
    /// active level; the inactive level shown is the pull resistor's.
    pub fn int_pin_at(&self, now_ns: u64) -> bool {
        let active_high = self.reg0(bank0::INT_CONFIG) & bits::INT1_POLARITY != 0;
        self.int_line_asserted(1, now_ns) == active_high
    }

    /// The level of INT1 at the chip's clock.
    pub fn int_pin(&self) -> bool {
        self.int_pin_at(self.now_ns)
    }

    /// The electrical level of INT2 at `now_ns` (`true` = high).
    pub fn int2_pin_at(&self, now_ns: u64) -> bool {
        let active_high = self.reg0(bank0::INT_CONFIG) & bits::INT2_POLARITY != 0;
        self.int_line_asserted(2, now_ns) == active_high
    }

    /// Whether INT1 is open drain (INT_CONFIG.INT1_DRIVE_CIRCUIT clear).
    pub fn int_open_drain(&self) -> bool {
        self.reg0(bank0::INT_CONFIG) & bits::INT1_DRIVE_CIRCUIT == 0
    }

    /// When the current INT1 pulse ends (pulsed mode only), for a board to schedule the edge.
    pub fn int_pulse_end_ns(&self) -> Option<u64> {
        let latched = self.reg0(bank0::INT_CONFIG) & bits::INT1_MODE != 0;
        let end = self.int1.end_ns()?;
        (!latched && end > self.now_ns).then_some(end)
    }

    /// The oldest register write not yet taken.
    pub fn pop_write(&mut self) -> Option<RegisterWrite> {
        self.log.pop()
    }

    /// The write log itself (length, dropped count).
    pub fn write_log(&self) -> &WriteLog<WRITE_LOG_LEN> {
        &self.log
    }

    /// Whether the sample clock runs: the gyro or the accel is on (PWR_MGMT0).
    pub fn is_running(&self) -> bool {
        self.gyro_on() || self.accel_on()
    }

    /// GYRO_MODE = 11 (low noise); off (00) and standby (01) give no data.
    fn gyro_on(&self) -> bool {
        self.reg0(bank0::PWR_MGMT0) & bits::GYRO_MODE == bits::GYRO_MODE
    }

    /// ACCEL_MODE = 10 (low power) or 11 (low noise).
    fn accel_on(&self) -> bool {
        self.reg0(bank0::PWR_MGMT0) & 0x02 != 0
    }

    /// The temperature sensor runs with either sensor unless TEMP_DIS.
    fn temp_on(&self) -> bool {
        self.is_running() && self.reg0(bank0::PWR_MGMT0) & bits::TEMP_DIS == 0
    }

    /// A stored bank 0 register.
    fn reg0(&self, addr: u8) -> u8 {
        self.banks[0][usize::from(addr & 0x7F)]
    }

    fn log_write(&mut self, bus: super::Bus, register: u8, value: u8) {
        self.log.push(RegisterWrite {
            bus,
            device: self.i2c_address(),
            register,
            value,
        });
    }
}
