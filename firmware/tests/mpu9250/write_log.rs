//! Every register write the device under test makes is logged for telemetry.

use super::*;
use margemu_firmware::chip::{Bus, RegisterWrite};

fn drain(c: &mut Mpu6xxx) -> Vec<RegisterWrite> {
    core::iter::from_fn(|| c.pop_write()).collect()
}

#[test]
fn spi_i2c_bypass_and_aux_writes_are_logged() {
    let mut c = chip();
    spi_write(&mut c, 0x1B, &[0x18, 0x08]); // burst: GYRO_CONFIG, ACCEL_CONFIG
    i2c_write(&mut c, 0x68, &[0x37, 0x02]);
    i2c_write(&mut c, 0x0C, &[0x0A, 0x16]);
    i2c_write(&mut c, 0x68, &[0x37, 0x00, 0x01]); // then INT_ENABLE
    spi_write(&mut c, 0x31, &[0x0C, 0x0A, 0x00, 0x80]); // slave 4 writes CNTL1 = 0
    spi_write(&mut c, 0x6A, &[0x20]);
    let w = |bus, device, register, value| RegisterWrite {
        bus,
        device,
        register,
        value,
    };
    assert_eq!(
        drain(&mut c),
        [
            w(Bus::Spi, 0x68, 0x1B, 0x18),
            w(Bus::Spi, 0x68, 0x1C, 0x08),
            w(Bus::I2c, 0x68, 0x37, 0x02),
            w(Bus::I2c, 0x0C, 0x0A, 0x16),
            w(Bus::I2c, 0x68, 0x37, 0x00),
            w(Bus::I2c, 0x68, 0x38, 0x01),
            w(Bus::Spi, 0x68, 0x31, 0x0C),
            w(Bus::Spi, 0x68, 0x32, 0x0A),
            w(Bus::Spi, 0x68, 0x33, 0x00),
            w(Bus::Spi, 0x68, 0x34, 0x80),
            w(Bus::Spi, 0x68, 0x6A, 0x20),
            w(Bus::Aux, 0x0C, 0x0A, 0x00),
        ]
    );
    assert_eq!(c.write_log().dropped(), 0);
}

#[test]
fn the_log_keeps_the_newest_when_not_drained() {
    let mut c = Mpu6xxx::with_config(Config {
        ad0: true,
        ..Config::default()
    });
    for k in 0..200u8 {
        spi_write(&mut c, 0x19, &[k]);
    }
    assert_eq!(c.write_log().len(), 128);
    assert_eq!(c.write_log().dropped(), 72);
    assert_eq!(c.pop_write().map(|w| (w.device, w.value)), Some((0x69, 72)));
}
