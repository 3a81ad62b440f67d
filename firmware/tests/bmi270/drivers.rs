//! The register sequences of three drivers, as read in their sources (no code taken):
//! ArduPilot `AP_InertialSensor_BMI270.cpp` (dummy read, CHIP_ID, soft reset, upload with
//! INTERNAL_STATUS check and retries, configuration with read-back of every write, FIFO at
//! 1.6 kHz), Betaflight `accgyro_spi_bmi270.c` (upload without a check, gyro 3.2 kHz / accel
//! 800 Hz, one data read from 0x0C) and the `bmi2` crate (8 KB file in chunks through
//! INIT_ADDR).

use super::*;
use margemu_firmware::chip::PhysicalSample;

const G: f32 = 9.80665;

/// Writes `value` and reads it back, as ArduPilot's `write_register` does (up to 8 tries);
/// whether it read back.
fn write_verified(c: &mut Bmi270, addr: u8, value: u8) -> bool {
    for _ in 0..8 {
        spi_write(c, addr, &[value]);
        if read1(c, addr) == value {
            return true;
        }
    }
    false
}

/// Dummy read, CHIP_ID check, soft reset, dummy read again.
fn probe_and_reset(c: &mut Bmi270) {
    dummy_read(c);
    assert_eq!(read1(c, 0x00), 0x24, "CHIP_ID");
    spi_write(c, 0x7E, &[0xB6]);
    c.advance(c.now_ns() + 2 * MS);
    dummy_read(c);
    assert_eq!(read1(c, 0x00), 0x24, "CHIP_ID after reset");
}

/// ArduPilot's `hardware_init`: dummy read, soft reset through the read-back write (CMD reads 0,
/// so it is sent 8 times, each time resetting the chip), dummy read, CHIP_ID, PWR_CONF 0,
/// upload, INIT_CTRL 1, init_ok after 20 ms; up to 5 tries.
fn ardupilot_init(c: &mut Bmi270, file: &[u8]) -> bool {
    for _ in 0..5 {
        dummy_read(c);
        c.advance(c.now_ns() + MS);
        assert!(!write_verified(c, 0x7E, 0xB6), "CMD never reads back");
        c.advance(c.now_ns() + 5 * MS);
        dummy_read(c);
        c.advance(c.now_ns() + MS);
        if read1(c, 0x00) != 0x24 {
            continue;
        }
        upload(c, file);
        c.advance(c.now_ns() + 20 * MS);
        if read1(c, 0x21) & 1 == 1 {
            return true;
        }
    }
    false
}

fn twelve_bytes(c: &mut Bmi270) -> Vec<i16> {
    read(c, 0x0C, 12)
        .chunks(2)
        .map(|w| i16::from_le_bytes([w[0], w[1]]))
        .collect()
}

#[test]
fn ardupilot_sequence() {
    let mut c = chip();
    assert!(ardupilot_init(&mut c, &config_file(328)));
    for (addr, value) in [
        (0x40, 0x8C), // ACC_CONF: 1.6 kHz, performance, OSR4
        (0x41, 0x03), // ACC_RANGE: ±16 g
        (0x42, 0xED), // GYR_CONF: 3.2 kHz, noise and filter performance, normal
        (0x43, 0x08), // GYR_RANGE: ±2000 °/s with the OIS range bit
        (0x48, 0x01), // FIFO_CONFIG_0: stop on full, no sensor time frame
        (0x49, 0xD0), // FIFO_CONFIG_1: gyro, accel, headers
        (0x45, 0x89), // FIFO_DOWNS: filtered data, gyro downsampled by 2
        (0x7C, 0x02), // PWR_CONF: fifo_self_wakeup, no advanced power save
        (0x7D, 0x0E), // PWR_CTRL: accel, gyro, temperature
    ] {
        assert!(write_verified(&mut c, addr, value), "{addr:#04x}");
    }
    assert_eq!(c.sample_period_ns(), Some(312_500));
    let s = PhysicalSample {
        acc: [0.0, 0.0, -G],
        gyr: [0.1, -0.2, 0.3],
        temp_c: 40.0,
        ..Default::default()
    };
    c.latch_at(&s, c.now_ns() + 312_500);
    let data = twelve_bytes(&mut c);
    assert_eq!(data[..3], [0, 0, -2048]);
    for (raw, w) in data[3..].iter().zip(s.gyr) {
        let want = f64::from(w).to_degrees() * 16.4;
        assert!((f64::from(*raw) - want).abs() <= 1.0, "{raw} vs {want}");
    }
    let t = read(&mut c, 0x22, 2);
    assert_ne!(t, [0x00, 0x80], "temperature valid");
    assert_eq!(i16::from_le_bytes([t[0], t[1]]), 17 * 512);
}

#[test]
fn ardupilot_gives_up_on_a_truncated_file() {
    let mut c = chip();
    assert!(!ardupilot_init(&mut c, &config_file(200)));
    assert_eq!(read1(&mut c, 0x21), 0x02);
}

#[test]
fn betaflight_sequence() {
    let mut c = chip();
    probe_and_reset(&mut c);
    upload(&mut c, &config_file(328));
    c.advance(c.now_ns() + 20 * MS); // Betaflight never checks INTERNAL_STATUS
    for (addr, value) in [
        (0x40, 0xAB), // ACC_CONF: 800 Hz
        (0x41, 0x03), // ACC_RANGE: ±16 g
        (0x42, 0xED), // GYR_CONF: 3.2 kHz
        (0x43, 0x08), // GYR_RANGE: ±2000 °/s, OIS ±2000
        (0x58, 0x04), // INT_MAP_DATA: data ready on INT1
        (0x53, 0x0A), // INT1_IO_CTRL: output, active high, push-pull
        (0x7C, 0x02), // PWR_CONF
        (0x7D, 0x0E), // PWR_CTRL
    ] {
        spi_write(&mut c, addr, &[value]);
    }
    assert_eq!(read1(&mut c, 0x21), 0x01); // init_ok all the same
    assert_eq!(c.sample_period_ns(), Some(312_500));
    let s = PhysicalSample {
        acc: [G, 2.0 * G, -4.0 * G],
        gyr: [1.0, -1.0, 0.0],
        temp_c: 23.0,
        ..Default::default()
    };
    c.latch_at(&s, c.now_ns() + 312_500);
    let data = twelve_bytes(&mut c);
    assert_eq!(data[..3], [2048, 4096, -8192]);
    let one_radps = 1.0f64.to_degrees() * 16.4; // 939.6
    assert!((f64::from(data[3]) - one_radps).abs() <= 1.0);
    assert!((f64::from(data[4]) + one_radps).abs() <= 1.0);
    assert_eq!(data[5], 0);
}

#[test]
fn bmi2_crate_uploads_8k_in_chunks() {
    let mut c = chip();
    probe_and_reset(&mut c);
    spi_write(&mut c, 0x7C, &[0x00]);
    c.advance(c.now_ns() + MS);
    spi_write(&mut c, 0x59, &[0x00]);
    let file = config_file(8192);
    for (i, chunk) in file.chunks(64).enumerate() {
        let word = i * 32;
        spi_write(&mut c, 0x5B, &[(word & 0x0F) as u8, (word >> 4) as u8]);
        spi_write(&mut c, 0x5E, chunk);
    }
    spi_write(&mut c, 0x59, &[0x01]);
    c.advance(c.now_ns() + 150 * MS);
    assert_eq!(read1(&mut c, 0x21), 0x01);
}
