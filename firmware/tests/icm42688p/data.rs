//! Data registers: power modes and −32768, full scales, endianness, the atomic swap, sample
//! periods (DS 4.11, 4.16, PWR_MGMT0,
//! GYRO_CONFIG0, ACCEL_CONFIG0, INTF_CONFIG0).

use super::*;

const S5: [u8; 14] = [
    0x00, 0x00, // temp 25 °C
    0x00, 0x05, 0xFF, 0xF6, 0x08, 0x00, // accel 5, −10, 2048
    0x00, 0x05, 0x00, 0x03, 0xFF, 0xFB, // gyro 5, 3, −5
];

#[test]
fn both_sensors_on() {
    let mut c = running();
    c.latch_at(&sample(5), MS);
    assert_eq!(spi_read(&mut c, 0x1D, 14), S5);
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x18],
        "DATA_RDY (RESET_DONE still set)"
    );
}

#[test]
fn sensors_off_read_minus_32768() {
    let mut c = chip();
    c.latch_at(&sample(5), MS);
    assert_eq!(
        spi_read(&mut c, 0x1D, 14),
        [0x80, 0x00].repeat(7),
        "power-on: both off"
    );
    spi_read(&mut c, 0x2D, 1);
    assert_eq!(spi_read(&mut c, 0x2D, 1), [0x00], "no data ready while off");

    spi_write(&mut c, 0x4E, &[0x02]); // accel low power only
    c.latch_at(&sample(5), 2 * MS);
    let mut want = S5;
    want[8..].copy_from_slice(&[0x80, 0x00, 0x80, 0x00, 0x80, 0x00]);
    assert_eq!(spi_read(&mut c, 0x1D, 14), want);

    spi_write(&mut c, 0x4E, &[0x2C]); // gyro only, temperature disabled
    c.latch_at(&sample(5), 3 * MS);
    let mut want = S5;
    want[..8].copy_from_slice(&[0x80, 0x00, 0x80, 0x00, 0x80, 0x00, 0x80, 0x00]);
    assert_eq!(spi_read(&mut c, 0x1D, 14), want);

    spi_write(&mut c, 0x4E, &[0x04]); // gyro standby: no data, registers invalid at once
    assert_eq!(spi_read(&mut c, 0x1D, 14), [0x80, 0x00].repeat(7));
    assert!(!c.is_running());
}

#[test]
fn full_scales() {
    let mut c = running();
    spi_write(&mut c, 0x4F, &[0x66, 0x66]); // ±250 °/s, ±2 g, 1 kHz
    c.latch_at(&sample(5), MS);
    let d = spi_read(&mut c, 0x1D, 14);
    assert_eq!(d[6..8], [0x40, 0x00], "1 g at ±2 g");
    assert_eq!(d[8..10], [0x00, 0x28], "5/16.4 °/s · 131 = 39.9");
    let cfg = c.image_config();
    assert_eq!(cfg.accel_fs.lsb_per_g(), 16384.0);
    assert_eq!(cfg.gyro_fs.lsb_per_dps(), 131.0);
}

#[test]
fn little_endian_data_registers() {
    let mut c = running();
    spi_write(&mut c, 0x4C, &[0x20]);
    c.latch_at(&sample(5), MS);
    assert_eq!(
        spi_read(&mut c, 0x1D, 14),
        [0x00, 0x00, 0x05, 0x00, 0xF6, 0xFF, 0x00, 0x08, 0x05, 0x00, 0x03, 0x00, 0xFB, 0xFF]
    );
    assert_eq!(c.peek(0, 0x1F), 0x05, "peek follows the endianness too");
}

#[test]
fn a_burst_in_progress_keeps_its_sample() {
    let mut c = running();
    c.latch_at(&sample(1), MS);
    let mut miso = vec![c.select(), c.exchange(0x80 | 0x1F)];
    miso.push(c.exchange(0));
    c.latch_at(&sample(2), 2 * MS);
    for _ in 0..5 {
        miso.push(c.exchange(0));
    }
    c.deselect();
    assert_eq!(
        miso[1..7],
        [0x00, 0x01, 0xFF, 0xFE, 0x08, 0x00],
        "sample 1 throughout"
    );
    assert_eq!(
        spi_read(&mut c, 0x1F, 2),
        [0x00, 0x02],
        "sample 2 once idle"
    );
}

#[test]
fn sample_periods() {
    let mut c = running();
    for (code, ns) in [
        (0x01, 31_250),
        (0x03, 125_000),
        (0x0F, 2_000_000),
        (0x0B, 80_000_000),
    ] {
        spi_write(&mut c, 0x4F, &[code]);
        assert_eq!(c.sample_period_ns(), ns);
    }
    spi_write(&mut c, 0x4F, &[0x00]);
    assert_eq!(c.sample_period_ns(), MS, "reserved code");
    spi_write(&mut c, 0x4E, &[0x03]); // accel only: its ODR rules
    spi_write(&mut c, 0x50, &[0x0E]);
    assert_eq!(c.sample_period_ns(), 640_000_000);
    assert_eq!(c.output_rate_hz(), 1.5625);
    c.latch(&sample(1));
    assert_eq!(c.now_ns(), 640_000_000);
    assert_eq!(c.next_sample_ns(), 1_280_000_000);
}
