use super::*;

extern crate std;
use std::string::ToString;
use std::vec;

fn buffers(case: &Case) -> (std::vec::Vec<Complex>, std::vec::Vec<f32>) {
    let (scratch, signal) = perturbation_buffer_lens(case).unwrap();
    (vec![Complex::ZERO; scratch], vec![0.0; signal])
}

#[test]
fn every_case_builds_and_runs_deterministically() {
    for case in &CASES {
        let (mut scratch, mut signal) = buffers(case);
        let mut ticks = 0;
        let a = run(case, &mut scratch, &mut signal, &mut || {
            ticks += 5;
            ticks
        })
        .unwrap_or_else(|e| panic!("{case}: {e}"));
        assert_eq!((a.samples, a.elapsed), (case.output_samples(), 5), "{case}");
        let b = run(case, &mut scratch, &mut signal, &mut || 0).unwrap();
        assert_eq!(a.hash, b.hash, "{case}");
    }
}

#[test]
fn the_terms_and_the_chain_change_the_images() {
    let family = Part::Mpu9250;
    let hash = |terms, chain| {
        let case = Case {
            family,
            terms,
            chain,
        };
        let (mut scratch, mut signal) = buffers(&case);
        run(&case, &mut scratch, &mut signal, &mut || 0)
            .unwrap()
            .hash
    };
    let ideal = hash(Terms::Ideal, Chain::Output);
    let eq18 = hash(Terms::Eq18, Chain::Output);
    let hashes = [
        ideal,
        eq18,
        hash(Terms::Eq18Perturbation, Chain::Output),
        hash(Terms::Every, Chain::Output),
        hash(Terms::Eq18, Chain::OutputTones),
        hash(Terms::Eq18, Chain::Internal),
    ];
    for (i, a) in hashes.iter().enumerate() {
        for b in &hashes[i + 1..] {
            assert_ne!(a, b);
        }
    }
}

#[test]
fn a_perturbation_case_refuses_small_buffers() {
    let case = Case {
        family: Part::Bmi088,
        terms: Terms::Eq18Perturbation,
        chain: Chain::Output,
    };
    let (scratch, signal) = perturbation_buffer_lens(&case).unwrap();
    assert!(scratch > 0 && signal > 0);
    for case in &CASES {
        let (scratch, signal) = perturbation_buffer_lens(case).unwrap();
        assert!(scratch <= PERTURBATION_SCRATCH_LEN, "{case}");
        assert!(signal <= PERTURBATION_SIGNAL_LEN, "{case}");
    }
    let err = run(&case, &mut [], &mut [], &mut || 0).unwrap_err();
    assert!(matches!(err, BenchError::Perturbation(_)), "{err}");
}

#[test]
fn cases_cover_every_family_once_per_configuration() {
    for family in Part::ALL {
        for (terms, chain) in PER_FAMILY {
            let case = Case {
                family,
                terms,
                chain,
            };
            assert_eq!(CASES.iter().filter(|c| **c == case).count(), 1, "{case}");
        }
    }
    let c = &CASES[8 + 2];
    assert_eq!(c.to_string(), "icm42688p/eq18+perturbation/output");
    assert_eq!((c.hold(), c.rate_hz()), (8, 8000));
}
