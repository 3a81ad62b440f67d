//! Both FIFOs: frames in order with their counts, partial reads, overflow, resets.

use super::*;

/// ±24 g, 1.6 kHz, FIFO mode with accel frames; `stop` chooses FIFO (stop-at-full) mode.
pub fn fifo_accel(stop: bool) -> Bmi088Accel {
    let mut c = running_accel();
    spi_write(&mut c, 0x40, &[0xAC]);
    spi_write(&mut c, 0x41, &[0x03]);
    spi_write(&mut c, 0x48, &[0x02 | u8::from(stop)]);
    spi_write(&mut c, 0x49, &[0x50]);
    c
}

/// Accel X of numbered frame `k`: k/8 g at ±24 g.
pub fn accel_k(c: &mut Bmi088Accel, k: u32) {
    let s = sample([k as f32 / 8.0, -1.0, 0.5], [0.0; 3], 23.0);
    c.latch_at(&s, c.now_ns() + 625_000);
}

pub fn fifo_length(c: &mut Bmi088Accel) -> usize {
    let len = aread(c, 0x24, 2);
    usize::from(u16::from_le_bytes([len[0], len[1]]))
}

#[test]
fn accel_frames_in_order_with_byte_counts() {
    let mut c = fifo_accel(true);
    assert_eq!(fifo_length(&mut c), 0);
    for k in 1..=5 {
        accel_k(&mut c, k);
        assert_eq!(fifo_length(&mut c), 7 * k as usize);
    }
    let bytes = aread(&mut c, 0x26, 35);
    for (k, frame) in (1..=5u32).zip(bytes.chunks(7)) {
        assert_eq!(frame[0], 0x84, "header of frame {k}");
        let want = (f64::from(k) / 8.0 * acc_lsb_per_g(3)).round() as i16;
        assert_eq!(words(&frame[1..]), [want, -1365, 683], "frame {k}");
    }
    assert_eq!(fifo_length(&mut c), 0);
}

#[test]
fn accel_sensortime_frame_then_overread() {
    let mut c = fifo_accel(true);
    accel_k(&mut c, 1);
    let bytes = aread(&mut c, 0x26, 13);
    let t = margemu_protocol::regmap::bmi088::convert::sensortime(c.now_ns()).to_le_bytes();
    assert_eq!(bytes[7..], [0x44, t[0], t[1], t[2], 0x80, 0x00]);
    assert_eq!(aread(&mut c, 0x26, 2), [0x80, 0x00]); // empty
}

#[test]
fn accel_partial_frame_is_read_again() {
    let mut c = fifo_accel(true);
    accel_k(&mut c, 1);
    accel_k(&mut c, 2);
    assert_eq!(aread(&mut c, 0x26, 3), [0x84, 0xAB, 0x00]); // 170.67 → 171
    assert_eq!(fifo_length(&mut c), 14);
    assert_eq!(
        aread(&mut c, 0x26, 8)[..8],
        [0x84, 0xAB, 0x00, 0xAB, 0xFA, 0xAB, 0x02, 0x84]
    );
    assert_eq!(fifo_length(&mut c), 7);
}

#[test]
fn accel_overflow_skip_frame_and_fifo_reset() {
    let mut c = fifo_accel(true);
    for k in 0..150 {
        accel_k(&mut c, k % 16);
    }
    assert_eq!(fifo_length(&mut c), 146 * 7);
    assert_eq!(aread(&mut c, 0x26, 3), [0x40, 4, 0x84]); // 4 frames lost, then frame 0
    spi_write(&mut c, 0x7E, &[0xB0]); // FIFO reset
    assert_eq!(fifo_length(&mut c), 0);
    assert!(c.is_spi_mode(), "a FIFO reset is no soft reset");
    let mut c = fifo_accel(false); // stream: the oldest go
    for k in 0..150 {
        accel_k(&mut c, k % 16);
    }
    let bytes = aread(&mut c, 0x26, 4);
    assert_eq!(bytes[..3], [0x40, 4, 0x84]);
    assert_eq!(bytes[3], 0xAB); // frame 4: X = 4/8 g = 682.67 → 683 = 0x02AB
}

#[test]
fn accel_downsampling_and_no_frames_unless_enabled() {
    let mut c = fifo_accel(true);
    spi_write(&mut c, 0x45, &[0x80 | (2 << 4)]); // every 4th sample
    for k in 0..8 {
        accel_k(&mut c, k);
    }
    assert_eq!(fifo_length(&mut c), 14);
    let mut c = fifo_accel(true);
    spi_write(&mut c, 0x49, &[0x10]); // acc_en off
    accel_k(&mut c, 1);
    assert_eq!(fifo_length(&mut c), 0);
}

/// ±2000 °/s at 2 kHz, FIFO_CONFIG_1 = `mode`.
pub fn fifo_gyro(mode: u8) -> Bmi088Gyro {
    let mut g = Bmi088Gyro::new();
    spi_write(&mut g, 0x3E, &[mode]);
    g
}

/// Gyro Z of numbered frame `k`: k °/s.
pub fn gyro_k(g: &mut Bmi088Gyro, k: u32) {
    let s = sample([0.0; 3], [-10.0, 20.0, k as f32], 23.0);
    g.latch_at(&s, g.now_ns() + 500_000);
}

#[test]
fn gyro_frames_in_order_with_frame_counts() {
    let mut g = fifo_gyro(0x40);
    for k in 1..=4 {
        gyro_k(&mut g, k);
        assert_eq!(gread1(&mut g, 0x0E), k as u8);
    }
    let bytes = spi_read(&mut g, 0x3F, 24);
    for (k, frame) in (1..=4u32).zip(bytes.chunks(6)) {
        let z = (f64::from(k) * 16.384).round() as i16;
        assert_eq!(words(frame), [-164, 328, z], "frame {k}");
    }
    assert_eq!(gread1(&mut g, 0x0E), 0);
}

#[test]
fn gyro_partial_frame_is_lost_and_single_axis_frames() {
    let mut g = fifo_gyro(0x40);
    gyro_k(&mut g, 1);
    gyro_k(&mut g, 2);
    spi_read(&mut g, 0x3F, 2);
    assert_eq!(gread1(&mut g, 0x0E), 1);
    assert_eq!(words(&spi_read(&mut g, 0x3F, 6))[2], 33);
    let mut g = fifo_gyro(0x43); // Z only: 2-byte frames
    gyro_k(&mut g, 1);
    gyro_k(&mut g, 2);
    assert_eq!(words(&spi_read(&mut g, 0x3F, 4)), [16, 33]);
}

#[test]
fn gyro_overrun_until_a_config_write() {
    let mut g = fifo_gyro(0x40);
    for k in 0..101 {
        gyro_k(&mut g, k);
    }
    assert_eq!(gread1(&mut g, 0x0E), 0x80 | 100);
    spi_read(&mut g, 0x3F, 600);
    assert_eq!(gread1(&mut g, 0x0E), 0x80); // reading does not clear the overrun
    spi_write(&mut g, 0x3E, &[0x40]);
    assert_eq!(gread1(&mut g, 0x0E), 0x00);
    let mut g = fifo_gyro(0x80); // stream: 99 frames, the oldest discarded
    for k in 0..101 {
        gyro_k(&mut g, k);
    }
    assert_eq!(gread1(&mut g, 0x0E), 0x80 | 99);
    assert_eq!(words(&spi_read(&mut g, 0x3F, 6))[2], 33); // frame 2: 32.77
    gyro_k(&mut g, 7);
    spi_write(&mut g, 0x3D, &[0x05]); // a watermark write clears the FIFO too
    assert_eq!(gread1(&mut g, 0x0E), 0x00);
}

#[test]
fn gyro_fifo_off_by_default_and_its_interrupt() {
    let mut g = Bmi088Gyro::new();
    gyro_k(&mut g, 1);
    assert_eq!(gread1(&mut g, 0x0E), 0);
    let mut g = fifo_gyro(0x40);
    spi_write(&mut g, 0x3D, &[0x03]); // watermark 3 frames
    spi_write(&mut g, 0x1E, &[0x88]);
    spi_write(&mut g, 0x15, &[0x40]); // fifo_en
    spi_write(&mut g, 0x18, &[0x04]); // FIFO interrupt to INT3
    spi_write(&mut g, 0x16, &[0x00]); // active low, push-pull
    gyro_k(&mut g, 1);
    gyro_k(&mut g, 2);
    assert_eq!((gread1(&mut g, 0x0A), g.int3_pin()), (0x00, true));
    gyro_k(&mut g, 3);
    assert_eq!((gread1(&mut g, 0x0A), g.int3_pin()), (0x10, false));
}
