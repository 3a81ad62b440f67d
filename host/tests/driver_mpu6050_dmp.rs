//! The `mpu6050-dmp` crate (0.6, embedded-hal 1.0), unmodified, drives the emulated MPU-6000
//! over I2C through margemu's embedded-hal 1.0 adapter (`margemu::bus::I2c`). The MPU-6000's
//! I2C interface and registers are the MPU-6050's (RM-MPU-6000A covers both), so the driver
//! talks to it as to its own part.
//!
//! The driver wakes the chip in its constructor; for each of its accelerometer and gyroscope
//! full scales the test resets the chip through the driver (`reset`, `disable_sleep`,
//! `set_clock_source`), sets the full scales and the DLPF (the driver ORs its settings into
//! the registers, so a lower setting needs a reset first), then reads known physical samples
//! (`latch_at` of a [`PhysicalSample`]: positive, negative and beyond full scale) with
//! `motion6`, `accel`, `gyro` and `temperature`. Each value must match the sample to within one
//! LSB of the current full scale (the sample in register counts at the datasheet sensitivity,
//! clipped like the register, against the driver's value times its own sensitivity).
//!
//! What the driver returns (read in `mpu6050-dmp-0.6.1/src`): `Accel::scaled` in g
//! (raw / 16384 … 2048), `Gyro::scaled` in °/s (raw / 131, 65.5, 32.8, 16.4), `Temperature::
//! celsius` = raw / 340 + 36.53: the datasheet values the chip uses. The DMP (firmware upload
//! through MEM_R_W, `initialize_dmp`) is not emulated and not used here.

mod driver_support;

use driver_support::{new_mpu6000 as new_chip, Spread, Worst, FRACTIONS};
use embedded_hal::delay::DelayNs;
use margemu::bus::{self, Shared};
use margemu_firmware::chip::{Config, Mpu6xxx as Chip, PhysicalSample};
use mpu6050_dmp::accel::{Accel, AccelFullScale};
use mpu6050_dmp::address::Address;
use mpu6050_dmp::clock_source::ClockSource;
use mpu6050_dmp::config::DigitalLowPassFilter;
use mpu6050_dmp::gyro::GyroFullScale;
use mpu6050_dmp::sensor::Mpu6050;

type Driver = Mpu6050<bus::I2c<Chip>>;

/// The driver on its own I2C adapter; its constructor wakes the chip.
fn driver(chip: &Shared<Chip>) -> Driver {
    assert_eq!(
        chip.borrow().peek(0x6B),
        0x40,
        "the MPU-6000 powers on asleep"
    );
    let mpu = Mpu6050::new(bus::I2c::new(chip.clone()), Address::default()).unwrap();
    assert_eq!(chip.borrow().peek(0x6B), 0x00, "disable_sleep");
    mpu
}

/// Reset through the driver, then wake, PLL clock, full scales, DLPF 1 (1 kHz output).
fn configure(mpu: &mut Driver, chip: &Shared<Chip>, accel: AccelFullScale, gyro: GyroFullScale) {
    let mut delay = bus::Delay::new();
    mpu.reset(&mut delay).unwrap();
    assert_eq!(chip.borrow().peek(0x6B), 0x40, "DEVICE_RESET: asleep again");
    mpu.disable_sleep().unwrap();
    mpu.set_clock_source(ClockSource::Xgyro).unwrap();
    assert_eq!(chip.borrow().peek(0x6B), 0x01);
    mpu.set_accel_full_scale(accel).unwrap();
    mpu.set_gyro_full_scale(gyro).unwrap();
    mpu.set_digital_lowpass_filter(DigitalLowPassFilter::Filter1)
        .unwrap();
    mpu.set_sample_rate_divider(0).unwrap();
    delay.delay_ms(1);
    assert_eq!(chip.borrow().sample_period_ns(), 1_000_000);
}

const ACCEL: [(AccelFullScale, f64); 4] = [
    (AccelFullScale::G2, 2.0),
    (AccelFullScale::G4, 4.0),
    (AccelFullScale::G8, 8.0),
    (AccelFullScale::G16, 16.0),
];
const GYRO: [(GyroFullScale, f64); 4] = [
    (GyroFullScale::Deg250, 250.0),
    (GyroFullScale::Deg500, 500.0),
    (GyroFullScale::Deg1000, 1000.0),
    (GyroFullScale::Deg2000, 2000.0),
];

/// Each axis a different fraction of full scale; 15 °C, then 2.3 °C warmer a sample.
const SPREAD: Spread = Spread {
    acc: [2, 4, 8],
    gyr: [1, 6, 10],
    temp_c: [15.0, 2.3],
};

#[test]
fn every_full_scale_within_one_lsb() {
    let chip = new_chip();
    let mut mpu = driver(&chip);
    let mut worst = Worst::default();
    for (accel_fs, accel_g) in ACCEL {
        for (gyro_fs, gyro_dps) in GYRO {
            configure(&mut mpu, &chip, accel_fs, gyro_fs);
            let (accel_lsb, gyro_lsb) = (accel_fs.scale() as f64, gyro_fs.scale() as f64);
            for i in 0..FRACTIONS.len() {
                let s = SPREAD.sample(i, accel_g, gyro_dps);
                let t = chip.borrow().now_ns() + 1_000_000;
                chip.borrow_mut().latch_at(&s, t);
                let (accel, gyro) = mpu.motion6().unwrap();
                assert_eq!(mpu.accel().unwrap(), accel, "accel() agrees with motion6()");
                assert_eq!(mpu.gyro().unwrap(), gyro);
                let a = accel.scaled(accel_fs);
                let w = gyro.scaled(gyro_fs);
                let (a, w) = ([a.x(), a.y(), a.z()], [w.x(), w.y(), w.z()]);
                worst.add(&s, a, w, accel_lsb, gyro_lsb);
                let celsius = f64::from(mpu.temperature().unwrap().celsius());
                worst.add_temperature((celsius - f64::from(s.temp_c)).abs() * 340.0);
            }
        }
    }
    worst.check();
}

#[test]
fn accel_calibration_registers_move_the_output() {
    // The driver's calibration writes XA/YA/ZA_OFFS at 0x06..=0x0B, the MPU-6000's factory
    // trim: each step of 2 (bit 0 unused) moves the output by 1/1024 g = 16 LSB at ±2 g.
    let chip = new_chip();
    let mut mpu = driver(&chip);
    configure(&mut mpu, &chip, AccelFullScale::G2, GyroFullScale::Deg250);
    let trim = mpu.get_accel_calibration().unwrap();
    assert_eq!(trim.x() as u16, Config::default().accel_offset[0]);
    let moved = Accel::new(trim.x() + 2, trim.y() - 4, trim.z());
    mpu.set_accel_calibration(&moved).unwrap();
    let t = chip.borrow().now_ns() + 1_000_000;
    chip.borrow_mut().latch_at(&PhysicalSample::default(), t);
    let accel = mpu.accel().unwrap();
    assert_eq!([accel.x(), accel.y(), accel.z()], [16, -32, 0]);
}

#[test]
fn fifo_through_the_driver() {
    let chip = new_chip();
    let mut mpu = driver(&chip);
    configure(&mut mpu, &chip, AccelFullScale::G16, GyroFullScale::Deg2000);
    let mut fifo = mpu6050_dmp::fifo::Fifo::all_disabled();
    fifo.accel = true;
    fifo.temp = true;
    fifo.xg = true;
    fifo.yg = true;
    fifo.zg = true;
    mpu.set_fifo_enabled(fifo).unwrap();
    mpu.enable_fifo().unwrap();
    for i in 0..3 {
        let t = chip.borrow().now_ns() + 1_000_000;
        chip.borrow_mut()
            .latch_at(&SPREAD.sample(i, 16.0, 2000.0), t);
    }
    assert_eq!(mpu.get_fifo_count().unwrap(), 42);
    let mut buf = [0u8; 64];
    let records = mpu.read_fifo(&mut buf).unwrap().to_vec();
    assert_eq!(records.len(), 42);
    let data = mpu.motion6().unwrap();
    let last = &records[28..];
    assert_eq!(i16::from_be_bytes([last[0], last[1]]), data.0.x());
    assert_eq!(i16::from_be_bytes([last[12], last[13]]), data.1.z());
}
