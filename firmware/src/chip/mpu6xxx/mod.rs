//! The InvenSense 6xxx family (accel + gyro + temperature), register by register: the MPU-9250
//! and MPU-9255 with the AK8963 magnetometer, the MPU-6500, the MPU-6000 and the ICM-20602.
//!
//! **Variants.** One model serves every part; [`Config::variant`] picks the part's data from
//! `margemu_protocol::regmap::mpu6xxx::variant` (identity, PRODUCT_ID, reset values, registers it
//! lacks — they read 0 and ignore writes — or adds, FIFO size and contents, temperature scale)
//! and `regmap::mpu6xxx::rates` (output rate, the accelerometer's own rate).
//!
//! [`Mpu6xxx`] serves both bus-target traits: [`SpiTarget`](super::SpiTarget) (first byte
//! `0x80 | address` reads, `address` writes; bursts increment the address except on FIFO_R_W and
//! MEM_R_W) and [`I2cTarget`](super::I2cTarget) (0x68, or 0x69 with AD0 high; the AK8963 answers
//! at 0x0C while INT_PIN_CFG.BYPASS_EN is set and USER_CTRL.I2C_MST_EN is clear).
//!
//! **Samples.** The board calls [`Mpu6xxx::latch_at`] once per sample period
//! ([`Mpu6xxx::sample_period_ns`], which follows SMPLRT_DIV, CONFIG and GYRO_CONFIG) with the
//! physical sample and its instant in ns (the accelerometer takes a new value only at its own
//! rate, [`Mpu6xxx::accel_period_ns`]; between its samples the accel bytes repeat; the gyro
//! likewise at [`Mpu6xxx::gyro_period_ns`], which latches at the output rate never outpace); [`Mpu6xxx::latch`] does the same at the next instant
//! of the chip's own sample clock (its clock + one period), for callers that count samples.
//! [`Mpu6xxx::latch_image_at`] / [`Mpu6xxx::latch_image`] take a finished
//! [register image](margemu_protocol::regmap::mpu6xxx::image) instead (source mode (a)). A latch converts
//! through the shared `regmap` conversions, runs the AK8963's own 8/100 Hz schedule, the
//! auxiliary I2C master's slaves and the FIFO, sets RAW_DATA_RDY and swaps the data registers in
//! one step: a burst that is in progress completes with the old sample, and the new one appears
//! when the bus goes idle.
//!
//! **Interrupt pin.** [`Mpu6xxx::int_pin`] is the INT level the board drives on a GPIO: held
//! while an enabled status bit is set (LATCH_INT_EN) or a 50 µs pulse from each latch; active
//! high or low (ACTL). Time only moves with the latches and [`Mpu6xxx::advance`].
//!
//! ```
//! use margemu_firmware::chip::{Mpu6xxx, PhysicalSample, SpiTarget};
//! let mut chip = Mpu6xxx::new();
//! let spi = |chip: &mut Mpu6xxx, bytes: &[u8]| -> [u8; 3] {
//!     let mut miso = [0; 3];
//!     miso[0] = chip.select();
//!     for (i, b) in bytes.iter().enumerate() {
//!         let next = chip.exchange(*b);
//!         if i + 1 < miso.len() {
//!             miso[i + 1] = next;
//!         }
//!     }
//!     chip.deselect();
//!     miso
//! };
//! assert_eq!(spi(&mut chip, &[0x80 | 0x75, 0x00])[1], 0x71); // WHO_AM_I
//! let sample = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 21.0, ..Default::default() };
//! chip.latch_at(&sample, 1_000_000);
//! assert_eq!(spi(&mut chip, &[0x80 | 0x3F, 0x00, 0x00])[1..], [0x40, 0x00]); // ACCEL_ZOUT
//! ```

mod aux_master;
mod boundary;
mod faults;
mod fifo;
mod i2c;
mod registers;
mod sample;
mod spi;

use margemu_protocol::regmap::ak8963::{self as ak_map, MagBits};
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, IMAGE_LEN};
use margemu_protocol::regmap::mpu6xxx::rates::{self, SensorClock};
use margemu_protocol::regmap::mpu6xxx::{bits, reg, AccelFs, GyroFs, DATA_LEN};

use super::ak8963::Ak8963;
use super::write_log::{RegisterWrite, WriteLog};
use super::PhysicalSample;

use super::spi_phase::SpiPhase;
use aux_master::AuxState;
use faults::FaultState;
use fifo::Fifo;
use i2c::I2cState;

/// Capacity of the register write log (entries of 4 bytes).
pub const WRITE_LOG_LEN: usize = 128;

/// Duration of the INT pulse when LATCH_INT_EN is clear (RM section 4.19).
pub const INT_PULSE_NS: u64 = 50_000;

pub use margemu_protocol::regmap::mpu6xxx::variant::Variant;

/// What makes one emulated part differ from another.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Which part: identity, reset values, registers, FIFO size, whether the AK8963 is present.
    pub variant: Variant,
    /// The AD0 pin: I2C address 0x69 when high, 0x68 when low.
    pub ad0: bool,
    /// AK8963 fuse ROM ASAX, ASAY, ASAZ.
    pub asa: [u8; 3],
    /// AK8963 INFO register (undocumented content).
    pub ak8963_info: u8,
    /// Factory self-test values: SELF_TEST_X/Y/Z_GYRO, SELF_TEST_X/Y/Z_ACCEL (the MPU-6000's
    /// SELF_TEST_X/Y/Z/A take the first four; see `Variant::self_test_registers`).
    pub self_test: [u8; 6],
    /// Factory accel offset trim: XA/YA/ZA_OFFSET_H:L register pairs (0x77.. or, on the
    /// MPU-6000, 0x06..).
    pub accel_offset: [u16; 3],
}

impl Default for Config {
    /// An MPU-9250 at 0x68 with plausible factory values (ASA near 0xB0 like real parts); other
    /// parts: `Config { variant, ..Config::default() }` (ASA and INFO unused without AK8963).
    fn default() -> Self {
        Self {
            variant: Variant::Mpu9250,
            ad0: false,
            asa: margemu_protocol::regmap::ak8963::EMULATED_ASA,
            ak8963_info: 0x00,
            self_test: [0xB4, 0xB9, 0xC2, 0x6A, 0x6E, 0x77],
            accel_offset: [0x1A32, 0xE5D8, 0x2C4C],
        }
    }
}

/// The emulated 6xxx-family chip (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Mpu6xxx {
    config: Config,
    /// Stored register values; 0x3B..=0x60 are the data registers the bus sees.
    regs: [u8; 128],
    /// A newer sample waiting for the bus to go idle.
    pending: Option<[u8; DATA_LEN]>,
    int_status: u8,
    /// Start of the last INT pulse (pulse mode).
    int_pulse_ns: Option<u64>,
    mst_status: u8,
    fifo: Fifo,
    /// When the accelerometer last produced a new value (the hold rule, [`rates`]).
    accel_clock: SensorClock,
    /// When the gyro last produced a new value.
    gyro_clock: SensorClock,
    /// FIFO count as latched by the last FIFO_COUNTH read.
    fifo_count_latch: u16,
    /// Whether a sample was latched since power-on (see [`Mpu6xxx::advance`]).
    latched: bool,
    aux: AuxState,
    ak: Option<Ak8963>,
    now_ns: u64,
    spi: SpiPhase,
    i2c: I2cState,
    log: WriteLog<WRITE_LOG_LEN>,
    /// The fault hooks' overrides (`faults.rs`), kept across resets.
    fault: FaultState,
}

impl Default for Mpu6xxx {
    fn default() -> Self {
        Self::new()
    }
}

impl Mpu6xxx {
    /// An MPU-9250 just powered on, with the default [`Config`].
    pub fn new() -> Self {
        Self::with_config(Config::default())
    }

    /// A chip of the given configuration just powered on.
    pub fn with_config(config: Config) -> Self {
        let ak = config
            .variant
            .has_magnetometer()
            .then(|| Ak8963::new(config.asa, config.ak8963_info));
        let mut chip = Self {
            config,
            regs: [0; 128],
            pending: None,
            int_status: 0,
            int_pulse_ns: None,
            mst_status: 0,
            fifo: Fifo::new(config.variant.fifo_size()),
            accel_clock: SensorClock::default(),
            gyro_clock: SensorClock::default(),
            fifo_count_latch: 0,
            latched: false,
            aux: AuxState::default(),
            ak,
            now_ns: 0,
            spi: SpiPhase::Idle,
            i2c: I2cState::default(),
            log: WriteLog::new(),
            fault: FaultState::default(),
        };
        chip.device_reset();
        chip
    }

    /// Power cycle: both dies and the bus state as from [`Mpu6xxx::with_config`]; the clock, the
    /// write log and the fault hooks' overrides are kept (the AK8963 keeps sensing the field it
    /// held).
    pub fn power_cycle(&mut self) {
        let now_ns = self.now_ns;
        let log = core::mem::take(&mut self.log);
        let fault = self.fault;
        let source = self.ak.as_ref().map(Ak8963::held_source);
        *self = Self::with_config(self.config);
        self.now_ns = now_ns;
        self.log = log;
        self.fault = fault;
        if let Some(ak) = &mut self.ak {
            ak.fault_identity(fault.who_am_i);
            ak.advance(
                now_ns,
                source.unwrap_or(super::MagSource::Physical([0.0; 3])),
            );
        }
    }

    /// The configuration the chip was built with.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The 7-bit I2C address (0x68, or 0x69 with AD0 high).
    pub fn i2c_address(&self) -> u8 {
        0x68 | u8::from(self.config.ad0)
    }

    /// The register value at `addr` (7 bits), without the side effects of a bus read.
    pub fn peek(&self, addr: u8) -> u8 {
        self.peek_register(addr)
    }

    /// The AK8963 die, if the variant has one.
    pub fn ak8963(&self) -> Option<&Ak8963> {
        self.ak.as_ref()
    }

    /// Whether the AK8963 answers on the primary I2C bus (BYPASS_EN set, I2C_MST_EN clear).
    pub fn bypass_active(&self) -> bool {
        self.ak.is_some()
            && self.regs[usize::from(reg::INT_PIN_CFG)] & bits::INT_BYPASS_EN != 0
            && self.regs[usize::from(reg::USER_CTRL)] & bits::USER_I2C_MST_EN == 0
    }

    /// The chip's clock: the latest instant given to a latch or [`Mpu6xxx::advance`].
    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// Nanoseconds between samples under the current CONFIG, GYRO_CONFIG and SMPLRT_DIV
    /// ([`rates::sample_period_ns`]).
    pub fn sample_period_ns(&self) -> u64 {
        rates::sample_period_ns(
            self.config.variant,
            self.regs[usize::from(reg::CONFIG)],
            self.regs[usize::from(reg::GYRO_CONFIG)],
            self.regs[usize::from(reg::SMPLRT_DIV)],
        )
    }

    /// Nanoseconds between the accelerometer's own samples under the current ACCEL_CONFIG2
    /// ([`rates::accel_period_ns`]): 250 000 (4 kHz) or 1 000 000 (1 kHz).
    pub fn accel_period_ns(&self) -> u64 {
        rates::accel_period_ns(
            self.config.variant,
            self.regs[usize::from(reg::ACCEL_CONFIG2)],
        )
    }

    /// Nanoseconds between the gyro's own samples under the current CONFIG and GYRO_CONFIG
    /// ([`rates::gyro_period_ns`]): 31 250 (32 kHz), 125 000 (8 kHz) or 1 000 000 (1 kHz).
    pub fn gyro_period_ns(&self) -> u64 {
        rates::gyro_period_ns(
            self.config.variant,
            self.regs[usize::from(reg::CONFIG)],
            self.regs[usize::from(reg::GYRO_CONFIG)],
        )
    }

    /// Samples per second under the current configuration (`1e9 / sample_period_ns`).
    pub fn output_rate_hz(&self) -> f64 {
        1e9 / self.sample_period_ns() as f64
    }

    /// The settings a physical sample is converted with right now (full scales, user offsets,
    /// AK8963 output bits and ASA): what the host needs to predict a register image.
    pub fn image_config(&self) -> ImageConfig {
        let pair = |addr: u8| {
            let a = usize::from(addr);
            i16::from_be_bytes([self.regs[a], self.regs[a + 1]])
        };
        let trim = self.config.accel_offset;
        let offset_regs = self.config.variant.accel_offset_registers();
        ImageConfig {
            accel_fs: AccelFs::from_accel_config(self.regs[usize::from(reg::ACCEL_CONFIG)]),
            gyro_fs: GyroFs::from_gyro_config(self.regs[usize::from(reg::GYRO_CONFIG)]),
            mag_bits: self.ak.as_ref().map_or(MagBits::Bits14, Ak8963::bits),
            asa: self.config.asa,
            gyro_offset: [reg::XG_OFFSET_H, reg::YG_OFFSET_H, reg::ZG_OFFSET_H].map(pair),
            accel_offset: core::array::from_fn(|i| {
                let now = pair(offset_regs[i]);
                (now & !1).wrapping_sub(trim[i] as i16 & !1)
            }),
            temp: self.config.variant.temperature(),
        }
    }

    /// Latches one physical sample (in the chip's accel/gyro axes) taken at `now_ns`.
    pub fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        self.latch_physical(sample, now_ns);
    }

    /// Latches one physical sample at the next instant of the chip's sample clock:
    /// [`Mpu6xxx::now_ns`] + [`Mpu6xxx::sample_period_ns`].
    pub fn latch(&mut self, sample: &PhysicalSample) {
        self.latch_at(sample, self.next_sample_ns());
    }

    /// Latches one finished register image taken at `now_ns` (source mode (a)); see
    /// [`margemu_protocol::regmap::mpu6xxx::image`] for the layout. A shorter image (the 14
    /// sensor bytes of a part without magnetometer) is zero-padded; bytes beyond
    /// [`IMAGE_LEN`] are ignored.
    pub fn latch_image_at(&mut self, image: &[u8], now_ns: u64) {
        let mut full = [0u8; IMAGE_LEN];
        let n = image.len().min(IMAGE_LEN);
        full[..n].copy_from_slice(&image[..n]);
        self.latch_registers(&full, now_ns);
    }

    /// Latches one register image at the next instant of the chip's sample clock.
    pub fn latch_image(&mut self, image: &[u8]) {
        self.latch_image_at(image, self.next_sample_ns());
    }

    /// The next instant of the chip's sample clock: its clock plus one sample period.
    pub fn next_sample_ns(&self) -> u64 {
        self.now_ns.saturating_add(self.sample_period_ns())
    }

    /// Moves the chip's clock to `now_ns` without a new sample (ends INT pulses). Before the
    /// first latch it lets the AK8963 measure the field it last saw. Once samples are latched,
    /// the field up to the next latch is that latch's (an image carries the field at its
    /// instant), so a measurement due between two latches completes at the next one, with its
    /// field: what the chip holds after a latch never depends on when, between latches, the
    /// board happened to call this.
    pub fn advance(&mut self, now_ns: u64) {
        self.now_ns = self.now_ns.max(now_ns);
        if self.latched {
            return;
        }
        if let Some(ak) = &mut self.ak {
            let source = ak.held_source();
            ak.advance(self.now_ns, source);
        }
    }

    /// Whether the INT output is asserted at `now_ns` (before ACTL).
    pub fn int_asserted_at(&self, now_ns: u64) -> bool {
        let cfg = self.regs[usize::from(reg::INT_PIN_CFG)];
        if cfg & bits::INT_LATCH_EN != 0 {
            self.int_status & self.int_sources() != 0
        } else {
            self.int_pulse_ns
                .is_some_and(|t| now_ns >= t && now_ns - t < INT_PULSE_NS)
        }
    }

    /// The electrical level of the INT pin at `now_ns` (`true` = high). With INT_OPEN set the
    /// pin only drives its active level; the inactive level shown is the pull resistor's.
    pub fn int_pin_at(&self, now_ns: u64) -> bool {
        let active_low = self.regs[usize::from(reg::INT_PIN_CFG)] & bits::INT_ACTL != 0;
        self.int_asserted_at(now_ns) != active_low
    }

    /// The level of the INT pin at the chip's clock ([`Mpu6xxx::now_ns`]).
    pub fn int_pin(&self) -> bool {
        self.int_pin_at(self.now_ns)
    }

    /// Whether INT is open drain (INT_PIN_CFG.OPEN).
    pub fn int_open_drain(&self) -> bool {
        self.regs[usize::from(reg::INT_PIN_CFG)] & bits::INT_OPEN != 0
    }

    /// When the current INT pulse ends (pulse mode only), for a board to schedule the edge.
    pub fn int_pulse_end_ns(&self) -> Option<u64> {
        let latched = self.regs[usize::from(reg::INT_PIN_CFG)] & bits::INT_LATCH_EN != 0;
        let end = self.int_pulse_ns?.saturating_add(INT_PULSE_NS);
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

    /// Whether the sample clock runs (not SLEEP, CLKSEL ≠ 7).
    pub fn is_running(&self) -> bool {
        let pwr1 = self.regs[usize::from(reg::PWR_MGMT_1)];
        pwr1 & bits::PWR1_SLEEP == 0 && pwr1 & bits::PWR1_CLKSEL != bits::PWR1_CLKSEL
    }

    fn int_sources(&self) -> u8 {
        self.regs[usize::from(reg::INT_ENABLE)]
            & (bits::INT_WOM | bits::INT_FIFO_OFLOW | bits::INT_FSYNC | bits::INT_RAW_RDY)
    }

    fn log_write(&mut self, bus: super::Bus, device: u8, register: u8, value: u8) {
        self.log.push(RegisterWrite {
            bus,
            device,
            register,
            value,
        });
    }

    fn ak_device_present(&self, address: u8) -> bool {
        self.ak.is_some() && address & 0x7F == ak_map::I2C_ADDRESS
    }
}
