//! Cost per 9-axis sample: (a) the ideal path, (b) the paper's model (eq. 18 with white noise,
//! plus the magnetic perturbation), (c) every term on, plus the perturbation.
//!
//! `cargo bench -p margemu-model -- --warm-up-time 1 --measurement-time 3`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use margemu_model::perturbation::{
    Amplitude, Complex, Perturbation, PerturbationConfig, PerturbationPlan,
};
use margemu_model::sensor::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, Marg, MargConfig, SensorErrors,
    TemperatureBias, Truth,
};
use margemu_model::vec3::add;
use std::hint::black_box;

fn truth() -> Truth {
    Truth {
        angular_rate: [0.3, -0.2, 0.5],
        specific_force: [0.1, 0.2, 9.80665],
        magnetic_field: [0.5, 0.0, -0.83],
        angular_acceleration: [0.6, 0.0, -0.5],
        temperature_c: Some(30.0),
    }
}

/// Eq. 18 with every one of its terms, the paper's noise densities (section 3.2).
fn paper_config() -> MargConfig {
    let eq18 = |density: f64| SensorErrors {
        scale_factor: Some([[0.01, 0.0, 0.0], [0.0, -0.02, 0.0], [0.0, 0.0, 0.015]]),
        misalignment: Some([
            [1.0, 0.003, -0.002],
            [-0.001, 1.0, 0.004],
            [0.002, -0.003, 1.0],
        ]),
        bias: Some([0.02, -0.01, 0.03]),
        noise_density: Some([density; 3]),
        ..SensorErrors::default()
    };
    MargConfig {
        gyro: GyroConfig {
            errors: eq18(0.0224),
            g_sensitivity: None,
        },
        accel: AccelConfig {
            errors: eq18(0.0224),
            lever_arm_m: None,
        },
        mag: MagConfig {
            errors: eq18(0.0022),
            soft_iron: Some([[1.05, 0.02, 0.0], [0.02, 0.97, 0.01], [0.0, 0.01, 1.01]]),
            hard_iron: Some([0.1, -0.05, 0.2]),
        },
    }
}

/// Every term on.
fn full_config() -> MargConfig {
    let mut cfg = paper_config();
    for e in [
        &mut cfg.gyro.errors,
        &mut cfg.accel.errors,
        &mut cfg.mag.errors,
    ] {
        e.bias_instability = Some(BiasInstability {
            coefficient: [0.002; 3],
            correlation_time_s: 100.0,
        });
        e.rate_random_walk = Some([1e-4; 3]);
        e.temperature_bias = Some(TemperatureBias {
            coefficient: [1e-3; 3],
            reference_c: 25.0,
        });
        e.resolution = Some([1.0 / 16384.0; 3]);
        e.range = Some([40.0; 3]);
    }
    cfg.gyro.g_sensitivity = Some([[1e-3, 0.0, 0.0], [0.0, 1e-3, 0.0], [0.0, 0.0, 1e-3]]);
    cfg.accel.lever_arm_m = Some([0.02, -0.01, 0.05]);
    cfg
}

fn with_perturbation(c: &mut Criterion, name: &str, cfg: &MargConfig, rate: f64) {
    let mut marg = Marg::new(cfg, rate, 42).unwrap();
    let pcfg = PerturbationConfig {
        amplitude: Amplitude::Reference,
        ..PerturbationConfig::default()
    };
    let plan = PerturbationPlan::new(&pcfg, rate).unwrap();
    let mut scratch = vec![Complex::ZERO; plan.scratch_len()];
    let mut signal = vec![0.0f32; plan.signal_len()];
    let mut pert = Perturbation::new(&plan, 42, &mut scratch, &mut signal).unwrap();
    let base = truth();
    c.bench_function(name, |b| {
        b.iter(|| {
            let mut t = black_box(base);
            let d = pert.sample();
            t.magnetic_field = add(t.magnetic_field, d);
            black_box((marg.sample(&t), d))
        })
    });
}

fn parts(c: &mut Criterion) {
    let mut rng = margemu_model::rng::stream(1, "bench");
    c.bench_function("part_chacha8_next_u32", |b| {
        b.iter(|| black_box(rand_core::Rng::next_u32(&mut rng)))
    });
    c.bench_function("part_standard_normal", |b| {
        b.iter(|| black_box(margemu_model::rng::standard_normal(&mut rng)))
    });
    for rate in [200.0, 8000.0] {
        let plan = PerturbationPlan::new(&PerturbationConfig::default(), rate).unwrap();
        let mut scratch = vec![Complex::ZERO; plan.scratch_len()];
        let mut shaper =
            margemu_model::perturbation::BurstShaper::new(&plan, &mut scratch).unwrap();
        let mut out = vec![0.0f32; plan.window_len()];
        c.bench_function(&format!("part_burst_shape_n{}", plan.window_len()), |b| {
            b.iter(|| black_box(shaper.shape(&mut rng, &mut out).unwrap()))
        });
    }
}

fn bench(c: &mut Criterion) {
    let mut ideal = Marg::new(&MargConfig::default(), 200.0, 42).unwrap();
    let t = truth();
    c.bench_function("a_ideal", |b| {
        b.iter(|| black_box(ideal.sample(black_box(&t))))
    });

    let mut paper_only = Marg::new(&paper_config(), 200.0, 42).unwrap();
    c.bench_function("b0_eq18_no_perturbation", |b| {
        b.iter(|| black_box(paper_only.sample(black_box(&t))))
    });
    with_perturbation(c, "b_paper_eq18_perturbation_200hz", &paper_config(), 200.0);
    with_perturbation(c, "b_paper_eq18_perturbation_8khz", &paper_config(), 8000.0);
    with_perturbation(c, "c_full_perturbation_200hz", &full_config(), 200.0);
    with_perturbation(c, "c_full_perturbation_8khz", &full_config(), 8000.0);
}

criterion_group!(benches, bench, parts);
criterion_main!(benches);
