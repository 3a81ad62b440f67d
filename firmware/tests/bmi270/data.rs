//! Latched samples in the data registers: ranges, little-endian order, temperature, drdy bits,
//! sensor time and the swap at bus idle.

use super::*;
use margemu_firmware::chip::PhysicalSample;

const G: f32 = 9.80665;

/// Sensitivities typed from the datasheet table, independently of the crate's own.
const ACC_LSB_PER_G: [(u8, f64); 4] = [(0, 16384.0), (1, 8192.0), (2, 4096.0), (3, 2048.0)];
const GYR_LSB_PER_DPS: [(u8, f64); 5] = [(0, 16.4), (1, 32.8), (2, 65.6), (3, 131.2), (4, 262.4)];

fn sample(acc: [f32; 3], gyr_dps: [f32; 3], temp_c: f32) -> PhysicalSample {
    PhysicalSample {
        acc,
        gyr: gyr_dps.map(f32::to_radians),
        temp_c,
        ..Default::default()
    }
}

fn words(bytes: &[u8]) -> Vec<i16> {
    bytes
        .chunks(2)
        .map(|w| i16::from_le_bytes([w[0], w[1]]))
        .collect()
}

fn expect_within_1_lsb(got: i16, physical: f64, lsb_per_unit: f64, what: &str) {
    let want = (physical * lsb_per_unit).clamp(-32768.0, 32767.0);
    assert!(
        (f64::from(got) - want).abs() <= 1.0,
        "{what}: read {got}, expected {want:.2}"
    );
}

/// A running chip: configuration uploaded, accel at 1.6 kHz (so that every latch of these tests
/// takes it), gyro at its reset 200 Hz, accel, gyro and temperature on.
fn running() -> Bmi270 {
    let mut c = ready_chip();
    spi_write(&mut c, 0x40, &[0xAC]);
    spi_write(&mut c, 0x7D, &[0x0E]);
    c
}

#[test]
fn accel_at_every_range_within_1_lsb() {
    let acc = [0.3 * G, -1.2 * G, 1.7 * G];
    for (code, lsb) in ACC_LSB_PER_G {
        let mut c = running();
        spi_write(&mut c, 0x41, &[code]);
        c.latch_at(&sample(acc, [0.0; 3], 23.0), MS);
        let got = words(&read(&mut c, 0x0C, 6));
        for (axis, (&raw, &a)) in got.iter().zip(&acc).enumerate() {
            let g = f64::from(a) / f64::from(G);
            expect_within_1_lsb(raw, g, lsb, &format!("range {code} axis {axis}"));
        }
    }
}

#[test]
fn gyro_at_every_range_within_1_lsb() {
    let dps = [100.0, -110.5, 12.25];
    for (code, lsb) in GYR_LSB_PER_DPS {
        let mut c = running();
        spi_write(&mut c, 0x43, &[code]);
        c.latch_at(&sample([0.0; 3], dps, 23.0), MS);
        let got = words(&read(&mut c, 0x12, 6));
        for (axis, (&raw, &w)) in got.iter().zip(&dps).enumerate() {
            expect_within_1_lsb(raw, f64::from(w), lsb, &format!("range {code} axis {axis}"));
        }
    }
}

#[test]
fn out_of_range_values_clip() {
    let mut c = running();
    spi_write(&mut c, 0x41, &[0x00]); // ±2 g
    spi_write(&mut c, 0x43, &[0x04]); // ±125 °/s
    c.latch_at(
        &sample([3.0 * G, -3.0 * G, 0.0], [200.0, -200.0, 0.0], 23.0),
        MS,
    );
    assert_eq!(
        words(&read(&mut c, 0x0C, 12)),
        [32767, -32768, 0, 32767, -32768, 0]
    );
}

#[test]
fn twelve_bytes_from_0x0c_little_endian() {
    let mut c = running();
    spi_write(&mut c, 0x41, &[0x02]); // ±8 g: 4096 LSB/g
    spi_write(&mut c, 0x43, &[0x00]); // ±2000 °/s: 16.4 LSB/(°/s)
    c.latch_at(&sample([G, -G, 0.5 * G], [10.0, -10.0, 0.0], 23.0), MS);
    let miso = spi(&mut c, &[0x8C, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        miso,
        [0x00, 0x00, 0x00, 0x10, 0x00, 0xF0, 0x00, 0x08, 0xA4, 0x00, 0x5C, 0xFF, 0x00, 0x00]
    );
}

#[test]
fn temperature_and_its_invalid_code() {
    let mut c = ready_chip();
    assert_eq!(read(&mut c, 0x22, 2), [0x00, 0x80]);
    spi_write(&mut c, 0x7D, &[0x08]); // temp_en only
    c.latch_at(&sample([0.0; 3], [0.0; 3], 25.5), MS);
    assert_eq!(words(&read(&mut c, 0x22, 2)), [1280]); // 2.5 K · 512
    assert_eq!(words(&read(&mut c, 0x0C, 2)), [0]); // accel off: not written
}

#[test]
fn sensors_off_keep_their_data_and_raise_no_drdy() {
    let mut c = ready_chip();
    c.latch_at(&sample([G; 3], [50.0; 3], 30.0), MS);
    assert_eq!(read(&mut c, 0x0C, 12), [0; 12]);
    assert_eq!(read(&mut c, 0x22, 2), [0x00, 0x80]);
    assert_eq!(read1(&mut c, 0x03), 0x10);
}

#[test]
fn drdy_bits_set_by_a_latch_and_cleared_by_a_data_read() {
    let mut c = running();
    assert_eq!(read1(&mut c, 0x03), 0x10); // cmd_rdy only
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.0), MS);
    assert_eq!(read1(&mut c, 0x03), 0xD0);
    read(&mut c, 0x12, 2);
    assert_eq!(read1(&mut c, 0x03), 0x90); // gyro read: drdy_gyr cleared
    read(&mut c, 0x0C, 1);
    assert_eq!(read1(&mut c, 0x03), 0x10);
    spi_write(&mut c, 0x7D, &[0x04]); // accel only
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.0), 2 * MS);
    assert_eq!(read1(&mut c, 0x03), 0x90);
}

#[test]
fn a_latch_during_a_burst_appears_when_the_bus_goes_idle() {
    let mut c = running();
    spi_write(&mut c, 0x41, &[0x00]); // ±2 g
    c.latch_at(&sample([0.0, 0.0, G], [0.0; 3], 23.0), MS);
    c.select();
    let mut miso = vec![c.exchange(0x80 | 0x10)]; // ACC_Z, then dummy
    c.latch_at(&sample([0.0, 0.0, -G], [0.0; 3], 23.0), 2 * MS);
    miso.push(c.exchange(0));
    miso.push(c.exchange(0));
    c.deselect();
    assert_eq!(miso, [0x00, 0x00, 0x40]); // dummy, ACC_Z_LSB 0x00, ACC_Z_MSB of +1 g
    assert_eq!(words(&read(&mut c, 0x10, 2)), [-16384]);
}

#[test]
fn sensortime_follows_the_chip_clock() {
    let mut c = running();
    assert_eq!(read(&mut c, 0x18, 3), [0, 0, 0]);
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.0), 1_000 * MS); // 1 s = 25600 ticks
    assert_eq!(read(&mut c, 0x18, 3), [0x00, 0x64, 0x00]);
    c.advance(1_000 * MS + 39_063);
    assert_eq!(read(&mut c, 0x18, 3), [0x01, 0x64, 0x00]);
    c.advance(500 * 1_000 * MS); // 500 s: 12 800 000 ticks = 0xC35000
    assert_eq!(read(&mut c, 0x18, 3), [0x00, 0x50, 0xC3]);
    c.advance(700 * 1_000 * MS); // wraps after 655.36 s
    assert_eq!(read(&mut c, 0x18, 3), [0x00, 0x70, 0x11]); // 17 920 000 − 2^24 = 0x117000
}

#[test]
fn sample_period_follows_the_enabled_sensors() {
    let mut c = spi_chip();
    assert_eq!(c.sample_period_ns(), None);
    spi_write(&mut c, 0x7D, &[0x04]);
    assert_eq!(c.sample_period_ns(), Some(10 * MS)); // accel reset ODR 100 Hz
    spi_write(&mut c, 0x7D, &[0x0E]);
    assert_eq!(c.sample_period_ns(), Some(5 * MS)); // gyro reset ODR 200 Hz
    spi_write(&mut c, 0x42, &[0xED]);
    assert_eq!(c.sample_period_ns(), Some(312_500)); // 3.2 kHz
}
