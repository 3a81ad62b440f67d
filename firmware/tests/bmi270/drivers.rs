//! The register sequences of three drivers, as read in their sources (no code taken):
//! ArduPilot `AP_InertialSensor_BMI270.cpp` and Betaflight `accgyro_spi_bmi270.c` through the
//! shared sequences of `fc.rs` (every sample decoded in order), and the `bmi2` crate's 8 KB
//! file in chunks through INIT_ADDR (the crate itself runs in `margemu-hil`'s
//! `tests/driver_bmi2.rs`, over I2C); and a driver that reads the chip before its upload has
//! completed.

use super::*;

/// Dummy read, CHIP_ID check, soft reset, dummy read again.
fn probe_and_reset(c: &mut Bmi270) {
    dummy_read(c);
    assert_eq!(read1(c, 0x00), 0x24, "CHIP_ID");
    spi_write(c, 0x7E, &[0xB6]);
    c.advance(c.now_ns() + 2 * MS);
    dummy_read(c);
    assert_eq!(read1(c, 0x00), 0x24, "CHIP_ID after reset");
}

#[test]
fn ardupilot_reads_every_sample_in_order_from_the_fifo_at_1600_hz() {
    let mut c = chip();
    let run = fc::ardupilot(&mut c, 400);
    assert_eq!(run.init_tries, 1);
    assert_eq!(run.samples.len(), 400, "one 0x8C frame per 625 µs poll");
    assert_eq!(run.samples, run.expected);
    assert_eq!((run.fifo_resets, run.single_frames), (0, 0));
    // Every 100 polls the temperature, updated every 10 ms (32 latches at 3.2 kHz): the
    // sample of the last 10 ms boundary, 23 °C + n/512 K reading n.
    assert_eq!(run.temperatures, [192, 384, 576, 768]);
    assert_eq!(c.sample_period_ns(), Some(fc::GYRO_3K2_NS));
}

#[test]
fn ardupilot_gives_up_on_a_truncated_file() {
    let mut c = chip();
    assert_eq!(fc::ardupilot_init(&mut c, 200), (false, 5));
    assert_eq!(read1(&mut c, 0x21), 0x02);
}

#[test]
fn betaflight_reads_every_sample_on_its_data_ready_edge() {
    let mut c = chip();
    let run = fc::betaflight(&mut c, 400);
    assert_eq!(run.samples.len(), 400, "one rising edge per 3.2 kHz sample");
    assert_eq!(
        run.samples, run.expected,
        "accel new every fourth sample (800 Hz)"
    );
    assert_eq!(read1(&mut c, 0x21), 0x01); // init_ok, though Betaflight never looks
}

/// Before the configuration upload has completed the chip answers, but its sensors do not run
/// (see the chip module's docs): a driver that skips or botches the upload reads zeros, the
/// invalid temperature, an empty FIFO and never gets a data-ready, and nothing panics.
#[test]
fn a_driver_reading_before_the_upload_completes() {
    let mut c = chip();
    probe_and_reset(&mut c);
    assert_eq!(read1(&mut c, 0x21), 0x00, "INTERNAL_STATUS not_init");
    let configure = |c: &mut Bmi270| {
        spi_write(c, 0x40, &[0xAC, 0x03, 0xAC, 0x08]); // 1.6 kHz, ±16 g, ±2000 °/s
        spi_write(c, 0x48, &[0x01, 0xD0]); // FIFO with headers
        spi_write(c, 0x58, &[0x04]); // data ready on INT1
        spi_write(c, 0x53, &[0x0A]); // push-pull, active high
        spi_write(c, 0x7D, &[0x0E]); // accel, gyro, temperature
    };
    configure(&mut c);
    let nothing = |c: &mut Bmi270, when: &str| {
        for k in 1..=8i16 {
            let t = c.now_ns() + 625_000;
            c.latch_at(&fc::sample(k), t);
            assert!(!c.int_pin_at(t), "{when}: no data-ready pulse");
        }
        assert_eq!(
            read(c, 0x0C, 12),
            [0; 12],
            "{when}: data registers at reset"
        );
        assert_eq!(
            read(c, 0x22, 2),
            [0x00, 0x80],
            "{when}: temperature invalid"
        );
        assert_eq!(read1(c, 0x03), 0x10, "{when}: STATUS cmd_rdy, no drdy");
        assert_eq!(read1(c, 0x1D), 0x00, "{when}: INT_STATUS_1");
        assert_eq!(read(c, 0x24, 2), [0, 0], "{when}: FIFO empty");
        assert_eq!(read(c, 0x26, 3), [0x80; 3], "{when}: FIFO_DATA over-read");
        assert_ne!(read(c, 0x18, 3), [0; 3], "{when}: SENSORTIME runs");
    };
    nothing(&mut c, "no upload");
    // Half the file, INIT_CTRL still 0: the load is under way.
    spi_write(&mut c, 0x59, &[0x00]);
    spi_write(&mut c, 0x5E, &config_file(164));
    assert_eq!(read1(&mut c, 0x21), 0x00);
    nothing(&mut c, "during the upload");
    // The load ends short: init_err, still nothing.
    spi_write(&mut c, 0x59, &[0x01]);
    assert_eq!(read1(&mut c, 0x21), 0x02);
    nothing(&mut c, "after init_err");
    // A whole file: the same configuration now gives data.
    upload(&mut c, &config_file(328));
    assert_eq!(read1(&mut c, 0x21), 0x01);
    let t = c.now_ns() + 625_000;
    c.latch_at(&fc::sample(5), t);
    assert!(c.int_pin_at(t));
    let data = read(&mut c, 0x0C, 12);
    assert_eq!(i16::from_le_bytes([data[0], data[1]]), 5);
    assert_eq!(read(&mut c, 0x24, 2), [13, 0]);
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
