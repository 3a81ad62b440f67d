//! ArduPilot's RM3100 driver. It has no identity check: the probe reads the six cycle-count
//! bytes one at a time and requires 0x00, 0xC8 for each axis. It then writes TMRC = 0x94
//! (~150 Hz) and CMM = 0x71 (continuous, x/y/z, DRDY after the whole sequence) and the six
//! cycle-count bytes again, all eight kept for its register check. Every 12.5 ms (80 Hz) it
//! reads STATUS and, when bit 7 is set, 9 bytes from 0x24 (24-bit big-endian, 75 LSB/µT).
//! Every tenth call its register check reads the next of the eight registers (a second time if
//! it differs) and writes the expected value back on a mismatch, which is how it recovers from
//! a reset of the chip (`Chip::fault_reset`).

use margemu_protocol::regmap::rm3100::continuous_period_ns;

use super::*;

const TIMER_NS: u64 = 12_500_000;

struct ArduPilot {
    link: Link,
    checked: Vec<(u8, u8)>,
    next: usize,
    counter: u32,
    rewrites: usize,
    readings: Vec<[i32; 3]>,
}

impl ArduPilot {
    fn probe(mag: &mut Rm3100, link: Link) -> Option<Self> {
        let defaults = [0x00, 0xC8, 0x00, 0xC8, 0x00, 0xC8];
        for (reg, want) in (0x04..=0x09).zip(defaults) {
            if read(mag, link, reg, 1) != [want] {
                return None;
            }
        }
        let mut ap = Self {
            link,
            checked: Vec::new(),
            next: 0,
            counter: 0,
            rewrites: 0,
            readings: Vec::new(),
        };
        let config = [0x0B, 0x01, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09].into_iter();
        for (reg, value) in config.zip([0x94, 0x71, 0x00, 0xC8, 0x00, 0xC8, 0x00, 0xC8]) {
            write_reg(mag, link, reg, value);
            ap.checked.push((reg, value));
        }
        Some(ap)
    }

    fn timer(&mut self, mag: &mut Rm3100) {
        if read(mag, self.link, 0x34, 1)[0] & 0x80 != 0 {
            let data = read(mag, self.link, 0x24, 9);
            self.readings.push(decode(&data));
        }
        self.check_next_register(mag);
    }

    fn check_next_register(&mut self, mag: &mut Rm3100) {
        self.counter += 1;
        if self.counter < 10 {
            return;
        }
        self.counter = 0;
        let (reg, value) = self.checked[self.next];
        if read(mag, self.link, reg, 1) != [value] && read(mag, self.link, reg, 1) != [value] {
            write_reg(mag, self.link, reg, value);
            self.rewrites += 1;
            return;
        }
        self.next = (self.next + 1) % self.checked.len();
    }
}

/// Runs ArduPilot for `calls` timer calls from `T_CFG`, the device latching the [`samples`] as
/// [`Bench`] does. Returns the driver and, for each call, the sample
/// the chip's last completed sequence measured (if any).
fn run(link: Link, strict: bool, calls: u64) -> (ArduPilot, Vec<Option<usize>>) {
    run_with_reset(link, strict, calls, None).0
}

/// [`run`] with a reset fault (`Chip::fault_reset`) before timer call `reset_at`; also returns
/// the call at which each reading was taken.
fn run_with_reset(
    link: Link,
    strict: bool,
    calls: u64,
    reset_at: Option<u64>,
) -> ((ArduPilot, Vec<Option<usize>>), Vec<u64>) {
    const T_CFG: u64 = MS;
    let mut mag = Rm3100::new();
    mag.set_strict_cmm(strict);
    mag.advance(T_CFG);
    let mut ap = ArduPilot::probe(&mut mag, link).expect("probe");
    // 3 axes at 200 counts (6.85 ms) are slower than TMRC 0x94 (6.67 ms): back to back.
    let period = continuous_period_ns(0x94, 0b111, [200; 3]);
    assert_eq!(period, MEAS_3X200);
    let mut bench = Bench::new(T_CFG, period, T_CFG + calls * TIMER_NS);
    let (mut expected, mut at) = (Vec::new(), Vec::new());
    for j in 1..=calls {
        let t = T_CFG + j * TIMER_NS;
        if reset_at == Some(j) {
            assert!(margemu_firmware::chip::Chip::fault_reset(&mut mag));
        }
        bench.run_to(&mut mag, t);
        // Sequence k completes at T_CFG + (k + 1) · period.
        expected.push(((t - T_CFG) / period).checked_sub(1).map(|k| k as usize));
        let before = ap.readings.len();
        ap.timer(&mut mag);
        at.extend((before..ap.readings.len()).map(|_| j));
    }
    ((ap, expected), at)
}

#[test]
fn every_reading_is_the_latest_sample_in_order() {
    for link in [Link::I2c(ADDRESS), Link::Spi] {
        let (ap, expected) = run(link, false, 200);
        let fields = samples(400);
        assert_eq!(
            ap.readings.len(),
            200,
            "{link:?}: DRDY at every 12.5 ms call"
        );
        let mut last = None;
        for (i, (raw, k)) in ap.readings.iter().zip(&expected).enumerate() {
            let k = k.expect("a sequence completed before every call");
            assert!(last < Some(k), "{link:?} call {i}: in order");
            last = Some(k);
            assert_sample(*raw, &fields, k, format!("{link:?} call {i}"));
        }
        assert_eq!(ap.rewrites, 0, "{link:?}: every checked register read back");
    }
}

#[test]
fn the_register_check_visits_all_eight_registers() {
    // 200 calls: 20 checks, every register read at least twice, none rewritten.
    let (ap, _) = run(Link::I2c(ADDRESS), false, 200);
    assert_eq!((ap.next, ap.counter, ap.rewrites), (20 % 8, 0, 0));
}

#[test]
fn if_reading_cmm_ended_continuous_mode_ardupilot_would_lose_most_data() {
    // The DS note (reading CMM ends continuous mode): the check reads CMM at call 20 and stops
    // the chip without noticing (0x71 was read); 80 calls later it reads 0x70, rewrites CMM
    // and reads CMM again 10 calls after that, stopping it once more.
    let (ap, _) = run(Link::I2c(ADDRESS), true, 400);
    assert_eq!(ap.rewrites, 4, "one CMM rewrite per round of checks");
    // Calls 1–20, then 10 calls after each rewrite.
    assert_eq!(ap.readings.len(), 60);
}

#[test]
fn a_chip_with_other_cycle_counts_is_not_probed() {
    let mut mag = Rm3100::new();
    write(&mut mag, Link::I2c(ADDRESS), 0x08, &[0x00, 0x64]);
    assert!(ArduPilot::probe(&mut mag, Link::I2c(ADDRESS)).is_none());
    let mut other = Rm3100::with_pins(true, false);
    assert_eq!(
        i2c_read(&mut other, ADDRESS, 0x04, 1),
        None,
        "0x21 does not answer 0x20"
    );
}

/// A reset mid-run (the chip idle at its power-on values: CMM 0, TMRC 0x96) stops the data;
/// ArduPilot's register check finds TMRC and CMM changed and writes them back, which restarts
/// continuous mode: the readings resume, in order and exact, without a re-probe.
#[test]
fn the_register_check_notices_a_reset_and_its_rewrite_of_cmm_restarts_the_data() {
    let ((clean, _), _) = run_with_reset(Link::I2c(ADDRESS), false, 200, None);
    assert_eq!(clean.rewrites, 0);
    let ((ap, expected), at) = run_with_reset(Link::I2c(ADDRESS), false, 200, Some(55));
    assert_eq!(ap.rewrites, 2, "TMRC and CMM written back");
    let fields = samples(400);
    assert_eq!(
        ap.readings[..54],
        clean.readings[..54],
        "exact before the reset"
    );
    let gap: Vec<u64> = at
        .windows(2)
        .filter(|w| w[1] - w[0] > 1)
        .map(|w| w[0])
        .collect();
    assert_eq!(gap, [54], "one gap, from the reset to the CMM rewrite");
    let resumed = *at.iter().find(|&&j| j > 55).unwrap();
    // Continuous mode restarts at the rewrite, on its own schedule: each reading after it is
    // exactly one of the samples (within one LSB), newer than the last, and none latched after
    // the call (the bench latches sample `e + 1` at the instant sequence `e` completes).
    let mut last = 0;
    for (raw, &j) in ap.readings.iter().zip(&at).filter(|(_, &j)| j >= resumed) {
        let k = fields
            .iter()
            .position(|f| within_one_lsb(*raw, *f, [200; 3]))
            .expect("a latched sample");
        let latched = expected[(j - 1) as usize].map_or(0, |e| e + 1);
        assert!(k > last && k <= latched, "call {j}: sample {k}");
        last = k;
    }
    assert!(
        resumed <= 55 + 8 * 10 + 10,
        "within one round of checks: call {resumed}"
    );
}
