//! Phase magnitudes and norms from measured (noisy) signals; see [`super::phase`] for the rules.

use super::input::Imu;
use super::phase::{moving_mean, PhaseRules, PhaseSample};
use super::run::Norms;

/// Standard gravity (m/s²), the norm of the specific force at rest.
const STANDARD_GRAVITY: f64 = 9.80665;

fn norm(v: &[f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Half the averaging window in samples of a series stamped `t_ns`.
fn half_window(t_ns: &[u64], window_ns: u64) -> usize {
    let mut steps: Vec<u64> = t_ns.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_unstable();
    let step = steps.get(steps.len() / 2).copied().unwrap_or(1).max(1);
    (window_ns / step / 2) as usize
}

/// `|mean(measured − true)| / |true|` per instant, the mean over the window.
pub fn measured_field_deviation(
    t_ns: &[u64],
    measured: &[[f64; 3]],
    truth: &[[f64; 3]],
    window_ns: u64,
) -> Vec<f64> {
    let diff: Vec<[f64; 3]> = measured
        .iter()
        .zip(truth)
        .map(|(m, f)| [0, 1, 2].map(|i| m[i] - f[i]))
        .collect();
    moving_mean(&diff, half_window(t_ns, window_ns))
        .iter()
        .zip(truth)
        .map(|(d, f)| norm(d) / norm(f).max(1e-12))
        .collect()
}

/// Phase magnitudes of an external recording: window means of the gyro vector, of
/// `|a| − g` (standard gravity) and of `|m| − median |m|` (relative to that median).
pub fn external_phases(imu: &Imu, rules: &PhaseRules) -> Vec<PhaseSample> {
    let half = half_window(&imu.t_ns, rules.window_ns);
    let g = STANDARD_GRAVITY;
    let mut mag_norms: Vec<f64> = imu.mag.iter().map(norm).collect();
    let rate = moving_mean(&imu.gyr, half);
    let accel: Vec<[f64; 1]> = imu.acc.iter().map(|a| [norm(a) - g]).collect();
    let accel = moving_mean(&accel, half);
    let field: Vec<[f64; 1]> = imu.mag.iter().map(|m| [norm(m)]).collect();
    mag_norms.sort_by(f64::total_cmp);
    let reference = mag_norms
        .get(mag_norms.len() / 2)
        .copied()
        .unwrap_or(1.0)
        .max(1e-12);
    let field = moving_mean(&field, half);
    (0..imu.t_ns.len())
        .map(|k| PhaseSample {
            rate: norm(&rate[k]),
            accel: accel[k][0].abs(),
            field: (field[k][0] - reference).abs() / reference,
        })
        .collect()
}

/// Accelerometer and magnetometer norms of a series.
pub fn norms(source: &str, t_ns: &[u64], acc: &[[f64; 3]], mag: &[[f64; 3]]) -> Norms {
    let mut norms = Norms::new(source);
    for ((&t, a), m) in t_ns.iter().zip(acc).zip(mag) {
        norms.push(t, a, m);
    }
    norms
}
