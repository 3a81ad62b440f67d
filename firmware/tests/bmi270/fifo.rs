//! The FIFO: headered and headerless frames, FIFO_LENGTH, FIFO_DATA, flush and ERR_REG.

use super::*;
use margemu_firmware::chip::PhysicalSample;

const G: f32 = 9.80665;

/// Configuration uploaded, accel and gyro at 1.6 kHz (the latches here are 625 µs apart), PWR_CTRL
/// accel + gyro + temperature, ±16 g, ±2000 °/s, FIFO_CONFIG_0/1 as given.
pub fn fifo_chip(config0: u8, config1: u8) -> Bmi270 {
    let mut c = ready_chip();
    spi_write(&mut c, 0x40, &[0xAC, 0x03, 0xAC]);
    spi_write(&mut c, 0x43, &[0x08]);
    spi_write(&mut c, 0x48, &[config0, config1]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    c
}

pub fn latch_numbered(c: &mut Bmi270, k: i16) {
    // accel X = k g at ±16 g reads 2048·k; gyro X = k · 10 °/s reads 164·k
    let s = PhysicalSample {
        acc: [f32::from(k) * G, 0.0, -G],
        gyr: [(f32::from(k) * 10.0).to_radians(), 0.0, 0.0],
        temp_c: 23.0,
        ..Default::default()
    };
    c.latch_at(&s, c.now_ns() + 625_000);
}

pub fn fifo_length(c: &mut Bmi270) -> usize {
    let len = read(c, 0x24, 2);
    usize::from(u16::from_le_bytes([len[0], len[1]]))
}

#[test]
fn headered_frames_gyro_then_accel() {
    let mut c = fifo_chip(0x01, 0xD0);
    assert_eq!(fifo_length(&mut c), 0);
    for k in 1..=3 {
        latch_numbered(&mut c, k);
    }
    assert_eq!(fifo_length(&mut c), 39);
    let bytes = read(&mut c, 0x26, 39);
    for (k, frame) in (1..=3i16).zip(bytes.chunks(13)) {
        let [gx0, gx1] = (164 * k).to_le_bytes();
        let [ax0, ax1] = (2048 * k).to_le_bytes();
        assert_eq!(
            frame,
            [0x8C, gx0, gx1, 0, 0, 0, 0, ax0, ax1, 0, 0, 0x00, 0xF8],
            "frame {k}"
        );
    }
    assert_eq!(fifo_length(&mut c), 0);
    assert_eq!(read(&mut c, 0x26, 2), [0x80, 0x80]); // empty
}

#[test]
fn frames_follow_the_enabled_sensors() {
    let mut c = fifo_chip(0x01, 0x50); // accel only, headers
    latch_numbered(&mut c, 1);
    assert_eq!(read(&mut c, 0x26, 7), [0x84, 0x00, 0x08, 0, 0, 0x00, 0xF8]);
    let mut c = fifo_chip(0x01, 0x90); // gyro only, headers
    latch_numbered(&mut c, 1);
    assert_eq!(read(&mut c, 0x26, 7), [0x88, 164, 0, 0, 0, 0, 0]);
    let mut c = fifo_chip(0x01, 0xC0); // both, no headers
    latch_numbered(&mut c, 1);
    assert_eq!(fifo_length(&mut c), 12);
    let mut c = fifo_chip(0x01, 0xD0);
    spi_write(&mut c, 0x7D, &[0x08]); // sensors off: nothing to push
    latch_numbered(&mut c, 1);
    assert_eq!(fifo_length(&mut c), 0);
}

#[test]
fn a_partially_read_frame_is_read_again_whole() {
    let mut c = fifo_chip(0x01, 0xD0);
    latch_numbered(&mut c, 1);
    latch_numbered(&mut c, 2);
    assert_eq!(read(&mut c, 0x26, 1), [0x8C]);
    assert_eq!(fifo_length(&mut c), 26);
    assert_eq!(read(&mut c, 0x26, 3), [0x8C, 164, 0]);
    assert_eq!(read(&mut c, 0x26, 14)[13], 0x8C); // frame 1 whole, then frame 2 begins
    assert_eq!(fifo_length(&mut c), 13);
    assert_eq!(read(&mut c, 0x26, 3), [0x8C, 72, 1]); // 328
}

#[test]
fn betaflight_burst_from_fifo_length_into_fifo_data() {
    let mut c = fifo_chip(0x00, 0x80); // gyro only, headerless (6.4 kHz mode)
    latch_numbered(&mut c, 1);
    latch_numbered(&mut c, 2);
    // FIFO_LENGTH_0, FIFO_LENGTH_1, then FIFO_DATA (the burst stays on the port).
    assert_eq!(read(&mut c, 0x24, 8), [12, 0, 164, 0, 0, 0, 0, 0]);
    assert_eq!(fifo_length(&mut c), 6);
}

#[test]
fn stop_on_full_drops_new_frames_without_error() {
    let mut c = fifo_chip(0x01, 0xD0);
    for k in 0..200 {
        latch_numbered(&mut c, k % 8);
    }
    assert_eq!(fifo_length(&mut c), 2048 / 13 * 13);
    assert_eq!(read1(&mut c, 0x02), 0x00);
}

#[test]
fn stream_mode_overflow_sets_fifo_err_until_a_flush() {
    let mut c = fifo_chip(0x00, 0xD0);
    for k in 0..200 {
        latch_numbered(&mut c, k % 8);
    }
    assert_eq!(read1(&mut c, 0x02) & 0x40, 0x40);
    spi_write(&mut c, 0x7E, &[0xB0]);
    assert_eq!(read1(&mut c, 0x02), 0x00);
    assert_eq!(fifo_length(&mut c), 0);
    assert!(c.is_spi_mode(), "a FIFO flush is no reset");
}

#[test]
fn two_frames_per_poll_at_1600_hz() {
    let mut c = fifo_chip(0x01, 0xD0);
    spi_write(&mut c, 0x7E, &[0xB0]);
    for round in 0..4i16 {
        latch_numbered(&mut c, round);
        latch_numbered(&mut c, round + 1);
        assert_eq!(read1(&mut c, 0x02) & 0x40, 0, "no FIFO error");
        let len = fifo_length(&mut c);
        assert_eq!(len, 26);
        let bytes = read(&mut c, 0x26, len);
        let headers: Vec<u8> = bytes.chunks(13).map(|f| f[0] & 0xFC).collect();
        assert_eq!(headers, [0x8C, 0x8C]);
        let accel_x = i16::from_le_bytes([bytes[20], bytes[21]]);
        assert_eq!(accel_x, 2048 * (round + 1));
    }
}
