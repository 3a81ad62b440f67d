//! Shared helpers of the integration tests: static inputs, attitudes, and a paper-like synthetic
//! scene driven through the project's own sensor model and magnetic perturbation generator.
#![allow(dead_code)]

use margemu_filters::quat::{from_euler_zyx, mul, world_to_body, Quat};
use margemu_filters::{Imu, Real};
use margemu_model::perturbation::{Complex, Perturbation, PerturbationConfig, PerturbationPlan};
use margemu_model::sensor::{Marg, MargConfig, Truth};
use std::f64::consts::{PI, TAU};

pub const G: f64 = 9.80665;
pub const MAG_REF: [f64; 3] = [0.5, 0.0, -0.83];

/// Attitudes (roll, pitch, yaw) for static tests, with the hard cases: yaw near ±π, pitch near
/// ±80°, upside down.
pub fn attitudes() -> Vec<[f64; 3]> {
    let d = PI / 180.0;
    vec![
        [0.0, 0.0, 0.0],
        [0.3, -0.2, 2.0],
        [0.1, 0.2, PI - 1e-3],
        [-0.2, 0.1, -PI + 1e-3],
        [0.3, 80.0 * d, 1.0],
        [-0.5, -80.0 * d, -2.5],
        [0.4, 79.5 * d, PI - 2e-3],
        [3.0, 0.2, 0.5],
    ]
}

/// The noise-free reading of a plate at rest with attitude `q`, in `T`.
pub fn static_imu<T: Real>(q: [f64; 4], gyro: [f64; 3]) -> Imu<T> {
    let v = |a: [f64; 3]| a.map(T::from_f64);
    Imu {
        gyro: v(gyro),
        acc: v(world_to_body(q, [0.0, 0.0, G])),
        mag: v(world_to_body(q, MAG_REF)),
    }
}

/// `q` turned by `angle` about the unit body `axis`.
pub fn turned(q: Quat<f64>, axis: [f64; 3], angle: f64) -> Quat<f64> {
    let (s, c) = (0.5 * angle).sin_cos();
    mul(q, [c, s * axis[0], s * axis[1], s * axis[2]])
}

/// Euler angles and their first derivatives of a sum of sines `Σ a·sin(2π f t + φ) + rate·t`.
fn angle(t: f64, terms: &[(f64, f64, f64)], rate: f64) -> (f64, f64) {
    let mut v = rate * t;
    let mut d = rate;
    for &(a, f, p) in terms {
        let w = TAU * f;
        v += a * (w * t + p).sin();
        d += a * w * (w * t + p).cos();
    }
    (v, d)
}

/// A paper-like scene at `rate` Hz (section 3.2): white noise of the paper's densities, body rates
/// oscillating up to about ±50 rad/s, external accelerations up to ±4 g switched on half of the
/// time, and magnetic bursts of 0–4 field units (the model's default perturbation).
pub struct Scene {
    rate: f64,
    k: u64,
    marg: Marg,
    pert: Perturbation<Vec<Complex>, Vec<f32>>,
    /// External accelerations on (the paper's ±4 g) or off.
    pub external_acceleration: bool,
    /// Magnetic bursts on or off.
    pub magnetic_bursts: bool,
}

impl Scene {
    pub fn new(rate: f64, seed: u64) -> Self {
        let mut cfg = MargConfig::default();
        cfg.gyro.errors.noise_density = Some([0.0224; 3]);
        cfg.accel.errors.noise_density = Some([0.0224; 3]);
        cfg.mag.errors.noise_density = Some([0.0022; 3]);
        let plan = PerturbationPlan::new(&PerturbationConfig::default(), rate).unwrap();
        let scratch = vec![Complex::ZERO; plan.scratch_len()];
        let signal = vec![0.0f32; plan.signal_len()];
        Self {
            rate,
            k: 0,
            marg: Marg::new(&cfg, rate, seed).unwrap(),
            pert: Perturbation::new(&plan, seed, scratch, signal).unwrap(),
            external_acceleration: true,
            magnetic_bursts: true,
        }
    }

    /// The next sample: the true attitude and what the MARG unit reads.
    pub fn next(&mut self) -> (Quat<f64>, Imu<f32>) {
        let t = self.k as f64 / self.rate;
        self.k += 1;
        let (phi, dphi) = angle(t, &[(0.6, 9.0, 0.0), (0.4, 0.37, 1.0)], 0.0);
        let (theta, dtheta) = angle(t, &[(0.4, 11.0, 1.0), (0.3, 0.23, 0.0)], 0.0);
        let (psi, dpsi) = angle(t, &[(0.7, 8.0, 2.0)], 0.5);
        let q = from_euler_zyx([phi, theta, psi]);
        let (sp, cp, st, ct) = (phi.sin(), phi.cos(), theta.sin(), theta.cos());
        let rate = [
            dphi - dpsi * st,
            dtheta * cp + dpsi * ct * sp,
            -dtheta * sp + dpsi * ct * cp,
        ];
        let gate = if self.external_acceleration {
            (TAU * 0.05 * t).sin().max(0.0)
        } else {
            0.0
        };
        let a_w = [
            4.0 * G * gate * (TAU * 1.3 * t).sin(),
            4.0 * G * gate * (TAU * 0.7 * t + 1.0).sin(),
            4.0 * G * gate * (TAU * 1.1 * t + 2.0).sin(),
        ];
        let f = world_to_body(q, [a_w[0], a_w[1], a_w[2] + G]);
        let mut m = world_to_body(q, MAG_REF).map(|c| c as f32);
        let d = self.pert.sample();
        if self.magnetic_bursts {
            m = [m[0] + d[0], m[1] + d[1], m[2] + d[2]];
        }
        let s = self.marg.sample(&Truth {
            angular_rate: rate.map(|c| c as f32),
            specific_force: f.map(|c| c as f32),
            magnetic_field: m,
            ..Truth::default()
        });
        (
            q,
            Imu {
                gyro: s.gyr,
                acc: s.acc,
                mag: s.mag,
            },
        )
    }
}

/// An `f32` sample in `f64`.
pub fn widen(imu: &Imu<f32>) -> Imu<f64> {
    let w = |v: [f32; 3]| v.map(f64::from);
    Imu {
        gyro: w(imu.gyro),
        acc: w(imu.acc),
        mag: w(imu.mag),
    }
}

/// Samples the benchmarks replay (`benches/`): the paper-like scene at 200 Hz, seed 3, after
/// its first 2000 samples (so that bursts and accelerations are under way).
pub const BENCH_SAMPLES: usize = 4096;

/// The [`BENCH_SAMPLES`] samples of the benchmarks.
pub fn bench_samples() -> Vec<Imu<f32>> {
    let mut scene = Scene::new(200.0, 3);
    (0..2000 + BENCH_SAMPLES)
        .map(|_| scene.next().1)
        .skip(2000)
        .collect()
}
