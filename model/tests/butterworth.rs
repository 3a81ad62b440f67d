//! The eq. 23 low-pass in f32 at 8 kHz with a 5 Hz cutoff (poles at radius 0.9972): stability,
//! and the magnitude error against the analytic |H(f)|, beside a plain f32 direct form.

use margemu_model::perturbation::butterworth::{eq23_coefficients, Butterworth2};
use std::f64::consts::PI;

const RATE: f64 = 8000.0;
const CUTOFF: f64 = 5.0;

/// The textbook alternative: transposed direct form II with eq. 23's coefficients in f32.
struct DirectForm {
    b: [f32; 3],
    a: [f32; 2],
    z: [f32; 2],
}

impl DirectForm {
    fn new() -> Self {
        let (b, a) = eq23_coefficients(CUTOFF, RATE);
        Self {
            b: b.map(|x| x as f32),
            a: a.map(|x| x as f32),
            z: [0.0; 2],
        }
    }
    fn process(&mut self, x: f32) -> f32 {
        let y = self.b[0] * x + self.z[0];
        self.z[0] = self.b[1] * x + self.a[0] * y + self.z[1];
        self.z[1] = self.b[2] * x + self.a[1] * y;
        y
    }
}

/// The measured gain at `f` Hz: settle 3 s, then correlate over whole periods (f64 analysis).
fn measured_gain(mut filter: impl FnMut(f32) -> f32, f: f64) -> f64 {
    let settle = (3.0 * RATE) as usize;
    let periods = (f * 2.0).ceil().max(1.0);
    let len = (periods * RATE / f).round() as usize;
    let (mut c, mut s) = (0.0, 0.0);
    for k in 0..settle + len {
        let phase = 2.0 * PI * f * k as f64 / RATE;
        let y = f64::from(filter(phase.sin() as f32));
        if k >= settle {
            c += y * phase.cos();
            s += y * phase.sin();
        }
    }
    2.0 * (c * c + s * s).sqrt() / len as f64
}

#[test]
fn f32_response_matches_the_analytic_one() {
    let probe = Butterworth2::low_pass(CUTOFF, RATE).unwrap();
    let freqs = [
        0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 15.0, 25.0, 50.0, 100.0, 250.0, 1000.0,
    ];
    println!("   f/Hz   |H| analytic     state-variable f32 error   direct form f32 error");
    let mut worst_pass = 0.0f64;
    for f in freqs {
        let analytic = probe.magnitude(f);
        let mut svf = Butterworth2::low_pass(CUTOFF, RATE).unwrap();
        let mut df = DirectForm::new();
        let e_svf = measured_gain(|x| svf.process(x), f) / analytic - 1.0;
        let e_df = measured_gain(|x| df.process(x), f) / analytic - 1.0;
        let db = |e: f64| 20.0 * (1.0 + e).log10();
        println!(
            "{f:7.1}   {analytic:.6e}   {:+.2e} ({:+.5} dB)   {:+.2e} ({:+.4} dB)",
            e_svf,
            db(e_svf),
            e_df,
            db(e_df)
        );
        if f <= 2.0 * CUTOFF {
            worst_pass = worst_pass.max(e_svf.abs());
            assert!(e_svf.abs() < 1e-4, "{f} Hz: relative error {e_svf}");
        } else if f <= 250.0 {
            assert!(e_svf.abs() < 1e-3, "{f} Hz: relative error {e_svf}");
        } else {
            // −100 dB: the f32 rounding of the input sine itself is of this order.
            assert!(e_svf.abs() < 0.05, "{f} Hz: relative error {e_svf}");
        }
    }
    println!("worst relative error up to 2·fc: {worst_pass:.2e}");
}

#[test]
fn f32_filter_is_stable_over_a_million_samples() {
    // Impulse response: decays, never blows up, and ends below the smallest normal f32 (it
    // settles on a fixed point of ~5·10⁻⁴³ where the increments underflow: 10⁻⁴² of the input).
    let mut lp = Butterworth2::low_pass(CUTOFF, RATE).unwrap();
    let mut peak_late = 0.0f32;
    let mut energy_early = 0.0f64;
    for k in 0..1_000_000 {
        let y = lp.process(if k == 0 { 1.0 } else { 0.0 });
        assert!(y.is_finite(), "sample {k}");
        if k < 8000 {
            energy_early += f64::from(y) * f64::from(y);
        } else if k >= 100_000 {
            peak_late = peak_late.max(y.abs());
        }
    }
    assert!(energy_early > 1e-4, "{energy_early}");
    assert!(peak_late < f32::MIN_POSITIVE, "{peak_late:e}");
    // Step response: settles at exactly 1 (unit DC gain, no dead band).
    let mut lp = Butterworth2::low_pass(CUTOFF, RATE).unwrap();
    let y = (0..1_000_000).map(|_| lp.process(1.0)).last().unwrap();
    assert_eq!(y, 1.0);
    // Full-scale noise in: bounded out, a million samples long.
    let mut lp = Butterworth2::low_pass(CUTOFF, RATE).unwrap();
    let mut s: u32 = 1;
    let mut peak = 0.0f32;
    for _ in 0..1_000_000 {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        let x = (s as f32 / u32::MAX as f32) * 2.0 - 1.0;
        peak = peak.max(lp.process(x * 1e3).abs());
    }
    assert!(peak.is_finite() && peak < 1e3, "{peak}");
}
