//! The chip faults on the MPU-6000 through the flight-controller sequences (`common::fc`,
//! `common::fc_faults`): a reset mid-run wakes the part asleep (PWR_MGMT_1 = 0x40) with every
//! register at its power-on value, which ArduPilot's read-back notices; Betaflight's probe
//! rejects a wrong WHO_AM_I.

use margemu_firmware::chip::Chip;

use super::common::fc::{fc_betaflight, FcError};
use super::common::fc_faults::{ardupilot_checked, assert_consecutive};
use super::*;

#[test]
fn a_reset_wakes_the_part_asleep_at_its_power_on_values() {
    let mut c = awake();
    spi_write(&mut c, 0x1B, &[0x18]);
    spi_write(&mut c, 0x6A, &[0x50]);
    c.latch_at(&numbered(5), 3 * MS);
    assert!(Chip::fault_reset(&mut c));
    let fresh = chip(Variant::Mpu6000);
    assert_eq!(
        registers(&c),
        registers(&fresh),
        "every register as at power-up"
    );
    assert_eq!(c.peek(0x6B), 0x40, "PWR_MGMT_1: SLEEP");
    assert_eq!(c.now_ns(), 3 * MS, "the clock is kept");
    c.latch_at(&numbered(6), 4 * MS);
    assert_eq!(spi_read(&mut c, 0x3B, 2), [0, 0], "asleep: no sample taken");
}

#[test]
fn ardupilot_read_back_notices_a_reset_and_recovers_after_initialising_again() {
    let mut clean = Bench::new(chip(Variant::Mpu6000));
    let run = ardupilot_checked(&mut clean, 60, 0x68, &mut |_, _| {}).unwrap();
    assert!(run.mismatches.is_empty());
    let all: Vec<_> = run.records.iter().map(|(_, r)| r).collect();
    assert_consecutive(&all);

    // Nine checked registers, one per poll: poll 30 re-reads the fourth, GYRO_CONFIG, which
    // the reset cleared (±250 °/s instead of ±2000 °/s): noticed at once; poll 27 re-reads
    // PWR_MGMT_2, 0 after the reset as before it, so CONFIG notices at poll 28.
    for (reset_at, noticed) in [(30, 30), (27, 28)] {
        let mut bench = Bench::new(chip(Variant::Mpu6000));
        let mut reset = |b: &mut Bench, poll: usize| {
            if poll == reset_at {
                assert!(Chip::fault_reset(&mut b.chip));
            }
        };
        let run = ardupilot_checked(&mut bench, 90, 0x68, &mut reset).unwrap();
        assert_eq!(run.mismatches, [noticed]);
        let (early, late): (Vec<_>, Vec<_>) = run.records.iter().partition(|(p, _)| *p < reset_at);
        assert!(late.iter().all(|(p, _)| *p > noticed), "none in between");
        // Before the reset: the clean run's records exactly; after the re-initialisation
        // every sample again, in order.
        let before: Vec<_> = early.iter().map(|(_, r)| r).collect();
        assert_eq!(before[..], all[..before.len()]);
        let after: Vec<_> = late.iter().map(|(_, r)| r).collect();
        assert!(
            after.len() >= 90 - noticed - 3,
            "{} records after",
            after.len()
        );
        assert_consecutive(&after);
    }
}

#[test]
fn betaflight_rejects_a_wrong_who_am_i_for_the_window_only() {
    let mut bench = Bench::new(chip(Variant::Mpu6000));
    assert!(Chip::fault_identity(&mut bench.chip, Some(0x70)));
    assert_eq!(
        fc_betaflight(&mut bench, 1).unwrap_err(),
        FcError::WhoAmI(0x70)
    );
    assert_eq!(
        bench.chip.peek(0x0C),
        0x58,
        "PRODUCT_ID is not an identity: unchanged"
    );
    assert!(Chip::fault_identity(&mut bench.chip, None));
    assert_eq!(fc_betaflight(&mut bench, 4).unwrap().records.len(), 4);
}
