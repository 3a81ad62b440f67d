//! The MPU-9250's accelerometer rate (RM-MPU-9250A rev. 1.6 section 4.8): 4 kHz with
//! ACCEL_FCHOICE_B = 1, else 1 kHz, whatever the gyro does (8 kHz at DLPF_CFG 0/7, 32 kHz with
//! FCHOICE_B); and PX4's MPU-9250 driver at 8 kHz, whose FIFO check needs each accel value
//! twice (`common::fc::px4_mpu9250`).

use super::chip;
use super::common::fc::{px4_mpu9250, FcError};
use super::common::{accel_after_each, accel_runs, expected_accel, Bench};

#[test]
fn accel_runs_at_4_khz_with_accel_fchoice_b_and_1_khz_otherwise() {
    // (CONFIG, FCHOICE_B, ACCEL_CONFIG2, output period, accel period)
    let cases = [
        (0x00, 0, 0x08, 125_000, 250_000), // 8 kHz latches, ACCEL_FCHOICE_B: 4 kHz
        (0x07, 0, 0x0F, 125_000, 250_000), // A_DLPF_CFG ignored when bypassed
        (0x00, 0, 0x00, 125_000, 1_000_000), // accel DLPF: 1 kHz
        (0x07, 0, 0x06, 125_000, 1_000_000), // A_DLPF_CFG 6: 1 kHz
        (0x03, 1, 0x08, 31_250, 250_000),  // gyro FCHOICE_B 01: 32 kHz, accel 4 kHz
        (0x03, 3, 0x08, 31_250, 250_000),  // FCHOICE_B 11 likewise
        (0x03, 2, 0x00, 31_250, 1_000_000), // FCHOICE_B 10: 32 kHz, accel 1 kHz
    ];
    for (config, fchoice_b, config2, period, accel) in cases {
        assert_eq!(
            accel_after_each(chip(), config, fchoice_b, config2, 72),
            expected_accel(period, accel, 72),
            "CONFIG {config:#04x} FCHOICE_B {fchoice_b} ACCEL_CONFIG2 {config2:#04x}"
        );
    }
    // At 8 kHz with the 4 kHz accelerometer each value appears twice; at 32 kHz, eight times.
    assert_eq!(
        accel_after_each(chip(), 0x00, 0, 0x08, 9),
        [1, 2, 2, 4, 4, 6, 6, 8, 8]
    );
    assert_eq!(
        accel_after_each(chip(), 0x00, 1, 0x08, 10),
        [1, 1, 1, 1, 1, 1, 1, 8, 8, 8]
    );
}

#[test]
fn px4_reads_the_8_khz_fifo_with_duplicated_accel() {
    let mut bench = Bench::new(chip());
    let run = px4_mpu9250(&mut bench, 50).unwrap();
    assert_eq!(bench.chip.sample_period_ns(), 125_000);
    assert_eq!(bench.chip.accel_period_ns(), 250_000);
    assert_eq!(run.bad_transfers, 0, "every transfer passes PX4's check");
    assert_eq!(run.records.len(), 50 * 8, "eight records per 1 ms");
    let first = run.records[0].gyro_x;
    assert!(
        run.records.iter().zip(first..).all(|(r, k)| r.gyro_x == k),
        "every sample once, in order"
    );
    let runs = accel_runs(&run.records);
    assert!(
        runs[1..runs.len() - 1].iter().all(|&(_, n)| n == 2),
        "{runs:?}"
    );
}

#[test]
fn px4_mpu9250_refuses_the_icm20602() {
    let mut bench = Bench::new(super::common::chip(
        margemu_firmware::chip::Variant::Icm20602,
    ));
    assert_eq!(
        px4_mpu9250(&mut bench, 1).unwrap_err(),
        FcError::WhoAmI(0x12)
    );
}
