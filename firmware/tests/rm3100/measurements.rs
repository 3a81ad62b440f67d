//! Measurement timing and data (DS §5.2–5.6): continuous mode at the TMRC rates, limited by the
//! cycle counts; single measurements and STATUS; DRDY and its clearing rules; 24-bit results at
//! several cycle counts; saturation; the self test; the DS's note on ending continuous mode.

use super::*;

const L: Link = Link::I2c(ADDRESS);

/// One axis at `cc` counts: 60 µs + `cc` cycles each way at 180 kHz.
fn axis_ns(cc: u64) -> u64 {
    60_000 + cc * 100_000 / 9
}

fn status(mag: &mut Rm3100) -> u8 {
    read(mag, L, 0x34, 1)[0]
}

fn results(mag: &mut Rm3100) -> [i32; 3] {
    decode(&read(mag, L, 0x24, 9))
}

/// Sequences complete at `first + k · period`, k = 0..n: DRDY is clear 1 ns before each and set
/// at it (reading the results clears it again).
fn assert_completions(mag: &mut Rm3100, first: u64, period: u64, n: u64) {
    for k in 0..n {
        let t = first + k * period;
        mag.advance(t - 1);
        assert_eq!(status(mag), 0x00, "1 ns before completion {k}");
        mag.advance(t);
        assert_eq!(status(mag), 0x80, "completion {k}");
        results(mag);
    }
}

#[test]
fn continuous_mode_at_each_tmrc_rate() {
    for n in 0..14u8 {
        let tmrc = 0x92 + n;
        let mut mag = Rm3100::new();
        let t0 = MS;
        mag.advance(t0);
        write_reg(&mut mag, L, 0x0B, tmrc);
        write_reg(&mut mag, L, 0x01, 0x71);
        // 600 Hz halved n times; 3 axes at 200 counts need 6.85 ms, which wins at 0x92/0x93.
        let period = ((5_000_000u64 << n) / 3).max(MEAS_3X200);
        assert_completions(&mut mag, t0 + MEAS_3X200, period, 3);
    }
}

#[test]
fn the_cycle_counts_limit_the_continuous_rate() {
    // (cycle counts, CMM axes, expected period) at TMRC 0x92 (~600 Hz, 1.67 ms).
    for (cc, cmm, period) in [
        ([200u16; 3], 0x71, MEAS_3X200),                   // ~146 Hz
        ([100; 3], 0x71, 3 * axis_ns(100)),                // ~285 Hz
        ([50; 3], 0x11, 1_666_666),                        // x only: TMRC rules
        ([50, 30, 800], 0x31, 1_666_666),                  // x and y: 0.99 ms
        ([50, 30, 800], 0x51, axis_ns(50) + axis_ns(800)), // x and z: 9.5 ms
    ] {
        let mut mag = Rm3100::new();
        let cc_bytes: Vec<u8> = cc.iter().flat_map(|c| c.to_be_bytes()).collect();
        assert!(write(&mut mag, L, 0x04, &cc_bytes));
        write_reg(&mut mag, L, 0x0B, 0x92);
        write_reg(&mut mag, L, 0x01, cmm);
        let first: u64 = (0..3)
            .filter(|i| cmm & (0x10 << i) != 0)
            .map(|i| axis_ns(u64::from(cc[i])))
            .sum();
        assert_completions(&mut mag, first, period, 4);
    }
}

#[test]
fn single_measurement_sets_status_when_the_requested_axes_are_done() {
    let mut mag = Rm3100::new();
    mag.latch_at(&field([10.0, -20.0, 30.0]), 0);
    mag.advance(MS);
    write_reg(&mut mag, L, 0x00, 0x10); // x at 200 counts
    mag.advance(MS + axis_ns(200) - 1);
    assert_eq!(status(&mut mag), 0x00);
    mag.advance(MS + axis_ns(200));
    assert_eq!(status(&mut mag), 0x80);
    assert_eq!(results(&mut mag), [750, 0, 0], "only x measured");
    assert_eq!(status(&mut mag), 0x00, "reading the results cleared DRDY");

    assert!(write(&mut mag, L, 0x06, &[0, 100, 0x01, 0x90])); // y 100, z 400
    let t = 10 * MS;
    mag.advance(t);
    write_reg(&mut mag, L, 0x00, 0x60); // y and z
    let done = t + axis_ns(100) + axis_ns(400);
    mag.advance(done - 1);
    assert_eq!(status(&mut mag), 0x00);
    mag.advance(done);
    assert_eq!(status(&mut mag), 0x80);
    assert_eq!(results(&mut mag), [750, -750, 4500]);
    mag.advance(done + 1_000 * MS);
    assert_eq!(status(&mut mag), 0x00, "one measurement only");
}

#[test]
fn results_are_within_one_lsb_at_several_cycle_counts() {
    for cc in [
        [30u16; 3],
        [50; 3],
        [100; 3],
        [200; 3],
        [300; 3],
        [400; 3],
        [800; 3],
        [50, 200, 400],
    ] {
        let mut mag = Rm3100::new();
        let cc_bytes: Vec<u8> = cc.iter().flat_map(|c| c.to_be_bytes()).collect();
        assert!(write(&mut mag, L, 0x04, &cc_bytes));
        let mut t = 0;
        for want in samples(25) {
            mag.latch_at(&field(want), t);
            write_reg(&mut mag, L, 0x00, 0x70);
            t += 30 * MS; // 3 axes at 800 counts take 26.8 ms
            mag.advance(t);
            assert_eq!(status(&mut mag), 0x80, "{cc:?}");
            let raw = results(&mut mag);
            assert!(within_one_lsb(raw, want, cc), "{cc:?}: {raw:?} vs {want:?}");
        }
    }
}

#[test]
fn results_saturate_at_24_bits() {
    let mut mag = Rm3100::new();
    assert!(write(&mut mag, L, 0x04, &[0xFF; 6])); // 65535 counts: 24576 LSB/µT
    mag.latch_at(&field([400.0, -400.0, f32::NAN]), 0);
    write_reg(&mut mag, L, 0x00, 0x70);
    mag.advance(3_000 * MS);
    assert_eq!(
        read(&mut mag, L, 0x24, 9),
        [0x7F, 0xFF, 0xFF, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00]
    );
    assert!(write(
        &mut mag,
        L,
        0x04,
        &[0x00, 0xC8, 0x00, 0xC8, 0x00, 0xC8]
    ));
    mag.latch_at(&field([1e6, -1e6, 111_848.0]), 4_000 * MS);
    write_reg(&mut mag, L, 0x00, 0x70);
    mag.advance(4_010 * MS);
    assert_eq!(results(&mut mag), [8_388_607, -8_388_608, 8_388_600]);
}

#[test]
fn drdm_raises_drdy_after_every_axis() {
    let mut mag = Rm3100::new();
    write_reg(&mut mag, L, 0x0B, 0x92);
    write_reg(&mut mag, L, 0x01, 0x75); // x, y, z, DRDM
    let a = axis_ns(200);
    assert_completions(&mut mag, a, a, 3);
    // The next sequence starts after the TMRC/measurement period (the measurement here).
    assert_completions(&mut mag, MEAS_3X200 + a, a, 3);
}

/// A 3-axis measurement polled at the chip's time and done 7 ms after `*t`: DRDY reads set.
fn measured(mag: &mut Rm3100, link: Link, t: &mut u64) {
    write_reg(mag, link, 0x00, 0x70);
    *t += 7 * MS;
    mag.advance(*t);
    assert_eq!(read(mag, link, 0x34, 1), [0x80]);
}

#[test]
fn drdy_clearing_follows_hshake() {
    // Defaults (DRC0, DRC1): a register read over I2C (pointer write, then read) keeps DRDY,
    // a data byte written clears it; on SPI the address byte of a write clears it.
    let mut t = 0;
    let mut mag = Rm3100::new();
    measured(&mut mag, L, &mut t);
    assert_eq!(read(&mut mag, L, 0x0B, 1), [0x96]);
    assert_eq!(status(&mut mag), 0x80);
    write_reg(&mut mag, L, 0x0B, 0x96);
    assert_eq!(status(&mut mag), 0x00, "DRC0");
    measured(&mut mag, Link::Spi, &mut t);
    assert_eq!(spi(&mut mag, &[0x0B]), [0x80]);
    assert_eq!(status(&mut mag), 0x00, "DRC0 at the SPI address byte");

    // DRC0 and DRC1 off (PX4's self test): DRDY survives writes and reading the results.
    let mut mag = Rm3100::new();
    write_reg(&mut mag, L, 0x35, 0x08);
    measured(&mut mag, L, &mut t);
    write_reg(&mut mag, L, 0x0B, 0x96);
    results(&mut mag);
    assert_eq!(status(&mut mag), 0x80);

    // DRC1 only: writes keep it, reading the results clears it.
    write_reg(&mut mag, L, 0x35, 0x02);
    write_reg(&mut mag, L, 0x0B, 0x96);
    assert_eq!(status(&mut mag), 0x80);
    results(&mut mag);
    assert_eq!(status(&mut mag), 0x00);
}

#[test]
fn reading_the_results_early_sets_nack2() {
    let mut mag = Rm3100::new();
    write_reg(&mut mag, L, 0x35, 0x03);
    assert_eq!(results(&mut mag), [0, 0, 0]);
    assert_eq!(read(&mut mag, L, 0x35, 1), [0x4B], "NACK2");
    write_reg(&mut mag, L, 0x35, 0x03);
    mag.latch_at(&field([1.0, 1.0, 1.0]), 0);
    write_reg(&mut mag, L, 0x00, 0x70);
    mag.advance(7 * MS);
    assert_eq!(results(&mut mag), [75, 75, 75]);
    assert_eq!(
        read(&mut mag, L, 0x35, 1),
        [0x0B],
        "DRDY was set: no NACK2, though the first byte cleared it"
    );
}

#[test]
fn self_test_reports_the_tested_axes() {
    let mut mag = Rm3100::new();
    mag.latch_at(&field([5.0, 5.0, 5.0]), 0);
    write_reg(&mut mag, L, 0x33, 0x8F); // STE, 120 µs timeout, 4 LR periods
    write_reg(&mut mag, L, 0x00, 0x70);
    mag.advance(1_440 * US - 1);
    assert_eq!(status(&mut mag), 0x00);
    mag.advance(1_440 * US);
    assert_eq!(status(&mut mag), 0x80);
    assert_eq!(read(&mut mag, L, 0x33, 1), [0xFF], "XOK, YOK, ZOK");
    assert_eq!(results(&mut mag), [0, 0, 0], "no measurement");
    write_reg(&mut mag, L, 0x33, 0x85); // a BIST write clears the results of the last test
    assert_eq!(read(&mut mag, L, 0x33, 1), [0x85]);
    write_reg(&mut mag, L, 0x00, 0x30); // x and y, 30 µs × 1 period each
    mag.advance(1_440 * US + 60 * US);
    assert_eq!(read(&mut mag, L, 0x33, 1), [0xB5]);
    write_reg(&mut mag, L, 0x33, 0x05);
    write_reg(&mut mag, L, 0x00, 0x70); // STE off: a measurement
    mag.advance(10 * MS);
    assert_eq!(results(&mut mag), [375, 375, 375]);
}

#[test]
fn ending_continuous_mode_by_the_datasheet_note_is_an_option() {
    for strict in [false, true] {
        let mut mag = Rm3100::new();
        mag.set_strict_cmm(strict);
        write_reg(&mut mag, L, 0x01, 0x71);
        assert_eq!(
            read(&mut mag, L, 0x01, 1),
            [0x71],
            "the value before the read"
        );
        assert_eq!(mag.is_continuous(), !strict, "reading CMM");
        assert_eq!(
            read(&mut mag, L, 0x01, 1),
            [if strict { 0x70 } else { 0x71 }]
        );
        write_reg(&mut mag, L, 0x01, 0x71);
        write_reg(&mut mag, L, 0x0B, 0x95);
        assert_eq!(mag.is_continuous(), !strict, "writing TMRC");
        mag.advance(100 * MS);
        assert_eq!(status(&mut mag), if strict { 0x00 } else { 0x80 });
    }
}

#[test]
fn cycle_counts_written_in_continuous_mode_restart_it_with_their_gain() {
    let mut mag = Rm3100::new();
    mag.latch_at(&field([2.0, -2.0, 4.0]), 0);
    write_reg(&mut mag, L, 0x0B, 0x92);
    write_reg(&mut mag, L, 0x01, 0x71);
    mag.advance(7 * MS);
    assert_eq!(results(&mut mag), [150, -150, 300]);
    let t = 20 * MS;
    mag.advance(t);
    results(&mut mag);
    assert!(write(
        &mut mag,
        L,
        0x04,
        &[0x01, 0x90, 0x01, 0x90, 0x01, 0x90]
    ));
    let first = t + 3 * axis_ns(400);
    mag.advance(first - 1);
    assert_eq!(status(&mut mag), 0x00, "restarted at the write");
    mag.advance(first);
    assert_eq!(
        results(&mut mag),
        [300, -300, 600],
        "150 LSB/µT at 400 counts"
    );
}
