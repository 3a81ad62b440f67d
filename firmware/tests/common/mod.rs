//! Helpers shared by the 6xxx-variant test crates (`mpu6000`, `mpu6500`, `icm20602`), included
//! with `#[path]`: byte-level bus transactions, a bench that latches numbered samples at the
//! chip's own output rate, and the flight-controller register sequences ([`fc`]).
//!
//! SPI transactions are written as the bytes on MOSI and the bytes expected on MISO, aligned:
//! `spi(&mut chip, &[0x80 | 0x75, 0x00]) == [0x00, 0x68]`.

#![allow(dead_code)]

pub mod fc;
pub mod fc_faults;
pub mod transactions;

pub use transactions::*;

use margemu_firmware::chip::{Config, Mpu6xxx, PhysicalSample, SpiTarget, Variant};

pub const MS: u64 = 1_000_000;
pub const G: f32 = 9.80665;

/// A fresh chip of `variant` with the default factory trim.
pub fn chip(variant: Variant) -> Mpu6xxx {
    Mpu6xxx::with_config(Config {
        variant,
        ..Config::default()
    })
}

/// Every register as the bus would read it, without side effects.
pub fn registers(chip: &Mpu6xxx) -> Vec<u8> {
    (0..0x80).map(|a| chip.peek(a)).collect()
}

/// Checks every register against `expected(addr)`, as the bus reads it without side effects.
pub fn assert_registers(chip: &Mpu6xxx, expected: impl Fn(usize) -> u8) {
    for (addr, value) in registers(chip).into_iter().enumerate() {
        assert_eq!(value, expected(addr), "register {addr:#04x}");
    }
}

/// Writes `value` to each of `addrs` (registers the variant lacks): each still reads 0x00.
pub fn assert_writes_ignored(chip: &mut Mpu6xxx, addrs: &[u8], value: u8) {
    for &addr in addrs {
        spi_write(chip, addr, &[value]);
        assert_eq!(spi_read(chip, addr, 1), [0x00], "register {addr:#04x}");
    }
}

/// Latches [`numbered`]`(0)` at each temperature in turn, 1 ms apart, and checks TEMP_OUT
/// against its raw value.
pub fn assert_temperature_scale(chip: &mut Mpu6xxx, points: [(f32, i16); 3]) {
    for (k, (t, raw)) in points.into_iter().enumerate() {
        let mut s = numbered(0);
        s.temp_c = t;
        chip.latch_at(&s, (k as u64 + 1) * MS);
        assert_eq!(spi_read(chip, 0x41, 2), raw.to_be_bytes(), "{t} °C");
    }
}

/// Big-endian i16 at `bytes[i..i + 2]`.
pub fn be(bytes: &[u8], i: usize) -> i16 {
    i16::from_be_bytes([bytes[i], bytes[i + 1]])
}

/// Sample number `k` as the chip sees it, so that at ±16 g / ±2000 °/s every register names it:
/// ACCEL_XOUT = GYRO_XOUT = `k`, ACCEL_YOUT = GYRO_YOUT = −`k`, ACCEL_ZOUT = 2048 (1 g),
/// GYRO_ZOUT = 7; 30 °C rising by 0.1 m°C per sample. `k` must stay below 16 384.
pub fn numbered(k: u64) -> PhysicalSample {
    let k = k as f32;
    let accel_lsb = G / 2048.0;
    let gyro_lsb = (1.0f64 / 16.4).to_radians() as f32;
    PhysicalSample {
        acc: [k * accel_lsb, -k * accel_lsb, G],
        gyr: [k * gyro_lsb, -k * gyro_lsb, 7.0 * gyro_lsb],
        mag: [0.0; 3],
        temp_c: 30.0 + k * 1e-4,
    }
}

/// Configures `c` (CONFIG, GYRO_CONFIG ±2000 °/s with `fchoice_b`, ACCEL_CONFIG ±16 g,
/// ACCEL_CONFIG2), latches `n` numbered samples at its output clock and returns the ACCEL_XOUT
/// read after each (checking that the gyro takes every sample).
pub fn accel_after_each(
    mut c: Mpu6xxx,
    config: u8,
    fchoice_b: u8,
    config2: u8,
    n: u64,
) -> Vec<i16> {
    spi_write(&mut c, 0x6B, &[0x01]);
    spi_write(&mut c, 0x1A, &[config]);
    spi_write(&mut c, 0x1B, &[0x18 | fchoice_b]);
    spi_write(&mut c, 0x1C, &[0x18]);
    spi_write(&mut c, 0x1D, &[config2]);
    let period = c.sample_period_ns();
    (1..=n)
        .map(|k| {
            c.latch_at(&numbered(k), k * period);
            let d = spi_read(&mut c, 0x3B, 14);
            assert_eq!(be(&d, 8), k as i16, "the gyro takes every sample");
            be(&d, 0)
        })
        .collect()
}

/// Sample numbers `1..=n` at `period` ns with each accel value taken at the first sample of
/// its `accel` ns period (sample 1 being the first).
pub fn expected_accel(period: u64, accel: u64, n: u64) -> Vec<i16> {
    let mut from = 1;
    (1..=n)
        .map(|k| {
            if k > 1 && (k * period) / accel != ((k - 1) * period) / accel {
                from = k;
            }
            from as i16
        })
        .collect()
}

/// The runs of equal ACCEL_XOUT in `records`, as (value, count).
pub fn accel_runs(records: &[fc::Record]) -> Vec<(i16, usize)> {
    let mut runs: Vec<(i16, usize)> = Vec::new();
    for r in records {
        match runs.last_mut() {
            Some((a, n)) if *a == r.accel_x => *n += 1,
            _ => runs.push((r.accel_x, 1)),
        }
    }
    runs
}

/// What a [`Bench`] needs of the chip on it: an [`Mpu6xxx`], or the same chip behind another
/// bus path (the SPI shadow's measuring rig).
pub trait BenchChip: SpiTarget {
    /// Nanoseconds between samples under the chip's current rate registers.
    fn sample_period_ns(&self) -> u64;
    /// Whether the chip's clock runs (it takes samples).
    fn is_running(&self) -> bool;
    /// Latches `sample` taken at `now_ns`.
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64);
    /// Moves the chip's clock to `now_ns`.
    fn advance(&mut self, now_ns: u64);
    /// The driver's initialisation is over ([`fc::Board::loop_starts`]).
    fn loop_starts(&mut self) {}
}

impl BenchChip for Mpu6xxx {
    fn sample_period_ns(&self) -> u64 {
        Mpu6xxx::sample_period_ns(self)
    }
    fn is_running(&self) -> bool {
        Mpu6xxx::is_running(self)
    }
    fn latch_at(&mut self, sample: &PhysicalSample, now_ns: u64) {
        Mpu6xxx::latch_at(self, sample, now_ns);
    }
    fn advance(&mut self, now_ns: u64) {
        Mpu6xxx::advance(self, now_ns);
    }
}

/// A chip on a bench: it latches [`numbered`] samples at the instants of its own output clock
/// (multiples of [`Mpu6xxx::sample_period_ns`], re-read after every latch and transaction) while
/// the flight-controller code waits, and serves SPI transactions in zero time in between.
pub struct Bench<C = Mpu6xxx> {
    pub chip: C,
    now_ns: u64,
    last_latch_ns: u64,
    /// Instant of every latch, by sample number (sample `k` latched at `instants[k]`).
    pub instants: Vec<u64>,
    /// Whether the chip's clock ran (it took the sample) at each latch.
    pub running: Vec<bool>,
}

impl<C: BenchChip> Bench<C> {
    pub fn new(chip: C) -> Self {
        Self {
            chip,
            now_ns: 0,
            last_latch_ns: 0,
            instants: Vec::new(),
            running: Vec::new(),
        }
    }

    pub fn now_ns(&self) -> u64 {
        self.now_ns
    }

    /// The number the next latched sample will carry.
    pub fn next_sample(&self) -> u64 {
        self.instants.len() as u64
    }

    fn next_instant(&self) -> u64 {
        let period = self.chip.sample_period_ns();
        (self.last_latch_ns / period + 1) * period
    }

    /// Lets `ns` pass, latching every sample instant in it.
    pub fn wait_ns(&mut self, ns: u64) {
        let end = self.now_ns + ns;
        loop {
            let next = self.next_instant();
            if next > end {
                break;
            }
            let k = self.next_sample();
            self.running.push(self.chip.is_running());
            self.chip.latch_at(&numbered(k), next);
            self.instants.push(next);
            self.last_latch_ns = next;
        }
        self.now_ns = end;
        self.chip.advance(end);
    }

    /// Waits for the next sample instant (the data-ready edge) and returns its sample number.
    pub fn wait_data_ready(&mut self) -> u64 {
        let next = self.next_instant();
        self.wait_ns(next.saturating_sub(self.now_ns));
        self.next_sample() - 1
    }

    /// One SPI transaction, byte by byte.
    pub fn spi(&mut self, mosi: &[u8]) -> Vec<u8> {
        spi(&mut self.chip, mosi)
    }

    /// Reads `n` registers from `addr`.
    pub fn read(&mut self, addr: u8, n: usize) -> Vec<u8> {
        spi_read(&mut self.chip, addr, n)
    }

    /// Reads one register.
    pub fn read1(&mut self, addr: u8) -> u8 {
        self.read(addr, 1)[0]
    }

    /// Writes one register.
    pub fn write(&mut self, addr: u8, value: u8) {
        spi_write(&mut self.chip, addr, &[value]);
    }
}

impl<C> Bench<C> {
    /// Whether sample `k` carries a new accel value (the rule of `regmap::mpu6xxx::rates`,
    /// restated): it is the first the chip took after sleeping, or `instant / accel_period`
    /// differs from sample `k − 1`'s. (Valid while no reset happens between the two.)
    pub fn new_accel(&self, k: u64, accel_period_ns: u64) -> bool {
        let k = k as usize;
        k == 0
            || !self.running[k - 1]
            || self.instants[k] / accel_period_ns != self.instants[k - 1] / accel_period_ns
    }

    /// The sample whose accel value sample `k` carries.
    pub fn accel_source(&self, k: u64, accel_period_ns: u64) -> u64 {
        let mut from = k;
        while !self.new_accel(from, accel_period_ns) {
            from -= 1;
        }
        from
    }
}
