//! The auxiliary I2C master: slave 4 single transfers, slaves 0–3 periodic transfers into
//! EXT_SENS_DATA, allocation, byte swapping, delays, NACKs (RM sections 4.12–4.18, 4.25, 4.30).

use super::*;

/// Slave 4 transfer as the `mpu9250` crate does it over SPI: ADDR, REG, (DO), CTRL = 0x80,
/// then poll I2C_MST_STATUS for SLV4_DONE. Returns I2C_SLV4_DI.
fn slv4(c: &mut Mpu6xxx, addr: u8, reg: u8, value: Option<u8>) -> u8 {
    match value {
        Some(v) => spi_write(c, 0x31, &[addr, reg, v, 0x80]),
        None => spi_write(c, 0x31, &[addr, reg]),
    }
    if value.is_none() {
        spi_write(c, 0x34, &[0x80]);
    }
    assert_eq!(
        spi_read(c, 0x36, 1)[0] & 0x40,
        0x40,
        "SLV4_DONE without any sample"
    );
    assert_eq!(
        spi_read(c, 0x34, 1),
        [0x00],
        "I2C_SLV4_EN cleared after the transfer"
    );
    spi_read(c, 0x35, 1)[0]
}

fn spi_mode_master(c: &mut Mpu6xxx) {
    spi_write(c, 0x6A, &[0x32]); // I2C_MST_EN | I2C_IF_DIS | I2C_MST_RST
    assert_eq!(spi_read(c, 0x6A, 1), [0x30]);
}

#[test]
fn slave_4_reads_and_writes_the_ak8963() {
    let mut c = Mpu6xxx::with_config(Config {
        asa: [0xB0, 0xB1, 0xB2],
        ..Config::default()
    });
    spi_mode_master(&mut c);
    assert_eq!(slv4(&mut c, 0x8C, 0x00, None), 0x48); // WIA
    slv4(&mut c, 0x0C, 0x0A, Some(0x1F)); // CNTL1: fuse ROM access, 16-bit
    assert_eq!(slv4(&mut c, 0x8C, 0x10, None), 0xB0);
    assert_eq!(slv4(&mut c, 0x8C, 0x11, None), 0xB1);
    assert_eq!(slv4(&mut c, 0x8C, 0x12, None), 0xB2);
    assert_eq!(slv4(&mut c, 0x8C, 0x0A, None), 0x1F);
}

#[test]
fn slv4_done_clears_when_i2c_mst_status_is_read() {
    let mut c = chip();
    spi_mode_master(&mut c);
    spi_write(&mut c, 0x31, &[0x8C, 0x00, 0x00, 0x80]);
    assert_eq!(spi_read(&mut c, 0x36, 2), [0x40, 0x00]);
    assert_eq!(spi_read(&mut c, 0x36, 1), [0x00]);
}

#[test]
fn slave_4_waits_for_the_master_to_be_enabled() {
    let mut c = chip();
    spi_write(&mut c, 0x31, &[0x8C, 0x00, 0x00, 0x80]);
    assert_eq!(spi_read(&mut c, 0x34, 1), [0x80], "pending");
    assert_eq!(spi_read(&mut c, 0x36, 1), [0x00]);
    spi_write(&mut c, 0x6A, &[0x20]);
    assert_eq!(spi_read(&mut c, 0x34, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x35, 2), [0x48, 0x40]);
}

#[test]
fn absent_slaves_are_not_acknowledged() {
    let mut c = chip();
    spi_mode_master(&mut c);
    spi_write(&mut c, 0x31, &[0xD0, 0x75, 0x00, 0x80]); // slave 4 to 0x50
    assert_eq!(spi_read(&mut c, 0x36, 1), [0x50], "SLV4_DONE | SLV4_NACK");
    spi_write(&mut c, 0x25, &[0x8D, 0x00, 0x81]); // slave 0 reads 0x0D
    c.latch_at(&at_rest(), MS);
    assert_eq!(spi_read(&mut c, 0x36, 1), [0x01], "SLV0_NACK");
    assert_eq!(spi_read(&mut c, 0x49, 1), [0x00]);
}

#[test]
fn slave_0_reads_the_magnetometer_every_sample() {
    // The mpu9250 crate's MARG setup: CNTL1 = 0x16 (16-bit, 100 Hz), SLV0 reads 7 bytes from
    // HXL (0x8C, 0x03, 0x87), then 21-byte bursts from ACCEL_XOUT_H.
    let mut c = chip();
    spi_mode_master(&mut c);
    slv4(&mut c, 0x0C, 0x0A, Some(0x16));
    spi_write(&mut c, 0x25, &[0x8C, 0x03, 0x87]);
    let s = PhysicalSample {
        mag: [30.0, 15.0, -45.0],
        ..at_rest()
    }; // AK axes: (15, 30, 45)
    c.latch_at(&s, MS);
    assert_eq!(
        spi_read(&mut c, 0x49, 7),
        [0, 0, 0, 0, 0, 0, 0],
        "no measurement yet"
    );
    for ms in 2..=9 {
        c.latch_at(&s, ms * MS);
    }
    // First measurement at 7.2 ms: 16-bit, 0.15 µT/LSB → (100, 200, 300), ST2 = BITM.
    let burst = spi_read(&mut c, 0x3B, 21);
    assert_eq!(burst[..6], [0x00, 0x00, 0x00, 0x00, 0x40, 0x00]);
    assert_eq!(burst[14..], [100, 0, 200, 0, 0x2C, 0x01, 0x10]);
}

#[test]
fn linux_style_byte_swap_and_single_measurement_trigger() {
    // drivers/iio/imu/inv_mpu6050/inv_mpu_magn.c: SLV0 reads 7 bytes from 0x03 with BYTE_SW and
    // GRP (big-endian words), SLV1 writes CNTL1 = single | 16-bit every sample.
    let mut c = chip();
    spi_write(&mut c, 0x25, &[0x8C, 0x03, 0x80 | 0x40 | 0x10 | 7]);
    spi_write(&mut c, 0x28, &[0x0C, 0x0A, 0x81]);
    spi_write(&mut c, 0x64, &[0x11]); // I2C_SLV1_DO
    spi_write(&mut c, 0x19, &[19]); // 50 Hz
    spi_write(&mut c, 0x1A, &[0x01]);
    spi_write(&mut c, 0x6A, &[0x20]);
    let s = PhysicalSample {
        mag: [30.0, 15.0, -45.0],
        ..at_rest()
    };
    c.latch_at(&s, 20 * MS); // SLV0 reads nothing new, SLV1 starts a measurement
    c.latch_at(&s, 40 * MS); // the measurement completed at 27.2 ms: SLV0 reads it
    assert_eq!(
        spi_read(&mut c, 0x49, 7),
        [0, 100, 0, 200, 0x01, 0x2C, 0x10]
    );
    assert_eq!(
        c.ak8963().map(|ak| ak.peek(0x0A)),
        Some(0x11),
        "a new one started"
    );
}

#[test]
fn ext_sens_data_is_allocated_in_slave_order() {
    let mut c = chip();
    i2c_write(&mut c, 0x68, &[0x25, 0x8C, 0x00, 0x82]); // SLV0: WIA, INFO
    i2c_write(&mut c, 0x68, &[0x28, 0x8C, 0x0A, 0x83]); // SLV1: CNTL1, CNTL2, ASTC
    i2c_write(&mut c, 0x68, &[0x6A, 0x20]);
    c.latch_at(&at_rest(), MS);
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x49, 6),
        Some(vec![0x48, 0x00, 0x00, 0x00, 0x00, 0x00])
    );
    // Disabling slave 0 keeps its space: slave 1 stays at EXT_SENS_DATA_02.
    i2c_write(&mut c, 0x68, &[0x27, 0x02]);
    i2c_write(&mut c, 0x68, &[0x29, 0x00]); // slave 1 now reads from WIA
    c.latch_at(&at_rest(), 2 * MS);
    assert_eq!(
        i2c_read(&mut c, 0x68, 0x49, 5),
        Some(vec![0x48, 0x00, 0x48, 0x00, 0x00])
    );
}

#[test]
fn delayed_slaves_run_every_1_plus_i2c_mst_dly_samples() {
    let mut c = chip();
    spi_write(&mut c, 0x25, &[0x0C, 0x0D, 0x81]); // SLV0 writes TS1 (a plain R/W register)
    spi_write(&mut c, 0x63, &[0x00]);
    spi_write(&mut c, 0x34, &[0x02]); // I2C_MST_DLY = 2
    spi_write(&mut c, 0x67, &[0x01]); // SLV0 delayed
    spi_write(&mut c, 0x6A, &[0x20]);
    let mut writes = Vec::new();
    for k in 0..7u8 {
        spi_write(&mut c, 0x63, &[k]);
        c.latch_at(&at_rest(), u64::from(k + 1) * MS);
        writes.push(c.ak8963().map(|ak| ak.peek(0x0D)).unwrap());
    }
    assert_eq!(writes, [0, 0, 0, 3, 3, 3, 6]);
}

#[test]
fn slave_data_goes_into_the_fifo_after_the_sensors() {
    let mut c = chip();
    spi_write(&mut c, 0x25, &[0x8C, 0x00, 0x81]); // SLV0: WIA
    spi_write(&mut c, 0x23, &[0x08 | 0x01]); // ACCEL, SLV0
    spi_write(&mut c, 0x6A, &[0x60]);
    c.latch_at(&at_rest(), MS);
    assert_eq!(spi_read(&mut c, 0x72, 2), [0x00, 0x07]);
    assert_eq!(spi_read(&mut c, 0x74, 7), [0, 0, 0, 0, 0x40, 0, 0x48]);
}

#[test]
fn i2c_mst_rst_clears_the_master_state() {
    let mut c = chip();
    spi_mode_master(&mut c);
    spi_write(&mut c, 0x31, &[0xD0, 0x00, 0x00, 0x80]);
    spi_write(&mut c, 0x6A, &[0x22]);
    assert_eq!(spi_read(&mut c, 0x36, 1), [0x00]);
    assert_eq!(spi_read(&mut c, 0x6A, 1), [0x20]);
}

/// What slave 0 read of the AK8963 (HXL..=HZH, ST2) at each of 12 latches 5 ms apart, in
/// continuous mode 2 (100 Hz), the field changing at every latch; `advance_between` calls
/// `advance` in the middle of every period, as a device loop between two latches may.
fn slave_0_reads(advance_between: bool) -> Vec<[u8; 7]> {
    let mut c = chip();
    spi_mode_master(&mut c);
    slv4(&mut c, 0x0C, 0x0A, Some(0x16)); // CNTL1: 16-bit, continuous mode 2
    spi_write(&mut c, 0x25, &[0x8C, 0x03, 0x87]); // slave 0: HXL.., 7 bytes
    (1..=12u64)
        .map(|k| {
            if advance_between {
                c.advance(k * 5 * MS - 2 * MS);
            }
            let sample = PhysicalSample {
                mag: [k as f32, -(k as f32), 2.0 * k as f32],
                ..at_rest()
            };
            c.latch_at(&sample, k * 5 * MS);
            let mut ext = [0u8; 7];
            ext.copy_from_slice(&spi_read(&mut c, 0x49, 7));
            ext
        })
        .collect()
}

#[test]
fn what_slave_0_reads_does_not_depend_on_advances_between_latches() {
    // A measurement due between two latches completes at the next one, with its field, however
    // often the device's loop moved the clock meanwhile: the FIFO's magnetometer bytes do not
    // depend on the load of the machine the device runs on.
    let quiet = slave_0_reads(true);
    assert_eq!(quiet, slave_0_reads(false));
    assert!(quiet.iter().any(|r| r[..6] != [0; 6]), "{quiet:?}");
}
