//! Samples in the data registers: every range within 1 LSB, little-endian order, power states,
//! data-ready flags, temperature, sensor time, the swap at bus idle and the interrupt pins.

use super::*;

#[test]
fn accel_at_every_range_within_1_lsb() {
    let acc = [0.3, -1.2, 2.7];
    for code in 0..4u8 {
        let mut c = running_accel();
        spi_write(&mut c, 0x41, &[code]);
        c.latch_at(&sample(acc, [0.0; 3], 23.0), MS);
        let got = words(&aread(&mut c, 0x12, 6));
        for (axis, (&raw, &g)) in got.iter().zip(&acc).enumerate() {
            let what = format!("range {code} axis {axis}");
            assert_within_1_lsb(raw, f64::from(g), acc_lsb_per_g(code), &what);
        }
    }
}

#[test]
fn gyro_at_every_range_within_1_lsb() {
    let dps = [100.0, -110.5, 12.25];
    for code in 0..5u8 {
        let mut g = Bmi088Gyro::new();
        spi_write(&mut g, 0x0F, &[code]);
        g.latch_at(&sample([0.0; 3], dps, 23.0), MS);
        let got = words(&spi_read(&mut g, 0x02, 6));
        for (axis, (&raw, &w)) in got.iter().zip(&dps).enumerate() {
            let what = format!("range {code} axis {axis}");
            assert_within_1_lsb(raw, f64::from(w), gyr_lsb_per_dps(code), &what);
        }
    }
}

#[test]
fn out_of_range_values_clip() {
    let mut c = running_accel();
    spi_write(&mut c, 0x41, &[0x00]); // ±3 g
    c.latch_at(&sample([4.0, -4.0, 0.0], [0.0; 3], 23.0), MS);
    assert_eq!(words(&aread(&mut c, 0x12, 6)), [32767, -32768, 0]);
    let mut g = Bmi088Gyro::new();
    spi_write(&mut g, 0x0F, &[0x04]); // ±125 °/s
    g.latch_at(&sample([0.0; 3], [200.0, -200.0, 0.0], 23.0), MS);
    assert_eq!(words(&spi_read(&mut g, 0x02, 6)), [32767, -32768, 0]);
}

#[test]
fn little_endian_bytes() {
    let mut c = running_accel();
    spi_write(&mut c, 0x41, &[0x03]); // ±24 g: 1365.33 LSB/g
    c.latch_at(&sample([1.0, -1.0, 0.0], [0.0; 3], 23.0), MS);
    let miso = spi(&mut c, &[0x92, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(miso, [0x00, 0x00, 0x55, 0x05, 0xAB, 0xFA, 0x00, 0x00]);
    let mut g = Bmi088Gyro::new(); // ±2000 °/s: 16.384 LSB/(°/s)
    g.latch_at(&sample([0.0; 3], [0.0, 0.0, -1000.0], 23.0), MS);
    assert_eq!(spi(&mut g, &[0x86, 0, 0]), [0x00, 0x00, 0xC0]); // −16384
}

#[test]
fn accel_off_until_acc_pwr_ctrl_is_4_and_keeps_its_data() {
    let mut c = spi_accel();
    assert_eq!(c.sample_period_ns(), None);
    c.latch_at(&sample([1.0; 3], [0.0; 3], 40.0), MS);
    assert_eq!(aread(&mut c, 0x12, 6), [0; 6]);
    assert_eq!(aread1(&mut c, 0x03), 0x10); // no drdy
    spi_write(&mut c, 0x7D, &[0x04]); // ACC_PWR_CONF still 0x03 (DS 3: PWR_CTRL alone)
    assert_eq!(c.sample_period_ns(), Some(10 * MS));
    c.latch_at(&sample([1.0; 3], [0.0; 3], 40.0), 2 * MS);
    assert_eq!(words(&aread(&mut c, 0x12, 6)), [5461; 3]);
    spi_write(&mut c, 0x7D, &[0x00]);
    c.latch_at(&sample([-1.0; 3], [0.0; 3], 40.0), 3 * MS);
    assert_eq!(words(&aread(&mut c, 0x12, 6)), [5461; 3]); // stale
}

#[test]
fn accel_drdy_flags() {
    let mut c = running_accel();
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.0), MS);
    assert_eq!((aread1(&mut c, 0x03), aread1(&mut c, 0x1D)), (0x90, 0x80));
    assert_eq!(aread1(&mut c, 0x1D), 0x00); // cleared by its own read
    assert_eq!(aread1(&mut c, 0x03), 0x90);
    aread(&mut c, 0x16, 1);
    assert_eq!(aread1(&mut c, 0x03), 0x10); // cleared by a data read
}

#[test]
fn gyro_data_ready_pulse_and_int3() {
    let mut g = Bmi088Gyro::new();
    g.latch_at(&sample([0.0; 3], [1.0; 3], 23.0), MS);
    assert_eq!(gread1(&mut g, 0x0A), 0x00); // data_en off
    spi_write(&mut g, 0x15, &[0x80]);
    spi_write(&mut g, 0x18, &[0x01]); // data ready to INT3
    spi_write(&mut g, 0x16, &[0x01]); // INT3 active high, push-pull
    g.latch_at(&sample([0.0; 3], [1.0; 3], 23.0), 2 * MS);
    // INT4: nothing mapped, active low (bit 2 cleared): high.
    assert_eq!(
        (gread1(&mut g, 0x0A), g.int3_pin(), g.int4_pin()),
        (0x80, true, true)
    );
    g.advance(2 * MS + 279_999);
    assert!(g.int3_pin());
    g.advance(2 * MS + 280_000);
    assert_eq!((gread1(&mut g, 0x0A), g.int3_pin()), (0x00, false));
}

#[test]
fn accel_int1_follows_drdy_at_its_polarity() {
    let mut c = running_accel();
    assert_eq!(c.int1_pin(), None); // not an output
    spi_write(&mut c, 0x53, &[0x08]); // output, push-pull, active low
    spi_write(&mut c, 0x58, &[0x04]); // drdy to INT1
    assert_eq!(c.int1_pin(), Some(true));
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.0), MS);
    assert_eq!((c.int1_pin(), c.int2_pin()), (Some(false), None));
    aread(&mut c, 0x12, 6);
    assert_eq!(c.int1_pin(), Some(true));
}

#[test]
fn temperature_every_1_28_s() {
    let mut c = running_accel();
    assert_eq!(aread(&mut c, 0x22, 2), [0x00, 0x00]);
    c.latch_at(&sample([0.0; 3], [0.0; 3], 85.0), MS);
    assert_eq!(aread(&mut c, 0x22, 2), [0x3E, 0x00]);
    c.latch_at(&sample([0.0; 3], [0.0; 3], -40.0), MS + 1_279_999_999);
    assert_eq!(aread(&mut c, 0x22, 2), [0x3E, 0x00]); // not yet
    c.latch_at(&sample([0.0; 3], [0.0; 3], 23.375), MS + 1_280_000_000);
    assert_eq!(aread(&mut c, 0x22, 2), [0x00, 0x60]);
}

#[test]
fn sensortime_counts_and_holds_during_a_burst() {
    let mut c = running_accel();
    c.advance(1_000 * MS); // 25600 ticks
    assert_eq!(aread(&mut c, 0x18, 3), [0x00, 0x64, 0x00]);
    c.select();
    let mut miso = vec![c.exchange(0x98), c.exchange(0)]; // dummy, SENSORTIME_0
    c.advance(2_000 * MS);
    miso.push(c.exchange(0));
    miso.push(c.exchange(0));
    c.deselect();
    assert_eq!(miso[1..], [0x00, 0x64, 0x00]); // held at the first read (else 0xC8)
    assert_eq!(aread(&mut c, 0x18, 3), [0x00, 0xC8, 0x00]);
}

#[test]
fn a_latch_during_a_burst_appears_when_the_bus_goes_idle() {
    let mut g = Bmi088Gyro::new();
    g.latch_at(&sample([0.0; 3], [0.0, 0.0, 1000.0], 23.0), MS);
    g.select();
    let mut miso = vec![g.exchange(0x86)];
    g.latch_at(&sample([0.0; 3], [0.0, 0.0, -1000.0], 23.0), 2 * MS);
    miso.push(g.exchange(0));
    g.deselect();
    assert_eq!(miso, [0x00, 0x40]); // RATE_Z of +1000 °/s: 16384
    assert_eq!(words(&spi_read(&mut g, 0x06, 2)), [-16384]);
}

#[test]
fn sample_periods_follow_odr_and_bandwidth() {
    let mut c = running_accel();
    for (conf, period) in [
        (0xA5, 80 * MS),
        (0xA8, 10 * MS),
        (0xAB, 1_250_000),
        (0xAC, 625_000),
    ] {
        spi_write(&mut c, 0x40, &[conf]);
        assert_eq!(c.sample_period_ns(), Some(period), "{conf:#04x}");
    }
    let mut g = Bmi088Gyro::new();
    for (bw, period) in [
        (0x00, 500_000),
        (0x02, MS),
        (0x03, 2_500_000),
        (0x07, 10 * MS),
    ] {
        spi_write(&mut g, 0x10, &[bw]);
        assert_eq!(g.sample_period_ns(), Some(period), "{bw:#04x}");
    }
}
