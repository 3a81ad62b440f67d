//! The EKF's update over the samples of `benches/filters.rs`, for an instruction count: the
//! load does not move it, so before and after compare exactly on a shared machine
//! (`docs/filters.md`, *Cost*).
//!
//! `ekf_instructions f64|f32 REPS` runs one pass over the 4096 samples, then `REPS` more, all
//! inside `run_updates`, and prints the final attitude and diagnostics. Under
//! `valgrind --tool=callgrind --toggle-collect='*run_updates*'`, the instructions of one update
//! are `(Ir(REPS) − Ir(0)) / (REPS · 4096)`:
//!
//! ```sh
//! cargo bench -p margemu-filters --bench ekf_instructions -- f64 0   # builds, prints the binary
//! valgrind --tool=callgrind --toggle-collect='*run_updates*' target/release/deps/ekf_instructions-* f64 0
//! valgrind --tool=callgrind --toggle-collect='*run_updates*' target/release/deps/ekf_instructions-* f64 10
//! ```

#[path = "../tests/common/mod.rs"]
mod common;

use common::{bench_samples, widen};
use margemu_filters::{AttitudeFilter, Ekf, EkfConfig, Imu, Real};
use std::hint::black_box;

/// `reps` passes of `f` over `input`; not inlined, so that callgrind can count it alone.
#[inline(never)]
fn run_updates<T: Real>(f: &mut Ekf<T>, input: &[Imu<T>], reps: usize) {
    let dt = T::from_f64(0.005);
    for _ in 0..reps {
        for imu in input {
            f.update(black_box(imu), black_box(dt));
        }
    }
}

fn run<T: Real>(input: &[Imu<T>], reps: usize) {
    let mut f = Ekf::<T>::new(&EkfConfig::default()).expect("default parameters are valid");
    run_updates(&mut f, input, 1);
    run_updates(&mut f, input, reps);
    println!(
        "{} updates: q = {:?}, {:?}",
        input.len() * (reps + 1),
        f.quaternion(),
        f.diagnostics()
    );
}

fn main() {
    // `cargo bench` adds `--bench`; the two arguments are the others.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let usage = "usage: ekf_instructions f64|f32 REPS";
    let (Some(ty), Some(reps)) = (args.first(), args.get(1)) else {
        eprintln!("{usage}");
        std::process::exit(2);
    };
    let Ok(reps) = reps.parse::<usize>() else {
        eprintln!("REPS must be a count, not {reps:?}; {usage}");
        std::process::exit(2);
    };
    let single = bench_samples();
    match ty.as_str() {
        "f32" => run(&single, reps),
        "f64" => run(&single.iter().map(widen).collect::<Vec<_>>(), reps),
        other => {
            eprintln!("unknown type {other:?}; {usage}");
            std::process::exit(2);
        }
    }
}
