//! The three flight-controller sequences (`fc_*.rs`) against the chip itself: every sample
//! decoded once and in order, with each driver's own checks.

use super::fc::{assert_complete, Recorder};
use super::fc_ardupilot::{ardupilot_sequence, fifo_reset, poll};
use super::fc_betaflight::betaflight_sequence;
use super::fc_px4::px4_sequence;
use super::*;

// Betaflight

#[test]
fn eight_khz_every_pulse_reads_its_sample() {
    let mut c = chip();
    let run = betaflight_sequence(&mut c, 3, 400);
    assert_complete(&run, 400);
    let last = run.transactions.last().unwrap();
    assert_eq!(last.mosi.len(), 15);
    assert_eq!(last.mosi[0], 0x9D);
    assert_eq!(
        c.peek(0, 0x4D),
        0x51,
        "AFSR field 01, reserved bits 5:4 kept"
    );
    assert_eq!((c.peek(1, 0x0C), c.peek(2, 0x03)), (6, 12));
}

#[test]
fn one_khz() {
    let mut c = chip();
    assert_complete(&betaflight_sequence(&mut c, 6, 100), 100);
    assert_eq!(c.sample_period_ns(), MS);
}

// ArduPilot

#[test]
fn one_khz_polling_decodes_every_sample() {
    let mut c = chip();
    let run = ardupilot_sequence(&mut c, false, 300);
    assert_complete(&run, 300);
    let two = run
        .transactions
        .iter()
        .filter(|t| t.mosi[0] == 0xB0 && t.mosi.len() == 33);
    assert!(two.count() > 50, "late polls read 2 packets in one burst");
}

#[test]
fn eight_khz_polling_decodes_every_sample() {
    let mut c = chip();
    assert_complete(&ardupilot_sequence(&mut c, true, 800), 800);
    assert_eq!(c.sample_period_ns(), 125 * US);
}

#[test]
fn a_bad_header_resets_the_fifo() {
    let mut c = chip();
    let mut r = Recorder::new(&mut c);
    fifo_reset(&mut r);
    r.write(0x4E, 0x0F);
    r.write(0x5F, 0x01); // accel only: 8-byte packets with header 0x40
    r.latch(1, MS, None);
    r.latch(2, 2 * MS, None);
    poll(&mut r);
    assert_eq!(r.run.fifo_resets, 1);
    assert_eq!(r.burst(0x2E, 2), [0, 0], "flushed");
    assert_eq!(r.read(0x5F), 0x07);
}

// PX4

#[test]
fn eight_khz_fifo_threshold_bursts_decode_every_sample() {
    let mut c = chip();
    let run = px4_sequence(&mut c, 800);
    assert_complete(&run, 800);
    let bursts: Vec<_> = run
        .transactions
        .iter()
        .filter(|t| t.mosi[0] == 0xAD && t.mosi.len() > 2)
        .collect();
    assert_eq!(bursts.len(), 100);
    assert_eq!(
        bursts[0].miso[1..4],
        [0x0C, 0x00, 0xA0],
        "DATA_RDY | FIFO_THS, 160 bytes"
    );
    assert_eq!(bursts[0].miso[4], 0x78, "first header");
    assert_eq!(c.peek(0, 0x5F), 0x7F);
}
