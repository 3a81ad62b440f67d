//! The EKF against its straightforward implementation (`common/ekf_reference.rs`, the filter as
//! it was before its covariance arithmetic used the structure of `Φ`, `H` and `P`): on long, hard
//! trajectories both must give the same estimates, within 1e-6 rad (geodesic) in `f64` at every
//! sample, the same bias and covariance to rounding, and the same diagnostics.

mod common;

use common::{widen, Scene, G, MAG_REF};
use margemu_filters::quat::{from_euler_zyx, geodesic_angle, mul, world_to_body, Quat};
use margemu_filters::{AttitudeFilter, Ekf, EkfConfig, Imu, Initial};

#[path = "common/ekf_reference.rs"]
mod ekf_reference;
use ekf_reference::ReferenceEkf;

const DT: f64 = 0.005;

/// The largest differences seen over a run.
#[derive(Debug, Default)]
struct Worst {
    angle: f64,
    bias: f64,
    /// Covariance entry difference relative to the largest entry of the reference at that step.
    cov: f64,
}

/// Runs both filters over `samples` and returns the worst differences; panics on any
/// difference in diagnostics.
fn compare(cfg: &EkfConfig, samples: &[Imu<f64>]) -> Worst {
    let mut fast = Ekf::<f64>::new(cfg).unwrap();
    let mut slow = ReferenceEkf::<f64>::new(cfg);
    let mut worst = Worst::default();
    for (n, imu) in samples.iter().enumerate() {
        fast.update(imu, DT);
        slow.update(imu, DT);
        worst.angle = worst
            .angle
            .max(geodesic_angle(fast.quaternion(), slow.quaternion()));
        let (bf, bs) = (fast.bias(), slow.bias());
        for i in 0..3 {
            worst.bias = worst.bias.max((bf[i] - bs[i]).abs());
        }
        let (pf, ps) = (fast.covariance(), slow.covariance());
        let scale = ps.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for i in 0..7 {
            for j in 0..7 {
                assert_eq!(pf[i][j], pf[j][i], "sample {n}: not symmetric");
                worst.cov = worst.cov.max((pf[i][j] - ps[i][j]).abs() / scale);
            }
        }
        assert_eq!(fast.diagnostics(), slow.diagnostics(), "sample {n}");
    }
    worst
}

fn assert_same(name: &str, w: &Worst) {
    println!("{name}: {w:?}");
    assert!(
        w.angle <= 1e-6,
        "{name}: attitude differs by {} rad",
        w.angle
    );
    assert!(w.bias <= 1e-6, "{name}: bias differs by {} rad/s", w.bias);
    assert!(
        w.cov <= 1e-9,
        "{name}: covariance differs by {} (relative)",
        w.cov
    );
}

/// A small deterministic noise source (xorshift64*), uniform in [−1, 1].
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn vec(&mut self, amplitude: f64) -> [f64; 3] {
        [0; 3].map(|_| amplitude * self.next())
    }
}

/// Samples of the attitude trajectory `attitude(t)` with a constant gyroscope `bias`: the body
/// rate from the quaternion's difference over one step, the specific force from gravity plus
/// `external(t)` (world, m/s²), the field from the reference plus `disturbance(t)` (body), and
/// white noise on all three.
fn trajectory(
    seconds: f64,
    attitude: impl Fn(f64) -> Quat<f64>,
    bias: [f64; 3],
    external: impl Fn(f64) -> [f64; 3],
    disturbance: impl Fn(f64) -> [f64; 3],
    seed: u64,
) -> Vec<Imu<f64>> {
    let mut noise = Noise(seed);
    let n = (seconds / DT) as usize;
    (0..n)
        .map(|k| {
            let t = k as f64 * DT;
            let (q0, q1) = (attitude(t - DT), attitude(t));
            // ω = 2·vec(q0* ⊗ q1) / dt (first order, the filter's own model).
            let d = mul([q0[0], -q0[1], -q0[2], -q0[3]], q1);
            let sign = if d[0] < 0.0 { -1.0 } else { 1.0 };
            let g = noise.vec(0.02);
            let gyro = [0, 1, 2].map(|i| sign * 2.0 * d[1 + i] / DT + bias[i] + g[i]);
            let a = external(t);
            let acc = world_to_body(q1, [a[0], a[1], a[2] + G]);
            let (na, nm, m) = (noise.vec(0.05), noise.vec(0.005), disturbance(t));
            let mag = world_to_body(q1, MAG_REF);
            Imu {
                gyro,
                acc: [0, 1, 2].map(|i| acc[i] + na[i]),
                mag: [0, 1, 2].map(|i| mag[i] + m[i] + nm[i]),
            }
        })
        .collect()
}

fn none(_: f64) -> [f64; 3] {
    [0.0; 3]
}

/// The paper-like scene (±50 rad/s oscillations, ±4 g external accelerations, magnetic bursts)
/// for ten minutes, with a large constant gyroscope bias added.
#[test]
fn paper_scene_with_large_bias() {
    let mut scene = Scene::new(200.0, 11);
    let bias = [0.3, -0.25, 0.2];
    let samples: Vec<Imu<f64>> = (0..120_000)
        .map(|_| {
            let mut imu = widen(&scene.next().1);
            for (g, b) in imu.gyro.iter_mut().zip(bias) {
                *g += b;
            }
            imu
        })
        .collect();
    let w = compare(&EkfConfig::default(), &samples);
    assert_same("paper scene, large bias", &w);
}

/// Fast rotation: a spin of up to 35 rad/s about a wandering axis, with magnetic steps of twice
/// the field and bursts of external acceleration, for five minutes, in the default tuning and in
/// one that trusts the vectors and lets the bias move fast.
#[test]
fn fast_rotation_with_magnetic_disturbance() {
    let attitude = |t: f64| {
        from_euler_zyx([
            25.0 * t + 0.5 * (3.0 * t).sin(),
            0.6 * (1.7 * t).sin(),
            -35.0 * t * (0.1 * t).cos(),
        ])
    };
    let external = |t: f64| {
        let on = if (t * 0.2).sin() > 0.5 { 2.0 * G } else { 0.0 };
        [on * (9.0 * t).sin(), on * (7.0 * t).cos(), 0.5 * on]
    };
    let disturbance = |t: f64| {
        if (t as u64 / 7) % 3 == 1 {
            [1.2, -0.8, 0.9]
        } else {
            [0.0; 3]
        }
    };
    let samples = trajectory(
        300.0,
        attitude,
        [0.05, 0.1, -0.08],
        external,
        disturbance,
        7,
    );
    assert_same(
        "fast rotation, default",
        &compare(&EkfConfig::default(), &samples),
    );
    let trusting = EkfConfig {
        accel_noise: 0.05,
        mag_noise: 0.05,
        gyro_bias_walk: 1e-2,
        ..EkfConfig::default()
    };
    assert_same("fast rotation, trusting", &compare(&trusting, &samples));
}

/// Near gimbal lock: pitch within a milliradian of ±90° for long stretches (where yaw and roll
/// are degenerate), yaw and roll turning, magnetic disturbance, a large bias; started from a
/// given attitude and with missing accelerometer and magnetometer samples.
#[test]
fn near_gimbal_lock() {
    let half_pi = core::f64::consts::FRAC_PI_2;
    let attitude = |t: f64| {
        let pitch = half_pi - 1e-3 * (1.0 + (0.3 * t).sin()) - if t > 150.0 { 3.0 } else { 0.0 };
        from_euler_zyx([2.0 * (0.5 * t).sin(), pitch, 1.5 * t])
    };
    let disturbance = |t: f64| [0.6 * (0.7 * t).sin(), 0.0, 0.4 * (1.3 * t).cos()];
    let mut samples = trajectory(300.0, attitude, [-0.4, 0.35, 0.3], none, disturbance, 99);
    for (k, imu) in samples.iter_mut().enumerate() {
        if k % 97 == 0 {
            imu.acc = [0.0; 3];
        }
        if k % 89 == 0 {
            imu.mag = [f64::NAN; 3];
        }
    }
    let cfg = EkfConfig {
        initial: Initial::Attitude(attitude(0.0)),
        initial_bias_std: 0.5,
        ..EkfConfig::default()
    };
    assert_same("near gimbal lock", &compare(&cfg, &samples));
}

/// The bench's scene in `f32` (the precision of the embedded target): the estimates stay
/// together there too, to the rounding of `f32` amplified by the filter.
#[test]
fn f32_estimates_match() {
    let mut scene = Scene::new(200.0, 3);
    let samples: Vec<Imu<f32>> = (0..60_000).map(|_| scene.next().1).collect();
    let cfg = EkfConfig::default();
    let mut fast = Ekf::<f32>::new(&cfg).unwrap();
    let mut slow = ReferenceEkf::<f32>::new(&cfg);
    let mut worst = 0.0f32;
    for imu in &samples {
        fast.update(imu, 0.005);
        slow.update(imu, 0.005);
        worst = worst.max(geodesic_angle(fast.quaternion(), slow.quaternion()));
    }
    println!("f32: {worst} rad");
    assert!(worst < 1e-3, "f32: attitude differs by {worst} rad");
    assert_eq!(fast.diagnostics(), slow.diagnostics());
}
