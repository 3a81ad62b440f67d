//! The primary I2C target: no dummy byte, auto-increment and the ports, the upload in chunks,
//! the addresses, and the switch to SPI that silences it.

use super::*;
use margemu_firmware::chip::bmi270::Config;
use margemu_firmware::chip::I2cTarget;

const ADDR: u8 = 0x68;

fn i2c_write_regs(c: &mut Bmi270, reg: u8, values: &[u8]) {
    let mut bytes = vec![reg];
    bytes.extend_from_slice(values);
    let acks = i2c_write(c, ADDR, &bytes);
    assert!(acks.iter().all(|&a| a), "{reg:#04x}: {acks:?}");
}

fn i2c_read_regs(c: &mut Bmi270, reg: u8, n: usize) -> Vec<u8> {
    i2c_read(c, ADDR, reg, n).expect("acknowledged")
}

/// The `bmi2` crate's upload over I2C: INIT_CTRL 0, chunks of 254 bytes each addressed
/// through INIT_ADDR_0/1 (word offsets), INIT_CTRL 1.
fn upload_in_chunks(c: &mut Bmi270, file: &[u8]) {
    i2c_write_regs(c, 0x59, &[0x00]);
    for (i, chunk) in file.chunks(254).enumerate() {
        let word = i * 127;
        i2c_write_regs(c, 0x5B, &[(word & 0x0F) as u8, (word >> 4) as u8]);
        i2c_write_regs(c, 0x5E, chunk);
    }
    i2c_write_regs(c, 0x59, &[0x01]);
}

#[test]
fn reads_have_no_dummy_byte_and_auto_increment() {
    let mut c = chip();
    assert_eq!(i2c_read_regs(&mut c, 0x00, 4), [0x24, 0x00, 0x00, 0x10]);
    i2c_write_regs(&mut c, 0x40, &[0xAC, 0x03]);
    assert_eq!(i2c_read_regs(&mut c, 0x40, 2), [0xAC, 0x03]);
    assert!(!c.is_spi_mode(), "I2C leaves the chip in I2C mode");
}

#[test]
fn the_8k_upload_over_i2c_and_data_after_it() {
    let mut c = chip();
    i2c_write_regs(&mut c, 0x7E, &[0xB6]);
    i2c_write_regs(&mut c, 0x7C, &[0x02]); // adv_power_save off
    upload_in_chunks(&mut c, &config_file(8192));
    assert_eq!(i2c_read_regs(&mut c, 0x21, 1), [0x01]);
    i2c_write_regs(&mut c, 0x40, &[0xAC, 0x03, 0xAC, 0x08]);
    i2c_write_regs(&mut c, 0x48, &[0x01, 0xD0]);
    i2c_write_regs(&mut c, 0x7D, &[0x0E]);
    for k in 1..=3i16 {
        c.latch_at(&fc::sample(k), u64::from(k as u16) * 625_000);
    }
    // Data: the latest sample, 12 bytes from 0x0C, then SENSORTIME (the bmi2 crate's get_data).
    let d = i2c_read_regs(&mut c, 0x0C, 15);
    assert_eq!(i16::from_le_bytes([d[0], d[1]]), 3);
    assert_eq!(i16::from_le_bytes([d[6], d[7]]), 3);
    assert_eq!(&d[12..], [0x30, 0x00, 0x00]); // 1.875 ms = 48 ticks
                                              // FIFO: the length, then the port does not auto-increment.
    assert_eq!(i2c_read_regs(&mut c, 0x24, 2), [39, 0]);
    let frames = i2c_read_regs(&mut c, 0x26, 39);
    let gx: Vec<i16> = frames
        .chunks(13)
        .map(|f| i16::from_le_bytes([f[1], f[2]]))
        .collect();
    assert_eq!(gx, [1, 2, 3]);
    assert_eq!(i2c_read_regs(&mut c, 0x24, 2), [0, 0]);
}

#[test]
fn a_truncated_i2c_upload_is_init_err() {
    let mut c = chip();
    upload_in_chunks(&mut c, &config_file(8192 - 254));
    assert_eq!(i2c_read_regs(&mut c, 0x21, 1), [0x02]);
}

#[test]
fn the_sdo_pin_selects_0x69() {
    let mut c = Bmi270::with_config(Config { sdo: true });
    assert_eq!(i2c_read(&mut c, 0x68, 0x00, 1), None);
    assert_eq!(i2c_read(&mut c, 0x69, 0x00, 1), Some(vec![0x24]));
    i2c_write(&mut c, 0x69, &[0x7D, 0x04]);
    let w = c.pop_write().expect("logged");
    assert_eq!((w.device, w.register, w.value), (0x69, 0x7D, 0x04));
}

#[test]
fn after_the_switch_to_spi_i2c_is_silent_until_a_reset() {
    let mut c = chip();
    dummy_read(&mut c);
    assert!(c.is_spi_mode());
    assert_eq!(i2c_read(&mut c, ADDR, 0x00, 1), None);
    assert_eq!(
        i2c_write(&mut c, ADDR, &[0x41, 0x00]),
        [false, false, false]
    );
    spi_write(&mut c, 0x7E, &[0xB6]);
    assert_eq!(i2c_read(&mut c, ADDR, 0x00, 1), Some(vec![0x24]));
}

#[test]
fn a_soft_reset_over_i2c_ends_the_transaction() {
    let mut c = chip();
    i2c_write_regs(&mut c, 0x41, &[0x00]);
    // CMD = 0xB6 then a byte for 0x7F: not acknowledged, not written.
    assert_eq!(
        i2c_write(&mut c, ADDR, &[0x7E, 0xB6, 0x55]),
        [true, true, true, false]
    );
    assert_eq!(i2c_read_regs(&mut c, 0x41, 1), [0x02], "reset value");
}

#[test]
fn a_sample_latched_during_a_transaction_appears_at_stop() {
    let mut c = ready_chip();
    spi_write(&mut c, 0x7E, &[0xB6]); // back to I2C, then upload over I2C
    upload_in_chunks(&mut c, &config_file(8192));
    i2c_write_regs(&mut c, 0x40, &[0xAC, 0x03]);
    i2c_write_regs(&mut c, 0x7D, &[0x0E]);
    c.latch_at(&fc::sample(1), MS);
    assert!(c.start(ADDR, false));
    c.write(0x0C);
    assert!(c.start(ADDR, true));
    let lsb = c.read();
    c.latch_at(&fc::sample(2), 2 * MS);
    let msb = c.read();
    c.stop();
    assert_eq!(
        i16::from_le_bytes([lsb, msb]),
        1,
        "the burst keeps the old sample"
    );
    assert_eq!(i2c_read_regs(&mut c, 0x0C, 2), [2, 0]);
}
