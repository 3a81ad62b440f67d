//! The sampling-chain benchmark cases run natively: deterministic, the internal path unlike the
//! output path when something vibrates, clipping counted where the shock exceeds the ranges,
//! the random buffer sized for the largest case. The device's bits are checked against these
//! in `tests/tests/qemu_chain.rs`.

use margemu_firmware::chain_bench::{
    self, random_buffer_len, BenchError, Case, Family, Outcome, Path, CASES, DURATION_NS,
    RANDOM_BUFFER_LEN,
};
use margemu_model::perturbation::Complex;

fn run(case: &Case) -> Outcome {
    let mut buffer = vec![Complex::ZERO; RANDOM_BUFFER_LEN];
    chain_bench::run(case, &mut buffer, &mut || 0).unwrap_or_else(|e| panic!("{case}: {e}"))
}

fn case(family: Family, path: Path) -> Case {
    Case { family, path }
}

#[test]
fn every_case_is_deterministic() {
    for case in &CASES {
        let (a, b) = (run(case), run(case));
        assert_eq!(a, b, "{case}");
        assert_eq!(a.samples, case.output_samples(), "{case}");
    }
}

#[test]
fn the_internal_path_differs_from_the_output_path_when_something_vibrates() {
    for family in Family::ALL {
        let output = run(&case(family, Path::OutputTones));
        let internal = run(&case(family, Path::InternalTonesShock));
        let quiet = run(&case(family, Path::Output));
        let random = run(&case(family, Path::InternalRandom));
        assert_ne!(output.hash, internal.hash, "{family}");
        assert_ne!(
            output.hash, quiet.hash,
            "{family}: the tones change the output"
        );
        assert_ne!(
            random.hash, quiet.hash,
            "{family}: the random vibration too"
        );
        assert_ne!(random.hash, internal.hash, "{family}");
    }
}

#[test]
fn internal_paths_run_the_internal_rates_and_output_paths_one_step_per_sample() {
    for case in &CASES {
        let out = run(case);
        let n = u64::from(case.output_samples());
        let expected = match case.path.is_internal() {
            // Instants k·period ≤ the last output instant (n − 1)·output period.
            true => case
                .family
                .internal_periods_ns()
                .map(|p| (n - 1) * case.family.output_period_ns() / p + 1),
            false => [n, n],
        };
        assert_eq!(out.internal_samples, expected, "{case}");
        assert_eq!(n, DURATION_NS / case.family.output_period_ns());
    }
}

#[test]
fn the_shock_clips_both_front_ends_and_nothing_else_does() {
    for case in &CASES {
        let out = run(case);
        let clipped = out.accel_clips.iter().chain(&out.gyro_clips).sum::<u64>();
        if case.path == Path::InternalTonesShock {
            // 300 m/s² on z and 40 rad/s on x beyond 16 g (24 g) and 2000 °/s.
            assert!(
                out.accel_clips[2] > 0 && out.gyro_clips[0] > 0,
                "{case}: {out:?}"
            );
            assert_eq!(out.accel_clips[1] + out.gyro_clips[1], 0, "{case}: {out:?}");
        } else {
            assert_eq!(clipped, 0, "{case}: {out:?}");
        }
    }
}

#[test]
fn the_random_buffer_fits_the_largest_case_exactly_and_a_smaller_one_is_refused() {
    let need = CASES.iter().map(|c| random_buffer_len(c).unwrap()).max();
    assert_eq!(need, Some(RANDOM_BUFFER_LEN));
    let big = case(Family::Icm42688p, Path::InternalRandom);
    let mut small = vec![Complex::ZERO; RANDOM_BUFFER_LEN - 1];
    let refused = chain_bench::run(&big, &mut small, &mut || 0);
    assert!(matches!(refused, Err(BenchError::Model(_))), "{refused:?}");
    // Cases without random vibration take no buffer at all.
    let quiet = case(Family::Icm42688p, Path::InternalTonesShock);
    assert!(chain_bench::run(&quiet, &mut [], &mut || 0).is_ok());
}

#[test]
fn the_clock_is_read_around_the_sample_loop_only() {
    let mut reads = 0u64;
    let out = chain_bench::run(&CASES[0], &mut [], &mut || {
        reads += 1;
        reads * 1000
    })
    .unwrap();
    assert_eq!((reads, out.elapsed), (2, 1000));
    let (hash, elapsed) = chain_bench::harness(8, 125_000, &mut || 7);
    assert_eq!(elapsed, 0);
    assert_ne!(hash, chain_bench::harness(9, 125_000, &mut || 7).0);
}

#[test]
fn case_names_are_family_slash_path() {
    let names: Vec<String> = CASES.iter().map(ToString::to_string).collect();
    assert_eq!(names[0], "icm20602/output");
    assert_eq!(names[8], "icm42688p/internal+tones+shock");
    assert_eq!(names[19], "bmi088/internal+random");
}

#[test]
fn each_family_runs_its_declared_chain() {
    for family in Family::ALL {
        let declared = family
            .declared()
            .unwrap_or_else(|e| panic!("{family}: {e}"));
        assert_eq!(
            declared.output_period_ns,
            family.output_period_ns(),
            "{family}"
        );
        assert_eq!(
            [declared.accel.period_ns, declared.gyro.period_ns],
            family.internal_periods_ns(),
            "{family}"
        );
        // The widest full scales: 16 g (24 g) and 2000 °/s.
        let g = if family == Family::Bmi088 { 24.0 } else { 16.0 };
        assert!(
            (declared.accel.range - g * 9.806_65).abs() < 1e-3,
            "{family}"
        );
        assert!(
            (declared.gyro.range - 2000f32.to_radians()).abs() < 1e-5,
            "{family}"
        );
        // Real filters: below unity gain well inside the internal Nyquist band.
        let nyquist = 0.45e9 / declared.gyro.period_ns as f64;
        assert!(declared.gyro.filter.gain_at(nyquist) < 0.9, "{family}");
    }
}
