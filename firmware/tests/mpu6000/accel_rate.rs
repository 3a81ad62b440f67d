//! The MPU-6000's output rate and its accelerometer's 1 kHz (RM-MPU-6000A section 4.2: "the
//! same accelerometer sample may be output to the FIFO, DMP, and sensor registers more than
//! once"): which latches bring a new accel value, for each DLPF_CFG / SMPLRT_DIV setting.

use super::*;

/// Latches `n` numbered samples at the chip's own output clock; returns (gyro x, accel x) of
/// each as read from the data registers.
fn run(c: &mut Mpu6xxx, n: u64) -> Vec<(i16, i16)> {
    spi_write(c, 0x1B, &[0x18]);
    spi_write(c, 0x1C, &[0x18]);
    let period = c.sample_period_ns();
    (1..=n)
        .map(|k| {
            c.latch_at(&numbered(k), k * period);
            let d = spi_read(c, 0x3B, 14);
            (be(&d, 8), be(&d, 0))
        })
        .collect()
}

#[test]
fn at_8_khz_each_accel_value_appears_eight_times() {
    let mut c = awake(); // CONFIG 0: 8 kHz
    assert_eq!(c.sample_period_ns(), 125_000);
    assert_eq!(c.accel_period_ns(), 1_000_000);
    let got = run(&mut c, 24);
    // New accel values at 1 ms (sample 8) and 2 ms (16); sample 1 is the first after reset.
    let accel: Vec<i16> = got.iter().map(|g| g.1).collect();
    assert_eq!(
        accel,
        [1, 1, 1, 1, 1, 1, 1, 8, 8, 8, 8, 8, 8, 8, 8, 16, 16, 16, 16, 16, 16, 16, 16, 24]
    );
    assert!(
        got.iter().zip(1..).all(|(g, k)| g.0 == k),
        "the gyro takes every sample"
    );
}

#[test]
fn accel_config2_and_fchoice_b_do_not_exist() {
    let mut c = awake();
    spi_write(&mut c, 0x1D, &[0x08]); // ACCEL_FCHOICE_B on an MPU-6500; nothing here
    spi_write(&mut c, 0x1B, &[0x03]); // FCHOICE_B bits: reserved on the MPU-6000
    assert_eq!(c.accel_period_ns(), 1_000_000);
    assert_eq!(c.sample_period_ns(), 125_000, "no 32 kHz mode");
    let accel: Vec<i16> = run(&mut c, 16).iter().map(|g| g.1).collect();
    assert_eq!(accel[6..10], [1, 8, 8, 8]);
}

#[test]
fn with_the_dlpf_every_sample_is_new() {
    let mut c = awake();
    spi_write(&mut c, 0x1A, &[0x01]); // DLPF_CFG 1: 1 kHz
    assert_eq!(c.sample_period_ns(), 1_000_000);
    let got = run(&mut c, 10);
    assert!(got.iter().zip(1..).all(|(g, k)| *g == (k, k)), "{got:?}");
}

#[test]
fn smplrt_div_divides_8_khz_too() {
    let mut c = awake();
    spi_write(&mut c, 0x19, &[0x01]); // 8 kHz / 2 = 4 kHz
    assert_eq!(c.sample_period_ns(), 250_000);
    let accel: Vec<i16> = run(&mut c, 9).iter().map(|g| g.1).collect();
    assert_eq!(accel, [1, 1, 1, 4, 4, 4, 4, 8, 8]);
    spi_write(&mut c, 0x19, &[0x07]); // 8 kHz / 8 = 1 kHz: every sample new
    assert_eq!(c.sample_period_ns(), 1_000_000);
}
