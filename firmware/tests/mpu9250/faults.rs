//! The chip faults on the MPU-9250 + AK8963 through the flight-controller sequences
//! (`common::fc`, `common::fc_faults`): a reset mid-run returns both dies to their power-on
//! values — the MPU-9250 wakes running (PWR_MGMT_1 = 0x01, RM-MPU-9250A-00 section 3: unlike
//! the MPU-6000 it does not sleep) at ±2 g / ±250 °/s and 8 kHz with the FIFO off — which
//! ArduPilot's read-back notices; a wrong identity fails PX4's WHO_AM_I check and shows in the
//! AK8963's WIA as well; a forced FIFO overflow makes PX4's FIFO reader reset the FIFO.

use margemu_firmware::chip::Chip;

use super::common::fc::{px4_mpu9250, px4_mpu9250_with, FcError};
use super::common::fc_faults::{ardupilot_checked, assert_consecutive};
use super::common::Bench;
use super::*;

#[test]
fn a_reset_wakes_both_dies_at_their_power_on_values_and_keeps_sampling() {
    let mut c = chip();
    spi_write(&mut c, 0x1B, &[0x18]); // ±2000 °/s
    spi_write(&mut c, 0x37, &[0x02]); // bypass: the AK8963 on the bus
    assert_eq!(i2c_write(&mut c, 0x0C, &[0x0A, 0x16]), [true; 3]); // AK8963 CNTL1: 100 Hz
    c.latch_at(&at_rest(), 20 * MS);
    assert!(Chip::fault_reset(&mut c));
    assert_eq!(
        registers(&c),
        registers(&chip()),
        "every register as at power-up"
    );
    assert_eq!(c.peek(0x6B), 0x01, "PWR_MGMT_1: awake, auto clock");
    assert_eq!(
        c.ak8963().unwrap().peek(0x0A),
        0x00,
        "AK8963 CNTL1: power-down"
    );
    assert_eq!(c.now_ns(), 20 * MS, "the clock is kept");
    // It samples on at its power-on settings: ±2 g (16384 LSB/g).
    c.latch_at(&at_rest(), 21 * MS);
    assert_eq!(spi_read(&mut c, 0x3F, 2), [0x40, 0x00]);
}

#[test]
fn ardupilot_read_back_notices_a_reset_and_recovers_after_initialising_again() {
    let mut clean = Bench::new(chip());
    let clean = ardupilot_checked(&mut clean, 60, 0x71, &mut |_, _| {}).unwrap();
    assert!(clean.mismatches.is_empty());
    let all: Vec<_> = clean.records.iter().map(|(_, r)| r).collect();
    assert_consecutive(&all);
    let mut bench = Bench::new(chip());
    let mut reset = |b: &mut Bench, poll: usize| {
        if poll == 30 {
            assert!(Chip::fault_reset(&mut b.chip));
        }
    };
    let run = ardupilot_checked(&mut bench, 90, 0x71, &mut reset).unwrap();
    assert_eq!(
        run.mismatches,
        [30],
        "GYRO_CONFIG re-read at poll 30: cleared"
    );
    let (early, late): (Vec<_>, Vec<_>) = run.records.iter().partition(|(p, _)| *p < 30);
    assert!(
        late.iter().all(|(p, _)| *p > 30),
        "none between the reset and the re-init"
    );
    let before: Vec<_> = early.iter().map(|(_, r)| r).collect();
    assert_eq!(
        before[..],
        all[..before.len()],
        "the clean run's records before it"
    );
    let after: Vec<_> = late.iter().map(|(_, r)| r).collect();
    assert!(after.len() >= 55, "{} records after", after.len());
    assert_consecutive(&after);
}

#[test]
fn a_wrong_identity_fails_px4s_check_and_the_ak8963s_wia_too() {
    let mut bench = Bench::new(chip());
    assert!(Chip::fault_identity(&mut bench.chip, Some(0x73)));
    assert_eq!(
        px4_mpu9250(&mut bench, 1).unwrap_err(),
        FcError::WhoAmI(0x73)
    );
    spi_write(&mut bench.chip, 0x37, &[0x02]);
    assert_eq!(
        i2c_read(&mut bench.chip, 0x0C, 0x00, 1),
        Some(vec![0x73]),
        "WIA"
    );
    assert!(Chip::fault_identity(&mut bench.chip, None));
    assert_eq!(
        i2c_read(&mut bench.chip, 0x0C, 0x00, 1),
        Some(vec![0x48]),
        "WIA"
    );
    assert_eq!(px4_mpu9250(&mut bench, 3).unwrap().records.len(), 3 * 8);
}

#[test]
fn px4_resets_the_fifo_on_a_forced_overflow_and_reads_exactly_after_it() {
    let mut bench = Bench::new(chip());
    let clean = px4_mpu9250(&mut bench, 40).unwrap();
    assert_eq!((clean.fifo_resets, clean.records.len()), (0, 40 * 8));
    let mut bench = Bench::new(chip());
    let mut oflow_seen = false;
    let mut fault = |b: &mut Bench, poll: usize| {
        if poll == 15 {
            assert!(Chip::fault_fifo_overflow(&mut b.chip, true));
        }
        if poll == 25 {
            oflow_seen = b.chip.peek(0x3A) & 0x10 != 0; // INT_STATUS.FIFO_OFLOW_INT
            assert!(Chip::fault_fifo_overflow(&mut b.chip, false));
        }
    };
    let run = px4_mpu9250_with(&mut bench, 40, &mut fault).unwrap();
    assert!(oflow_seen, "FIFO_OFLOW_INT set during the window");
    assert_eq!(
        run.fifo_resets, 10,
        "every poll of the window sees a full FIFO"
    );
    // 15 polls before and 15 after (the first poll after the window finds the FIFO the last
    // reset left: 8 fresh records) decoded exactly: consecutive samples, as in the clean run.
    assert_eq!(run.records.len(), 30 * 8);
    let gyro: Vec<i16> = run.records.iter().map(|r| r.gyro_x).collect();
    let k0 = gyro[0];
    assert_eq!(
        gyro[..15 * 8],
        (k0..k0 + 120).collect::<Vec<_>>()[..],
        "before"
    );
    let k1 = gyro[15 * 8];
    assert_eq!(
        gyro[15 * 8..],
        (k1..k1 + 120).collect::<Vec<_>>()[..],
        "after"
    );
    assert_eq!(k1, k0 + 25 * 8, "the window's 10 polls of samples lost");
}
