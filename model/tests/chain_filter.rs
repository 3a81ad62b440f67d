//! The sampling chain's filter designs: −3 dB points, low-frequency delays, unit DC gain in
//! `f32`, non-finite input, cascades and the errors.

use core::f64::consts::{FRAC_1_SQRT_2, PI};
use margemu_model::chain::filter::{FilterDesign, FilterState, MAX_DELAY, MAX_ORDER};
use margemu_model::Error;

/// `(cutoff, rate)` pairs from the chips' tables, the extremes included.
const CASES: [(f64, f64); 8] = [
    (5.0, 1000.0),
    (184.0, 1000.0),
    (460.0, 1000.0),
    (250.0, 8000.0),
    (3600.0, 8000.0),
    (10.0, 32_000.0),
    (258.0, 32_000.0),
    (8800.0, 32_000.0),
];

/// Σ sin((2k−1)π/(2n)): the analog Butterworth's DC group delay times its cutoff (rad/s).
fn prototype_delay(order: u8) -> f64 {
    let n = f64::from(order);
    (1..=order)
        .map(|k| libm::sin((2.0 * f64::from(k) - 1.0) * PI / (2.0 * n)))
        .sum()
}

#[test]
fn minus_3_db_at_the_cutoff_for_every_order() {
    for (fc, fs) in CASES {
        for order in 1..=MAX_ORDER {
            let f = FilterDesign::butterworth(order, fc, fs).unwrap();
            let g = f.gain_at(fc);
            assert!(
                (g - FRAC_1_SQRT_2).abs() < 1e-5,
                "order {order} {fc}/{fs}: {g}"
            );
            assert!(f.gain_at(0.0) > 1.0 - 1e-6 && f.gain_at(0.0) < 1.0 + 1e-6);
            assert!(f.gain_at(fc * 0.5) > g && f.gain_at(0.5 * (fc + 0.5 * fs)) < g);
            assert_eq!(f.order(), usize::from(order));
            let bw = f.bandwidth_hz().unwrap();
            assert!((bw - fc).abs() < 1e-4 * fc, "{bw} vs {fc}");
        }
    }
}

#[test]
fn low_frequency_delay_is_the_bilinear_butterworth_one() {
    // Bilinear with prewarping: delay (samples) = prototype delay / (2·tan(π fc/fs)).
    for (fc, fs) in CASES {
        for order in 1..=MAX_ORDER {
            let f = FilterDesign::butterworth(order, fc, fs).unwrap();
            let g = libm::tan(PI * fc / fs);
            let want = prototype_delay(order) / (2.0 * g) / fs;
            let got = f.delay_s();
            assert!(
                (got - want).abs() < 1e-5 * want,
                "order {order} {fc}/{fs}: {got} vs {want}"
            );
            let delayed = f.with_delay(7).unwrap();
            assert!((delayed.delay_s() - want - 7.0 / fs).abs() < 1e-5 * want + 1e-12);
        }
    }
}

#[test]
fn step_response_settles_on_one_in_f32() {
    for (fc, fs) in CASES {
        for order in [1, 2, 3, 4] {
            let f = FilterDesign::butterworth(order, fc, fs).unwrap();
            let mut s = FilterState::default();
            // 40 time constants of the slowest pole.
            let n = (40.0 * fs / (2.0 * PI * fc) * f64::from(order)) as usize + 100;
            let mut y = 0.0;
            for _ in 0..n {
                y = f.step(&mut s, 1.0);
            }
            assert!((y - 1.0).abs() <= 1e-6, "order {order} {fc}/{fs}: {y}");
        }
    }
}

#[test]
fn sine_amplitude_in_f32_matches_gain_at() {
    for (fc, fs) in [(5.0, 1000.0), (250.0, 32_000.0), (20.0, 1000.0)] {
        let f = FilterDesign::butterworth(3, fc, fs).unwrap();
        for freq in [0.5 * fc, fc, 2.0 * fc] {
            let mut s = FilterState::default();
            let period = fs / freq;
            let settle = (60.0 * fs / (2.0 * PI * fc)) as usize;
            let mut peak = 0.0f64;
            for n in 0..settle + (4.0 * period) as usize {
                let x = libm::sin(2.0 * PI * freq * n as f64 / fs) as f32;
                let y = f.step(&mut s, x);
                if n >= settle {
                    peak = peak.max(f64::from(y).abs());
                }
            }
            let want = f.gain_at(freq);
            assert!(
                (peak - want).abs() < 2e-3,
                "{fc}/{fs} at {freq}: {peak} vs {want}"
            );
        }
    }
}

#[test]
fn a_non_finite_input_is_taken_as_the_previous_one() {
    let f = FilterDesign::butterworth(3, 41.0, 1000.0)
        .unwrap()
        .with_delay(3)
        .unwrap();
    let input = |n: usize| libm::sinf(n as f32 * 0.1) * 3.0;
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let (mut faulty, mut held) = (FilterState::default(), FilterState::default());
        for n in 0..500 {
            let x = input(n);
            let (a, b) = if n == 200 {
                let prev = input(199);
                (f.step(&mut faulty, bad), f.step(&mut held, prev))
            } else {
                (f.step(&mut faulty, x), f.step(&mut held, x))
            };
            assert!(a.is_finite());
            assert_eq!(a.to_bits(), b.to_bits(), "sample {n}");
        }
    }
    // Before any input, a NaN is taken as 0.
    let mut s = FilterState::default();
    assert_eq!(f.step(&mut s, f32::NAN), 0.0);
    // Huge finite inputs are clamped, never overflowing the state.
    let mut s = FilterState::default();
    for _ in 0..100 {
        assert!(f.step(&mut s, f32::MAX).is_finite());
    }
}

#[test]
fn pure_delay_shifts_by_whole_samples() {
    let f = FilterDesign::identity(1000.0)
        .unwrap()
        .with_delay(5)
        .unwrap();
    let mut s = FilterState::default();
    let out: Vec<f32> = (0..10).map(|n| f.step(&mut s, n as f32 + 1.0)).collect();
    assert_eq!(out, [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    assert_eq!((f.delay_samples(), f.delay_s()), (5, 0.005));
    let id = FilterDesign::identity(1000.0).unwrap();
    let mut s = FilterState::default();
    assert_eq!(id.step(&mut s, 2.5), 2.5);
    assert_eq!(
        (id.gain_at(300.0), id.delay_s(), id.bandwidth_hz()),
        (1.0, 0.0, None)
    );
}

#[test]
fn settle_starts_at_the_steady_state() {
    let f = FilterDesign::butterworth(2, 258.0, 32_000.0)
        .unwrap()
        .then(FilterDesign::butterworth(3, 100.0, 32_000.0).unwrap())
        .unwrap()
        .with_delay(4)
        .unwrap();
    let mut s = FilterState::default();
    f.settle(&mut s, 9.80665);
    for _ in 0..1000 {
        let y = f.step(&mut s, 9.80665);
        assert!((y - 9.80665).abs() < 1e-5, "{y}");
    }
}

#[test]
fn a_cascade_multiplies_gains_and_adds_delays() {
    let a = FilterDesign::butterworth(2, 536.0, 32_000.0).unwrap();
    let b = FilterDesign::butterworth(3, 250.0, 32_000.0)
        .unwrap()
        .with_delay(2)
        .unwrap();
    let ab = a.then(b).unwrap();
    assert_eq!((ab.sections(), ab.order(), ab.delay_samples()), (3, 5, 2));
    for f in [10.0, 250.0, 536.0, 3000.0] {
        assert!((ab.gain_at(f) - a.gain_at(f) * b.gain_at(f)).abs() < 1e-12);
    }
    assert!((ab.delay_s() - a.delay_s() - b.delay_s()).abs() < 1e-12);
}

#[test]
fn errors_name_what_was_wrong() {
    assert_eq!(FilterDesign::identity(0.0), Err(Error::InvalidRate));
    assert_eq!(FilterDesign::identity(f64::NAN), Err(Error::InvalidRate));
    assert_eq!(
        FilterDesign::butterworth(2, 500.0, 1000.0),
        Err(Error::CutoffAboveNyquist)
    );
    assert!(FilterDesign::butterworth(2, 0.0, 1000.0).is_err());
    let e = FilterDesign::butterworth(0, 5.0, 1000.0).unwrap_err();
    assert_eq!(e, Error::FilterOrder { order: 0 });
    assert_eq!(e.to_string(), "filter order 0 is outside 1 to 8");
    assert_eq!(
        FilterDesign::butterworth(9, 5.0, 1000.0),
        Err(Error::FilterOrder { order: 9 })
    );
    let eight = FilterDesign::butterworth(8, 5.0, 1000.0).unwrap();
    let e = eight
        .then(FilterDesign::first_order(5.0, 1000.0).unwrap())
        .unwrap_err();
    assert_eq!(e, Error::TooManyFilterSections);
    assert_eq!(e.to_string(), "filter design needs more than 4 sections");
    let e = eight
        .then(FilterDesign::identity(2000.0).unwrap())
        .unwrap_err();
    assert_eq!(e, Error::FilterRateMismatch);
    let e = eight.with_delay(MAX_DELAY + 1).unwrap_err();
    assert_eq!(e, Error::FilterDelayTooLong { samples: 161 });
    assert_eq!(
        e.to_string(),
        "filter delay of 161 samples exceeds 160 samples"
    );
    assert!(eight.with_delay(MAX_DELAY).is_ok());
}
