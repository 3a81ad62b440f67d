//! The chip faults (`Chip::fault_*` hooks) as flight-controller code meets them: ArduPilot's
//! register read-back (`fc_ardupilot.rs`: one checked register re-read per poll, its
//! `check_next_register`) notices a reset and the driver recovers by initialising again; a
//! probe of WHO_AM_I as Betaflight's detection does it rejects a wrong identity; PX4's FIFO
//! reader (`fc_px4.rs`) sees a forced overflow's FIFO_FULL_INT and flushes the FIFO. Outside
//! each fault the bytes are those of a run without it.

use margemu_firmware::chip::Chip;

use super::fc::{Decoded, Recorder, Rig, Transaction};
use super::fc_ardupilot::{ardupilot_init, poll};
use super::fc_px4::{px4_init, transfer};
use super::*;

/// What an ArduPilot-style run saw: the samples each poll decoded (by sample number), the
/// polls whose read-back did not match, and every transaction.
struct CheckedRun {
    decoded: Vec<(usize, Decoded)>,
    expected: Vec<Decoded>,
    mismatches: Vec<usize>,
    transactions: Vec<Transaction>,
    /// Transactions made before the reset.
    before_reset: usize,
}

/// ArduPilot's init, then `n` samples at 1 kHz, each followed by a poll and one read-back of
/// the next checked register; on a mismatch the driver initialises again. A reset fault hits
/// the chip before sample `reset_at`.
fn ardupilot_checked(n: usize, reset_at: Option<usize>) -> CheckedRun {
    let mut chip = chip();
    let mut r = Recorder::new(&mut chip);
    let checked = ardupilot_init(&mut r, false);
    let (mut decoded, mut mismatches) = (Vec::new(), Vec::new());
    let mut before_reset = usize::MAX;
    for k in 0..n {
        if reset_at == Some(k) {
            assert!(Chip::fault_reset(r.rig));
            before_reset = r.run.transactions.len();
        }
        r.latch(k as i16, 50 * MS + k as u64 * MS, None);
        let before = r.run.samples.len();
        poll(&mut r);
        decoded.extend(r.run.samples[before..].iter().map(|d| (k, *d)));
        let (reg, value) = checked[k % checked.len()];
        if r.read(reg) != value {
            mismatches.push(k);
            assert_eq!(
                ardupilot_init(&mut r, false),
                checked,
                "the same configuration"
            );
        }
    }
    CheckedRun {
        decoded,
        expected: r.run.expected,
        mismatches,
        transactions: r.run.transactions,
        before_reset,
    }
}

#[test]
fn ardupilot_read_back_notices_a_reset_and_recovers_after_initialising_again() {
    let clean = ardupilot_checked(60, None);
    assert!(clean.mismatches.is_empty());
    assert_eq!(clean.decoded.len(), 60);
    // Sample 25 meets GYRO_CONFIG0, 26 ACCEL_CONFIG0: both at their reset values at 1 kHz
    // (0x06), so the read-back that notices is INTF_CONFIG1's (0x91, AFSR back on) at 27.
    for (reset_at, noticed) in [(21, 21), (25, 27)] {
        let run = ardupilot_checked(60, Some(reset_at));
        assert_eq!(run.mismatches, [noticed], "reset before sample {reset_at}");
        // Before the fault: the clean run's bytes exactly.
        let until = run
            .transactions
            .iter()
            .zip(&clean.transactions)
            .take_while(|(a, b)| a == b)
            .count();
        assert!(
            until >= run.before_reset,
            "every byte before the reset is the clean run's"
        );
        for (k, d) in &run.decoded {
            assert_eq!(*d, run.expected[*k], "sample {k}: exact when decoded");
        }
        // Lost: the samples from the reset to the re-initialisation (sensors off, FIFO in
        // bypass); every sample after it is decoded again.
        let numbers: Vec<usize> = run.decoded.iter().map(|(k, _)| *k).collect();
        let want: Vec<usize> = (0..reset_at).chain(noticed + 1..60).collect();
        assert_eq!(numbers, want);
    }
}

#[test]
fn a_reset_restores_the_power_on_registers_and_keeps_the_clock() {
    let mut c = running();
    spi_write(&mut c, 0x4D, &[0x51]); // AFSR off
    spi_write(&mut c, 0x4F, &[0x23]); // ±1000 °/s, 8 kHz
    spi_write(&mut c, 0x16, &[0x40]); // FIFO stream
    spi_write(&mut c, 0x5F, &[0x03]);
    c.latch_at(&sample(100), 5 * MS);
    let fresh = chip();
    assert!(Chip::fault_reset(&mut c));
    assert_eq!(c.now_ns(), 5 * MS, "the clock is kept");
    for bank in 0..5 {
        for addr in 0..0x80 {
            assert_eq!(
                c.peek(bank, addr),
                fresh.peek(bank, addr),
                "{bank}:{addr:#04x}"
            );
        }
    }
    assert!(c.afsr_enabled());
    assert_eq!(
        spi_read(&mut c, 0x2D, 1),
        [0x10],
        "RESET_DONE_INT, as after power-up"
    );
    // Sensors off: a latch changes nothing until a driver turns them on again.
    c.latch_at(&sample(7), 6 * MS);
    let power_on = [fresh.peek(0, 0x25), fresh.peek(0, 0x26)];
    assert_eq!(
        spi_read(&mut c, 0x25, 2),
        power_on,
        "GYRO_DATA_X as at power-up"
    );
}

/// Betaflight's detection: soft reset, PWR_MGMT0 off, WHO_AM_I must name a part it knows.
fn betaflight_detect(r: &mut Recorder<impl Rig>) -> Option<&'static str> {
    r.write(0x11, 0x01);
    r.write(0x4E, 0x00);
    match r.read(0x75) {
        0x42 => Some("ICM-42605"),
        0x47 => Some("ICM-42688-P"),
        _ => None,
    }
}

#[test]
fn a_probe_rejects_the_wrong_identity_and_accepts_it_again_after_the_window() {
    let mut c = chip();
    let mut clean = chip();
    assert!(Chip::fault_identity(&mut c, Some(0x00)));
    let mut r = Recorder::new(&mut c);
    assert_eq!(betaflight_detect(&mut r), None, "WHO_AM_I 0x00 rejected");
    let faulty = r.run.transactions;
    let mut r = Recorder::new(&mut clean);
    assert_eq!(betaflight_detect(&mut r), Some("ICM-42688-P"));
    let good = r.run.transactions;
    assert_eq!(faulty[..2], good[..2], "the same bytes but WHO_AM_I's");
    assert_eq!(faulty[2].miso, [0x00, 0x00]);
    assert_eq!(good[2].miso, [0x00, 0x47]);
    // A soft reset inside the window keeps the wrong identity (it belongs to the window).
    assert_eq!(c.peek(0, 0x75), 0x00);
    assert!(Chip::fault_identity(&mut c, None));
    let mut r = Recorder::new(&mut c);
    assert_eq!(betaflight_detect(&mut r), Some("ICM-42688-P"));
}

#[test]
fn px4_sees_the_forced_overflow_flushes_and_reads_exactly_after_it() {
    const N: usize = 400;
    let window = 120..200; // samples, 125 µs apart: 10 ms of overflow
    let run = |fault: bool| {
        let mut chip = chip();
        let mut p = px4_init(&mut chip);
        let mut resets_at = Vec::new();
        let mut decoded = Vec::new();
        for k in 0..N {
            if fault && k == window.start {
                assert!(Chip::fault_fifo_overflow(p.r.rig, true));
            }
            if fault && k == window.end {
                assert!(Chip::fault_fifo_overflow(p.r.rig, false));
            }
            let t = 40 * MS + k as u64 * 125 * US;
            p.r.latch(k as i16, t, Some((2, 1)));
            if p.r.rig.int1(t) {
                continue; // active low: not asserted
            }
            p.select(0);
            let bytes = p.r.burst(0x2D, 3 + 8 * 20);
            let (resets, before) = (p.r.run.fifo_resets, p.r.run.samples.len());
            transfer(&mut p.r, &bytes);
            if p.r.run.fifo_resets > resets {
                assert_ne!(bytes[0] & 0x02, 0, "FIFO_FULL_INT at {k}");
                p.r.write(0x4B, 0x02); // FIFOReset: SIGNAL_PATH_RESET.FIFO_FLUSH
                resets_at.push(k);
            }
            decoded.extend(p.r.run.samples[before..].iter().copied());
        }
        (resets_at, decoded, p.r.run.expected)
    };
    let (clean_resets, clean, expected) = run(false);
    assert!(clean_resets.is_empty());
    assert_eq!(clean, expected);
    let (resets, decoded, expected) = run(true);
    assert!(!resets.is_empty(), "the overflow is seen");
    assert!(resets.iter().all(|k| window.contains(k)), "{resets:?}");
    assert_eq!(resets[0], window.start, "at the first burst of the window");
    // Each decoded packet is exactly one latched sample's: which ones got through?
    let numbers: Vec<usize> = decoded
        .iter()
        .map(|d| {
            expected
                .iter()
                .position(|e| e == d)
                .expect("an exact sample")
        })
        .collect();
    let before = numbers.iter().take_while(|&&k| k < window.start).count();
    assert_eq!(
        numbers[..before],
        (0..before).collect::<Vec<_>>()[..],
        "all before"
    );
    assert!(
        before + 8 >= window.start,
        "up to the last watermark before the window"
    );
    let after = &numbers[before..];
    assert!(
        after.iter().all(|&k| k >= window.end),
        "none from inside the window"
    );
    assert_eq!(
        after,
        (after[0]..N).collect::<Vec<_>>(),
        "every one after it, in order"
    );
    assert!(
        after[0] < window.end + 8,
        "from the first burst after the window"
    );
}
