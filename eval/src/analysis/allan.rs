//! Overlapping Allan deviation.
//!
//! For a rate signal `y` sampled every `τ₀`, the integrated signal `θ_k = τ₀ Σ_{i<k} y_i` gives
//! `σ²(mτ₀) = Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2 (mτ₀)² (N − 2m))`. τ runs over about ten
//! log-spaced cluster sizes per decade from `τ₀` to `N τ₀ / 10`.

/// One point of an Allan deviation curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AllanPoint {
    /// Averaging time (s).
    pub tau: f64,
    /// Allan deviation (unit of the signal).
    pub adev: f64,
    /// Number of terms averaged (the estimate's confidence grows with it).
    pub terms: usize,
}

/// Overlapping Allan deviation of `y` sampled at `rate` Hz.
pub fn overlapping(y: &[f64], rate: f64) -> Vec<AllanPoint> {
    let n = y.len();
    let tau0 = 1.0 / rate;
    let mut theta = Vec::with_capacity(n + 1);
    let mut sum = 0.0;
    theta.push(0.0);
    for &v in y {
        sum += v * tau0;
        theta.push(sum);
    }
    cluster_sizes(n / 10)
        .into_iter()
        .map(|m| {
            let terms = n + 1 - 2 * m;
            let mut acc = 0.0;
            for k in 0..terms {
                let d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
                acc += d * d;
            }
            let tau = m as f64 * tau0;
            AllanPoint {
                tau,
                adev: (acc / (2.0 * tau * tau * terms as f64)).sqrt(),
                terms,
            }
        })
        .collect()
}

/// Log-spaced cluster sizes from 1 to `max` (about ten per decade, no repeats).
fn cluster_sizes(max: usize) -> Vec<usize> {
    let mut sizes = Vec::new();
    let mut m = 1.0f64;
    while m as usize <= max {
        let k = m as usize;
        if sizes.last() != Some(&k) {
            sizes.push(k);
        }
        m *= 10f64.powf(0.1);
    }
    sizes
}

/// The Allan deviation at `tau`, interpolated log-log between the nearest points.
pub fn at(points: &[AllanPoint], tau: f64) -> Option<f64> {
    let i = points
        .windows(2)
        .position(|w| w[0].tau <= tau && tau <= w[1].tau)?;
    let (a, b) = (points[i], points[i + 1]);
    let w = (tau / a.tau).ln() / (b.tau / a.tau).ln();
    Some((a.adev.ln() * (1.0 - w) + b.adev.ln() * w).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_falls_as_one_over_root_tau() {
        // σ = N·√fs gives ADEV(1 s) = N.
        let (rate, density) = (100.0, 0.02);
        let mut rng = margemu_model::rng::stream(5, "test/allan");
        let sigma = density * f64::sqrt(rate);
        let y: Vec<f64> = (0..200_000).map(|_| sigma * gaussian(&mut rng)).collect();
        let points = overlapping(&y, rate);
        let one = at(&points, 1.0).unwrap();
        assert!((one / density - 1.0).abs() < 0.05, "ADEV(1 s) = {one}");
        let ten = at(&points, 10.0).unwrap();
        assert!(
            (ten / (density / 10f64.sqrt()) - 1.0).abs() < 0.15,
            "ADEV(10 s) = {ten}"
        );
        assert!(points.last().unwrap().tau <= 200.0 + 1e-9);
    }

    #[test]
    fn a_constant_has_zero_deviation() {
        let points = overlapping(&[3.0; 1000], 10.0);
        assert!(points.iter().all(|p| p.adev < 1e-12));
    }

    fn gaussian(rng: &mut margemu_model::rng::StreamRng) -> f64 {
        // Box–Muller on two uniforms (test helper only).
        let u1 = margemu_model::rng::unit_f64(rng).max(1e-300);
        let u2 = margemu_model::rng::unit_f64(rng);
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}
