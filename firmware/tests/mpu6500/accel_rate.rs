//! Which latches bring a new accelerometer value, under every gyro setting (FCHOICE_B,
//! DLPF_CFG) and accel setting (ACCEL_FCHOICE_B, A_DLPF_CFG), on the MPU-6500 and the
//! ICM-20602 (RM-MPU-6500A sections 4.6 and 4.8 tables; DS-000176 section 10 tables 2 and 3):
//! gyro 32 kHz / 8 kHz / 1 kHz, accel 4 kHz with ACCEL_FCHOICE_B, else 1 kHz.

use super::*;

fn accel_after_each(variant: Variant, config: u8, fchoice_b: u8, config2: u8, n: u64) -> Vec<i16> {
    common::accel_after_each(chip(variant), config, fchoice_b, config2, n)
}

#[test]
fn every_setting() {
    for variant in [Variant::Mpu6500, Variant::Icm20602, Variant::Mpu9250] {
        // (CONFIG, FCHOICE_B, ACCEL_CONFIG2, output period, accel period)
        let cases = [
            (0x00, 0, 0x00, 125_000, 1_000_000), // gyro 8 kHz, accel DLPF 1 kHz
            (0x07, 0, 0x00, 125_000, 1_000_000), // DLPF_CFG 7: 8 kHz too
            (0x00, 0, 0x08, 125_000, 250_000),   // ACCEL_FCHOICE_B: 4 kHz
            (0x07, 0, 0x0F, 125_000, 250_000),   // A_DLPF_CFG ignored when bypassed
            (0x03, 1, 0x08, 31_250, 250_000),    // FCHOICE_B = 01: 32 kHz
            (0x03, 2, 0x00, 31_250, 1_000_000),  // FCHOICE_B = 10: 32 kHz
            (0x01, 0, 0x08, 1_000_000, 250_000), // 1 kHz output: every sample new
            (0x03, 0, 0x03, 1_000_000, 1_000_000), // DLPF both ways
        ];
        for (config, fchoice_b, config2, period, accel) in cases {
            let got = accel_after_each(variant, config, fchoice_b, config2, 40);
            assert_eq!(
                got,
                expected_accel(period, accel, 40),
                "{variant:?} CONFIG {config:#04x} FCHOICE_B {fchoice_b} ACCEL_CONFIG2 {config2:#04x}"
            );
        }
    }
}

#[test]
fn at_8_khz_with_a_4_khz_accelerometer_each_value_appears_twice() {
    let got = accel_after_each(Variant::Mpu6500, 0x00, 0, 0x08, 9);
    assert_eq!(got, [1, 2, 2, 4, 4, 6, 6, 8, 8]);
    let got = accel_after_each(Variant::Icm20602, 0x07, 0, 0x08, 9);
    assert_eq!(got, [1, 2, 2, 4, 4, 6, 6, 8, 8]);
}

#[test]
fn the_fifo_repeats_the_accel_like_the_registers() {
    for variant in [Variant::Mpu6500, Variant::Icm20602] {
        let mut c = chip(variant);
        spi_write(&mut c, 0x6B, &[0x01]);
        spi_write(&mut c, 0x1A, &[0x00]);
        spi_write(&mut c, 0x1C, &[0x18]);
        spi_write(&mut c, 0x1D, &[0x08]);
        spi_write(&mut c, 0x23, &[0xF8]); // ICM-20602: bits 4 and 3 mean gyro and accel
        spi_write(&mut c, 0x6A, &[0x40]);
        for k in 1..=8 {
            c.latch_at(&numbered(k), k * 125_000);
        }
        let fifo = spi_read(&mut c, 0x74, 8 * 14);
        let accel: Vec<i16> = fifo.chunks(14).map(|r| be(r, 0)).collect();
        assert_eq!(accel, [1, 2, 2, 4, 4, 6, 6, 8], "{variant:?}");
        assert_eq!(spi_read(&mut c, 0x72, 2), [0x00, 0x00]);
    }
}

#[test]
fn changing_the_accel_rate_takes_a_value_at_once() {
    let mut c = chip(Variant::Mpu6500);
    spi_write(&mut c, 0x1C, &[0x18]);
    c.latch_at(&numbered(1), 1_000_000);
    c.latch_at(&numbered(2), 1_125_000);
    spi_write(&mut c, 0x1D, &[0x08]);
    c.latch_at(&numbered(3), 1_250_000);
    assert_eq!(spi_read(&mut c, 0x3B, 2), [0x00, 0x03]);
    assert_eq!(c.accel_period_ns(), 250_000);
}

#[test]
fn image_latches_keep_the_accelerometer_rate_too() {
    // Source mode (a): an image is what the sensors would measure at its instant; the 1 kHz
    // accelerometer takes a new one only at its own instants (t = 1 ms here), the gyro each.
    let mut c: Mpu6xxx = chip(Variant::Mpu6500);
    let mut image = [0u8; 22];
    for k in 1..=9u8 {
        image[1] = k;
        image[9] = k;
        c.latch_image_at(&image, u64::from(k) * 125_000);
        let accel = if k < 8 { 1 } else { 8 };
        assert_eq!(
            spi_read(&mut c, 0x3B, 2),
            [0x00, accel],
            "accel at latch {k}"
        );
        assert_eq!(spi_read(&mut c, 0x43, 2), [0x00, k], "gyro at latch {k}");
    }
}

#[test]
fn the_gyro_repeats_only_when_latched_faster_than_it_samples() {
    // DLPF_CFG 1: gyro 1 kHz. A board latching every 125 µs (faster than the output rate the
    // chip asks for) sees each gyro value eight times; GYRO_RST restarts the gyro's clock.
    let mut c = chip(Variant::Mpu6500);
    spi_write(&mut c, 0x1A, &[0x01]);
    spi_write(&mut c, 0x1B, &[0x18]);
    assert_eq!(c.gyro_period_ns(), 1_000_000);
    let gyro: Vec<i16> = (1..=9u64)
        .map(|k| {
            c.latch_at(&numbered(k), k * 125_000);
            be(&spi_read(&mut c, 0x43, 2), 0)
        })
        .collect();
    assert_eq!(gyro, [1, 1, 1, 1, 1, 1, 1, 8, 8]);
    spi_write(&mut c, 0x68, &[0x04]); // GYRO_RST
    c.latch_at(&numbered(10), 10 * 125_000);
    assert_eq!(spi_read(&mut c, 0x43, 2), [0x00, 0x0A]);
    // The ICM-20602 has no GYRO_RST: bit 2 is stored and restarts nothing.
    let mut c = chip(Variant::Icm20602);
    spi_write(&mut c, 0x6B, &[0x01]);
    spi_write(&mut c, 0x1A, &[0x01]);
    spi_write(&mut c, 0x1B, &[0x18]);
    c.latch_at(&numbered(8), MS);
    spi_write(&mut c, 0x68, &[0x04]);
    c.latch_at(&numbered(9), MS + 125_000);
    assert_eq!(spi_read(&mut c, 0x43, 2), [0x00, 0x08]);
}
