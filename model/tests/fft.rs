//! The crate's no_std FFT against rustfft.

use margemu_model::perturbation::fft::{Complex, Fft};
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

fn signal(n: usize) -> Vec<Complex> {
    // Deterministic, broadband, with a DC offset and a large dynamic range.
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15 ^ n as u64;
    (0..n)
        .map(|k| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            Complex::new(0.3 + u + (k as f64 * 0.01).sin(), 0.5 * u)
        })
        .collect()
}

/// max |X − X_ref| / max |X_ref| of the forward transform.
fn relative_error(n: usize, inverse: bool) -> f64 {
    let x = signal(n);
    let mut scratch = vec![Complex::ZERO; Fft::scratch_len(n).unwrap()];
    let mut fft = Fft::new(n, &mut scratch).unwrap();
    let mut ours = x.clone();
    let mut reference: Vec<Complex64> = x.iter().map(|z| Complex64::new(z.re, z.im)).collect();
    let mut planner = FftPlanner::new();
    if inverse {
        fft.inverse(&mut ours).unwrap();
        planner.plan_fft_inverse(n).process(&mut reference);
    } else {
        fft.forward(&mut ours).unwrap();
        planner.plan_fft_forward(n).process(&mut reference);
    }
    let scale = reference.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let err = ours
        .iter()
        .zip(&reference)
        .map(|(a, b)| (Complex64::new(a.re, a.im) - b).norm())
        .fold(0.0, f64::max);
    err / scale
}

#[test]
fn agrees_with_rustfft_within_1e_minus_6() {
    // Powers of two, the paper's 400 (2 s at 200 Hz), 16 000 (2 s at 8 kHz), 667 (2 s at
    // 333.33 Hz: 23·29), primes (Bluestein), and odd smooth lengths.
    let lengths = [
        1, 2, 8, 1024, 4096, 65_536, 400, 2000, 16_000, 667, 7, 997, 7919, 15_625, 729,
    ];
    for n in lengths {
        for inverse in [false, true] {
            let e = relative_error(n, inverse);
            println!(
                "n = {n:6} {}: relative error {e:.2e}",
                if inverse { "inverse" } else { "forward" }
            );
            assert!(e < 1e-6, "n = {n}: {e}");
            assert!(e < 1e-12, "n = {n}: {e} (much worse than a textbook FFT)");
        }
    }
}

#[test]
fn plans_are_reusable_and_deterministic() {
    let n = 667;
    let x = signal(n);
    let mut scratch = vec![Complex::ZERO; Fft::scratch_len(n).unwrap()];
    let mut fft = Fft::new(n, &mut scratch).unwrap();
    let mut a = x.clone();
    let mut b = x.clone();
    fft.forward(&mut a).unwrap();
    fft.forward(&mut b).unwrap();
    assert!(a
        .iter()
        .zip(&b)
        .all(|(p, q)| p.re.to_bits() == q.re.to_bits() && p.im.to_bits() == q.im.to_bits()));
}
