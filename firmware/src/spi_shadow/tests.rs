use margemu_protocol::regmap::mpu6xxx::image::IMAGE_LEN;
use margemu_protocol::regmap::mpu6xxx::{is_read_only, reg};

use super::sim::{SimPort, Timing, FAST, SLOW, UNDERRUN};
use super::*;
use crate::chip::{Mpu6xxx, SpiTarget};

const READ: u8 = 0x80;

/// A chip with a recognisable sample latched (every image byte distinct and non-zero).
fn chip_with_sample() -> Mpu6xxx {
    let mut chip = Mpu6xxx::new();
    let image: [u8; IMAGE_LEN] = core::array::from_fn(|i| 0x11 + i as u8 * 7);
    chip.latch_image_at(&image, 1_000_000);
    chip
}

/// What the chip itself puts on MISO for `mosi` (one byte ahead, as `SpiTarget` specifies),
/// on a copy so the chip is left as it was.
fn reference(chip: &Mpu6xxx, mosi: &[u8]) -> [u8; 256] {
    let mut chip = chip.clone();
    let mut miso = [0; 256];
    let mut next = chip.select();
    for (slot, &m) in miso.iter_mut().zip(mosi) {
        *slot = next;
        next = chip.exchange(m);
    }
    chip.deselect();
    miso
}

/// Serves `mosi` through the simulated port from `shadow`; returns the capture and the MISO the
/// controller saw, and checks the capture records exactly what was sent.
fn transact(timing: Timing, shadow: &mut Shadow, mosi: &[u8]) -> (Capture, [u8; 256]) {
    let mut port = SimPort::new(timing, mosi, shadow.stream());
    let mut capture = Capture::new();
    serve(&mut port, shadow, &mut capture);
    let n = capture.sent().len();
    assert_eq!(
        capture.sent(),
        &port.miso()[..n],
        "capture records what was sent"
    );
    (capture, port.shifted)
}

fn burst(start: u8, data_bytes: usize) -> [u8; 40] {
    let mut mosi = [0; 40];
    mosi[0] = READ | start;
    mosi[data_bytes + 1..].fill(0xA5); // beyond the burst: marks bytes a test must not send
    mosi
}

#[test]
fn shadow_reads_what_the_bus_reads_and_streams_the_burst() {
    let chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 3);
    for addr in 0..128u8 {
        assert_eq!(shadow.read(addr), chip.peek(addr), "register {addr:#04x}");
    }
    let mut mosi = [0u8; STREAM_LEN];
    mosi[0] = READ | DEFAULT_START;
    let want = reference(&chip, &mosi);
    assert_eq!(&shadow.stream()[..], &want[..STREAM_LEN]);
    assert_eq!(shadow.generation(), 3);
    assert_eq!(burst_address(0x3B, 1), 0x3B);
    assert_eq!(burst_address(0x3B, 6), 0x40);
    assert_eq!(burst_address(reg::FIFO_R_W, 9), reg::FIFO_R_W);
    assert_eq!(burst_address(0x7F, 2), 0x00);
}

#[test]
fn write_through_matches_the_chip_wherever_it_acts() {
    for addr in 0..128u8 {
        for value in [0x00, 0xFF, 0xA5, 0x5A] {
            let mut chip = chip_with_sample();
            let mut shadow = Shadow::new();
            shadow.capture(&chip, DEFAULT_START, 0);
            let mosi = [addr, value];
            shadow.write_through(&mosi);
            replay(&mut chip, &Capture::from_bytes(&mosi, &[0, 0], 0, None), 0);
            let mut fresh = Shadow::new();
            fresh.capture(&chip, DEFAULT_START, 0);
            if WRITE_SIDE_EFFECTS.contains(&addr) {
                continue; // left to the replay and the next capture
            }
            assert_eq!(shadow, fresh, "write {value:#04x} to {addr:#04x}");
        }
    }
}

#[test]
fn write_through_ignores_reads_and_read_only_registers() {
    let chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let before = shadow.clone();
    shadow.write_through(&[READ | reg::SMPLRT_DIV, 0x07]);
    shadow.write_through(&[reg::WHO_AM_I, 0x00]);
    shadow.write_through(&[reg::ACCEL_XOUT_H, 0x00, 0x00]);
    shadow.write_through(&[]);
    assert!(is_read_only(reg::WHO_AM_I));
    assert_eq!(shadow, before);
}

#[test]
fn sim_port_fast_burst_at_the_predicted_start_is_served_by_the_stream() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = burst(DEFAULT_START, 21);
    let want = reference(&chip, &mosi[..22]);
    let (capture, miso) = transact(FAST, &mut shadow, &mosi[..22]);
    assert_eq!(&miso[..22], &want[..22]);
    assert_eq!(capture.takeover(), None);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Hit);
}

#[test]
fn sim_port_slow_register_read_is_taken_over_in_time() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [READ | reg::WHO_AM_I, 0, 0];
    let (capture, miso) = transact(SLOW, &mut shadow, &mosi);
    assert_eq!(&miso[..3], &reference(&chip, &mosi)[..3]);
    assert_eq!(miso[1], 0x71);
    assert_eq!(capture.takeover(), Some(1));
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
}

#[test]
fn sim_port_fast_register_read_misses_the_first_byte_and_is_counted() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [READ | reg::WHO_AM_I, 0, 0, 0];
    let want = reference(&chip, &mosi);
    let (capture, miso) = transact(FAST, &mut shadow, &mosi);
    assert_eq!(miso[1], shadow.stream()[1], "the speculated byte went out");
    assert_ne!(miso[1], want[1]);
    assert!(!miso[..4].contains(&UNDERRUN));
    let took = capture.takeover().expect("a read elsewhere is taken over");
    assert!(took >= 2);
    assert_eq!(
        &miso[took..4],
        &want[took..4],
        "right again from the takeover on"
    );
    let mut stats = Stats::default();
    let outcome = replay(&mut chip, &capture, 0);
    stats.record(outcome);
    assert_eq!(
        outcome,
        Outcome::Miss {
            start: reg::WHO_AM_I
        }
    );
    assert_eq!((stats.transactions, stats.misses), (1, 1));
}

#[test]
fn sim_port_write_reaches_the_shadow_at_once_and_the_chip_on_replay() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mosi = [reg::SMPLRT_DIV, 0x07, 0x03]; // SMPLRT_DIV, then CONFIG
    let (capture, _) = transact(FAST, &mut shadow, &mosi);
    assert_eq!(
        (shadow.read(reg::SMPLRT_DIV), shadow.read(reg::CONFIG)),
        (0x07, 0x03)
    );
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Write);
    assert_eq!(
        (chip.peek(reg::SMPLRT_DIV), chip.peek(reg::CONFIG)),
        (0x07, 0x03)
    );
    // The read-back, even at a fast clock, is served in time only by a takeover; at a slow one
    // it is right.
    let (capture, miso) = transact(SLOW, &mut shadow, &[READ | reg::SMPLRT_DIV, 0]);
    assert_eq!(miso[1], 0x07);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Fixed);
}

#[test]
fn read_side_effects_reach_the_chip_through_the_replay() {
    let mut chip = chip_with_sample();
    let mut setup =
        |mosi: &[u8]| replay(&mut chip, &Capture::from_bytes(mosi, &[0; 3], 0, None), 0);
    setup(&[reg::INT_ENABLE, 0x01]);
    setup(&[reg::INT_PIN_CFG, 0x20]); // LATCH_INT_EN: the status holds until read
    let image = [0x22; IMAGE_LEN];
    chip.latch_image_at(&image, 2_000_000);
    assert_eq!(chip.peek(reg::INT_STATUS), 0x01);
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 1);
    let (capture, miso) = transact(SLOW, &mut shadow, &[READ | reg::INT_STATUS, 0]);
    assert_eq!(miso[1], 0x01);
    assert_eq!(replay(&mut chip, &capture, 1), Outcome::Fixed);
    assert_eq!(
        chip.peek(reg::INT_STATUS),
        0x00,
        "cleared by the replayed read"
    );
}

#[test]
fn sim_port_burst_from_an_older_shadow_is_stale_not_a_miss() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    chip.latch_image_at(&[0x33; IMAGE_LEN], 2_000_000); // generation 1, not yet in the shadow
    let mosi = burst(DEFAULT_START, 14);
    let (capture, _) = transact(FAST, &mut shadow, &mosi[..15]);
    assert_eq!(
        replay(&mut chip, &capture, 1),
        Outcome::Stale {
            start: DEFAULT_START
        }
    );
}

#[test]
fn sim_port_speculator_learns_a_new_burst_start() {
    let mut chip = chip_with_sample();
    let mut speculator = Speculator::new();
    let mut shadow = Shadow::new();
    let gyro = burst(reg::GYRO_XOUT_H, 6);
    let mut outcomes = [Outcome::Empty; 6];
    for outcome in &mut outcomes {
        shadow.capture(&chip, speculator.start(), 0);
        let (capture, _) = transact(FAST, &mut shadow, &gyro[..7]);
        *outcome = replay(&mut chip, &capture, 0);
        speculator.observe(&capture);
    }
    let miss = Outcome::Miss {
        start: reg::GYRO_XOUT_H,
    };
    assert_eq!(
        outcomes,
        [miss, miss, miss, miss, Outcome::Hit, Outcome::Hit]
    );
    assert_eq!(speculator.start(), reg::GYRO_XOUT_H);
    // Single-register reads and writes do not move it.
    for mosi in [[READ | reg::WHO_AM_I, 0, 0], [reg::CONFIG, 1, 0]] {
        for _ in 0..2 * SWITCH_AFTER {
            let len = if mosi[0] & READ != 0 { 2 } else { 3 };
            let capture = Capture::from_bytes(&mosi[..len], &[0; 3], 0, None);
            assert!(!speculator.observe(&capture));
        }
    }
    assert_eq!(speculator.start(), reg::GYRO_XOUT_H);
}

#[test]
fn sim_port_overlong_and_empty_transactions() {
    let mut chip = chip_with_sample();
    let mut shadow = Shadow::new();
    shadow.capture(&chip, DEFAULT_START, 0);
    let mut long = [0u8; 200];
    long[0] = READ | DEFAULT_START;
    let (capture, _) = transact(FAST, &mut shadow, &long);
    assert!(capture.truncated());
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Truncated);
    let (capture, _) = transact(FAST, &mut shadow, &[]);
    assert_eq!(replay(&mut chip, &capture, 0), Outcome::Empty);
}
