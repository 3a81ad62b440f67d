//! The served BMI088 ([`Bmi088`], as `EmulatedChip::Bmi088`): both dies behind one chip, two
//! chip selects, two I2C addresses, images latched at the gyro's rate with the accel at its own
//! ODR, register overrides per die, and what the SPI shadow reads (the accelerometer die).

use super::*;
use margemu_firmware::chip::bmi088::{Bmi088, Config};
use margemu_firmware::chip::{Chip, EmulatedChip, I2cTarget};
use margemu_protocol::chip::{ChipModel, ChipSettings, FullScale};

fn emulated(address: u8) -> EmulatedChip {
    EmulatedChip::new(ChipModel::Bmi088, 0x1E, address).expect("the BMI088 is emulated")
}

/// Sample `k`'s image: distinct bytes, accel 0..6, gyro 6..12, TEMP_MSB/LSB 12..14.
fn image(k: u8) -> [u8; 14] {
    core::array::from_fn(|i| k.wrapping_mul(31).wrapping_add(i as u8 * 7))
}

/// A package with the accelerometer in SPI mode and on, at `acc_conf`.
fn running(acc_conf: u8) -> Bmi088 {
    let mut c = Bmi088::new(Config::default());
    dummy_read(&mut c);
    spi_write(&mut c, 0x7C, &[0x00]);
    spi_write(&mut c, 0x7D, &[0x04]);
    spi_write(&mut c, 0x40, &[acc_conf]);
    c
}

fn gyro_data(c: &mut Bmi088) -> Vec<u8> {
    spi_read(c.die_spi_target(1).unwrap(), 0x02, 6)
}

#[test]
fn identity_addresses_and_chip_selects() {
    assert!(EmulatedChip::models().any(|m| m == ChipModel::Bmi088));
    assert!(EmulatedChip::new(ChipModel::Bmi088, 0x0F, 0x18).is_none()); // the gyro's id
    assert!(EmulatedChip::new(ChipModel::Bmi088, 0x1E, 0x68).is_none()); // the gyro's address
    let mut c = emulated(0x19);
    assert_eq!(
        (c.model(), Chip::i2c_address(&c)),
        (ChipModel::Bmi088, 0x19)
    );
    assert_eq!(c.i2c_addresses_now(), [Some(0x19), Some(0x69)]);
    assert_eq!(i2c_read(&mut c, 0x19, 0x00, 1), Some(vec![0x1E]));
    assert_eq!(i2c_read(&mut c, 0x69, 0x00, 1), Some(vec![0x0F]));
    assert_eq!(i2c_read(&mut c, 0x18, 0x00, 1), None);
    assert_eq!(i2c_read(&mut c, 0x68, 0x00, 1), None);
    // Die 0 is the chip's own SPI target (the accel, dummy byte first); die 1 the gyro.
    assert_eq!(spi(&mut c, &[0x80, 0, 0]), [0, 0, 0]); // I2C mode: not driven
    assert_eq!(
        spi(c.die_spi_target(0).unwrap(), &[0x80, 0, 0]),
        [0, 0, 0x1E]
    );
    assert_eq!(spi(c.die_spi_target(1).unwrap(), &[0x80, 0]), [0, 0x0F]);
    assert!(c.die_spi_target(2).is_none());
    // In SPI mode the accel no longer answers I2C; the gyro does.
    assert_eq!(c.i2c_addresses_now(), [None, Some(0x69)]);
    assert_eq!(i2c_read(&mut c, 0x19, 0x00, 1), None);
    assert_eq!(i2c_read(&mut c, 0x69, 0x00, 1), Some(vec![0x0F]));
    // One-die chips have one select.
    let mut icm = EmulatedChip::new(ChipModel::Icm42688p, 0x47, 0x68).unwrap();
    assert!(icm.die_spi_target(0).is_some() && icm.die_spi_target(1).is_none());
}

#[test]
fn overrides_reach_each_die_and_leave_the_accel_in_i2c_mode() {
    let mut c = emulated(0x18);
    let fs = FullScale {
        accel_g: 12.0,
        gyro_dps: 250.0,
    };
    let want = ChipSettings::with_full_scale(ChipModel::Bmi088, fs).unwrap();
    for (file, reg, value) in want.config_writes(400.0) {
        assert!(c.write_register(file, reg, value), "file {file}");
    }
    assert!(!c.write_register(2, 0x0F, 0x00), "two register files");
    assert_eq!(c.settings(), want);
    assert_eq!(c.sample_period_ns(), 2_500_000, "gyro 400 Hz");
    let logged: Vec<_> = std::iter::from_fn(|| c.pop_write())
        .map(|w| (w.device, w.register, w.value))
        .collect();
    assert_eq!(
        logged,
        [
            (0x18, 0x41, 0x02),
            (0x18, 0x40, 0xAA),
            (0x68, 0x0F, 0x03),
            (0x68, 0x10, 0x83)
        ]
    );
    // Still in I2C mode: the device under test's first SPI read is its dummy read.
    assert_eq!(spi(&mut c, &[0x80 | 0x41, 0, 0]), [0, 0, 0]);
    assert_eq!(aread1(&mut c, 0x41), 0x02);
    // Once in SPI mode, accel overrides go over SPI.
    assert!(c.write_register(0, 0x41, 0x03));
    assert_eq!(aread1(&mut c, 0x41), 0x03);
    assert_eq!(
        c.pop_write().map(|w| w.bus),
        Some(margemu_firmware::chip::Bus::Spi)
    );
}

#[test]
fn images_latch_the_gyro_every_sample_and_the_accel_at_its_odr() {
    // Gyro 2 kHz (power-on), accel 800 Hz: the accel takes the images at 0, 1.25, 2.5 ms...
    let mut c = running(0xAB);
    let period = 500_000;
    let mut accel_from = 0;
    for k in 0..12u8 {
        let t = u64::from(k) * period;
        Chip::latch_image_at(&mut c, &image(k), t);
        if t % 1_250_000 < period {
            accel_from = k;
        }
        assert_eq!(gyro_data(&mut c), image(k)[6..12], "gyro {k}");
        assert_eq!(aread(&mut c, 0x12, 6), image(accel_from)[..6], "accel {k}");
        assert_eq!(aread(&mut c, 0x22, 2), image(0)[12..], "temperature {k}");
    }
    assert_eq!(accel_from, 10);
    // 1.28 s on, the next accel sample brings the temperature.
    Chip::latch_image_at(&mut c, &image(50), 1_280_000_000);
    assert_eq!(aread(&mut c, 0x22, 2), image(50)[12..]);
    // A wrong length latches nothing and moves the clock.
    Chip::latch_image_at(&mut c, &image(60)[..13], 1_300_000_000);
    assert_eq!(Chip::now_ns(&c), 1_300_000_000);
    assert_eq!(gyro_data(&mut c), image(50)[6..12]);
}

#[test]
fn a_die_that_is_off_takes_nothing_and_the_served_rate_follows_the_dies() {
    let mut c = Bmi088::new(Config::default());
    dummy_read(&mut c);
    assert_eq!(
        Chip::sample_period_ns(&c),
        500_000,
        "the gyro at power-on: 2 kHz"
    );
    Chip::latch_image_at(&mut c, &image(1), 500_000);
    assert_eq!(gyro_data(&mut c), image(1)[6..12]);
    assert_eq!(
        aread(&mut c, 0x12, 6),
        [0; 6],
        "the accel is off at power-on"
    );
    // Gyro suspended, accel on at 100 Hz: the served rate is the accel's; then both off: the
    // gyro's setting (1 kHz).
    spi_write(c.die_spi_target(1).unwrap(), 0x10, &[0x02]);
    spi_write(c.die_spi_target(1).unwrap(), 0x11, &[0x80]);
    spi_write(&mut c, 0x7D, &[0x04]);
    assert_eq!(Chip::sample_period_ns(&c), 10_000_000);
    Chip::latch_image_at(&mut c, &image(2), 1_000_000);
    assert_eq!(gyro_data(&mut c), image(1)[6..12], "suspended: data kept");
    assert_eq!(aread(&mut c, 0x12, 6), image(2)[..6]);
    spi_write(&mut c, 0x7D, &[0x00]);
    assert_eq!(Chip::sample_period_ns(&c), 1_000_000);
}

#[test]
fn an_image_latches_as_its_physical_sample_would() {
    let mut by_image = running(0xAC);
    let mut by_sample = running(0xAC);
    for c in [&mut by_image, &mut by_sample] {
        spi_write(c, 0x41, &[0x00]); // ±3 g
        spi_write(c.die_spi_target(1).unwrap(), 0x0F, &[0x04]); // ±125 °/s
    }
    let s = numbered(7);
    let image = Chip::settings(&by_image).image(&s);
    Chip::latch_image_at(&mut by_image, &image, MS);
    Chip::latch_at(&mut by_sample, &s, MS);
    assert_eq!(
        aread(&mut by_image, 0x00, 0x7E),
        aread(&mut by_sample, 0x00, 0x7E)
    );
    assert_eq!(gyro_data(&mut by_image), gyro_data(&mut by_sample));
    assert_eq!(gyro_data(&mut by_image), image[6..12]);
    assert_eq!(aread(&mut by_image, 0x12, 6), image[..6]);
}

#[test]
fn i2c_reads_are_the_wired_and_of_the_dies() {
    let mut c = Bmi088::new(Config::default());
    // A START to the gyro, then a read: the accel does not drive SDA.
    assert!(c.start(0x68, false) && c.write(0x00));
    assert!(c.start(0x68, true));
    assert_eq!(c.read(), 0x0F);
    // A repeated START to the accel mid-transaction: now the accel answers.
    assert!(c.start(0x18, false) && c.write(0x00));
    assert!(c.start(0x18, true));
    assert_eq!(c.read(), 0x1E);
    c.stop();
    assert!(!c.start(0x6A, false));
    assert!(!c.write(0x00));
    assert_eq!(c.read(), 0xFF);
    c.stop();
}

#[test]
fn what_the_spi_shadow_reads_is_the_accel_die() {
    let mut c = Bmi088::new(Config::default());
    assert_eq!((c.spi_peek(0x00), c.spi_read_dummy()), (0x00, None));
    assert_eq!(c.spi_plain_write(0x41, 0x02), None);
    dummy_read(&mut c);
    assert_eq!((c.spi_peek(0x00), c.spi_read_dummy()), (0x1E, Some(0x00)));
    assert_eq!(c.burst_start(), 0x12);
    assert_eq!(
        c.spi_plain_write(0x41, 0xFE),
        Some(0x02),
        "ACC_RANGE bits 1:0"
    );
    for side_effects in [0x7E, 0x40, 0x7D] {
        assert_eq!(
            c.spi_plain_write(side_effects, 0x00),
            None,
            "{side_effects:#04x}"
        );
    }
    assert_eq!(c.spi_plain_write(0x00, 0x55), None, "read-only");
    assert_eq!(
        (c.spi_next_address(0x26), c.spi_next_address(0x12)),
        (0x26, 0x13)
    );
    // The burst runs on a copy: FIFO frames stay.
    spi_write(&mut c, 0x7C, &[0x00]);
    spi_write(&mut c, 0x7D, &[0x04]);
    spi_write(&mut c, 0x49, &[0x50]); // FIFO acc_en
    Chip::latch_image_at(&mut c, &image(3), MS);
    let mut burst = [0u8; 9];
    c.spi_read_burst(0x26, &mut burst);
    let mut want = vec![0x00, 0x84];
    want.extend_from_slice(&image(3)[..6]);
    want.push(0x44); // the sensortime frame after the last frame
    assert_eq!(burst[..], want[..]);
    assert_eq!(aread(&mut c, 0x24, 2), [7, 0], "still one frame");
    // INT1: pulled up while not an output; data ready, active high, push-pull once mapped.
    assert!(Chip::int_pin_at(&c, MS) && Chip::int_open_drain(&c));
    spi_write(&mut c, 0x53, &[0x0A]);
    spi_write(&mut c, 0x58, &[0x04]);
    assert!(Chip::int_pin_at(&c, MS) && !Chip::int_open_drain(&c));
    aread(&mut c, 0x12, 6);
    assert!(!Chip::int_pin_at(&c, MS), "data read: drdy clear");
    assert_eq!(Chip::int_pulse_end_ns(&c), None);
}
