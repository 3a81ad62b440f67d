//! PX4's ICM-20602 driver sequence at 8 kHz (`common::fc::px4_icm20602`): every transfer passes
//! its duplicated-accel check, every sample arrives once and in order, each accel value twice.

use super::common::fc::{px4_accel_pattern_ok, px4_icm20602, FcError};
use super::*;

#[test]
fn px4_reads_the_8_khz_fifo_with_duplicated_accel() {
    let mut bench = Bench::new(chip(Variant::Icm20602));
    let run = px4_icm20602(&mut bench, 200).unwrap();
    assert_eq!(bench.chip.sample_period_ns(), 125_000);
    assert_eq!(bench.chip.accel_period_ns(), 250_000);
    assert_eq!(run.bad_transfers, 0);
    assert_eq!(run.records.len(), 200 * 8, "eight records per 1 ms");
    let first = run.records[0].gyro_x as u64;
    let mut accel_from = bench.accel_source(first, 250_000);
    for (i, r) in run.records.iter().enumerate() {
        let k = first + i as u64;
        assert_eq!(r.gyro_x as u64, k, "record {i}: lost or repeated");
        if bench.new_accel(k, 250_000) {
            accel_from = k;
        }
        assert_eq!(r.accel_x as u64, accel_from, "record {i}");
    }
    assert_eq!(
        first + run.records.len() as u64,
        bench.next_sample(),
        "none left behind"
    );
    // Each accel value exactly twice in a row.
    let runs = accel_runs(&run.records);
    let inner = &runs[1..runs.len() - 1];
    assert!(inner.iter().all(|&(_, n)| n == 2), "{runs:?}");
}

/// Four FIFO records at 8 kHz with a 4 kHz accelerometer, latched from physical samples or,
/// with `images`, from register images (the accelerometer holds its value either way).
fn four_records(images: bool) -> Vec<u8> {
    let mut c = awake();
    spi_write(&mut c, 0x1A, &[0x47]);
    spi_write(&mut c, 0x1D, &[0x08]);
    spi_write(&mut c, 0x23, &[0x18]);
    spi_write(&mut c, 0x6A, &[0x40]);
    for k in 1..=4u8 {
        let t = u64::from(k) * 125_000;
        if images {
            let mut image = [0u8; 22];
            image[1] = k;
            c.latch_image_at(&image, t);
        } else {
            c.latch_at(&numbered(u64::from(k)), t);
        }
    }
    spi_read(&mut c, 0x74, 4 * 14)
}

#[test]
fn px4_check_needs_the_duplicates() {
    assert!(px4_accel_pattern_ok(&four_records(false), 4));
    assert!(
        px4_accel_pattern_ok(&four_records(true), 4),
        "register images keep the accelerometer's own rate too"
    );
    // A FIFO whose every record has a new accel value (a chip that ignored its accel rate).
    let mut every_new = four_records(false);
    for (k, record) in every_new.chunks_mut(14).enumerate() {
        record[1] = 0x40 + k as u8;
    }
    assert!(
        !px4_accel_pattern_ok(&every_new, 4),
        "every record new: rejected"
    );
}

#[test]
fn px4_refuses_another_chip() {
    let mut bench = Bench::new(chip(Variant::Mpu6000));
    assert_eq!(
        px4_icm20602(&mut bench, 1).unwrap_err(),
        FcError::WhoAmI(0x68)
    );
}
