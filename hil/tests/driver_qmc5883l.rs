//! The `qmc5883l` crate (0.0.1, AGPL-3.0-or-later: a test-only client, never linked into
//! anything margemu ships; on embedded-hal 0.2 through `embedded-hal-compat`), unmodified,
//! drives the emulated QMC5883L over I2C (`bus::I2c`).
//!
//! What the crate does (read in `qmc5883l-0.0.1/src/lib.rs`, not its docs):
//! - `QMC5883L::new(i2c)`: reads CHIP_ID (0x0D) and wants 0xFF (`InvalidDevice` otherwise),
//!   then soft-resets (CONF2 = 0x80), sets CONF2 = ROL_PNT | INT_ENB (0x41: pointer roll-over
//!   on, DRDY pin off) and the SET/RESET period (0x0B) = 0x01. Unlike ArduPilot it reads neither
//!   0x00 nor 0x0C first.
//! - `set_output_data_rate`, `set_oversample`, `set_field_range`, `continuous`, `standby`:
//!   read-modify-write of CONF1 (0x09), one field each.
//! - `mag()`: one write-read of 7 bytes from STATUS (0x06): STATUS, then the data from 0x00,
//!   which the chip's pointer roll-over (06H → 00H with ROL_PNT) provides. `NotReady` without
//!   DRDY, `Overflow` with OVL, else x, y, z (little endian). Reading the data registers clears
//!   DRDY, so a second `mag()` before the next measurement is `NotReady`.
//!
//! **The crate cannot set the 8 G range.** Its `FieldRange::Range8Gauss` is `1 << 3`, and its
//! `set_field_range` clears and sets that bit; the datasheet's RNG field is CONF1 bits 5:4 (8 G
//! = 01, i.e. `0x10`, as ArduPilot's `QMC5883L_RNG_8G` has it). Bit 3 is the high bit of ODR:
//! `set_field_range(Range8Gauss)` leaves the chip at ±2 G and turns 10 Hz into 100 Hz (50 Hz
//! into 200 Hz), and `set_output_data_rate` afterwards clears it again. So the 2 G range is
//! tested through the crate at every output rate, the crate's "8 G" is shown to be 2 G at
//! another rate (a 300 µT field overflows), and the real 8 G range is set behind the crate's
//! back (CONF1 RNG = 01 over the same bus) to check that `mag()` reads it right.
//!
//! Every sample is checked in order: each axis within one LSB of the latched field at the
//! range's sensitivity (2 G: 12000 LSB/G = 120 LSB/µT; 8 G: 3000 LSB/G = 30 LSB/µT), or
//! `Overflow` when an axis is beyond the range (the chip clips at ±24000 and sets OVL).
//! Not covered: `temp()` (TOUT is not emulated, it reads 0).

mod mag_support;

use embedded_hal::i2c::{Error as _, ErrorKind, I2c as _, NoAcknowledgeSource};
use embedded_hal_compat::{Reverse, ReverseCompat};
use mag_support::{assert_within_one_lsb, fields_beyond, fields_inside, Bench, MS};
use margemu_firmware::chip::Qmc5883l as Chip;
use margemu_hil::bus::{self, I2c, I2cBus, I2cError};
use margemu_protocol::regmap::qmc5883l::{Odr, Range};
use qmc5883l::{Error, FieldRange, OutputDataRate, OversampleRate, QMC5883L};

/// Where the chip clips, in LSB (both ranges).
const MAX_RAW: [i16; 3] = [24_000; 3];

type Driver = QMC5883L<Reverse<I2c<Chip>>>;

/// A fresh chip and the crate's driver on it (soft reset done).
fn init() -> (Bench<Chip>, Driver) {
    let bench = Bench::new(bus::shared(Chip::new()));
    let driver = QMC5883L::new(I2c::new(bench.chip.clone()).reverse()).unwrap();
    (bench, driver)
}

/// CONF1, CONF2 and the SET/RESET period as the chip holds them.
fn config(bench: &Bench<Chip>) -> [u8; 3] {
    [0x09, 0x0A, 0x0B].map(|a| bench.chip.borrow().peek(a))
}

/// The chip's range and output rate.
fn range_and_rate(bench: &Bench<Chip>) -> (Range, Odr) {
    let chip = bench.chip.borrow();
    (chip.range(), chip.odr())
}

/// Latches each field in the middle of a measurement period and reads it through the crate at
/// the period's end: `NotReady` just before, the sample (or `Overflow`) at the end, `NotReady`
/// again right after. Continuous mode was set at time 0: the first measurement completes one
/// period later.
fn replay(bench: &Bench<Chip>, driver: &mut Driver, fields: &[[f32; 3]], range: Range) {
    let period = bench.chip.borrow().odr().period_ns();
    let lsb_per_ut = range.lsb_per_ut();
    for (k, &field) in fields.iter().enumerate() {
        let end = (k as u64 + 1) * period;
        bench.latch(end - period / 2, field);
        bench.run_to(end - 1_000);
        assert!(
            matches!(driver.mag(), Err(Error::NotReady)),
            "sample {k} early"
        );
        bench.run_to(end);
        let overflow = field
            .iter()
            .any(|b| (b * lsb_per_ut).abs() >= f32::from(MAX_RAW[0]));
        match driver.mag() {
            Err(Error::Overflow) if overflow => {}
            Ok((x, y, z)) if !overflow => {
                assert_within_one_lsb(k, [x, y, z], field, lsb_per_ut, MAX_RAW)
            }
            other => panic!("sample {k}: {field:?} µT read as {other:?}"),
        }
        assert!(
            matches!(driver.mag(), Err(Error::NotReady)),
            "sample {k} twice"
        );
    }
}

/// Fields inside the range at `lsb_per_ut`, then beyond it.
fn fields(range: Range) -> Vec<[f32; 3]> {
    let full_scale = 24_000.0 / range.lsb_per_ut();
    let mut out = fields_inside([full_scale; 3], 1.0 / range.lsb_per_ut());
    out.extend(fields_beyond([full_scale; 3]));
    out
}

#[test]
fn initialisation_resets_and_the_setters_write_conf1() {
    let chip = bus::shared(Chip::new());
    let mut raw = I2c::new(chip.clone());
    raw.write(0x0D, &[0x09, 0x1D, 0x00, 0x07]).unwrap(); // CONF1, CONF2, PERIOD
    let bench = Bench::new(chip);
    let mut driver = QMC5883L::new(I2c::new(bench.chip.clone()).reverse()).unwrap();
    assert_eq!(config(&bench), [0x00, 0x41, 0x01]);
    driver
        .set_output_data_rate(OutputDataRate::Rate50Hz)
        .unwrap();
    driver.set_oversample(OversampleRate::Rate128).unwrap();
    driver.continuous().unwrap();
    assert_eq!(config(&bench)[0], 0x85, "OSR 128, 50 Hz, 2 G, continuous");
    driver.standby().unwrap();
    assert_eq!(config(&bench)[0], 0x84);
}

#[test]
fn two_gauss_at_every_output_rate() {
    let rates = [
        (OutputDataRate::Rate10Hz, Odr::Hz10),
        (OutputDataRate::Rate50Hz, Odr::Hz50),
        (OutputDataRate::Rate100Hz, Odr::Hz100),
        (OutputDataRate::Rate200Hz, Odr::Hz200),
    ];
    for (rate, odr) in rates {
        let (bench, mut driver) = init();
        driver.set_field_range(FieldRange::Range2Gauss).unwrap();
        driver.set_output_data_rate(rate).unwrap();
        driver.set_oversample(OversampleRate::Rate512).unwrap();
        driver.continuous().unwrap();
        assert_eq!(range_and_rate(&bench), (Range::Gauss2, odr));
        assert!(matches!(driver.mag(), Err(Error::NotReady)));
        replay(&bench, &mut driver, &fields(Range::Gauss2), Range::Gauss2);
    }
}

#[test]
fn the_crates_eight_gauss_sets_an_output_rate_bit_instead() {
    let (bench, mut driver) = init();
    driver
        .set_output_data_rate(OutputDataRate::Rate10Hz)
        .unwrap();
    driver.set_field_range(FieldRange::Range8Gauss).unwrap();
    driver.continuous().unwrap();
    assert_eq!(config(&bench)[0], 0x09);
    assert_eq!(
        range_and_rate(&bench),
        (Range::Gauss2, Odr::Hz100),
        "still 2 G, now 100 Hz"
    );
    // 300 µT fits 8 G but overflows the 2 G range the chip is in.
    let mut fields = fields(Range::Gauss2);
    fields.push([300.0, 0.0, 0.0]);
    replay(&bench, &mut driver, &fields, Range::Gauss2);
    // In the other order the rate setter clears the bit again: no effect at all.
    driver.set_field_range(FieldRange::Range8Gauss).unwrap();
    driver
        .set_output_data_rate(OutputDataRate::Rate10Hz)
        .unwrap();
    assert_eq!(config(&bench)[0], 0x01);
}

#[test]
fn eight_gauss_set_behind_the_crates_back_reads_right() {
    let (bench, mut driver) = init();
    driver
        .set_output_data_rate(OutputDataRate::Rate200Hz)
        .unwrap();
    driver.continuous().unwrap();
    // The datasheet's RNG = 01 over the same bus, keeping the rest of CONF1.
    let mut raw = I2c::new(bench.chip.clone());
    let mut conf1 = [0u8; 1];
    raw.write_read(0x0D, &[0x09], &mut conf1).unwrap();
    raw.write(0x0D, &[0x09, conf1[0] | 0x10]).unwrap();
    assert_eq!(range_and_rate(&bench), (Range::Gauss8, Odr::Hz200));
    replay(&bench, &mut driver, &fields(Range::Gauss8), Range::Gauss8);
}

#[test]
fn the_crate_on_a_shared_bus_and_at_an_absent_address() {
    // Alone on an I2C bus with no QMC5883L: the crate's first read is NACKed at the address.
    let empty = bus::shared(I2cBus::new());
    let Err(Error::BusError(err)) = QMC5883L::new(I2c::new(empty).reverse()) else {
        panic!("a QMC5883L on an empty bus")
    };
    assert_eq!(err, I2cError::AddressNack(0x0D));
    let kind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
    assert_eq!(err.kind(), kind);
    // Beside an IST8310 on one bus, the crate finds and reads its own chip.
    let chip = bus::shared(Chip::new());
    let ist8310 = bus::shared(margemu_firmware::chip::Ist8310::new());
    let wires = I2cBus::new()
        .with_shared(ist8310.clone())
        .with_shared(chip.clone());
    let mut driver = QMC5883L::new(I2c::new(bus::shared(wires)).reverse()).unwrap();
    driver.continuous().unwrap();
    chip.borrow_mut().advance(100 * MS, [10.0, -20.0, 30.0]);
    assert_eq!(driver.mag().unwrap(), (1200, -2400, 3600));
    assert_eq!(ist8310.borrow().pointer(), 0x00, "the IST8310 took no byte");
}
