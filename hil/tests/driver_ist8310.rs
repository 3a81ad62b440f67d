//! The `ist8310` crate (0.1.1, BSD-3-Clause, on embedded-hal 0.2 through
//! `embedded-hal-compat`), unmodified, drives the emulated IST8310 over I2C (`bus::I2c`).
//!
//! What the crate does (read in `ist8310-0.1.1/src/lib.rs`, not its docs):
//! - `IST8310::new(i2c, address)` (`default` is 0x0E): writes CNTL2 = 0x01 (soft reset), then at
//!   once AVGCNTL = 0x24 (16 times averaging on every axis) and PDCNTL = 0xC0, then reads WAI
//!   and wants 0x10 (`UnknownChipId` otherwise). It neither waits after the reset nor polls
//!   CNTL2.SRST as ArduPilot does; margemu's reset completes at once, so the writes that follow
//!   land.
//! - `get_mag_vector(delay)`: writes CNTL1 = 0x01 (one single measurement), waits
//!   `delay_ms(6)`, then reads the six data bytes from 0x03 in one write-read (x, y, z, little
//!   endian). It never reads STAT1.DRDY. It returns `OutOfRange` when |x| or |y| exceeds 5333 or
//!   |z| 8333; the chip clips its output exactly there (±1600 µT and ±2500 µT at 0.3 µT/LSB), so
//!   that never happens with a datasheet chip and fields beyond the range read clipped.
//! - The chip has one range; the crate sets no other.
//!
//! **The crate reads one measurement late.** With 16 times averaging a measurement takes
//! 1 / 166 Hz ≈ 6.02 ms (datasheet AVGCNTL: "ODRmax = 166 Hz"; margemu rounds it to 6.1 ms,
//! `margemu_protocol::regmap::ist8310::MEASUREMENT_16X_NS`), longer than the 6 ms the crate
//! waits, and the crate does not look at DRDY: it reads the data registers while the new
//! measurement is still running, so it gets the previous one (zeros, the reset value, on the
//! first call). On a real board the read's own bus time (≥ 0.2 ms for the write-read at
//! 100 kHz) usually makes up the difference; margemu's bus adapters take no time, so the test
//! shows the late reading, checks that DRDY is still clear when the crate returns, and that
//! the chip completes the measurement 6.1 ms after the crate started it. The chip is not bent
//! to the crate.
//!
//! Every reading is checked in order, each axis within one LSB (0.3 µT) of the field latched
//! before the previous call, clipped at the chip's range.

mod mag_support;

use embedded_hal::i2c::{Error as _, ErrorKind, I2c as _, NoAcknowledgeSource};
use embedded_hal_compat::{Reverse, ReverseCompat};
use ist8310::{Error, IST8310};
use mag_support::{assert_within_one_lsb, fields_beyond, fields_inside, Bench, MS};
use margemu_firmware::chip::Ist8310 as Chip;
use margemu_hil::bus::{self, I2c, I2cError};

/// The chip's sensitivity, LSB per µT (datasheet: 0.3 µT/LSB).
const LSB_PER_UT: f32 = 1.0 / 0.3;
/// Where the chip clips x, y, z: the range (±1600, ±1600, ±2500 µT) in LSB.
const MAX_RAW: [i16; 3] = [5333, 5333, 8333];
const FULL_SCALE_UT: [f32; 3] = [1600.0, 1600.0, 2500.0];
/// The application's read period (a 50 Hz loop).
const PERIOD_NS: u64 = 20 * MS;
/// When the chip completes a measurement with 16 times averaging.
const MEASUREMENT_NS: u64 = 6_100_000;

type Driver = IST8310<Reverse<I2c<Chip>>>;

/// A fresh chip and the crate's driver on it at 0x0E, initialised.
fn init() -> (Bench<Chip>, Driver) {
    let bench = Bench::new(bus::shared(Chip::new()));
    let driver = IST8310::default(I2c::new(bench.chip.clone()).reverse()).unwrap();
    (bench, driver)
}

#[test]
fn initialisation_resets_and_configures_the_chip() {
    let chip = bus::shared(Chip::new());
    // Something for the soft reset to clear: CNTL2.DREN, a measurement started.
    let mut raw = I2c::new(chip.clone());
    raw.write(0x0E, &[0x0B, 0x08]).unwrap();
    raw.write(0x0E, &[0x0A, 0x01]).unwrap();
    let _driver = IST8310::default(I2c::new(chip.clone()).reverse()).unwrap();
    let chip = chip.borrow();
    let registers = [0x0A, 0x0B, 0x41, 0x42].map(|a| chip.peek(a));
    assert_eq!(
        registers,
        [0x00, 0x00, 0x24, 0xC0],
        "CNTL1, CNTL2, AVGCNTL, PDCNTL"
    );
}

#[test]
fn every_sample_arrives_one_measurement_late() {
    let (bench, mut driver) = init();
    let mut delay = bench.delay();
    let mut fields = fields_inside(FULL_SCALE_UT, 0.3);
    fields.extend(fields_beyond(FULL_SCALE_UT));
    let mut previous: Option<[f32; 3]> = None;
    for (k, &field) in fields.iter().chain([[0.0; 3]].iter()).enumerate() {
        let start = k as u64 * PERIOD_NS;
        bench.latch(start, field);
        let got = driver.get_mag_vector(&mut delay).unwrap();
        assert_eq!(bench.clock.now_ns(), start + 6 * MS, "the crate waits 6 ms");
        match previous {
            None => assert_eq!(got, [0; 3], "first call: the reset value"),
            Some(p) => assert_within_one_lsb(k, got, p, LSB_PER_UT, MAX_RAW),
        }
        // The measurement the crate started is still running: no DRDY, CNTL1 still single.
        assert_eq!(
            [0x02, 0x0A].map(|a| bench.chip.borrow().peek(a)),
            [0x00, 0x01]
        );
        bench.run_to(start + MEASUREMENT_NS);
        assert_eq!(
            bench.chip.borrow().peek(0x02),
            0x01,
            "DRDY 6.1 ms after CNTL1"
        );
        previous = Some(field);
    }
}

#[test]
fn an_absent_address_is_a_nack() {
    let chip = bus::shared(Chip::new());
    let result = IST8310::new(I2c::new(chip.clone()).reverse(), ist8310::ADDR_0_0_7BIT);
    let Err(Error::Comm(err)) = result else {
        panic!("IST8310 found at 0x0C")
    };
    assert_eq!(err, I2cError::AddressNack(0x0C));
    let kind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
    assert_eq!(err.kind(), kind);
    assert_eq!(chip.borrow().peek(0x41), 0x00, "nothing written");
}
