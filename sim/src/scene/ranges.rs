//! Plausible ranges of every physical scene input.
//!
//! A value must be finite (and of the right sign, as before); a finite value outside its
//! plausible range is refused too, with the value and the range, because nothing physical
//! asks for it and the arithmetic downstream (gains, truth, samples) would overflow or lose
//! all precision. The ranges are wide on purpose: they refuse the absurd, not the unusual. The
//! user guide lists them (`docs/scenes.md`, "Plausible ranges").

use super::error::Violation;

/// A closed interval `[lo, hi]` in `unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plausible {
    /// Smallest value accepted.
    pub lo: f64,
    /// Largest value accepted.
    pub hi: f64,
    /// Unit for messages (empty for dimensionless values).
    pub unit: &'static str,
}

const fn range(lo: f64, hi: f64, unit: &'static str) -> Plausible {
    Plausible { lo, hi, unit }
}

/// `duration` and every time in a source (step times, holds, segments, CSV `t`): up to 10⁷ s
/// (116 days).
pub const TIME: Plausible = range(0.0, 1e7, "s");
/// Times of a CSV joint source (`t` column; rows before t = 0 are allowed).
pub const SOURCE_TIME: Plausible = range(-1e7, 1e7, "s");
/// `rate`: 1 mHz to 1 MHz.
pub const RATE: Plausible = range(1e-3, 1e6, "Hz");
/// `integrator.step`: 1 ns to 10 s.
pub const STEP: Plausible = range(1e-9, 10.0, "s");
/// `bench.link_mass`, `bench.plate_mass`: 1 mg to 1000 t.
pub const MASS: Plausible = range(1e-6, 1e6, "kg");
/// `bench.plate_inertia`.
pub const INERTIA: Plausible = range(1e-12, 1e6, "kg·m²");
/// `bench.viscous_friction`.
pub const VISCOUS_FRICTION: Plausible = range(0.0, 1e9, "N·s/m or N·m·s/rad");
/// `bench.static_friction`.
pub const STATIC_FRICTION: Plausible = range(0.0, 1e9, "N or N·m");
/// `bench.effort_limit`.
pub const EFFORT: Plausible = range(0.0, 1e12, "N or N·m");
/// `bench.gravity`.
pub const GRAVITY: Plausible = range(0.0, 1e3, "m/s²");
/// Joint positions: `bench.initial`, source values, amplitudes, offsets, ranges, CSV values.
pub const JOINT_VALUE: Plausible = range(-1e6, 1e6, "m or rad");
/// Polynomial coefficients (joint unit per sⁱ).
pub const COEFFICIENT: Plausible = range(-1e6, 1e6, "");
/// Source frequencies (`sine`, `random-sine`).
pub const FREQUENCY: Plausible = range(0.0, 1e6, "Hz");
/// Setpoint smoothing natural frequency.
pub const SMOOTHING_FREQUENCY: Plausible = range(0.0, 1e6, "rad/s");
/// Setpoint smoothing damping ratio.
pub const DAMPING: Plausible = range(0.0, 1e3, "");
/// `control.settling_time`.
pub const SETTLING_TIME: Plausible = range(1e-4, 1e4, "s");
/// `control.pole_ratio`.
pub const POLE_RATIO: Plausible = range(1.0, 1e3, "");
/// `control.gains` (explicit `[kp, ki, kd]`).
pub const GAIN: Plausible = range(-1e12, 1e12, "");
/// `control.external_acceleration` (reported only).
pub const EXTERNAL_ACCELERATION: Plausible = range(0.0, 1e6, "g");
/// `control.oscillation_rate` (reported only).
pub const OSCILLATION_RATE: Plausible = range(0.0, 1e6, "rad/s");
/// `field.reference` components (1 T in µT).
pub const FIELD: Plausible = range(-1e6, 1e6, "field unit");
/// Every sensor error term (`[sensors.*]` vectors and matrices) and `perturbation.direction`.
pub const SENSOR_TERM: Plausible = range(-1e6, 1e6, "");
/// `bias_instability.correlation_time`.
pub const CORRELATION_TIME: Plausible = range(0.0, 1e9, "s");
/// Temperatures (`sensors.temperature[0]`, `temperature_bias.reference`).
pub const TEMPERATURE: Plausible = range(-273.15, 1e3, "°C");
/// `sensors.temperature[1]`.
pub const TEMPERATURE_SLOPE: Plausible = range(-1e3, 1e3, "°C/s");
/// `perturbation.amplitude`.
pub const PERTURBATION_AMPLITUDE: Plausible = range(0.0, 1e6, "field unit");

/// Motor speeds of `[[vibration.tones]]` (`rpm`, ramps, steps, CSV rows).
pub const RPM: Plausible = range(0.0, 1e6, "rpm");
/// Harmonic orders of `[[vibration.tones.harmonics]]`.
pub const HARMONIC_ORDER: Plausible = range(0.0, 1e3, "");
/// Linear vibration amplitudes (tone harmonics, shock peaks).
pub const VIBRATION_LINEAR: Plausible = range(-1e6, 1e6, "m/s²");
/// Angular vibration amplitudes (tone harmonics, shock peaks).
pub const VIBRATION_ANGULAR: Plausible = range(-1e4, 1e4, "rad/s");
/// Random vibration PSD values.
pub const PSD_VALUE: Plausible = range(0.0, 1e6, "g²/Hz");
/// Random vibration `gains`.
pub const VIBRATION_GAIN: Plausible = range(0.0, 1e3, "");

impl Plausible {
    /// Whether `x` lies in the range.
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// The range as text, e.g. `[1e-6, 1e6] kg`.
    pub fn describe(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("[{}, {}]{unit}", number(self.lo), number(self.hi))
    }

    /// The refusal of a finite `x` outside the range, at key path `at`.
    pub(crate) fn check(&self, x: f64, at: &[&str]) -> Result<(), Violation> {
        if self.contains(x) {
            Ok(())
        } else {
            Err(Violation::at(at, self.refusal(x)))
        }
    }

    /// Why `x` is refused.
    pub fn refusal(&self, x: f64) -> String {
        format!(
            "{} is outside the plausible range {}",
            number(x),
            self.describe()
        )
    }
}

/// `x` in plain notation between 10⁻³ and 10⁴, in scientific notation beyond (never the
/// 309 digits `{}` prints for 1e308).
pub fn number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e4).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_read_naturally() {
        assert_eq!(MASS.describe(), "[1e-6, 1e6] kg");
        assert_eq!(GRAVITY.describe(), "[0, 1000] m/s²");
        assert_eq!(POLE_RATIO.describe(), "[1, 1000]");
        assert_eq!(TEMPERATURE.describe(), "[-273.15, 1000] °C");
    }

    /// The user guide's table lists every range as the code defines it.
    #[test]
    fn the_guide_lists_every_range() {
        let guide = include_str!("../../../docs/scenes.md");
        let all = [
            TIME,
            SOURCE_TIME,
            RATE,
            STEP,
            MASS,
            INERTIA,
            VISCOUS_FRICTION,
            STATIC_FRICTION,
            EFFORT,
            GRAVITY,
            JOINT_VALUE,
            COEFFICIENT,
            FREQUENCY,
            SMOOTHING_FREQUENCY,
            DAMPING,
            SETTLING_TIME,
            POLE_RATIO,
            GAIN,
            EXTERNAL_ACCELERATION,
            OSCILLATION_RATE,
            FIELD,
            SENSOR_TERM,
            CORRELATION_TIME,
            TEMPERATURE,
            TEMPERATURE_SLOPE,
            PERTURBATION_AMPLITUDE,
            RPM,
            HARMONIC_ORDER,
            VIBRATION_LINEAR,
            VIBRATION_ANGULAR,
            PSD_VALUE,
            VIBRATION_GAIN,
        ];
        for range in all {
            let cell = format!("| {} |", range.describe());
            assert!(guide.contains(&cell), "docs/scenes.md lacks {cell}");
        }
        assert_eq!(
            MASS.refusal(1e308),
            "1e308 is outside the plausible range [1e-6, 1e6] kg"
        );
    }
}
