//! Each sensor at its own rate: the accelerometer at its ODR below the gyro's, the temperature
//! every 10 ms, the FIFO's frames with FIFO_DOWNS and with accel and gyro at different rates.

use super::*;

/// Uploaded, ±16 g, ±2000 °/s, ACC_CONF / GYR_CONF as given, PWR_CTRL accel + gyro + temp.
fn at_rates(acc_conf: u8, gyr_conf: u8) -> Bmi270 {
    let mut c = ready_chip();
    spi_write(&mut c, 0x40, &[acc_conf, 0x03, gyr_conf, 0x08]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    c
}

fn accel_x(c: &mut Bmi270) -> i16 {
    let b = read(c, 0x0C, 2);
    i16::from_le_bytes([b[0], b[1]])
}

fn gyro_x(c: &mut Bmi270) -> i16 {
    let b = read(c, 0x12, 2);
    i16::from_le_bytes([b[0], b[1]])
}

#[test]
fn the_accel_takes_every_fourth_latch_at_800_hz_beside_a_3200_hz_gyro() {
    let mut c = at_rates(0xAB, 0xED);
    let mut seen = Vec::new();
    for k in 0..12i16 {
        let t = 100 * MS + u64::from(k as u16) * fc::GYRO_3K2_NS;
        c.latch_at(&fc::sample(k), t);
        let status = read1(&mut c, 0x03);
        seen.push((accel_x(&mut c), gyro_x(&mut c), status & 0xC0));
    }
    let want: Vec<_> = (0..12i16)
        .map(|k| (k - k % 4, k, if k % 4 == 0 { 0xC0 } else { 0x40 }))
        .collect();
    assert_eq!(seen, want, "(accel, gyro, drdy_acc|drdy_gyr) per latch");
}

#[test]
fn an_accel_faster_than_the_gyro_takes_every_latch() {
    let mut c = at_rates(0xAC, 0xA9); // accel 1.6 kHz, gyro 200 Hz
    for k in 0..4i16 {
        c.latch_at(&fc::sample(k), 5 * MS * u64::from(k as u16));
        assert_eq!(accel_x(&mut c), k);
    }
    assert_eq!(
        c.sample_period_ns(),
        Some(5 * MS),
        "the gyro's rate is served"
    );
}

#[test]
fn the_accel_alone_takes_every_latch_at_its_rate() {
    let mut c = at_rates(0xA8, 0xED); // accel 100 Hz
    spi_write(&mut c, 0x7D, &[0x0C]); // accel + temperature
    assert_eq!(c.sample_period_ns(), Some(10 * MS));
    for k in 0..4i16 {
        c.latch_at(&fc::sample(k), 3 * MS + 10 * MS * u64::from(k as u16));
        assert_eq!(accel_x(&mut c), k);
    }
}

#[test]
fn a_rate_write_restarts_the_accel_divider() {
    let mut c = at_rates(0xA8, 0xED); // accel 100 Hz
    c.latch_at(&fc::sample(1), 10 * MS);
    c.latch_at(&fc::sample(2), 11 * MS);
    assert_eq!(accel_x(&mut c), 1, "still the first 10 ms period");
    spi_write(&mut c, 0x40, &[0xAC]); // accel 1.6 kHz
    c.latch_at(&fc::sample(3), 11 * MS + 312_500);
    assert_eq!(accel_x(&mut c), 3);
}

#[test]
fn the_temperature_updates_every_10_ms() {
    let mut c = at_rates(0xAC, 0xED);
    let mut temps = Vec::new();
    for k in 0..80i16 {
        c.latch_at(
            &fc::sample(k),
            20 * MS + u64::from(k as u16) * fc::GYRO_3K2_NS,
        );
        let t = read(&mut c, 0x22, 2);
        temps.push(i16::from_le_bytes([t[0], t[1]]));
    }
    let want: Vec<i16> = (0..80).map(|k| k - k % 32).collect();
    assert_eq!(temps, want);
}

#[test]
fn fifo_frames_carry_the_sensors_with_a_new_sample() {
    let mut c = at_rates(0xAB, 0xED); // accel 800 Hz, gyro 3.2 kHz
    spi_write(&mut c, 0x45, &[0x88]); // FIFO_DOWNS reset value: no downsampling
    spi_write(&mut c, 0x48, &[0x01, 0xD0]);
    for k in 0..8i16 {
        c.latch_at(
            &fc::sample(k),
            100 * MS + u64::from(k as u16) * fc::GYRO_3K2_NS,
        );
    }
    let len = read(&mut c, 0x24, 2);
    assert_eq!(len, [2 * 13 + 6 * 7, 0]);
    let bytes = read(&mut c, 0x26, 2 * 13 + 6 * 7);
    let mut headers = Vec::new();
    let mut p = 0;
    while p < bytes.len() {
        headers.push(bytes[p]);
        p += if bytes[p] == 0x8C { 13 } else { 7 };
    }
    assert_eq!(headers, [0x8C, 0x88, 0x88, 0x88, 0x8C, 0x88, 0x88, 0x88]);
}

#[test]
fn fifo_downs_halves_the_gyro_as_ardupilot_sets_it() {
    let mut c = at_rates(0x8C, 0xED); // accel 1.6 kHz, gyro 3.2 kHz
    spi_write(&mut c, 0x45, &[0x89]);
    spi_write(&mut c, 0x48, &[0x01, 0xD0]);
    for k in 0..8i16 {
        c.latch_at(
            &fc::sample(k),
            100 * MS + u64::from(k as u16) * fc::GYRO_3K2_NS,
        );
    }
    let bytes = read(&mut c, 0x26, 4 * 13);
    let gyro_x: Vec<i16> = bytes
        .chunks(13)
        .map(|f| {
            assert_eq!(f[0], 0x8C);
            i16::from_le_bytes([f[1], f[2]])
        })
        .collect();
    assert_eq!(gyro_x, [0, 2, 4, 6]);
    assert_eq!(read(&mut c, 0x24, 2), [0, 0]);
}

#[test]
fn headerless_frames_repeat_the_slower_sensor() {
    let mut c = at_rates(0xAB, 0xED); // accel 800 Hz, gyro 3.2 kHz
    spi_write(&mut c, 0x48, &[0x01, 0xC0]); // gyro + accel, no headers
    for k in 0..4i16 {
        c.latch_at(
            &fc::sample(k),
            100 * MS + u64::from(k as u16) * fc::GYRO_3K2_NS,
        );
    }
    let bytes = read(&mut c, 0x26, 4 * 12);
    let pairs: Vec<(i16, i16)> = bytes
        .chunks(12)
        .map(|f| {
            let gx = i16::from_le_bytes([f[0], f[1]]);
            let ax = i16::from_le_bytes([f[6], f[7]]);
            (gx, ax)
        })
        .collect();
    assert_eq!(pairs, [(0, 0), (1, 0), (2, 0), (3, 0)]);
}
