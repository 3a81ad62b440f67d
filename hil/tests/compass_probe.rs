//! ArduPilot's probe of external I2C compasses, run on an [`I2cBus`] holding an emulated
//! IST8310 at 0x0E and an emulated QMC5883L at 0x0D: the probe finds exactly those two, with
//! the right identities, and every other address it tries is NACKed at the address
//! (embedded-hal `NoAcknowledge(Address)`), without a panic.
//!
//! The probe is described here from ArduPilot's sources, not copied:
//! `libraries/AP_Compass/AP_Compass.cpp`: `Compass::_probe_external_i2c_compasses` (run by
//! `_detect_backends` on boards that ask for external probing, `AP_COMPASS_PROBING_ENABLED`,
//! and by `probe_i2c_spi_compasses` on the auto-detected Pixhawk-family boards) tries the
//! drivers below in this order on each external bus, at these addresses, and each driver's
//! `probe`/`init` (`AP_Compass_<chip>.cpp`, addresses from the headers) first makes the
//! identity transactions listed in [`DRIVERS`]; a driver that recognises its chip goes on to set
//! it up. An address where a compass is already registered is not probed again
//! (`GET_I2C_DEVICE` gives the driver no device when `_i2c_sensor_is_registered`), so once the
//! QMC5883L is found the IST8310 probe leaves 0x0D alone. Register reads are ArduPilot's
//! `read_registers`: the register written, then a repeated START reading.
//!
//! Simplifications, none of which changes what an absent address answers: ArduPilot's HAL
//! retries a failed transfer (`set_retries(10)` during probing) and some drivers have their own
//! retry loops (BMM150 4, BMM350 5 boot attempts, MMC5983 10 reads of its product ID); here a
//! driver repeats its identity transactions `attempts` times and the HAL retries are not
//! repeated. Internal-bus probing (`AP_COMPASS_INTERNAL_BUS_PROBING_ENABLED`) and the board
//! types that skip a driver are left out; the LIS2MDL's external probe is behind
//! `AP_COMPASS_LIS2MDL_EXTERNAL_BUS_PROBING_ENABLED` and is included. No time passes during the
//! probe (its only delays follow a match, while the IST8310 resets).

use embedded_hal::i2c::{Error as _, ErrorKind, I2c as _, NoAcknowledgeSource};
use margemu_firmware::chip::{Ist8310, Qmc5883l};
use margemu_hil::bus::{self, I2c, I2cBus, Shared};

/// One transaction of a driver's probe.
#[derive(Clone, Copy)]
enum Step {
    /// Reads `len` bytes from register `reg`; the probe goes on only if `check` accepts them.
    Read {
        reg: u8,
        len: usize,
        check: fn(&[u8]) -> bool,
    },
    /// A read whose outcome, even a NACK, the driver ignores.
    Dummy { reg: u8 },
    /// Writes `value` to register `reg`; a NACK ends the attempt.
    Write { reg: u8, value: u8 },
}

use Step::{Dummy, Read, Write};

/// Reads `len` bytes from `reg`, checked by `check`.
const fn read(reg: u8, len: usize, check: fn(&[u8]) -> bool) -> Step {
    Read { reg, len, check }
}

/// Writes `value` to `reg`.
const fn write(reg: u8, value: u8) -> Step {
    Write { reg, value }
}

/// A driver's probe: where it looks and how it recognises its chip.
struct Driver {
    name: &'static str,
    addresses: &'static [u8],
    /// Runs of `identity` before the driver gives up.
    attempts: usize,
    identity: &'static [Step],
    /// What the driver writes and checks once it has recognised its chip.
    setup: &'static [Step],
}

const fn probe(name: &'static str, addresses: &'static [u8], identity: &'static [Step]) -> Driver {
    Driver {
        name,
        addresses,
        attempts: 1,
        identity,
        setup: &[],
    }
}

/// ArduPilot's external-bus probes, in order.
const DRIVERS: [Driver; 15] = [
    // ID registers A..C (0x0A..0x0C) read "H43".
    probe("HMC5843", &[0x1E], &[read(0x0A, 3, |b| b == b"H43")]),
    // A dummy read of 0x00, then 0x0C = 0x01 and CHIP_ID (0x0D) = 0xFF; then the SET/RESET
    // period, two undocumented registers and CONF1 = continuous, 100 Hz, OSR 512, 8 G.
    Driver {
        setup: &[
            write(0x0B, 0x01),
            write(0x20, 0x40),
            write(0x21, 0x01),
            write(0x09, 0x19),
        ],
        ..probe(
            "QMC5883L",
            &[0x0D],
            &[
                Dummy { reg: 0x00 },
                read(0x0C, 1, |b| b == [0x01]),
                read(0x0D, 1, |b| b == [0xFF]),
            ],
        )
    },
    probe("QMC5883P", &[0x2C], &[read(0x00, 1, |b| b == [0x80])]),
    probe("IIS2MDC", &[0x1E], &[read(0x4F, 1, |b| b == [0x40])]),
    // The AK09916 inside an ICM-20948: the ICM's WHO_AM_I (0xEA) at 0x69, then 0x68, first.
    probe("ICM20948", &[0x69, 0x68], &[read(0x00, 1, |b| b == [0xEA])]),
    probe("LIS3MDL", &[0x1C, 0x1E], &[read(0x0F, 1, |b| b == [0x3D])]),
    probe("LIS2MDL", &[0x1E], &[read(0x4F, 1, |b| b == [0x40])]),
    // Soft reset (CNTL3 = 0x01) first, then WIA2 (0x01) = 0x09.
    probe(
        "AK09916",
        &[0x0C],
        &[write(0x32, 0x01), read(0x01, 1, |b| b == [0x09])],
    ),
    // WAI (0x00) = 0x10 at all four strap addresses; then soft reset, SRST reads 0 again,
    // AVGCNTL = 16 times, PDCNTL = normal pulse, and the first single measurement.
    Driver {
        setup: &[
            write(0x0B, 0x01),
            read(0x0B, 1, |b| b[0] & 0x01 == 0),
            write(0x41, 0x24),
            write(0x42, 0xC0),
            write(0x0A, 0x01),
        ],
        ..probe(
            "IST8310",
            &[0x0C, 0x0D, 0x0E, 0x0F],
            &[read(0x00, 1, |b| b == [0x10])],
        )
    },
    probe("IST8308", &[0x0C], &[read(0x00, 1, |b| b == [0x08])]),
    probe("MMC3416", &[0x30], &[read(0x20, 1, |b| b == [0x06])]),
    Driver {
        attempts: 10,
        ..probe("MMC5983", &[0x30], &[read(0x2F, 1, |b| b == [0x30])])
    },
    // The cycle-count registers 0x04..0x09 at their defaults (0x00C8 per axis), one by one.
    probe(
        "RM3100",
        &[0x20, 0x21, 0x22, 0x23],
        &[
            read(0x04, 1, |b| b == [0x00]),
            read(0x05, 1, |b| b == [0xC8]),
            read(0x06, 1, |b| b == [0x00]),
            read(0x07, 1, |b| b == [0xC8]),
            read(0x08, 1, |b| b == [0x00]),
            read(0x09, 1, |b| b == [0xC8]),
        ],
    ),
    // Soft reset, power control on, then CHIP_ID (0x40) = 0x32.
    Driver {
        attempts: 4,
        ..probe(
            "BMM150",
            &[0x10, 0x11, 0x12, 0x13],
            &[
                write(0x4B, 0x82),
                write(0x4B, 0x01),
                read(0x40, 1, |b| b == [0x32]),
            ],
        )
    },
    // Soft reset (CMD = 0xB6), then CHIP_ID (0x00) = 0x33 after two dummy bytes.
    Driver {
        attempts: 5,
        ..probe(
            "BMM350",
            &[0x14, 0x15, 0x16, 0x17],
            &[write(0x7E, 0xB6), read(0x00, 3, |b| b[2] == 0x33)],
        )
    },
];

/// How one driver's probe at one address ended.
#[derive(Clone, Debug, PartialEq)]
enum Outcome {
    Found,
    /// The chip answered, but not with the driver's identity (the bytes it read).
    Rejected(Vec<u8>),
    /// A transaction failed (its embedded-hal error kind).
    Failed(ErrorKind),
    /// Not probed: a compass found earlier holds the address.
    Skipped,
}

/// Runs `steps` at `address`: `Found` if every check passed.
fn run(i2c: &mut I2c<I2cBus>, address: u8, steps: &[Step]) -> Outcome {
    for step in steps {
        match *step {
            Read { reg, len, check } => {
                let mut buf = vec![0u8; len];
                if let Err(e) = i2c.write_read(address, &[reg], &mut buf) {
                    return Outcome::Failed(e.kind());
                }
                if !check(&buf) {
                    return Outcome::Rejected(buf);
                }
            }
            Dummy { reg } => drop(i2c.write_read(address, &[reg], &mut [0])),
            Write { reg, value } => {
                if let Err(e) = i2c.write(address, &[reg, value]) {
                    return Outcome::Failed(e.kind());
                }
            }
        }
    }
    Outcome::Found
}

/// ArduPilot's external probe on `i2c`: every (driver, address, outcome) in order.
fn probe_all(i2c: &mut I2c<I2cBus>) -> Vec<(&'static str, u8, Outcome)> {
    let mut tried = Vec::new();
    let mut registered = Vec::new();
    for driver in &DRIVERS {
        for &address in driver.addresses {
            let mut outcome = Outcome::Skipped;
            for _ in 0..driver.attempts {
                if registered.contains(&address) {
                    break;
                }
                outcome = run(i2c, address, driver.identity);
                if outcome == Outcome::Found {
                    assert_eq!(run(i2c, address, driver.setup), Outcome::Found);
                    registered.push(address);
                }
            }
            tried.push((driver.name, address, outcome));
        }
    }
    tried
}

const ADDRESS_NACK: Outcome =
    Outcome::Failed(ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address));

/// The two chips on one bus, the bench keeping a handle on each.
fn bench() -> (Shared<Ist8310>, Shared<Qmc5883l>, I2c<I2cBus>) {
    let ist8310 = bus::shared(Ist8310::new());
    let qmc5883l = bus::shared(Qmc5883l::new());
    let wires = I2cBus::new()
        .with_shared(ist8310.clone())
        .with_shared(qmc5883l.clone());
    (ist8310, qmc5883l, I2c::new(bus::shared(wires)))
}

#[test]
fn the_probe_tries_ardupilots_addresses() {
    let (_, _, mut i2c) = bench();
    let mut addresses: Vec<u8> = probe_all(&mut i2c).iter().map(|t| t.1).collect();
    addresses.sort_unstable();
    addresses.dedup();
    let mut expected: Vec<u8> = (0x0C..=0x17).collect();
    expected.extend([0x1C, 0x1E, 0x20, 0x21, 0x22, 0x23, 0x2C, 0x30, 0x68, 0x69]);
    assert_eq!(addresses, expected);
}

#[test]
fn the_probe_finds_the_ist8310_and_the_qmc5883l_and_nothing_else() {
    let (ist8310, qmc5883l, mut i2c) = bench();
    let tried = probe_all(&mut i2c);
    let found: Vec<_> = tried
        .iter()
        .filter(|t| t.2 == Outcome::Found)
        .map(|t| (t.0, t.1))
        .collect();
    assert_eq!(found, [("QMC5883L", 0x0D), ("IST8310", 0x0E)]);
    for (name, address, outcome) in &tried {
        match (*name, *address) {
            ("QMC5883L", 0x0D) | ("IST8310", 0x0E) => {}
            // The QMC5883L registered 0x0D: the IST8310 probe does not go there.
            ("IST8310", 0x0D) => assert_eq!(*outcome, Outcome::Skipped),
            _ => assert_eq!(*outcome, ADDRESS_NACK, "{name} at {address:#04x}"),
        }
    }
    // Each driver set its chip up.
    let qmc = qmc5883l.borrow();
    assert_eq!(
        [0x09, 0x0B, 0x20, 0x21].map(|a| qmc.peek(a)),
        [0x19, 0x01, 0x40, 0x01]
    );
    let ist = ist8310.borrow();
    assert_eq!([0x0A, 0x41, 0x42].map(|a| ist.peek(a)), [0x01, 0x24, 0xC0]);
    assert_eq!(i2c.target().borrow().missed_events(), 0);
}

#[test]
fn on_an_empty_bus_every_address_is_nacked() {
    let mut i2c = I2c::new(bus::shared(I2cBus::new()));
    let tried = probe_all(&mut i2c);
    assert_eq!(tried.len(), 29, "probes (driver, address)");
    for (name, address, outcome) in &tried {
        assert_eq!(*outcome, ADDRESS_NACK, "{name} at {address:#04x}");
    }
}

#[test]
fn without_the_qmc5883l_its_address_is_nacked_too() {
    let ist8310 = bus::shared(Ist8310::new());
    let mut i2c = I2c::new(bus::shared(I2cBus::new().with_shared(ist8310)));
    let tried = probe_all(&mut i2c);
    let at_0x0d: Vec<_> = tried.iter().filter(|t| t.1 == 0x0D).collect();
    assert_eq!(at_0x0d.len(), 2);
    assert!(at_0x0d.iter().all(|t| t.2 == ADDRESS_NACK));
    let found: Vec<_> = tried.iter().filter(|t| t.2 == Outcome::Found).collect();
    assert_eq!(found.len(), 1);
    assert_eq!((found[0].0, found[0].1), ("IST8310", 0x0E));
}
