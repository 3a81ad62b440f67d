//! Cost of the in-process scoring a tuner calls per trial, and of the latency search:
//! `cargo bench -p margemu --bench evaluate -- --warm-up-time 1 --measurement-time 3`.

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use margemu::evaluate::quat::from_euler;
use margemu::evaluate::{
    estimate_latency, score, Estimates, LatencySearch, Reference, ScoreOptions,
};
use std::f64::consts::TAU;
use std::hint::black_box;

type Run = Vec<(u64, [f64; 4])>;

/// The paper's case-study length: 20 s at 200 Hz; estimates 37 ms late and 0.01 rad off in roll.
fn run() -> (Run, Run) {
    let at = |t: f64, roll_off: f64| {
        let e = [
            0.6 * (TAU * 0.7 * t).sin() + roll_off,
            0.4 * (TAU * 0.45 * t + 1.0).sin(),
            2.5 * (TAU * 0.23 * t).sin(),
        ];
        let q = from_euler(e);
        [q.w, q.i, q.j, q.k]
    };
    let truth = (0..4000u64)
        .map(|k| (k * 5_000_000, at(k as f64 * 0.005, 0.0)))
        .collect();
    let est = (0..4000u64)
        .map(|k| (k * 5_000_000, at(k as f64 * 0.005 - 0.037, 0.01)))
        .collect();
    (truth, est)
}

fn bench(c: &mut Criterion) {
    let (truth, est) = run();
    let same_instants: Vec<_> = truth.iter().map(|&(t, q)| (t, q)).collect();
    c.bench_function("score 4000 samples, same instants (tuner trial)", |b| {
        b.iter(|| {
            score(
                black_box(&truth),
                black_box(&same_instants),
                &ScoreOptions::default(),
            )
        })
    });
    let reference = Reference::new(&truth).unwrap();
    let estimates = Estimates::new(&est).unwrap();
    let shifted = ScoreOptions {
        latency_ns: 37_000_000,
        ..ScoreOptions::default()
    };
    c.bench_function(
        "Reference::score 4000 samples, 37 ms latency (slerp)",
        |b| b.iter(|| reference.score(black_box(&estimates), &shifted)),
    );
    c.bench_function("latency search ±500 ms, 4000 samples", |b| {
        b.iter(|| estimate_latency(&reference, black_box(&estimates), &LatencySearch::default()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
