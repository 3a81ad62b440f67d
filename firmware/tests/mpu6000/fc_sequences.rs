//! Betaflight's and ArduPilot's MPU-6000 register sequences (`common::fc`) against the chip on
//! a bench that latches numbered samples at the chip's own output clock: every sample decoded
//! in order, none lost or repeated, the accel repeating exactly as its 1 kHz clock says.

use super::common::fc::{fc_ardupilot, fc_betaflight, ArduPilotOptions, FcError, FcRun};
use super::*;

/// Checks `run` decoded consecutive samples from its first record on, each carrying the accel
/// value of the latch that opened its accelerometer period. Returns the first sample number.
fn assert_in_order(bench: &Bench, run: &FcRun, accel_period_ns: u64) -> u64 {
    let first = run.records[0].gyro_x as u64;
    let mut accel_from = bench.accel_source(first, accel_period_ns);
    for (i, r) in run.records.iter().enumerate() {
        let k = first + i as u64;
        assert_eq!(r.gyro_x as u64, k, "record {i}: lost or repeated sample");
        if bench.new_accel(k, accel_period_ns) {
            accel_from = k;
        }
        assert_eq!(
            r.accel_x as u64, accel_from,
            "record {i} (sample {k}): accel"
        );
    }
    first
}

#[test]
fn betaflight_detects_configures_and_reads_every_data_ready() {
    let mut bench = Bench::new(chip(Variant::Mpu6000));
    let run = fc_betaflight(&mut bench, 400).unwrap();
    assert_eq!(bench.chip.sample_period_ns(), 125_000, "8 kHz");
    assert_eq!(run.records.len(), 400);
    let first = assert_in_order(&bench, &run, 1_000_000);
    assert_eq!(
        first + 399,
        bench.next_sample() - 1,
        "the last read is the last latched"
    );
    // 8 kHz over a 1 kHz accelerometer: 400 records hold 50 or 51 distinct accel values.
    let mut distinct: Vec<i16> = run.records.iter().map(|r| r.accel_x).collect();
    distinct.dedup();
    assert!((50..=51).contains(&distinct.len()), "{}", distinct.len());
}

#[test]
fn betaflight_rejects_an_unknown_product_id() {
    for variant in [Variant::WhoAmI68, Variant::Mpu6500] {
        let mut bench = Bench::new(chip(variant));
        let err = fc_betaflight(&mut bench, 1).unwrap_err();
        let expected = match variant {
            Variant::WhoAmI68 => FcError::ProductId(0x00),
            _ => FcError::WhoAmI(0x70),
        };
        assert_eq!(err, expected);
    }
}

/// The records from the first one converted at ±16 g (ACCEL_ZOUT = 2048) on: before it the
/// chip still ran at the reset full scales (the driver sets them after enabling the FIFO).
fn configured(run: &FcRun) -> FcRun {
    let start = run.records.iter().position(|r| r.accel_z == 2048).unwrap();
    assert!(start <= 40, "{start} records before the full scales");
    FcRun {
        records: run.records[start..].to_vec(),
        ..FcRun::default()
    }
}

/// ArduPilot's run after its `_hardware_init` and `start`.
fn ardupilot(options: ArduPilotOptions, polls: usize) -> (Bench, FcRun) {
    let mut bench = Bench::new(chip(Variant::Mpu6000));
    let run = fc_ardupilot(&mut bench, polls, options).unwrap();
    assert_eq!(bench.chip.peek(0x6B), 0x03, "clock read back");
    assert_eq!(bench.chip.peek(0x1C), 0x18, "rev. D8: ±16 g");
    (bench, run)
}

#[test]
fn ardupilot_at_1_khz() {
    let (bench, run) = ardupilot(ArduPilotOptions::default(), 300);
    assert_eq!(bench.chip.sample_period_ns(), 1_000_000);
    assert_eq!(run.fifo_resets, 0);
    // CONFIG (1 kHz) follows the FIFO reset at once, but GYRO_CONFIG and ACCEL_CONFIG come
    // 1–2 ms later: the first records carry ±250 °/s / ±2 g values. From the first sample
    // latched after ACCEL_CONFIG on, each record is its sample.
    let tail = configured(&run);
    assert!(run.records.len() - tail.records.len() <= 4);
    let first = assert_in_order(&bench, &tail, 1_000_000);
    assert_eq!(
        first + tail.records.len() as u64,
        bench.next_sample(),
        "none lost"
    );
}

#[test]
fn ardupilot_fast_sampling_at_8_khz() {
    let (bench, run) = ardupilot(
        ArduPilotOptions {
            fast_sampling: true,
            ..ArduPilotOptions::default()
        },
        200,
    );
    assert_eq!(bench.chip.sample_period_ns(), 125_000);
    // The first poll finds more than 32 records (8 kHz during the 4 ms of start-up): the
    // driver reads 24 and resets the FIFO, once. From then on 8 records per 1 ms poll.
    assert_eq!(run.fifo_resets, 1);
    let tail = FcRun {
        records: run.records[24..].to_vec(),
        ..FcRun::default()
    };
    let first = assert_in_order(&bench, &tail, 1_000_000);
    assert_eq!(
        first + tail.records.len() as u64,
        bench.next_sample(),
        "none lost"
    );
    assert_eq!(tail.records.len(), 199 * 8);
}

#[test]
fn ardupilot_resets_a_misaligned_fifo_on_the_temperature_check() {
    let (bench, run) = ardupilot(
        ArduPilotOptions {
            lose_byte_before_poll: Some(100),
            ..ArduPilotOptions::default()
        },
        300,
    );
    assert_eq!(
        run.fifo_resets, 1,
        "the misaligned record failed the 800 LSB check"
    );
    // Before and after the reset the records are in order; the reset drops what the FIFO held.
    let run = configured(&run);
    let gap = run
        .records
        .windows(2)
        .position(|w| w[1].gyro_x != w[0].gyro_x + 1)
        .unwrap();
    let after = FcRun {
        records: run.records[gap + 1..].to_vec(),
        ..FcRun::default()
    };
    let first = assert_in_order(&bench, &after, 1_000_000);
    assert_eq!(first + after.records.len() as u64, bench.next_sample());
    // 30 °C on the MPU-6000's scale: (30 − 36.53) · 340 = −2220 LSB, rising slowly.
    assert!(run.records.iter().all(|r| (-2300..-2000).contains(&r.temp)));
}
