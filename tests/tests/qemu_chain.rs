//! The sampling chain on the Cortex-M4F: the board's `chain-bench` binary runs every case of
//! `margemu_firmware::chain_bench` under QEMU with `-icount shift=0`, and each case's hash of
//! every output sample's bits and its clipping counts must equal the host's for the same case
//! (the chain is bit-identical on the M4F). Its instruction counts must be positive, exact on
//! the calibration loop, and grow with what the case runs (vibration, the internal rate).
//!
//! The figures in `docs/figures.md` ("Sampling chain on the Cortex-M4F") come from
//! `cargo test -p margemu-tests --test qemu_chain -- --nocapture`, which prints the table.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use margemu_firmware::chain_bench::{self, Case, Family, Path, CASES, RANDOM_BUFFER_LEN};
use margemu_model::perturbation::Complex;
use margemu_tests::qemu;
use margemu_tests::qemu_chain::{self, DeviceCase, Report};

fn device_run() -> Option<Report> {
    if !qemu::prerequisites_or_skip("qemu_chain") {
        return None;
    }
    let elf = qemu::chain_bench_elf().unwrap_or_else(|e| panic!("chain-bench ELF: {e}"));
    let (status, report, output) = qemu_chain::run(&elf).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        status.success(),
        "chain-bench exited with {status}:\n{output}"
    );
    assert!(report.done && report.other.is_empty(), "{output}");
    Some(report)
}

fn on_device<'a>(report: &'a Report, case: &Case) -> &'a DeviceCase {
    let name = case.to_string();
    let found = report.cases.iter().find(|c| c.name == name);
    found.unwrap_or_else(|| panic!("{name} missing from the device's report: {report:?}"))
}

#[test]
fn the_chain_is_bit_identical_on_the_m4f_and_its_cost_grows_with_the_work() {
    let Some(report) = device_run() else {
        return;
    };
    println!("{}", report.table());

    // The method: a loop of known length measures exactly, to one TIMER0 tick (40).
    assert_eq!(report.calibration.len(), 2, "{report:?}");
    for c in &report.calibration {
        assert!(c.measured.abs_diff(c.instructions) <= 40, "{c:?}");
    }

    // Bit identity: every case's hash, clips and internal sample counts as on the host.
    assert_eq!(report.cases.len(), CASES.len());
    let mut buffer = vec![Complex::ZERO; RANDOM_BUFFER_LEN];
    for case in &CASES {
        let host = chain_bench::run(case, &mut buffer, &mut || 0).unwrap();
        let device = on_device(&report, case);
        assert_eq!(device.samples, host.samples, "{case}");
        assert_eq!(
            device.hash, host.hash,
            "{case}: the M4F's bits differ from the host's"
        );
        assert_eq!(
            (device.accel_clips, device.gyro_clips),
            (host.accel_clips, host.gyro_clips),
            "{case}"
        );
        assert_eq!(device.internal, host.internal_samples, "{case}");
    }
    let harness = report.harness.expect("a harness line");
    let (hash, _) = chain_bench::harness(harness.samples, 125_000, &mut || 0);
    assert_eq!(harness.hash, hash);

    // Cost: positive, above the harness's, and growing with the work.
    let per_sample = |family, path| {
        let c = on_device(&report, &Case { family, path });
        c.instructions as f64 / f64::from(c.samples)
    };
    assert!(harness.instructions > 0);
    for family in Family::ALL {
        for path in Path::ALL {
            assert!(
                per_sample(family, path) > report.harness_per_sample(),
                "{family}/{path}"
            );
        }
        // Without vibration the internal path costs more than the output path (its division
        // of the instant, its filters), even where it runs fewer accelerometer steps.
        assert!(
            per_sample(family, Path::Internal) > per_sample(family, Path::Output),
            "{family}"
        );
        // Vibration costs on either path.
        assert!(per_sample(family, Path::OutputTones) > per_sample(family, Path::Output));
        for path in [Path::InternalTonesShock, Path::InternalRandom] {
            assert!(
                per_sample(family, path) > per_sample(family, Path::Internal),
                "{family}"
            );
        }
        // With the tones, the internal path costs more wherever it runs more steps than the
        // output path's one per sensor and output sample.
        let internal = on_device(
            &report,
            &Case {
                family,
                path: Path::InternalTonesShock,
            },
        );
        let steps = internal.internal.iter().sum::<u64>();
        if steps > 2 * u64::from(internal.samples) {
            let (i, o) = (
                per_sample(family, Path::InternalTonesShock),
                per_sample(family, Path::OutputTones),
            );
            assert!(i > o, "{family}: {i} <= {o}");
        }
    }
}
