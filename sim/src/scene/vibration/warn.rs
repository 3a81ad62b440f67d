//! Vibration inputs that are legal but likely wrong: a shock that starts after the run ends,
//! and content above the output Nyquist frequency on the output path (the samples alias it).

use super::at::At;
use super::{DeviceVibration, SamplingPath, VibrationSpec};
use crate::scene::error::Violation;
use crate::scene::ranges::number;
use crate::scene::rig::Device;

/// The warnings of a resolved `[vibration]` (`vibration` per device of `devices`), for a scene
/// at output `rate` Hz lasting `duration` s.
pub(crate) fn collect(
    spec: &VibrationSpec,
    devices: &[Device],
    vibration: &[DeviceVibration],
    rate: f64,
    duration: f64,
) -> Vec<Violation> {
    let mut out = Vec::new();
    for (i, shock) in spec.shocks.iter().enumerate() {
        if shock.at >= duration {
            let at = At::root().key("shocks").index(i).key("at");
            out.push(at.error(format!(
                "the shock starts at {} s, not before the run ends ({} s): it never happens",
                number(shock.at),
                number(duration)
            )));
        }
    }
    let nyquist = rate / 2.0;
    let aliased: Vec<String> = devices
        .iter()
        .zip(vibration)
        .map(|(d, v)| (d, v.max_frequency_hz()))
        .filter(|(_, top)| *top > nyquist)
        .map(|(d, top)| format!("`{}` up to {} Hz", d.name, number(top)))
        .collect();
    if spec.path == SamplingPath::Output && !aliased.is_empty() {
        out.push(Violation::at(
            &["vibration", "path"],
            format!(
                "vibration reaches above the output Nyquist frequency {} Hz ({}): on the output \
                 path the samples alias it",
                number(nyquist),
                aliased.join(", ")
            ),
        ));
    }
    out
}
