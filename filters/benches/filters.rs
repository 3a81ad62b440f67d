//! Cost of one update of each filter, in `f32` and `f64`, on realistic input: 4096 samples of the
//! paper-like scene of the tests (200 Hz, the paper's noise, ±50 rad/s oscillations, ±4 g
//! external accelerations, magnetic bursts), replayed in a loop.
//!
//! The baseline is the `ahrs` crate's Madgwick filter (MARG update, nalgebra), a plain Rust
//! implementation of the same algorithm family, timed in the same run so that ratios hold on a
//! shared machine.
//!
//! The EKF is timed twice: `ekf_*` is the filter of the crate, `ekf_reference_*` the
//! straightforward implementation it replaced (`tests/common/ekf_reference.rs`, the oracle of
//! `tests/ekf_reference.rs`), so that before and after come from one run.
//!
//! `cargo bench -p margemu-filters -- --warm-up-time 1 --measurement-time 3`
//!
//! With `MARGEMU_BENCH_SAMPLES=<file>` set, the bench first writes its input there, one sample
//! a line (`gx gy gz ax ay az mx my mz`, rad/s, m/s², model field units), so that another
//! implementation can be timed on the same samples (`docs/filters.md`, *Cost*).

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "../tests/common/ekf_reference.rs"]
mod ekf_reference;

use common::{bench_samples, widen, BENCH_SAMPLES as SAMPLES};
use criterion::{criterion_group, criterion_main, Criterion};
use ekf_reference::ReferenceEkf;
use margemu_filters::{AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Imu, Real};
use std::hint::black_box;

fn bench_filter<T: Real, F: AttitudeFilter<T>>(
    c: &mut Criterion,
    name: &str,
    mut f: F,
    input: &[Imu<T>],
) {
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

/// The `ahrs` crate's Madgwick MARG update over the same samples.
macro_rules! baseline {
    ($c:expr, $t:ty, $name:expr, $input:expr) => {{
        use ahrs::{Ahrs, Madgwick};
        use nalgebra_for_ahrs::Vector3;
        let v = |a: [$t; 3]| Vector3::new(a[0], a[1], a[2]);
        let input: Vec<[Vector3<$t>; 3]> = $input
            .iter()
            .map(|i| [v(i.gyro), v(i.acc), v(i.mag)])
            .collect();
        let mut f = Madgwick::<$t>::new(0.005, 0.1);
        let mut k = 0;
        $c.bench_function($name, |b| {
            b.iter(|| {
                let [g, a, m] = black_box(&input[k]);
                let q = f.update(g, a, m).map(|q| *q);
                k = (k + 1) % SAMPLES;
                black_box(q)
            })
        });
    }};
}

fn bench(c: &mut Criterion) {
    let single = bench_samples();
    let double: Vec<Imu<f64>> = single.iter().map(widen).collect();
    if let Some(path) = std::env::var_os("MARGEMU_BENCH_SAMPLES") {
        let mut text = String::new();
        for i in &double {
            let [g, a, m] = [i.gyro, i.acc, i.mag];
            let line: Vec<String> = [g, a, m].concat().iter().map(f64::to_string).collect();
            text.push_str(&line.join(" "));
            text.push('\n');
        }
        std::fs::write(path, text).expect("cannot write MARGEMU_BENCH_SAMPLES");
    }
    baseline!(c, f32, "baseline_ahrs_madgwick_f32", single);
    baseline!(c, f64, "baseline_ahrs_madgwick_f64", double);
    bench_all(c, "f32", &single);
    bench_all(c, "f64", &double);
}

/// ECF, GDA, EKF and the reference EKF with default parameters in `T`.
fn bench_all<T: Real>(c: &mut Criterion, ty: &str, input: &[Imu<T>]) {
    let ecf = Ecf::<T>::new(&EcfConfig::default()).unwrap();
    let gda = Gda::<T>::new(&GdaConfig::default()).unwrap();
    let ekf = Ekf::<T>::new(&EkfConfig::default()).unwrap();
    bench_filter(c, &format!("ecf_{ty}"), ecf, input);
    bench_filter(c, &format!("gda_{ty}"), gda, input);
    bench_filter(c, &format!("ekf_{ty}"), ekf, input);
    let reference = ReferenceEkf::<T>::new(&EkfConfig::default());
    bench_filter(c, &format!("ekf_reference_{ty}"), reference, input);
}

criterion_group!(benches, bench);
criterion_main!(benches);
