//! PX4's RM3100 driver, as of 2022 and before.
//!
//! Both probe REVID = 0x22: on I2C at 0x20 by writing the register address in a transaction of
//! its own and reading in the next, on SPI (mode 3) with bit 7 of the address byte set.
//!
//! Since 2022 the self test sets CMM = 0x70, HSHAKE = 0x08 (DRDY no longer cleared by writes or
//! reads), BIST = 0x8F and POLL = 0x70, reads STATUS until bit 7 (for at most 26 ms), requires
//! BIST to read STE with XOK, YOK and ZOK, then writes BIST = 0. The configuration is three
//! 2-byte cycle-count writes (0x00C8), HSHAKE = 0x0B, CMM = 0x71, TMRC = 0x95 (~75 Hz) and
//! BIST = 0. Every 13 ms it reads 9 bytes from 0x24 without looking at STATUS and publishes a
//! reading only when it differs from the previous one; a repeat counts as a failure, a new
//! reading takes one off, and more than ten failures make it write the configuration again.
//!
//! Before 2022 it measured on demand: configuration (cycle counts, CMM = 0x70, TMRC = 0x94,
//! BIST = 0), a self test (10 ms wait, STATUS and the results if ready, BIST = 0x8F, POLL =
//! 0x70, 10 ms wait, STATUS bit 7 required, the BIST OK bits read), the configuration again,
//! then every 10 ms: STATUS, the 9 result bytes when bit 7 is set, and POLL = 0x70.

use margemu_firmware::chip::I2cTarget;
use margemu_protocol::regmap::rm3100::continuous_period_ns;

use super::*;

const RUN_NS: u64 = 13 * MS;

/// PX4's register read: over I2C the address goes out in its own write transaction.
fn px4_read(mag: &mut Rm3100, link: Link, reg: u8, n: usize) -> Vec<u8> {
    match link {
        Link::I2c(address) => {
            assert_eq!(i2c_write(mag, address, &[reg]), [true, true]);
            assert!(mag.start(address, true));
            let bytes = (0..n).map(|_| mag.read()).collect();
            mag.stop();
            bytes
        }
        Link::Spi => read(mag, link, reg, n),
    }
}

fn probe(mag: &mut Rm3100, link: Link) -> bool {
    px4_read(mag, link, 0x36, 1) == [0x22]
}

/// The self test since 2022; `t` moves on by 100 µs per STATUS read.
fn self_test(mag: &mut Rm3100, link: Link, t: &mut u64) -> bool {
    for (reg, value) in [(0x01, 0x70), (0x35, 0x08), (0x33, 0x8F), (0x00, 0x70)] {
        write_reg(mag, link, reg, value);
    }
    let start = *t;
    while *t - start < 26 * MS {
        *t += 100 * US;
        mag.advance(*t);
        if px4_read(mag, link, 0x34, 1)[0] & 0x80 != 0 {
            let bist = px4_read(mag, link, 0x33, 1)[0];
            if bist & 0x80 != 0 {
                write_reg(mag, link, 0x33, 0x00);
                return bist & 0x70 == 0x70;
            }
        }
    }
    false
}

fn configure(mag: &mut Rm3100, link: Link) {
    for reg in [0x04, 0x06, 0x08] {
        assert!(write(mag, link, reg, &[0x00, 0xC8]));
    }
    for (reg, value) in [(0x35, 0x0B), (0x01, 0x71), (0x0B, 0x95), (0x33, 0x00)] {
        write_reg(mag, link, reg, value);
    }
}

struct Px4 {
    prev: [i32; 3],
    failures: u32,
    resets: usize,
    published: Vec<[i32; 3]>,
}

impl Px4 {
    fn run(&mut self, mag: &mut Rm3100, link: Link) {
        if self.failures > 10 {
            self.failures = 0;
            self.resets += 1;
            configure(mag, link);
            return;
        }
        let raw = decode(&px4_read(mag, link, 0x24, 9));
        if raw != self.prev {
            self.published.push(raw);
            self.prev = raw;
            self.failures = self.failures.saturating_sub(1);
        } else {
            self.failures += 1;
        }
    }
}

/// Runs PX4 (since 2022) for `runs` cycles, the device latching the [`samples`] as [`Bench`]
/// does. Returns the driver and the fields.
fn run_current(link: Link, strict: bool, runs: u64) -> (Px4, Vec<[f32; 3]>) {
    let mut mag = Rm3100::new();
    mag.set_strict_cmm(strict);
    let mut t = MS;
    mag.advance(t);
    assert!(probe(&mut mag, link), "{link:?}");
    assert!(self_test(&mut mag, link, &mut t), "{link:?}: self test");
    configure(&mut mag, link);
    let t_cfg = t;
    // TMRC 0x95 (13.3 ms) is slower than the 6.85 ms measurement.
    let period = continuous_period_ns(0x95, 0b111, [200; 3]);
    assert_eq!(period, 13_333_333);
    let mut bench = Bench::new(t_cfg, period, t_cfg + runs * RUN_NS);
    let mut px4 = Px4 {
        prev: [0; 3],
        failures: 0,
        resets: 0,
        published: Vec::new(),
    };
    for j in 1..=runs {
        bench.run_to(&mut mag, t_cfg + j * RUN_NS);
        px4.run(&mut mag, link);
    }
    (px4, bench.fields)
}

#[test]
fn every_sample_is_published_in_order() {
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let runs = 300;
        let (px4, fields) = run_current(link, false, runs);
        // Sequence k completes at t_cfg + k · 13.33 ms + 6.85 ms; PX4 reads every 13 ms, faster
        // than the data, so it sees every one of them, some twice (not published again).
        let completed = ((runs * RUN_NS - MEAS_3X200) / 13_333_333 + 1) as usize;
        assert_eq!(px4.published.len(), completed, "{link:?}");
        for (k, raw) in px4.published.iter().enumerate() {
            assert_sample(*raw, &fields, k, format!("{link:?}"));
        }
        assert_eq!(px4.resets, 0, "{link:?}: repeats never pile up past ten");
    }
}

#[test]
fn if_writing_tmrc_ended_continuous_mode_px4_would_get_no_data() {
    // PX4 writes TMRC after CMM: under the DS note the chip stops before its first
    // measurement, every read repeats the power-on zeros and PX4 reconfigures in vain.
    let (px4, _) = run_current(Link::I2c(ADDRESS), true, 100);
    assert_eq!(px4.published, Vec::<[i32; 3]>::new());
    assert_eq!(px4.resets, 8, "every 12th run");
}

#[test]
fn the_self_test_needs_drdy_kept_and_the_ok_bits() {
    let mut mag = Rm3100::new();
    let mut t = 0;
    assert!(self_test(&mut mag, Link::Spi, &mut t));
    assert_eq!(t, 1_500 * US, "1.44 ms, seen at the 15th STATUS read");
    assert_eq!(
        px4_read(&mut mag, Link::Spi, 0x33, 1),
        [0x00],
        "BIST off again"
    );
    // The drivers' BIST read: STE off hides the OK bits.
    write_reg(&mut mag, Link::Spi, 0x33, 0x0F);
    assert_eq!(px4_read(&mut mag, Link::Spi, 0x33, 1), [0x0F]);
}

#[test]
fn the_pre_2022_driver_reads_every_polled_sample_in_order() {
    let link = Link::I2c(ADDRESS);
    let mut mag = Rm3100::new();
    let config = |mag: &mut Rm3100| {
        for reg in [0x04, 0x06, 0x08] {
            assert!(write(mag, link, reg, &[0x00, 0xC8]));
        }
        for (reg, value) in [(0x01, 0x70), (0x0B, 0x94), (0x33, 0x00)] {
            write_reg(mag, link, reg, value);
        }
    };
    let collect = |mag: &mut Rm3100| -> Option<[i32; 3]> {
        (px4_read(mag, link, 0x34, 1)[0] & 0x80 != 0).then(|| decode(&px4_read(mag, link, 0x24, 9)))
    };
    assert!(probe(&mut mag, link));
    config(&mut mag);
    let mut t = 10 * MS;
    mag.advance(t);
    assert_eq!(collect(&mut mag), None, "nothing measured yet");
    write_reg(&mut mag, link, 0x33, 0x8F);
    write_reg(&mut mag, link, 0x00, 0x70);
    t += 10 * MS;
    mag.advance(t);
    assert_eq!(px4_read(&mut mag, link, 0x34, 1), [0x80], "self test done");
    assert_eq!(px4_read(&mut mag, link, 0x33, 1)[0] & 0x70, 0x70);
    config(&mut mag);

    let fields = samples(150);
    let mut got = Vec::new();
    for (k, want) in fields.iter().enumerate() {
        // collect() then measure(): the POLL of sample k, read 10 ms later.
        if let Some(raw) = collect(&mut mag) {
            got.push(raw);
        }
        mag.latch_at(&field(*want), t);
        write_reg(&mut mag, link, 0x00, 0x70);
        t += 10 * MS;
        mag.advance(t);
        assert_eq!(got.len(), k, "sample {k}");
    }
    got.extend(collect(&mut mag));
    assert_eq!(got.len(), fields.len());
    for (k, raw) in got.iter().enumerate() {
        assert_sample(*raw, &fields, k, "POLL every 10 ms");
    }
}
