use super::*;
use margemu_model::fault::{Fault, UNTIL_END};

const SEED: u64 = 0x5EED;
/// The byte the fake target drives.
const BYTE: u8 = 0x5A;

/// A target that drives [`BYTE`] and counts what reaches it.
#[derive(Default)]
struct Fake {
    events: usize,
}

impl SpiTarget for Fake {
    fn select(&mut self) -> u8 {
        self.events += 1;
        BYTE
    }
    fn exchange(&mut self, _: u8) -> u8 {
        self.events += 1;
        BYTE
    }
    fn deselect(&mut self) {
        self.events += 1;
    }
}

impl I2cTarget for Fake {
    fn start(&mut self, _: u8, _: bool) -> bool {
        self.events += 1;
        true
    }
    fn write(&mut self, _: u8) -> bool {
        self.events += 1;
        true
    }
    fn read(&mut self) -> u8 {
        self.events += 1;
        BYTE
    }
    fn stop(&mut self) {
        self.events += 1;
    }
}

fn schedule(faults: &[(u8, u64, u64, FaultKind)]) -> FaultSchedule {
    let mut s = FaultSchedule::new();
    for &(device, start, end, kind) in faults {
        s.push(Fault::new(device, Window::new(start, end), kind), SEED)
            .unwrap();
    }
    s
}

/// The module docs' rule, drawn from `rng`: what the controller receives for `byte`.
fn predicted(rng: &mut StreamRng, probability: f64, byte: u8) -> u8 {
    if unit_f64(rng) < probability {
        byte ^ 1 << (unit_f64(rng) * 8.0) as u32
    } else {
        byte
    }
}

#[test]
fn corrupt_flips_one_bit_per_hit_from_the_faults_stream() {
    let kind = FaultKind::Corrupt { probability: 0.3 };
    let s = schedule(&[(0, 100, 200, FaultKind::Nak), (0, 1_000, 2_000, kind)]);
    let mut faults = BusFaults::for_device(&s, 0);
    let mut fake = Fake::default();
    // Outside the window: exact, and no draw is made.
    for t in [0, 999, 2_000, UNTIL_END - 1] {
        let mut bus = faults.on(&mut fake, t);
        assert_eq!(SpiTarget::select(&mut bus), BYTE);
        assert_eq!(bus.exchange(0), BYTE);
        assert_eq!(I2cTarget::read(&mut bus), BYTE);
        SpiTarget::deselect(&mut bus);
    }
    let corrupt = s.iter().nth(1).unwrap();
    assert_eq!(corrupt.index, 1);
    let mut rng = corrupt.rng();
    let mut hits = 0;
    for i in 0..4_000u64 {
        let t = 1_000 + i / 4;
        let mut bus = faults.on(&mut fake, t);
        let got = if i % 2 == 0 {
            bus.exchange(0x00)
        } else {
            I2cTarget::read(&mut bus)
        };
        assert_eq!(got, predicted(&mut rng, 0.3, BYTE), "byte {i}");
        assert!((got ^ BYTE).count_ones() <= 1);
        hits += usize::from(got != BYTE);
    }
    // 30 % of 4000 bytes, within five standard deviations (29).
    assert!((1_055..=1_345).contains(&hits), "{hits}");
    // Every byte reached the target.
    assert_eq!(fake.events, 4 * 4 + 4_000);
}

#[test]
fn corrupt_at_probability_one_hits_every_bit_position() {
    let s = schedule(&[(2, 0, UNTIL_END, FaultKind::Corrupt { probability: 1.0 })]);
    let mut faults = BusFaults::for_device(&s, 2);
    let mut fake = Fake::default();
    let mut seen = 0u8;
    for _ in 0..200 {
        let flipped = faults.on(&mut fake, 5).exchange(0) ^ BYTE;
        assert_eq!(flipped.count_ones(), 1);
        seen |= flipped;
    }
    assert_eq!(seen, 0xFF);
}

#[test]
fn two_runs_corrupt_the_same_bytes() {
    let s = schedule(&[(0, 0, 1_000, FaultKind::Corrupt { probability: 0.5 })]);
    let run = || {
        let mut faults = BusFaults::for_device(&s, 0);
        let mut fake = Fake::default();
        (0..500)
            .map(|t| faults.on(&mut fake, t).exchange(0))
            .collect::<heapless::Vec<u8, 500>>()
    };
    assert_eq!(run(), run());
}

#[test]
fn nak_on_spi_is_a_dead_chip() {
    let s = schedule(&[(1, 10, 20, FaultKind::Nak)]);
    let mut faults = BusFaults::for_device(&s, 1);
    let mut fake = Fake::default();
    let mut bus = faults.on(&mut fake, 10);
    assert_eq!(bus.select(), RELEASED);
    assert_eq!([bus.exchange(0x80), bus.exchange(0)], [RELEASED; 2]);
    bus.deselect();
    assert_eq!(fake.events, 0, "the chip saw nothing");
    // After the window the chip answers again.
    let mut bus = faults.on(&mut fake, 20);
    assert_eq!(bus.select(), BYTE);
    bus.deselect();
    assert_eq!(fake.events, 2);
}

#[test]
fn nak_on_i2c_refuses_the_address_and_the_bytes() {
    let s = schedule(&[(0, 10, 20, FaultKind::Nak)]);
    let mut faults = BusFaults::for_device(&s, 0);
    let mut fake = Fake::default();
    // Pointer written before the window, then a repeated START inside it.
    assert!(faults.on(&mut fake, 9).start(0x0E, false));
    assert!(faults.on(&mut fake, 9).write(0x03));
    let mut bus = faults.on(&mut fake, 10);
    assert!(!bus.start(0x0E, true));
    assert_eq!(I2cTarget::read(&mut bus), RELEASED);
    assert!(!bus.write(0x00));
    bus.stop();
    assert_eq!(fake.events, 3, "START, the pointer and STOP");
    assert!(faults.on(&mut fake, 20).start(0x0E, false));
}

#[test]
fn clock_stretch_is_owed_per_byte_read_on_i2c_only() {
    let kind = FaultKind::ClockStretch { stretch_ns: 7_000 };
    let s = schedule(&[(0, 100, 200, kind)]);
    let mut faults = BusFaults::for_device(&s, 0);
    let mut fake = Fake::default();
    assert_eq!(faults.stretch_ns(150), 7_000);
    let mut bus = faults.on(&mut fake, 150);
    assert!(bus.start(0x0E, false));
    assert!(bus.write(0x03));
    assert!(bus.start(0x0E, true));
    for _ in 0..6 {
        assert_eq!(I2cTarget::read(&mut bus), BYTE);
    }
    bus.stop();
    assert_eq!(faults.take_stretch_ns(), 6 * 7_000);
    assert_eq!(faults.take_stretch_ns(), 0);
    // SPI: nothing.
    let mut bus = faults.on(&mut fake, 150);
    assert_eq!((bus.select(), bus.exchange(0)), (BYTE, BYTE));
    bus.deselect();
    assert_eq!(faults.take_stretch_ns(), 0);
    // Outside the window: nothing.
    assert_eq!(I2cTarget::read(&mut faults.on(&mut fake, 200)), BYTE);
    assert_eq!(faults.take_stretch_ns(), 0);
}

#[test]
fn a_new_run_of_the_same_schedule_draws_the_same_bits_again() {
    let s = schedule(&[(0, 0, 1_000, FaultKind::Corrupt { probability: 0.5 })]);
    let mut faults = BusFaults::for_device(&s, 0);
    let mut fake = Fake::default();
    let mut run = |faults: &mut BusFaults| {
        (0..300)
            .map(|t| faults.on(&mut fake, t).exchange(0))
            .collect::<heapless::Vec<u8, 300>>()
    };
    let first = run(&mut faults);
    // A new Configure with the same schedule: the same faults, time from 0 again.
    faults.sync(&s);
    assert_eq!(run(&mut faults), first);
    assert_ne!(first.iter().filter(|&&b| b != BYTE).count(), 0);
}

#[test]
fn sync_takes_new_faults_and_starts_over_after_a_clear() {
    let mut s = schedule(&[(0, 0, 10, FaultKind::Reset), (1, 0, 10, FaultKind::Nak)]);
    let mut faults = BusFaults::new(0);
    faults.sync(&s);
    assert!(faults.is_empty(), "a chip fault is not a bus fault");
    s.push(Fault::new(0, Window::new(5, 8), FaultKind::Nak), SEED)
        .unwrap();
    faults.sync(&s);
    assert!(faults.nak(5) && !faults.nak(8) && !faults.is_empty());
    s.clear();
    faults.sync(&s);
    assert!(faults.is_empty() && !faults.nak(5));
    // Cleared and refilled between two syncs (Configure and AddFault in one read).
    s.push(Fault::new(0, Window::new(20, 30), FaultKind::Nak), SEED)
        .unwrap();
    faults.sync(&s);
    s.clear();
    s.push(Fault::new(0, Window::new(40, 50), FaultKind::Nak), SEED)
        .unwrap();
    faults.sync(&s);
    assert!(!faults.nak(25) && faults.nak(45));
    assert_eq!(faults.device(), 0);
}

#[test]
fn preview_shows_the_flips_the_next_bytes_will_get() {
    let s = schedule(&[(0, 100, 10_000, FaultKind::Corrupt { probability: 0.3 })]);
    let mut faults = BusFaults::for_device(&s, 0);
    let mut fake = Fake::default();
    let mut ahead = [BYTE; 64];
    faults.preview(50, &mut ahead);
    assert_eq!(ahead, [BYTE; 64], "outside the window: nothing");
    for t in [100, 200, 9_000] {
        faults.preview(t, &mut ahead);
        let mut bus = faults.on(&mut fake, t);
        let mut got = [bus.select(); 64];
        for slot in got.iter_mut().skip(1) {
            *slot = bus.exchange(0);
        }
        bus.deselect();
        assert_eq!(got, ahead, "at {t}");
        assert_ne!(got, [BYTE; 64]);
        ahead = [BYTE; 64];
    }
}
