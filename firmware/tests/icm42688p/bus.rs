//! SPI bursts across banks, I2C addressing and bursts, and the write log (DS: I2C and SPI
//! interfaces).

use super::*;
use margemu_firmware::chip::icm42688p::Config;
use margemu_firmware::chip::{Bus, RegisterWrite};

#[test]
fn spi_burst_writes_move_within_the_bank() {
    let mut c = chip();
    spi_write(&mut c, 0x4E, &[0x0F, 0x66, 0x69]);
    assert_eq!(spi_read(&mut c, 0x4E, 3), [0x0F, 0x66, 0x69]);
    bank(&mut c, 1);
    spi_write(&mut c, 0x0C, &[21, 0xB8, 0x61]);
    assert_eq!(spi_read(&mut c, 0x0C, 3), [21, 0xB8, 0x61]);
    bank(&mut c, 0);
    assert_eq!(spi_read(&mut c, 0x0C, 1), [0x00], "bank 0 0x0C is reserved");
}

#[test]
fn spi_burst_from_int_status_stays_on_fifo_data() {
    let mut c = running();
    spi_write(&mut c, 0x5F, &[0x01]);
    spi_write(&mut c, 0x16, &[0x40]);
    c.latch_at(&sample(3), MS);
    c.latch_at(&sample(4), 2 * MS);
    let b = spi_read(&mut c, 0x2D, 3 + 16);
    assert_eq!(b[..3], [0x18, 0x00, 0x10]);
    assert_eq!(b[3..6], [0x40, 0x00, 0x03]);
    assert_eq!(b[11..14], [0x40, 0x00, 0x04]);
}

#[test]
fn spi_without_select_is_ignored() {
    let mut c = chip();
    assert_eq!(c.exchange(0x11), 0x00);
    assert_eq!(c.exchange(0x01), 0x00);
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x10],
        "no soft reset happened... nor anything"
    );
    assert_eq!(c.write_log().len(), 0);
}

#[test]
fn i2c_address_pointer_and_bursts() {
    let mut c = running();
    assert_eq!(i2c_read(&mut c, 0x69, 0x75, 1), None);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 2), Some(vec![0x47, 0x00]));
    assert_eq!(i2c_write(&mut c, 0x68, &[0x4F, 0x66, 0x66]), [true; 4]);
    c.latch_at(&sample(5), MS);
    let d = i2c_read(&mut c, 0x68, 0x1D, 14).unwrap();
    assert_eq!(d[6..8], [0x40, 0x00]);
    assert_eq!(i2c_write(&mut c, 0x68, &[0x76, 0x02]), [true; 3]);
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x03, 3),
        Some(vec![0x30, 0x40, 0x62])
    );
    let mut ad0 = Icm42688p::with_config(Config {
        ad0: true,
        ..Config::default()
    });
    assert_eq!(ad0.i2c_address(), 0x69);
    assert_eq!(i2c_read(&mut ad0, 0x69, 0x75, 1), Some(vec![0x47]));
    assert_eq!(
        i2c_write(&mut ad0, 0x68, &[0x11, 0x01]),
        [false, false, false]
    );
}

#[test]
fn ui_sifs_cfg_11_disables_i2c() {
    let mut c = chip();
    spi_write(&mut c, 0x4C, &[0x33]);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), None);
    spi_write(&mut c, 0x4C, &[0x30]);
    assert_eq!(i2c_read(&mut c, 0x68, 0x75, 1), Some(vec![0x47]));
}

#[test]
fn i2c_fifo_reads_stay_on_fifo_data() {
    let mut c = running();
    spi_write(&mut c, 0x5F, &[0x02]);
    spi_write(&mut c, 0x16, &[0x40]);
    c.latch_at(&sample(9), MS);
    let bytes = i2c_read(&mut c, 0x68, 0x30, 9).unwrap();
    assert_eq!(
        bytes,
        [0x20, 0x00, 0x09, 0x00, 0x03, 0xFF, 0xF7, 0x00, 0xFF]
    );
}

#[test]
fn write_log_records_spi_and_i2c_writes_with_bank_selects() {
    let mut c = chip();
    bank(&mut c, 1);
    spi_write(&mut c, 0x0C, &[21]);
    i2c_write(&mut c, 0x68, &[0x76, 0x00]);
    spi_write(&mut c, 0x75, &[0x00]); // read only, still logged
    let w = |bus, register, value| RegisterWrite {
        bus,
        device: 0x68,
        register,
        value,
    };
    assert_eq!(c.pop_write(), Some(w(Bus::Spi, 0x76, 1)));
    assert_eq!(c.pop_write(), Some(w(Bus::Spi, 0x0C, 21)));
    assert_eq!(c.pop_write(), Some(w(Bus::I2c, 0x76, 0)));
    assert_eq!(c.pop_write(), Some(w(Bus::Spi, 0x75, 0)));
    assert_eq!(c.pop_write(), None);
    c.power_cycle();
    spi_write(&mut c, 0x4E, &[0x0F]);
    assert_eq!(c.write_log().len(), 1, "the log survives a power cycle");
}
