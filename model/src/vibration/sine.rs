//! `sin(2π·p)` for a phase `p` in cycles, in `f32` arithmetic only.
//!
//! `libm::sinf` reduces and evaluates in `f64`, which the Cortex-M4F runs in software (about
//! 1400 instructions a call); the tones need a sine per motor, harmonic and internal sample. Here
//! the phase is reduced exactly in cycles (to the nearest quarter turn `n` and a remainder
//! `r ∈ [−⅛, ⅛]` turn), and `sin` or `cos` of `x = 2πr ∈ [−π/4, π/4]` is a Taylor polynomial to
//! `x⁹` / `x⁸` (truncation below 3·10⁻⁸), each term in a fixed order, no fused multiply-add:
//! the same bits on every target, within 2·10⁻⁷ of the true sine.
//!
//! ```
//! use margemu_model::vibration::sine::sin_cycles;
//! assert_eq!(sin_cycles(0.0), 0.0);
//! assert!((sin_cycles(0.25) - 1.0).abs() < 1e-7);
//! assert!((sin_cycles(0.1) - (0.2 * std::f32::consts::PI).sin()).abs() < 2e-7);
//! ```

/// `sin(2π·p)`; any finite `p` (its whole turns are dropped), 0 for a non-finite one.
#[inline]
pub fn sin_cycles(p: f32) -> f32 {
    if !p.is_finite() {
        return 0.0;
    }
    let p = p - libm::floorf(p);
    let q = p * 4.0;
    let n = libm::floorf(q + 0.5);
    let x = (q - n) * core::f32::consts::FRAC_PI_2;
    let x2 = x * x;
    let sin = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    let cos = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0))));
    match n as u32 & 3 {
        0 => sin,
        1 => cos,
        2 => -sin,
        _ => -cos,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_two_tenths_of_a_micro_of_the_true_sine() {
        let mut worst = 0.0f64;
        for i in 0..=100_000 {
            let p = i as f32 / 100_000.0;
            let exact = libm::sin(core::f64::consts::TAU * f64::from(p));
            worst = worst.max((f64::from(sin_cycles(p)) - exact).abs());
        }
        assert!(worst < 2e-7, "{worst}");
        assert_eq!(sin_cycles(f32::NAN), 0.0);
        assert!((sin_cycles(3.25) - 1.0).abs() < 1e-7 && (sin_cycles(-0.25) + 1.0).abs() < 1e-7);
    }
}
