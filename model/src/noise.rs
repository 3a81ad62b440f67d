//! Stochastic error processes per axis: white noise, bias instability, rate random walk.
//!
//! Each process owns one [`StreamRng`] and draws, per sample, one [`standard_normal`] per axis in
//! the order x, y, z. Its coefficients are computed once in `f64` from the configuration and the
//! output rate `fs`, then stored as `f32`; the per-sample update is `f32` only.
//!
//! # Conventions
//! - **White noise** (eq. 18's μ, ν, ε) is given as a *noise density* `N` in unit/√Hz and becomes
//!   the per-sample standard deviation `σ = N·√fs` (the Kalibr convention). Then the Allan
//!   deviation is `N/√τ`, so it equals `N` at τ = 1 s; the *two-sided* PSD is `N²` over
//!   `[-fs/2, fs/2]` and the *one-sided* PSD is `2·N²` (unit²/Hz) over `[0, fs/2]`. A datasheet
//!   that quotes a one-sided amplitude density `A` corresponds to `N = A/√2`.
//! - **Bias instability** is a first-order Gauss–Markov process per axis with correlation time
//!   `T`: `b[k+1] = φ·b[k] + σ_b·√(1−φ²)·w[k]`, `φ = exp(−1/(fs·T))`, started from its stationary
//!   distribution. It is configured by the IEEE Std 952 bias-instability coefficient `B`, whose
//!   Allan floor is `√(2 ln 2/π)·B ≈ 0.664·B` ([`FLICKER_FLOOR_FACTOR`]). The Allan deviation of a
//!   Gauss–Markov process peaks at `0.6174·σ_b` for τ ≈ 1.89·T ([`GAUSS_MARKOV_PEAK`],
//!   [`GAUSS_MARKOV_PEAK_TAU`]), stays within 8 % of that peak for τ in `[0.95 T, 3.8 T]` and
//!   within 20 % for τ in `[0.54 T, 6.2 T]` (a plateau, not the decades-long floor of true
//!   flicker noise: choose `T` so that the plateau covers the τ range of interest); so
//!   `σ_b = 0.664·B / 0.6174 ≈ 1.076·B`, and the floor shows at `0.664·B` around τ = 1.89·T.
//!   (A datasheet that quotes the Allan minimum itself as "bias instability": divide it by 0.664.)
//! - **Rate random walk** `K` in unit/√s: `b[k+1] = b[k] + K/√fs · w[k]`, Allan deviation
//!   `K·√(τ/3)`, started at zero.
//!
//! ```
//! use margemu_model::noise::WhiteNoise;
//! use margemu_model::rng::stream;
//! // 0.0224 (rad/s)/√Hz at 200 Hz, the paper's gyroscope: σ = 0.0224·√200 = 0.3168 rad/s.
//! let mut noise = WhiteNoise::new([0.0224; 3], 200.0, stream(1, "noise/gyro"), "density")?;
//! assert!((noise.sigma()[0] - 0.316_784_4).abs() < 1e-6);
//! let n = 100_000;
//! let var: f64 = (0..n).map(|_| f64::from(noise.sample()[1]).powi(2)).sum::<f64>() / n as f64;
//! assert!((var.sqrt() / 0.316_784_4 - 1.0).abs() < 0.01);
//! # Ok::<(), margemu_model::Error>(())
//! ```

use crate::error::Error;
use crate::rng::{standard_normal, StreamRng};
use crate::vec3::Vec3;

/// Rounds coefficients to `f32`, refusing any that overflow (`what` names the parameter).
fn coefficients(v: [f64; 3], what: &'static str) -> Result<Vec3, Error> {
    let out = v.map(|x| x as f32);
    if out.iter().all(|x| x.is_finite()) {
        Ok(out)
    } else {
        Err(Error::ParameterTooLarge { what })
    }
}

/// `√(2 ln 2 / π)`: the Allan floor of flicker (bias-instability) noise per unit coefficient `B`.
pub const FLICKER_FLOOR_FACTOR: f64 = 0.664_282_470_267_960_1;

/// The peak of the Allan deviation of a first-order Gauss–Markov process per unit of its
/// stationary standard deviation.
pub const GAUSS_MARKOV_PEAK: f64 = 0.617_364_283_144_441_3;

/// Where that peak lies, in units of the correlation time.
pub const GAUSS_MARKOV_PEAK_TAU: f64 = 1.892_617_784_147_588;

/// Three normal draws, x then y then z.
#[inline(always)]
fn normals(rng: &mut StreamRng) -> Vec3 {
    let x = standard_normal(rng);
    let y = standard_normal(rng);
    let z = standard_normal(rng);
    [x, y, z]
}

/// White noise with a per-axis density (unit/√Hz).
#[derive(Clone, Debug)]
pub struct WhiteNoise {
    sigma: Vec3,
    rng: StreamRng,
}

impl WhiteNoise {
    /// White noise of density `density` (unit/√Hz, per axis) at `rate_hz`, both finite and not
    /// negative (the sensor constructors check); `what` names the parameter in errors.
    pub fn new(
        density: [f64; 3],
        rate_hz: f64,
        rng: StreamRng,
        what: &'static str,
    ) -> Result<Self, Error> {
        let root = libm::sqrt(rate_hz);
        Ok(Self {
            sigma: coefficients(density.map(|d| d * root), what)?,
            rng,
        })
    }

    /// The per-sample standard deviation `density·√rate`.
    pub fn sigma(&self) -> Vec3 {
        self.sigma
    }

    /// The next sample.
    #[inline(always)]
    pub fn sample(&mut self) -> Vec3 {
        let w = normals(&mut self.rng);
        [
            self.sigma[0] * w[0],
            self.sigma[1] * w[1],
            self.sigma[2] * w[2],
        ]
    }
}

/// First-order Gauss–Markov bias instability.
#[derive(Clone, Debug)]
pub struct GaussMarkov {
    phi: Vec3,
    drive: Vec3,
    state: Vec3,
    rng: StreamRng,
}

impl GaussMarkov {
    /// Bias instability of coefficient `coefficient` (IEEE Std 952 `B`, per axis, ≥ 0) and
    /// correlation time `correlation_s` (> 0) at `rate_hz` (> 0), as the sensor constructors
    /// check. The state starts from the stationary distribution (one draw per axis here).
    pub fn new(
        coefficient: [f64; 3],
        correlation_s: f64,
        rate_hz: f64,
        mut rng: StreamRng,
        what: &'static str,
    ) -> Result<Self, Error> {
        let x = 1.0 / (rate_hz * correlation_s);
        let phi = libm::exp(-x);
        let one_minus_phi2 = -libm::expm1(-2.0 * x);
        let sigma = coefficient.map(|b| b * FLICKER_FLOOR_FACTOR / GAUSS_MARKOV_PEAK);
        let drive = sigma.map(|s| s * libm::sqrt(one_minus_phi2));
        let w = normals(&mut rng);
        let sigma = coefficients(sigma, what)?;
        Ok(Self {
            phi: [phi as f32; 3],
            drive: coefficients(drive, what)?,
            state: [sigma[0] * w[0], sigma[1] * w[1], sigma[2] * w[2]],
            rng,
        })
    }

    /// The current bias, then one step forward.
    #[inline(always)]
    pub fn sample(&mut self) -> Vec3 {
        let (b, w) = (self.state, normals(&mut self.rng));
        let (phi, q) = (self.phi, self.drive);
        self.state = [
            phi[0] * b[0] + q[0] * w[0],
            phi[1] * b[1] + q[1] * w[1],
            phi[2] * b[2] + q[2] * w[2],
        ];
        b
    }
}

/// Rate random walk: an integrated white noise, starting at zero.
#[derive(Clone, Debug)]
pub struct RandomWalk {
    step: Vec3,
    state: Vec3,
    rng: StreamRng,
}

impl RandomWalk {
    /// A random walk of coefficient `coefficient` (unit/√s, per axis, ≥ 0) at `rate_hz` (> 0).
    pub fn new(
        coefficient: [f64; 3],
        rate_hz: f64,
        rng: StreamRng,
        what: &'static str,
    ) -> Result<Self, Error> {
        let root = libm::sqrt(rate_hz);
        Ok(Self {
            step: coefficients(coefficient.map(|k| k / root), what)?,
            state: [0.0; 3],
            rng,
        })
    }

    /// The current bias, then one step forward.
    #[inline(always)]
    pub fn sample(&mut self) -> Vec3 {
        let (b, w, k) = (self.state, normals(&mut self.rng), self.step);
        self.state = [b[0] + k[0] * w[0], b[1] + k[1] * w[1], b[2] + k[2] * w[2]];
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constants_match_their_formulas() {
        let flicker = libm::sqrt(2.0 * core::f64::consts::LN_2 / core::f64::consts::PI);
        assert!((flicker - FLICKER_FLOOR_FACTOR).abs() < 1e-15);
        // The Gauss–Markov Allan variance: (2/u)(1 − (3 − 4e^{−u} + e^{−2u})/(2u)), u = τ/T.
        let adev = |u: f64| {
            let e = libm::exp(-u);
            libm::sqrt(2.0 / u * (1.0 - (3.0 - 4.0 * e + e * e) / (2.0 * u)))
        };
        let peak = adev(GAUSS_MARKOV_PEAK_TAU);
        assert!((peak - GAUSS_MARKOV_PEAK).abs() < 1e-12);
        assert!(adev(GAUSS_MARKOV_PEAK_TAU * 0.99) < peak);
        assert!(adev(GAUSS_MARKOV_PEAK_TAU * 1.01) < peak);
        assert!(adev(0.95) > 0.92 * peak && adev(3.8) > 0.92 * peak);
    }
}
