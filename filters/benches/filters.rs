//! Cost of one update of each filter, in `f32` and `f64`, on realistic input: 4096 samples of the
//! paper-like scene of the tests (200 Hz, the paper's noise, ±50 rad/s oscillations, ±4 g
//! external accelerations, magnetic bursts), replayed in a loop.
//!
//! `cargo bench -p margemu-filters -- --warm-up-time 1 --measurement-time 3`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use common::{widen, Scene};
use criterion::{criterion_group, criterion_main, Criterion};
use margemu_filters::{
    AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Imu, Real,
};
use std::hint::black_box;

const SAMPLES: usize = 4096;

fn samples() -> Vec<Imu<f32>> {
    let mut scene = Scene::new(200.0, 3);
    // Skip the first seconds so that bursts and accelerations are under way.
    (0..2000 + SAMPLES).map(|_| scene.next().1).skip(2000).collect()
}

fn bench_filter<T: Real, F: AttitudeFilter<T>>(c: &mut Criterion, name: &str, mut f: F, input: &[Imu<T>]) {
    let dt = T::from_f64(0.005);
    for imu in input {
        f.update(imu, dt);
    }
    let mut k = 0;
    c.bench_function(name, |b| {
        b.iter(|| {
            f.update(black_box(&input[k]), black_box(dt));
            k = (k + 1) % SAMPLES;
            black_box(f.quaternion())
        })
    });
}

fn bench(c: &mut Criterion) {
    let single = samples();
    let double: Vec<Imu<f64>> = single.iter().map(widen).collect();
    bench_filter(c, "ecf_f32", Ecf::<f32>::new(&EcfConfig::default()).unwrap(), &single);
    bench_filter(c, "ecf_f64", Ecf::<f64>::new(&EcfConfig::default()).unwrap(), &double);
    bench_filter(c, "gda_f32", Gda::<f32>::new(&GdaConfig::default()).unwrap(), &single);
    bench_filter(c, "gda_f64", Gda::<f64>::new(&GdaConfig::default()).unwrap(), &double);
    bench_filter(c, "ekf_f32", Ekf::<f32>::new(&EkfConfig::default()).unwrap(), &single);
    bench_filter(c, "ekf_f64", Ekf::<f64>::new(&EkfConfig::default()).unwrap(), &double);
}

criterion_group!(benches, bench);
criterion_main!(benches);
