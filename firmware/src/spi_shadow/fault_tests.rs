//! The shadow with the chip's bus faults ([`Shadow::apply_bus_faults`]) and the replay through
//! the same faults: what a board served from the stream is what the host's bus would give.

use super::*;
use crate::chip::EmulatedChip;
use crate::fault::FaultSchedule;
use margemu_model::fault::{Fault, FaultKind, Window};

const T: u64 = 5_000_000;

fn faults(kind: FaultKind) -> BusFaults {
    let mut s = FaultSchedule::new();
    s.push(Fault::new(0, Window::new(T, 2 * T), kind), 3)
        .unwrap();
    BusFaults::for_device(&s, 0)
}

/// A chip at `T` and its shadow, predicted burst from ACCEL_XOUT_H, with `faults` applied.
fn shadow(chip: &mut EmulatedChip, faults: &BusFaults) -> Shadow {
    chip.advance(T);
    let mut shadow = Shadow::new();
    shadow.capture(chip, 0x3B, 0);
    shadow.apply_bus_faults(faults, chip.now_ns());
    shadow
}

/// A read of `n` bytes from the predicted start, served from the stream (no takeover).
fn streamed(shadow: &Shadow, n: usize) -> Capture {
    let mut mosi = [0u8; 32];
    mosi[0] = 0x80 | shadow.start();
    Capture::from_bytes(&mosi[..=n], &shadow.stream()[..=n], 0, None)
}

#[test]
fn a_nak_window_makes_the_shadow_a_dead_chip() {
    let mut chip = EmulatedChip::default();
    let mut faults = faults(FaultKind::Nak);
    let mut shadow = shadow(&mut chip, &faults);
    assert_eq!(shadow.read(0x75), RELEASED, "WHO_AM_I");
    assert!(shadow.stream().iter().all(|&b| b == RELEASED));
    let read = streamed(&shadow, 14);
    assert_eq!(replay(&mut faults.on(&mut chip, T), &read, 0), Outcome::Hit);
    // A write served meanwhile stores nothing, in the shadow or in the chip.
    let before = chip.spi_peek(0x6B);
    shadow.write_through(&[0x6B, 0x80]);
    assert_eq!(shadow.read(0x6B), RELEASED);
    let write = Capture::from_bytes(&[0x6B, 0x80], &[RELEASED; 2], 0, None);
    assert_eq!(
        replay(&mut faults.on(&mut chip, T), &write, 0),
        Outcome::Write
    );
    assert_eq!(chip.spi_peek(0x6B), before);
}

#[test]
fn a_corrupt_window_serves_the_flips_the_replay_draws() {
    let mut chip = EmulatedChip::default();
    let mut twin = EmulatedChip::default();
    let mut faults = faults(FaultKind::Corrupt { probability: 0.4 });
    let clean = shadow(&mut twin, &BusFaults::new(0));
    let mut flipped = 0;
    for _ in 0..4 {
        let shadow = shadow(&mut chip, &faults);
        let read = streamed(&shadow, 14);
        flipped += read
            .sent()
            .iter()
            .zip(clean.stream())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(replay(&mut faults.on(&mut chip, T), &read, 0), Outcome::Hit);
        // The clean twin reads the same registers.
        replay(&mut twin, &streamed(&clean, 14), 0);
    }
    assert!(flipped > 4, "{flipped}");
    // Outside the window the stream is the chip's own.
    chip.advance(2 * T);
    let mut outside = Shadow::new();
    outside.capture(&chip, 0x3B, 0);
    let untouched = outside.clone();
    outside.apply_bus_faults(&faults, chip.now_ns());
    assert_eq!(outside, untouched);
}
