//! Arbitrary configurations and inputs, finite or not, never panic: a constructor returns an
//! error or a model, and a model turns any input into a sample.

use margemu_model::perturbation::fft::Fft;
use margemu_model::perturbation::{
    Amplitude, BurstShaper, Complex, Perturbation, PerturbationConfig, PerturbationPlan, Placement,
};
use margemu_model::rng::stream;
use margemu_model::sensor::{
    AccelConfig, BiasInstability, GyroConfig, MagConfig, Marg, MargConfig, SensorErrors,
    TemperatureBias, Truth,
};
use proptest::option::of;
use proptest::prelude::*;

/// Mostly plausible numbers, often the special ones.
fn num() -> BoxedStrategy<f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        1 => 0.0..1e-3f64,
        1 => any::<f64>(),
        1 => prop::sample::select(vec![0.0, -0.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 1e38, f64::MIN_POSITIVE]),
    ]
    .boxed()
}

fn num32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -100.0..100.0f32,
        1 => any::<f32>(),
        1 => prop::sample::select(vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -f32::MAX, 1e30, -1e30]),
    ]
}

/// Plausible positive numbers only: every configuration built from them is valid.
fn plausible() -> BoxedStrategy<f64> {
    (1e-3..10.0f64).boxed()
}

fn vec3() -> BoxedStrategy<[f64; 3]> {
    vec3_of(num)
}

fn vec3_of(n: fn() -> BoxedStrategy<f64>) -> BoxedStrategy<[f64; 3]> {
    prop::array::uniform3(n()).boxed()
}

fn mat3_of(n: fn() -> BoxedStrategy<f64>) -> BoxedStrategy<[[f64; 3]; 3]> {
    prop::array::uniform3(vec3_of(n)).boxed()
}

fn errors(n: fn() -> BoxedStrategy<f64>) -> BoxedStrategy<SensorErrors> {
    let (v, m) = (|| vec3_of(n), || mat3_of(n));
    (
        (of(m()), of(m()), of(v()), of(v())),
        (of((v(), n())), of(v()), of((v(), n())), of(v()), of(v())),
    )
        .prop_map(
            |((scale, mis, bias, density), (bi, rrw, temp, res, range))| SensorErrors {
                scale_factor: scale,
                misalignment: mis,
                bias,
                noise_density: density,
                bias_instability: bi.map(|(c, t)| BiasInstability {
                    coefficient: c,
                    correlation_time_s: t,
                }),
                rate_random_walk: rrw,
                temperature_bias: temp.map(|(c, r)| TemperatureBias {
                    coefficient: c,
                    reference_c: r,
                }),
                resolution: res,
                range,
            },
        )
        .boxed()
}

fn config(n: fn() -> BoxedStrategy<f64>) -> BoxedStrategy<MargConfig> {
    let (v, m) = (|| vec3_of(n), || mat3_of(n));
    (
        errors(n),
        errors(n),
        errors(n),
        of(m()),
        of(v()),
        of(m()),
        of(v()),
    )
        .prop_map(|(g, a, m, gs, lever, soft, hard)| MargConfig {
            gyro: GyroConfig {
                errors: g,
                g_sensitivity: gs,
            },
            accel: AccelConfig {
                errors: a,
                lever_arm_m: lever,
            },
            mag: MagConfig {
                errors: m,
                soft_iron: soft,
                hard_iron: hard,
            },
        })
        .boxed()
}

fn truth() -> impl Strategy<Value = Truth> {
    let v = || prop::array::uniform3(num32());
    (v(), v(), v(), v(), of(num32())).prop_map(|(w, f, h, dw, t)| Truth {
        angular_rate: w,
        specific_force: f,
        magnetic_field: h,
        angular_acceleration: dw,
        temperature_c: t,
    })
}

fn perturbation_config() -> impl Strategy<Value = PerturbationConfig> {
    let amplitude = prop_oneof![
        (num(), num()).prop_map(|(lo, hi)| Amplitude::Uniform { lo, hi }),
        Just(Amplitude::Reference),
    ];
    let placement = prop_oneof![
        Just(Placement::PerAxis),
        Just(Placement::RandomDirection),
        vec3().prop_map(Placement::Direction),
    ];
    let small = prop_oneof![3 => 0.0..0.5f64, 1 => num()];
    (
        prop_oneof![3 => 0.0..3.0f64, 1 => num()],
        num(),
        amplitude,
        (small.clone(), small),
        placement,
    )
        .prop_map(
            |(window_s, cutoff_hz, amplitude, (g0, g1), placement)| PerturbationConfig {
                window_s,
                cutoff_hz,
                amplitude,
                gap_s: [g0, g1],
                placement,
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn marg_never_panics(cfg in config(num), rate in num(), seed in any::<u64>(), inputs in prop::collection::vec(truth(), 1..20)) {
        if let Ok(mut marg) = Marg::new(&cfg, rate, seed) {
            for t in &inputs {
                let _ = marg.sample(t);
            }
        }
    }

    #[test]
    fn valid_configs_take_any_input(cfg in config(plausible), seed in any::<u64>(), inputs in prop::collection::vec(truth(), 1..20)) {
        let mut marg = Marg::new(&cfg, 200.0, seed).unwrap();
        for t in &inputs {
            let _ = marg.sample(t);
        }
    }

    #[test]
    fn range_always_bounds_finite_outputs(range in 0.01..100.0f64, inputs in prop::collection::vec(truth(), 1..20)) {
        let mut cfg = MargConfig::default();
        for e in [&mut cfg.accel.errors, &mut cfg.gyro.errors, &mut cfg.mag.errors] {
            e.range = Some([range; 3]);
            e.noise_density = Some([0.1; 3]);
        }
        let mut marg = Marg::new(&cfg, 100.0, 1).unwrap();
        for t in &inputs {
            let s = marg.sample(t);
            for v in s.acc.iter().chain(&s.gyr).chain(&s.mag) {
                prop_assert!(v.is_nan() || v.abs() <= range as f32);
            }
        }
    }

    #[test]
    fn perturbation_never_panics(cfg in perturbation_config(), rate in prop_oneof![3 => 10.0..400.0f64, 1 => num()], seed in any::<u64>()) {
        if let Ok(plan) = PerturbationPlan::new(&cfg, rate) {
            prop_assume!(plan.scratch_len() <= 20_000);
            let mut scratch = vec![Complex::ZERO; plan.scratch_len()];
            let mut signal = vec![0.0f32; plan.signal_len()];
            let mut pert = Perturbation::new(&plan, seed, &mut scratch, &mut signal).unwrap();
            for _ in 0..3 * plan.window_len() {
                let d = pert.sample();
                prop_assert!(d.iter().all(|v| v.is_finite()));
            }
        }
    }

    #[test]
    fn shaper_and_fft_take_any_buffer(n in 0usize..600, len in 0usize..3000, data in prop::collection::vec(num(), 0..600)) {
        let mut scratch = vec![Complex::ZERO; len];
        if let Ok(mut fft) = Fft::new(n, &mut scratch) {
            let mut x: Vec<Complex> = data.iter().map(|&v| Complex::new(v, -v)).collect();
            let _ = fft.forward(&mut x);
            let _ = fft.inverse(&mut x);
        }
        let cfg = PerturbationConfig { window_s: n as f64 / 100.0, ..PerturbationConfig::default() };
        if let Ok(plan) = PerturbationPlan::new(&cfg, 100.0) {
            let mut scratch = vec![Complex::ZERO; len];
            if let Ok(mut shaper) = BurstShaper::new(&plan, &mut scratch) {
                let mut out = vec![0.0f32; data.len()];
                let _ = shaper.shape(&mut stream(0, "p"), &mut out);
            }
        }
    }
}
