//! The `mpu6000` crate (0.3, embedded-hal 0.2), unmodified, drives the emulated MPU-6000 over
//! SPI through margemu's embedded-hal 1.0 adapters (`margemu::bus::SpiBus` + `ChipSelect`),
//! bridged back to 0.2 by `embedded-hal-compat` (`.reverse()`, `.reverse_cell()`).
//!
//! The driver verifies the chip (WHO_AM_I 0x68 and a known PRODUCT_ID), resets it (DEVICE_RESET,
//! then SIGNAL_PATH_RESET), wakes it and selects the PLL clock, and sets the DLPF and rate; then,
//! at each of its accelerometer and gyroscope full scales, it reads known physical samples
//! (`latch_at` of a [`PhysicalSample`]: positive, negative and beyond full scale). Each value
//! must match the sample to within one LSB of the current full scale: the sample in register
//! counts at the datasheet sensitivity, clipped like the register, against what the driver
//! returns times the driver's own sensitivity.
//!
//! What the driver returns (read in `mpu6000-0.3.0/src`, not its docs):
//! - `read_all` (lib.rs): one 14-byte burst from 0x3B; `Acceleration / AccelerometerSensitive`
//!   is in g (raw / 16384, 8192, 4096, 2048), `Gyro / GyroSensitive` in °/s (raw / 131, 65.5,
//!   32.8, 16.4): the datasheet sensitivities the chip uses, so no scale error;
//! - `read_temperature` reads two bytes from **0x3B** (ACCEL_XOUT), not TEMP_OUT (0x41);
//!   `Temperature`'s `Into<f32>` adds 365.3 instead of 36.53 (`celcius()` is right, in
//!   hundredths of °C); both are pinned below;
//! - `set_i2c_disable` writes bit 2 of USER_CTRL (FIFO_RST), not bit 4 (I2C_IF_DIS): the
//!   chip's I2C interface stays on, pinned below.

mod driver_support;

use driver_support::{new_mpu6000 as new_chip, Spread, Worst, FRACTIONS, G};
use embedded_hal_02::blocking::delay::{DelayMs, DelayUs};
use embedded_hal_compat::ReverseCompat;
use margemu::bus::{self, Shared};
use margemu_firmware::chip::{I2cTarget, Mpu6xxx as Chip, PhysicalSample};
use mpu6000::bus::{RegAccess, SpiBus};
use mpu6000::registers::{AccelerometerSensitive, GyroSensitive};
use mpu6000::{ClockSource, FifoEnable, MPU6000};

/// The driver's 0.2 delays (embedded-hal-compat reverses only `u16`/`u32` delays); the chip
/// needs no real time to pass.
struct NoDelay;

impl DelayUs<u8> for NoDelay {
    fn delay_us(&mut self, _us: u8) {}
}

impl DelayMs<u8> for NoDelay {
    fn delay_ms(&mut self, _ms: u8) {}
}

/// `Result::unwrap` for the driver's error types, which do not implement `Debug`.
fn ok<T, E>(result: Result<T, E>, what: &str) -> T {
    result.unwrap_or_else(|_| panic!("{what}: bus error"))
}

/// The driver over SPI, the crate's own bus wrapper on the reversed adapters.
fn driver(chip: &Shared<Chip>) -> MPU6000<impl RegAccess> {
    let (spi, cs) = bus::SpiBus::new(chip.clone());
    MPU6000::new(SpiBus::new(spi.reverse(), cs.reverse_cell(), NoDelay))
}

/// The driver's set-up: verify, reset, wake, PLL clock, DLPF 1 (1 kHz), 1 kHz sample rate.
fn set_up<B: RegAccess>(mpu: &mut MPU6000<B>, chip: &Shared<Chip>) {
    assert!(ok(mpu.verify(), "verify"), "WHO_AM_I and PRODUCT_ID");
    assert_eq!(ok(mpu.product_id(), "product_id"), 0x58);
    ok(mpu.reset(&mut NoDelay), "reset");
    assert_eq!(chip.borrow().peek(0x6B), 0x40, "asleep after DEVICE_RESET");
    ok(mpu.set_sleep(false), "set_sleep");
    ok(
        mpu.set_clock_source(ClockSource::PLLGyroZ),
        "set_clock_source",
    );
    assert_eq!(chip.borrow().peek(0x6B), 0x03, "awake, PLL with gyro Z");
    ok(mpu.set_dlpf(1), "set_dlpf");
    ok(mpu.set_sample_rate(1000), "set_sample_rate");
    assert_eq!(chip.borrow().sample_period_ns(), 1_000_000);
}

const ACCEL: [(AccelerometerSensitive, f64, f64); 4] = [
    (AccelerometerSensitive::Sensitive16384, 2.0, 16384.0),
    (AccelerometerSensitive::Sensitive8192, 4.0, 8192.0),
    (AccelerometerSensitive::Sensitive4096, 8.0, 4096.0),
    (AccelerometerSensitive::Sensitive2048, 16.0, 2048.0),
];
const GYRO: [(GyroSensitive, f64, f64); 4] = [
    (GyroSensitive::Sensitive131, 250.0, 131.0),
    (GyroSensitive::Sensitive65_5, 500.0, 65.5),
    (GyroSensitive::Sensitive32_8, 1000.0, 32.8),
    (GyroSensitive::Sensitive16_4, 2000.0, 16.4),
];

/// Each axis a different fraction of full scale; 20 °C, then 1.7 °C warmer a sample.
const SPREAD: Spread = Spread {
    acc: [0, 3, 7],
    gyr: [1, 5, 9],
    temp_c: [20.0, 1.7],
};

#[test]
fn every_full_scale_within_one_lsb() {
    let chip = new_chip();
    let mut mpu = driver(&chip);
    set_up(&mut mpu, &chip);
    let mut t_ns = chip.borrow().now_ns();
    let mut worst = Worst::default();
    for (accel_sens, accel_g, accel_lsb) in ACCEL {
        for (gyro_sens, gyro_dps, gyro_lsb) in GYRO {
            ok(mpu.set_accelerometer_sensitive(accel_sens), "accel scale");
            ok(mpu.set_gyro_sensitive(gyro_sens), "gyro scale");
            for i in 0..FRACTIONS.len() {
                let s = SPREAD.sample(i, accel_g, gyro_dps);
                t_ns += 1_000_000;
                chip.borrow_mut().latch_at(&s, t_ns);
                let (accel, temp, gyro) = ok(mpu.read_all(), "read_all");
                let (accel_raw, gyro_raw) = (accel.0, gyro.0);
                let accel_g_read = accel / accel_sens;
                let gyro_dps_read = gyro / gyro_sens;
                worst.add(&s, accel_g_read, gyro_dps_read, accel_lsb, gyro_lsb);
                let ideal_t = (f64::from(s.temp_c) - 36.53) * 340.0;
                worst.add_temperature((f64::from(temp.0) - ideal_t).abs());
                let celsius = f64::from(temp.celcius().0) / 100.0;
                assert!((celsius - f64::from(s.temp_c)).abs() < 0.02, "{celsius} °C");
                // The single reads agree with the burst.
                assert_eq!(ok(mpu.read_acceleration(), "accel").0, accel_raw);
                assert_eq!(ok(mpu.read_gyro(), "gyro").0, gyro_raw);
            }
        }
    }
    worst.check();
}

#[test]
fn fifo_counter_counts_records() {
    let chip = new_chip();
    let mut mpu = driver(&chip);
    set_up(&mut mpu, &chip);
    let fifo = FifoEnable {
        temperature: true,
        x_g_force: true,
        y_g_force: true,
        z_g_force: true,
        acceleration: true,
        ..FifoEnable::default()
    };
    ok(mpu.enable_fifo(fifo), "enable_fifo");
    ok(mpu.enable_fifo_buffer(), "enable_fifo_buffer");
    let t0 = chip.borrow().now_ns();
    for k in 1..=5 {
        chip.borrow_mut()
            .latch_at(&SPREAD.sample(k, 2.0, 250.0), t0 + k as u64 * 1_000_000);
    }
    assert_eq!(
        ok(mpu.get_fifo_counter(), "fifo count"),
        70,
        "5 records of 14 bytes"
    );
}

#[test]
fn driver_quirks_are_pinned() {
    let chip = new_chip();
    let mut mpu = driver(&chip);
    set_up(&mut mpu, &chip);
    ok(
        mpu.set_accelerometer_sensitive(AccelerometerSensitive::Sensitive2048),
        "accel",
    );
    let s = PhysicalSample {
        acc: [(0.5 * G) as f32, 0.0, 0.0],
        temp_c: 30.0,
        ..PhysicalSample::default()
    };
    let t = chip.borrow().now_ns() + 1_000_000;
    chip.borrow_mut().latch_at(&s, t);
    // read_temperature returns ACCEL_XOUT (1024 at 0.5 g, ±16 g).
    let wrong = ok(mpu.read_temperature(), "read_temperature");
    assert_eq!(wrong.0, 1024);
    let (_, temp, _) = ok(mpu.read_all(), "read_all");
    assert_eq!(temp.0, -2220, "(30 − 36.53) · 340");
    let as_f32: f32 = temp.into();
    assert!(
        (as_f32 - (-2220.0 / 340.0 + 365.3)).abs() < 1e-3,
        "Into<f32> adds 365.3"
    );
    // set_i2c_disable(true) pulses FIFO_RST: I2C still answers.
    ok(mpu.set_i2c_disable(true), "set_i2c_disable");
    assert_eq!(chip.borrow().peek(0x6A) & 0x10, 0x00);
    let mut c = chip.borrow_mut();
    assert!(c.start(0x68, false), "I2C still enabled");
    c.stop();
}
