//! AFSR left on: the gyro stalls at each range switch (`margemu_firmware::chip::icm42688p`'s
//! `afsr` module: ±100 °/s, 2 ms). A Betaflight-style reader (`fc_betaflight.rs`) with and
//! without the INTF_CONFIG1 write that turns AFSR off, over a rate sweep up through the
//! threshold and back down.

use margemu_firmware::chip::icm42688p::{AFSR_STALL_NS, AFSR_THRESHOLD_DPS};

use super::fc::{Recorder, Rig};
use super::fc_betaflight::{betaflight_init, betaflight_read};
use super::*;

/// Sample `i` of the sweep: gyro x = 20·i counts at ±2000 °/s (16.4 LSB/(°/s)) up to 2000 at
/// i = 100, then back down; gyro z the opposite, gyro y 3 counts (never near the threshold).
fn sweep(i: usize) -> i16 {
    (20 * i.min(200 - i)) as i16
}

/// Betaflight's init (`afsr_off` as given) and 200 data-ready reads of the sweep at 1 kHz:
/// (what the driver decoded, what the chip was given).
fn betaflight_sweep(afsr_off: bool) -> super::fc::Run {
    let mut chip = chip();
    let mut r = Recorder::new(&mut chip);
    betaflight_init(&mut r, 6, afsr_off);
    let t0 = 100 * MS;
    for i in 0..=200 {
        let t = t0 + i as u64 * MS;
        r.latch(sweep(i), t, None);
        assert!(r.rig.int1(t), "data ready at {i}");
        let d = betaflight_read(&mut r);
        r.run.samples.push(d);
    }
    r.run
}

#[test]
fn the_threshold_and_stall_are_the_reported_ones() {
    assert_eq!(AFSR_THRESHOLD_DPS, 100.0);
    assert_eq!(
        AFSR_STALL_NS,
        2 * MS,
        "the upper end of the reported 1–2 ms"
    );
}

#[test]
fn betaflight_without_the_afsr_write_sees_the_gyro_held_at_each_switch() {
    let run = betaflight_sweep(false);
    // 100 °/s at ±2000 °/s is 1640 counts: up at i = 82 (1640), down at i = 119 (1620).
    let stalled = [82, 83, 119, 120];
    for (i, (got, want)) in run.samples.iter().zip(&run.expected).enumerate() {
        assert_eq!(
            got.accel, want.accel,
            "sample {i}: the accelerometer never stalls"
        );
        assert_eq!(
            got.gyro[1], want.gyro[1],
            "sample {i}: y stays below the threshold"
        );
        if stalled.contains(&i) {
            let before = run.samples[i - 1].gyro;
            assert_ne!(got.gyro, want.gyro, "sample {i}: held");
            assert_eq!(
                [got.gyro[0], got.gyro[2]],
                [before[0], before[2]],
                "sample {i}"
            );
        } else {
            assert_eq!(got.gyro, want.gyro, "sample {i}: live");
        }
    }
    // The held values are the last ones before each switch, bitwise.
    assert_eq!(run.samples[83].gyro, [1620, 3, -1620]);
    assert_eq!(run.samples[120].gyro, [1640, 3, -1640]);
}

#[test]
fn betaflight_with_the_afsr_write_never_sees_a_stall() {
    let run = betaflight_sweep(true);
    assert_eq!(run.samples, run.expected);
    assert!(
        run.transactions.iter().any(|t| t.mosi == [0x4D, 0x51]),
        "AFSR 01 written"
    );
}

#[test]
fn the_fifo_holds_the_same_values_as_the_registers() {
    let mut c = running();
    spi_write(&mut c, 0x16, &[0x40]); // FIFO_CONFIG: stream
    spi_write(&mut c, 0x5F, &[0x03]); // FIFO_CONFIG1: accel + gyro, 16-byte packets
    spi_write(&mut c, 0x4F, &[0x06]); // ±2000 °/s, 1 kHz
    for i in 0..=200 {
        c.latch_at(&sample(sweep(i)), (i as u64 + 1) * MS);
        let regs = spi_read(&mut c, 0x25, 6); // GYRO_DATA_X1..Z0, big-endian
        let packet = spi_read(&mut c, 0x30, 16);
        assert_eq!(packet[0] & 0xFC, 0x68, "packet {i}: accel + gyro header");
        assert_eq!(
            packet[7..13],
            regs[..],
            "packet {i}: the FIFO gyro is the registers'"
        );
        let x = i16::from_be_bytes([regs[0], regs[1]]);
        let held = [82, 83, 119, 120].contains(&i);
        assert_eq!(x != sweep(i), held, "sample {i}: x = {x}");
    }
}

#[test]
fn a_smaller_full_scale_switches_at_the_same_rate() {
    // ±500 °/s: 65.5 LSB/(°/s), so the switch is at 6550 counts (100 °/s) too.
    let mut c = running();
    spi_write(&mut c, 0x4F, &[0x46]); // GYRO_FS_SEL 2, 1 kHz
    let at_dps = |dps: f32| PhysicalSample {
        gyr: [dps.to_radians(), 0.0, 0.0],
        ..sample(0)
    };
    let x = |c: &mut Icm42688p| i16::from_be_bytes(spi_read(c, 0x25, 2).try_into().unwrap());
    c.latch_at(&at_dps(99.0), MS);
    assert_eq!(x(&mut c), 6485);
    c.latch_at(&at_dps(101.0), 2 * MS);
    assert_eq!(x(&mut c), 6485, "held: the switch at 100 °/s");
    c.latch_at(&at_dps(101.0), 4 * MS);
    assert_eq!(x(&mut c), 6616, "2 ms later: live");
}
