//! The vibration sources: tone frequency and amplitude, rpm profiles, the random PSD, shocks,
//! determinism.

use margemu_model::perturbation::Complex;
use margemu_model::vibration::{
    Harmonic, PsdPoint, RandomSource, RpmPoint, Sense, Shock, ToneSource, Vibration,
};
use margemu_model::Error;
use rustfft::{num_complex::Complex64, FftPlanner};

type Vib<'a> = Vibration<&'a [RpmPoint], Vec<Complex>>;

/// Amplitude of the component at `f_hz` in `x` sampled at `rate_hz` (single-bin DFT).
fn amplitude_at(x: &[f32], f_hz: f64, rate_hz: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (n, v) in x.iter().enumerate() {
        let a = std::f64::consts::TAU * f_hz * n as f64 / rate_hz;
        re += f64::from(*v) * a.cos();
        im += f64::from(*v) * a.sin();
    }
    2.0 * (re * re + im * im).sqrt() / x.len() as f64
}

/// Welch's one-sided PSD (Hann, 50 % overlap) of `x` at `rate_hz`, segments of `n`.
pub fn welch(x: &[f64], rate_hz: f64, n: usize) -> Vec<f64> {
    let w: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos())
        .collect();
    let u: f64 = w.iter().map(|v| v * v).sum();
    let fft = FftPlanner::new().plan_fft_forward(n);
    let mut psd = vec![0.0; n / 2 + 1];
    let mut segments = 0;
    let mut start = 0;
    while start + n <= x.len() {
        let mut buf: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new(x[start + i] * w[i], 0.0))
            .collect();
        fft.process(&mut buf);
        for (k, p) in psd.iter_mut().enumerate() {
            let scale = if k == 0 || k == n / 2 { 1.0 } else { 2.0 };
            *p += scale * buf[k].norm_sqr() / (rate_hz * u);
        }
        segments += 1;
        start += n / 2;
    }
    psd.iter().map(|p| p / segments as f64).collect()
}

#[test]
fn a_constant_tone_has_its_frequency_and_amplitude_per_motor() {
    // 9000 rpm = 150 Hz, 2nd harmonic 300 Hz; two motors without spread, random phases.
    let profile = [RpmPoint {
        t_ns: 0,
        rpm: 9000.0,
    }];
    let mut tone = ToneSource::new(1, &profile[..]);
    tone.push(Harmonic {
        order: 1.0,
        linear: [0.0, 0.0, 2.0],
        angular: [0.1, 0.0, 0.0],
    })
    .unwrap();
    tone.push(Harmonic {
        order: 2.0,
        linear: [1.0, 0.0, 0.0],
        angular: [0.0; 3],
    })
    .unwrap();
    let mut vib: Vib = Vibration::new(Sense::Linear, 250_000, 3);
    vib.add_tones(tone).unwrap();
    let x: Vec<[f32; 3]> = (0..4000u64).map(|k| vib.next(k * 250_000)).collect();
    let axis = |i: usize| x.iter().map(|v| v[i]).collect::<Vec<f32>>();
    assert!((amplitude_at(&axis(2), 150.0, 4000.0) - 2.0).abs() < 0.01);
    assert!(amplitude_at(&axis(2), 300.0, 4000.0) < 0.01);
    assert!((amplitude_at(&axis(0), 300.0, 4000.0) - 1.0).abs() < 0.01);
    assert!(axis(1).iter().all(|v| *v == 0.0));
    // The gyroscope's sense takes the angular amplitudes.
    let mut tone = ToneSource::new(1, &profile[..]);
    tone.push(Harmonic {
        order: 1.0,
        linear: [0.0, 0.0, 2.0],
        angular: [0.1, 0.0, 0.0],
    })
    .unwrap();
    let mut gyro: Vib = Vibration::new(Sense::Angular, 125_000, 3);
    gyro.add_tones(tone).unwrap();
    let g: Vec<f32> = (0..8000u64).map(|k| gyro.next(k * 125_000)[0]).collect();
    assert!((amplitude_at(&g, 150.0, 8000.0) - 0.1).abs() < 0.001);
}

#[test]
fn motors_with_spread_beat_and_a_ramp_sweeps() {
    // Four motors at ±5 % around 6000 rpm: four tones between 95 and 105 Hz, not one.
    let profile = [RpmPoint {
        t_ns: 0,
        rpm: 6000.0,
    }];
    let mut tone = ToneSource::new(4, &profile[..]);
    tone.spread = 0.05;
    tone.push(Harmonic {
        order: 1.0,
        linear: [1.0, 0.0, 0.0],
        angular: [0.0; 3],
    })
    .unwrap();
    let mut vib: Vib = Vibration::new(Sense::Linear, 250_000, 11);
    vib.add_tones(tone).unwrap();
    let x: Vec<f32> = (0..40_000u64).map(|k| vib.next(k * 250_000)[0]).collect();
    let peak = (0..40_000).map(|i| x[i].abs()).fold(0.0f32, f32::max);
    assert!(
        peak > 2.0 && peak <= 4.0,
        "four motors add up to at most 4: {peak}"
    );
    assert!(
        amplitude_at(&x, 100.0, 4000.0) < 0.9,
        "spread moves them off 100 Hz"
    );
    // A ramp 0 → 12 000 rpm over 1 s: the zero crossings get denser.
    let ramp = [
        RpmPoint { t_ns: 0, rpm: 0.0 },
        RpmPoint {
            t_ns: 1_000_000_000,
            rpm: 12_000.0,
        },
    ];
    let mut tone = ToneSource::new(1, &ramp[..]);
    tone.push(Harmonic {
        order: 1.0,
        linear: [1.0, 0.0, 0.0],
        angular: [0.0; 3],
    })
    .unwrap();
    let mut vib: Vib = Vibration::new(Sense::Linear, 100_000, 1);
    vib.add_tones(tone).unwrap();
    let x: Vec<f32> = (0..10_000u64).map(|k| vib.next(k * 100_000)[0]).collect();
    let crossings = |s: &[f32]| {
        s.windows(2)
            .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
            .count()
    };
    // Phase = ∫ 200 t dt = 100 t² cycles: 25 cycles in the first half second, 75 in the second.
    let (first, second) = (crossings(&x[..5000]), crossings(&x[5000..]));
    assert!(
        (first as i64 - 50).abs() <= 2 && (second as i64 - 150).abs() <= 2,
        "{first} {second}"
    );
}

#[test]
fn a_random_source_has_its_psd() {
    // 30..1500 Hz, rising 3 dB/octave to 200 Hz then flat, at 4 kHz.
    let psd = [
        PsdPoint {
            f_hz: 30.0,
            g2_per_hz: 0.002,
        },
        PsdPoint {
            f_hz: 200.0,
            g2_per_hz: 0.0133,
        },
        PsdPoint {
            f_hz: 1500.0,
            g2_per_hz: 0.0133,
        },
    ];
    let source = RandomSource::new(&psd).unwrap();
    let rate = 4000.0;
    let buffers = vec![Complex::ZERO; source.buffer_len(rate).unwrap()];
    let mut vib: Vib = Vibration::new(Sense::Linear, 250_000, 5);
    vib.add_random(&source, buffers).unwrap();
    let n = 400_000;
    let x: Vec<[f32; 3]> = (0..n as u64).map(|k| vib.next(k * 250_000)).collect();
    let g2 = 9.80665f64 * 9.80665;
    for axis in 0..3 {
        let s: Vec<f64> = x.iter().map(|v| f64::from(v[axis])).collect();
        let est = welch(&s, rate, 1024);
        for (k, p) in est.iter().enumerate() {
            let f = k as f64 * rate / 1024.0;
            if (60.0..1400.0).contains(&f) {
                let db = 10.0 * (p / g2 / source.psd_at(f)).log10();
                assert!(db.abs() < 1.0, "axis {axis} at {f} Hz: {db:.2} dB");
            }
            if f < 10.0 || (1700.0..1990.0).contains(&f) {
                assert!(p / g2 < 1e-3 * 0.0133, "axis {axis} at {f} Hz leaks {p}");
            }
        }
    }
    // Axes are independent: the correlation of x and y is near zero.
    let c: f64 = x
        .iter()
        .map(|v| f64::from(v[0]) * f64::from(v[1]))
        .sum::<f64>()
        / n as f64;
    let vx: f64 = x.iter().map(|v| f64::from(v[0]).powi(2)).sum::<f64>() / n as f64;
    assert!((c / vx).abs() < 0.02, "x-y correlation {}", c / vx);
}

#[test]
fn a_shock_is_a_half_sine() {
    let shock = Shock {
        t_ns: 1_000_000,
        duration_ns: 2_000_000,
        linear: [0.0, 0.0, 100.0],
        angular: [1.0, 0.0, 0.0],
    };
    let mut vib: Vib = Vibration::new(Sense::Linear, 100_000, 0);
    vib.add_shock(&shock).unwrap();
    let z: Vec<f32> = (0..40u64).map(|k| vib.next(k * 100_000)[2]).collect();
    assert!(z[..10].iter().all(|v| *v == 0.0) && z[30..].iter().all(|v| *v == 0.0));
    assert_eq!(z[20], 100.0);
    assert!((z[15] - 100.0 * (std::f32::consts::PI / 4.0).sin()).abs() < 1e-4);
    let mut gyro: Vib = Vibration::new(Sense::Angular, 100_000, 0);
    gyro.add_shock(&shock).unwrap();
    assert_eq!(
        (0..21u64).map(|k| gyro.next(k * 100_000)).last().unwrap(),
        [1.0, 0.0, 0.0]
    );
}

#[test]
fn the_same_seed_gives_the_same_bits_and_another_seed_others() {
    let run = |seed: u64| {
        let psd = [
            PsdPoint {
                f_hz: 50.0,
                g2_per_hz: 0.01,
            },
            PsdPoint {
                f_hz: 800.0,
                g2_per_hz: 0.01,
            },
        ];
        let source = RandomSource::new(&psd).unwrap();
        let profile = [RpmPoint {
            t_ns: 0,
            rpm: 10_000.0,
        }];
        let mut tone = ToneSource::new(2, &profile[..]);
        tone.spread = 0.01;
        tone.push(Harmonic {
            order: 1.0,
            linear: [1.0; 3],
            angular: [0.0; 3],
        })
        .unwrap();
        let mut vib: Vib = Vibration::new(Sense::Linear, 250_000, seed);
        vib.add_tones(tone).unwrap();
        let buffers = vec![Complex::ZERO; source.buffer_len(4000.0).unwrap()];
        vib.add_random(&source, buffers).unwrap();
        (0..5000u64)
            .map(|k| vib.next(k * 250_000))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(9), run(9));
    assert_ne!(run(9), run(10));
}

#[test]
fn bad_sources_are_refused() {
    let empty: [RpmPoint; 0] = [];
    let mut vib: Vib = Vibration::new(Sense::Linear, 250_000, 0);
    assert_eq!(
        vib.add_tones(ToneSource::new(1, &empty[..])),
        Err(Error::InvalidRpmProfile)
    );
    let profile = [RpmPoint { t_ns: 0, rpm: 1.0 }];
    assert_eq!(
        vib.add_tones(ToneSource::new(0, &profile[..])),
        Err(Error::InvalidMotorCount)
    );
    let back = [
        RpmPoint { t_ns: 5, rpm: 1.0 },
        RpmPoint { t_ns: 4, rpm: 1.0 },
    ];
    assert_eq!(
        vib.add_tones(ToneSource::new(1, &back[..])),
        Err(Error::InvalidRpmProfile)
    );
    let flat = [
        PsdPoint {
            f_hz: 10.0,
            g2_per_hz: 1.0,
        },
        PsdPoint {
            f_hz: 10.0,
            g2_per_hz: 1.0,
        },
    ];
    assert_eq!(RandomSource::new(&flat), Err(Error::InvalidPsd));
    let low = [
        PsdPoint {
            f_hz: 0.1,
            g2_per_hz: 1.0,
        },
        PsdPoint {
            f_hz: 10.0,
            g2_per_hz: 1.0,
        },
    ];
    assert_eq!(
        RandomSource::new(&low).unwrap().fft_len(32_000.0),
        Err(Error::PsdTooFine)
    );
    let ok = RandomSource::new(&[
        PsdPoint {
            f_hz: 20.0,
            g2_per_hz: 1.0,
        },
        PsdPoint {
            f_hz: 100.0,
            g2_per_hz: 1.0,
        },
    ])
    .unwrap();
    let mut gyro: Vib = Vibration::new(Sense::Angular, 250_000, 0);
    assert_eq!(
        gyro.add_random(&ok, vec![]),
        Err(Error::RandomVibrationNotLinear)
    );
    assert!(matches!(
        vib.add_random(&ok, vec![Complex::ZERO; 3]),
        Err(Error::BufferTooSmall { .. })
    ));
    assert_eq!(
        vib.add_shock(&Shock {
            duration_ns: 0,
            ..Shock::default()
        }),
        Err(Error::NonPositiveParameter {
            what: "vibration.shock.duration"
        })
    );
    assert!(vib.is_empty());
}
