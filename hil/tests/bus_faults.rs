//! Bus faults on the host's virtual buses (`margemu_hil::bus` through
//! `margemu_firmware::bus_fault`): the served bytes inside each window are what the fault
//! defines, and exact outside every window.
//!
//! - `nak`: the `ist8310` crate (unmodified, as in `driver_ist8310.rs`) gets NoAcknowledge of
//!   the address for every call inside the window and the exact fields outside it; on SPI the
//!   ICM-42688-P is a dead chip (MISO `0xFF`, writes lost).
//! - `corrupt`: one bit per hit, from the fault's stream, through `SpiBus` + `ChipSelect`.
//! - `clock_stretch`: the crate's read of six bytes advances the clock by 6 × the stretch; a
//!   controller with a timeout fails the transaction at it; on SPI nothing happens.
//! - On a shared `I2cBus`, a chip's faults silence or stretch that chip only.

mod mag_support;

use embedded_hal::digital::OutputPin;
use embedded_hal::i2c::{Error as _, ErrorKind, NoAcknowledgeSource};
use embedded_hal::spi::{SpiBus as _, SpiDevice as _};
use embedded_hal_compat::ReverseCompat;
use ist8310::{Error, IST8310};
use mag_support::{assert_within_one_lsb, fields_inside, Bench, MS};
use margemu_firmware::bus_fault::{BusFaults, RELEASED};
use margemu_firmware::chip::{Chip, Icm42688p, Ist8310};
use margemu_firmware::fault::FaultSchedule;
use margemu_hil::bus::{self, I2c, I2cError, SpiBus, SpiDevice};
use margemu_model::fault::{Fault, FaultKind, Window, UNTIL_END};
use margemu_model::rng::unit_f64;

const SEED: u64 = 42;
/// The application's read period of the compass (a 50 Hz loop).
const PERIOD_NS: u64 = 20 * MS;
const LSB_PER_UT: f32 = 1.0 / 0.3;
const MAX_RAW: [i16; 3] = [5333, 5333, 8333];
const ADDRESS_NACK: ErrorKind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);

fn faults(device: u8, windows: &[(u64, u64, FaultKind)]) -> (FaultSchedule, BusFaults) {
    let mut s = FaultSchedule::new();
    for &(start, end, kind) in windows {
        s.push(Fault::new(device, Window::new(start, end), kind), SEED)
            .unwrap();
    }
    let bus = BusFaults::for_device(&s, device);
    (s, bus)
}

#[test]
fn the_ist8310_crate_gets_no_acknowledge_inside_a_nak_window_and_exact_fields_outside() {
    // Calls 10..15 fall in the window.
    let window = (10 * PERIOD_NS, 15 * PERIOD_NS, FaultKind::Nak);
    let (_, nak) = faults(0, &[window]);
    let bench = Bench::new(bus::shared(Ist8310::new()));
    let i2c = I2c::new(bench.chip.clone()).with_faults(nak);
    let mut driver = IST8310::default(i2c.reverse()).unwrap();
    let mut delay = bench.delay();
    let fields = fields_inside([1600.0, 1600.0, 2500.0], 0.3);
    // The crate reads the measurement the previous successful call started (driver_ist8310.rs):
    // after the window, that is the one started before it.
    let mut started: Option<[f32; 3]> = None;
    let (mut nacked, mut exact) = (0, 0);
    for (k, &field) in fields.iter().cycle().take(30).enumerate() {
        let start = k as u64 * PERIOD_NS;
        bench.latch(start, field);
        let result = driver.get_mag_vector(&mut delay);
        if (10..15).contains(&k) {
            let Err(Error::Comm(err)) = result else {
                panic!("call {k} inside the window: {result:?}")
            };
            assert_eq!(
                (err, err.kind()),
                (I2cError::AddressNack(0x0E), ADDRESS_NACK)
            );
            assert_eq!(
                bench.clock.now_ns(),
                start,
                "the crate gave up before its wait"
            );
            nacked += 1;
            continue;
        }
        let got = result.unwrap();
        match started {
            None => assert_eq!(got, [0; 3]),
            Some(f) => assert_within_one_lsb(k, got, f, LSB_PER_UT, MAX_RAW),
        }
        started = Some(field);
        exact += 1;
    }
    assert_eq!((nacked, exact), (5, 25));
}

#[test]
fn clock_stretch_advances_the_clock_by_the_stretch_of_each_byte_read() {
    let stretch_ns = 40_000;
    let window = (
        2 * PERIOD_NS,
        UNTIL_END,
        FaultKind::ClockStretch { stretch_ns },
    );
    let (_, stretch) = faults(0, &[window]);
    let bench = Bench::new(bus::shared(Ist8310::new()));
    let i2c = I2c::new(bench.chip.clone())
        .with_faults(stretch)
        .with_clock(bench.clock.clone());
    let mut driver = IST8310::default(i2c.reverse()).unwrap();
    let mut delay = bench.delay();
    for k in 0..6u64 {
        let start = k * PERIOD_NS;
        bench.latch(start, [10.0, -20.0, 30.0]);
        driver.get_mag_vector(&mut delay).unwrap();
        // CNTL1 written (no byte driven by the chip), 6 ms, then six data bytes read.
        let stretched = if k >= 2 { 6 * u64::from(stretch_ns) } else { 0 };
        assert_eq!(bench.clock.now_ns(), start + 6 * MS + stretched, "call {k}");
    }
}

#[test]
fn a_controller_with_a_timeout_gives_up_on_a_long_stretch() {
    // 5 ms per byte: the six data bytes would hold the bus 30 ms, past SMBus's 25 ms.
    let window = (
        0,
        UNTIL_END,
        FaultKind::ClockStretch {
            stretch_ns: 5_000_000,
        },
    );
    let bench = Bench::new(bus::shared(Ist8310::new()));
    // The crate's initialisation reads WAI (one byte, 5 ms): within the timeout.
    let (_, stretch) = faults(0, &[window]);
    let i2c = I2c::new(bench.chip.clone())
        .with_faults(stretch)
        .with_clock(bench.clock.clone())
        .with_timeout_ns(25 * MS);
    let mut driver = IST8310::default(i2c.reverse()).unwrap();
    assert_eq!(bench.clock.now_ns(), 5 * MS);
    let mut delay = bench.delay();
    let Err(Error::Comm(err)) = driver.get_mag_vector(&mut delay) else {
        panic!("the read outlasted the timeout")
    };
    let timeout = I2cError::Timeout {
        address: 0x0E,
        timeout_ns: 25 * MS,
    };
    assert_eq!((err, err.kind()), (timeout, ErrorKind::Other));
    // It waited 6 ms, then exactly the timeout, not the 30 ms the chip would have held it.
    assert_eq!(bench.clock.now_ns(), 5 * MS + 6 * MS + 25 * MS);
}

/// Moves the chip's scene clock to `t_ns`.
fn at(chip: &bus::Shared<Icm42688p>, t_ns: u64) {
    Chip::advance(&mut *chip.borrow_mut(), t_ns);
}

/// Reads `n` registers of the ICM-42688-P from `reg` in one transaction.
fn read(spi: &mut SpiDevice<Icm42688p>, reg: u8, n: usize) -> Vec<u8> {
    let mut buf = vec![0; n + 1];
    buf[0] = reg | 0x80;
    spi.transfer_in_place(&mut buf).unwrap();
    buf.split_off(1)
}

#[test]
fn nak_on_spi_is_a_dead_chip_reading_0xff() {
    let chip = bus::shared(Icm42688p::new());
    let (_, nak) = faults(0, &[(1_000, 2_000, FaultKind::Nak)]);
    let mut spi = SpiDevice::new(chip.clone()).with_faults(nak);
    assert_eq!(
        read(&mut spi, 0x75, 1),
        [0x47],
        "WHO_AM_I before the window"
    );
    at(&chip, 1_000);
    assert_eq!(read(&mut spi, 0x75, 3), [RELEASED; 3]);
    spi.write(&[0x4E, 0x0F]).unwrap(); // PWR_MGMT0: lost
    assert_eq!(chip.borrow().peek(0, 0x4E), 0x00);
    at(&chip, 2_000);
    assert_eq!(read(&mut spi, 0x75, 1), [0x47], "WHO_AM_I after the window");
}

#[test]
fn clock_stretch_on_spi_does_nothing() {
    let chip = bus::shared(Icm42688p::new());
    let twin = bus::shared(Icm42688p::new());
    let kind = FaultKind::ClockStretch {
        stretch_ns: 1_000_000,
    };
    let (_, stretch) = faults(0, &[(0, UNTIL_END, kind)]);
    let clock = bus::Clock::new();
    let mut spi = SpiDevice::new(chip)
        .with_faults(stretch)
        .with_clock(clock.clone());
    let mut clean = SpiDevice::new(twin);
    assert_eq!(read(&mut spi, 0x00, 0x80), read(&mut clean, 0x00, 0x80));
    assert_eq!(clock.now_ns(), 0);
}

#[test]
fn corrupt_through_spi_bus_and_chip_select_flips_the_streams_bits() {
    let chip = bus::shared(Icm42688p::new());
    let twin = bus::shared(Icm42688p::new());
    let (s, corrupt) = faults(0, &[(500, 600, FaultKind::Corrupt { probability: 0.25 })]);
    let (mut spi, mut cs) = SpiBus::new(chip.clone());
    spi.faults().set(corrupt);
    let mut clean = SpiDevice::new(twin);
    let mut rng = s.iter().next().unwrap().rng();
    let selection = |cs: &mut bus::ChipSelect<Icm42688p>, spi: &mut SpiBus<Icm42688p>| {
        let mut buf = [0u8; 0x21];
        buf[0] = 0x80; // bank 0 from 0x00, split over two bus calls
        cs.set_low().unwrap();
        spi.transfer_in_place(&mut buf[..5]).unwrap();
        spi.transfer_in_place(&mut buf[5..]).unwrap();
        cs.set_high().unwrap();
        buf
    };
    let want = {
        let mut buf = [0u8; 0x21];
        buf[0] = 0x80;
        clean.transfer_in_place(&mut buf).unwrap();
        buf
    };
    assert_eq!(
        selection(&mut cs, &mut spi),
        want,
        "before the window: exact"
    );
    at(&chip, 500);
    let got = selection(&mut cs, &mut spi);
    // The chip prepares a MISO byte at select and after each of the 33 bytes: 34 draws' worth,
    // of which the controller clocks the first 33.
    let mut hits = 0;
    for (i, (&g, &w)) in got.iter().zip(&want).enumerate() {
        let expected = if unit_f64(&mut rng) < 0.25 {
            hits += 1;
            w ^ 1 << (unit_f64(&mut rng) * 8.0) as u32
        } else {
            w
        };
        assert_eq!(g, expected, "byte {i}");
    }
    assert!(hits > 0);
    at(&chip, 600);
    assert_eq!(
        selection(&mut cs, &mut spi),
        want,
        "after the window: exact"
    );
}

#[test]
fn a_nak_window_on_a_shared_i2c_bus_silences_only_its_device() {
    use embedded_hal::i2c::I2c as _;
    use margemu_firmware::chip::Qmc5883l;
    use margemu_hil::bus::I2cBus;
    let ist8310 = bus::shared(Ist8310::new());
    let qmc5883l = bus::shared(Qmc5883l::new());
    // The IST8310 is the rig's device 1, with a nak window; the QMC5883L has no faults.
    let (s, faults) = faults(1, &[(1_000, 2_000, FaultKind::Nak)]);
    let wires = I2cBus::new()
        .with_shared_faulted(ist8310.clone(), faults)
        .with_shared(qmc5883l.clone());
    let mut i2c = I2c::new(bus::shared(wires));
    let mut id = [0u8; 1];
    let mut ids = |i2c: &mut I2c<I2cBus>| {
        let ist = i2c.write_read(0x0E, &[0x00], &mut id).map(|()| id[0]);
        let qmc = i2c.write_read(0x0D, &[0x0D], &mut id).map(|()| id[0]);
        (ist, qmc)
    };
    assert_eq!(ids(&mut i2c), (Ok(0x10), Ok(0xFF)));
    Chip::advance(&mut *ist8310.borrow_mut(), 1_000);
    assert_eq!(ids(&mut i2c), (Err(I2cError::AddressNack(0x0E)), Ok(0xFF)));
    Chip::advance(&mut *ist8310.borrow_mut(), 2_000);
    assert_eq!(ids(&mut i2c), (Ok(0x10), Ok(0xFF)));
    // The schedule can be given again (a new Configure): same faults, same answers.
    i2c.target().borrow_mut().sync_faults(&s);
    assert_eq!(ids(&mut i2c), (Ok(0x10), Ok(0xFF)));
    assert_eq!(i2c.target().borrow().stretched_ns(), 0);
}

#[test]
fn clock_stretch_of_a_target_on_a_shared_bus_is_counted_by_the_bus() {
    use embedded_hal::i2c::I2c as _;
    use margemu_hil::bus::I2cBus;
    let ist8310 = bus::shared(Ist8310::new());
    let kind = FaultKind::ClockStretch { stretch_ns: 3_000 };
    let (_, faults) = faults(0, &[(0, UNTIL_END, kind)]);
    let wires = I2cBus::new().with_shared_faulted(ist8310, faults);
    let mut i2c = I2c::new(bus::shared(wires));
    let mut data = [0u8; 6];
    i2c.write_read(0x0E, &[0x03], &mut data).unwrap();
    assert_eq!(i2c.target().borrow().stretched_ns(), 6 * 3_000);
}
