//! Inputs that are legal but likely wrong. Loading collects them, located like errors
//! ([`super::SceneWarning`]); commands print them once, to stderr, and go on.
//!
//! - a sine (or the top of a random-sine frequency range) above the output Nyquist frequency:
//!   the samples alias it;
//! - a perturbation window longer than the scene: no burst ends within the run;
//! - a zero reference field: the magnetometer reads nothing but its error terms.

use super::error::Violation;
use super::ranges::number;
use super::schema::{SceneSpec, SourceSpec};

/// The warnings of a validated scene, in file order of their sections.
pub(crate) fn collect(spec: &SceneSpec) -> Vec<Violation> {
    let mut out = Vec::new();
    if spec.field.reference == [0.0; 3] {
        out.push(Violation::at(
            &["field", "reference"],
            "the reference field is zero: the magnetometer reads only its error terms and \
             the perturbation",
        ));
    }
    let nyquist = spec.rate / 2.0;
    for (name, source) in &spec.joints {
        let top = match source {
            SourceSpec::Sine { frequency, .. } => *frequency,
            SourceSpec::RandomSine { frequency, .. } => frequency[1],
            _ => continue,
        };
        if top > nyquist {
            out.push(Violation::at_keys(
                vec!["joints".into(), name.clone(), "frequency".into()],
                format!(
                    "{} Hz is above the output Nyquist frequency {} Hz (rate {} Hz): the \
                     samples alias it",
                    number(top),
                    number(nyquist),
                    number(spec.rate)
                ),
            ));
        }
    }
    if let Some(p) = &spec.perturbation {
        if p.window > spec.duration {
            out.push(Violation::at(
                &["perturbation", "window"],
                format!(
                    "the {} s burst window is longer than the scene ({} s): no burst ends \
                     within the run",
                    number(p.window),
                    number(spec.duration)
                ),
            ));
        }
    }
    out
}
