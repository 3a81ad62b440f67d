//! Source mode (b)'s cost on the Cortex-M4F: the board's `model-bench` binary runs every case
//! of `margemu_firmware::model_bench` (the whole per-sample serving path: kinematics hold, the
//! sensor model with the case's terms, the chain, the register image and its latch) under QEMU
//! with `-icount shift=0`. Each case's hash of every image's bytes must equal the host's
//! (x86-64) for the same case, and its instructions per output sample must agree with the
//! budget's cost model (`margemu_firmware::budget`, which is fitted to these figures) and
//! grow with the terms and the chain.
//!
//! The table in `docs/figures.md` ("Source mode (b) on the Cortex-M4F") comes from
//! `cargo test -p margemu-tests --test qemu_model_cost -- --nocapture`, which prints it.
//!
//! Skipped, with a message, where `qemu-system-arm` or a cross toolchain is missing; under
//! `CI=true` that is a failure instead.

use std::fmt::Write;

use margemu_firmware::budget::{self, BLACKPILL_F411};
use margemu_firmware::model_bench::{self, Case, Chain, Part, Terms, CASES};
use margemu_model::perturbation::Complex;
use margemu_tests::qemu;
use margemu_tests::qemu_chain::{ICOUNT, TIMEOUT};

/// One line of the binary's output: `[harness ]case=<name> samples=<n> hash=<hex>
/// instructions=<n>`.
#[derive(Debug)]
struct Line {
    harness: bool,
    name: String,
    samples: u32,
    hash: u64,
    instructions: u64,
}

fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
}

fn parse(line: &str) -> Option<Line> {
    let (harness, rest) = match line.strip_prefix("harness ") {
        Some(rest) => (true, rest),
        None => (false, line),
    };
    Some(Line {
        harness,
        name: field(rest, "case")?.to_owned(),
        samples: field(rest, "samples")?.parse().ok()?,
        hash: u64::from_str_radix(field(rest, "hash")?, 16).ok()?,
        instructions: field(rest, "instructions")?.parse().ok()?,
    })
}

fn device_run() -> Option<Vec<Line>> {
    if !qemu::prerequisites_or_skip("qemu_model_cost") {
        return None;
    }
    let elf = qemu::build_board_bin(&qemu::board_dir(), &qemu::board_target_dir(), "model-bench")
        .unwrap_or_else(|e| panic!("model-bench ELF: {e}"));
    let (status, output) = qemu::run_to_exit(&elf, &ICOUNT, TIMEOUT).unwrap();
    assert!(
        status.success(),
        "model-bench exited with {status}:\n{output}"
    );
    let lines: Vec<&str> = output
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    assert_eq!(lines.last(), Some(&"model-bench: done"), "{output}");
    let parsed: Vec<Line> = lines[..lines.len() - 1]
        .iter()
        .map(|l| parse(l).unwrap_or_else(|| panic!("unexpected line: {l}\n{output}")))
        .collect();
    Some(parsed)
}

fn per_sample(lines: &[Line], case: &Case) -> f64 {
    let name = case.to_string();
    let line = lines.iter().find(|l| !l.harness && l.name == name);
    let line = line.unwrap_or_else(|| panic!("{name} missing from the device's report"));
    line.instructions as f64 / f64::from(line.samples)
}

/// The Markdown table of `docs/figures.md`.
fn table(lines: &[Line]) -> String {
    let mut out = String::from(
        "| case | output rate | instructions / sample | max rate (50 % of 96 MHz) | core at its rate |\n\
         |---|---|---|---|---|\n",
    );
    for case in &CASES {
        let n = per_sample(lines, case);
        let hz = f64::from(case.rate_hz());
        let max = BLACKPILL_F411.budget_instructions_per_s() / n;
        let share = n * hz * budget::CYCLES_PER_INSTRUCTION / BLACKPILL_F411.core_hz;
        let fits = if share <= budget::BUDGET_SHARE {
            ""
        } else {
            " (over budget)"
        };
        let _ = writeln!(
            out,
            "| {case} | {} | {n:.0} | {} | {:.0} %{fits} |",
            rate(hz),
            rate(max),
            share * 100.0
        );
    }
    for l in lines.iter().filter(|l| l.harness) {
        let _ = writeln!(
            out,
            "harness {}: {:.0} instructions / sample",
            l.name,
            l.instructions as f64 / f64::from(l.samples)
        );
    }
    out
}

fn rate(hz: f64) -> String {
    match hz >= 1000.0 {
        true => format!("{:.1} kHz", hz / 1000.0),
        false => format!("{hz:.0} Hz"),
    }
}

#[test]
fn mode_b_is_bit_identical_on_the_m4f_and_costs_what_the_budget_says() {
    let Some(lines) = device_run() else {
        return;
    };
    println!("{}", table(&lines));

    // Bit identity: every case's images as on the host.
    assert_eq!(lines.iter().filter(|l| !l.harness).count(), CASES.len());
    for case in &CASES {
        let (scratch, signal) = model_bench::perturbation_buffer_lens(case).unwrap();
        let (mut scratch, mut signal) = (vec![Complex::ZERO; scratch], vec![0.0; signal]);
        let host = model_bench::run(case, &mut scratch, &mut signal, &mut || 0).unwrap();
        let name = case.to_string();
        let device = lines.iter().find(|l| !l.harness && l.name == name).unwrap();
        assert_eq!(device.samples, host.samples, "{case}");
        assert_eq!(
            device.hash, host.hash,
            "{case}: the M4F's images differ from the host's"
        );
        if case.terms == Terms::Ideal && case.chain == Chain::Output {
            let harness = lines.iter().find(|l| l.harness && l.name == name).unwrap();
            assert_eq!(
                harness.hash,
                model_bench::harness(case, &mut || 0).0,
                "{case}"
            );
        }
    }

    // The budget's cost model holds for this build: at most 2 % under, 20 % over.
    for case in &CASES {
        let load = model_bench::load(case).unwrap();
        let predicted = budget::instructions_per_sample(&load, f64::from(case.rate_hz()));
        let measured = per_sample(&lines, case);
        assert!(
            predicted >= 0.98 * measured && predicted <= 1.2 * measured,
            "{case}: the budget predicts {predicted:.0}, the M4F spent {measured:.0}"
        );
    }

    // Cost grows with the terms and the chain.
    for family in Part::ALL {
        let n = |terms, chain| {
            per_sample(
                &lines,
                &Case {
                    family,
                    terms,
                    chain,
                },
            )
        };
        assert!(n(Terms::Eq18, Chain::Output) > n(Terms::Ideal, Chain::Output));
        assert!(n(Terms::Every, Chain::Output) > n(Terms::Eq18, Chain::Output));
        assert!(n(Terms::Eq18Perturbation, Chain::Output) > n(Terms::Every, Chain::Output));
        assert!(n(Terms::Eq18, Chain::OutputTones) > n(Terms::Eq18, Chain::Output));
        assert!(n(Terms::Eq18, Chain::Internal) > n(Terms::Eq18, Chain::Output));
        assert!(
            n(Terms::Eq18, Chain::InternalTonesShock) > n(Terms::Eq18, Chain::Internal),
            "{family}"
        );
        assert!(
            n(Terms::Every, Chain::InternalTonesShock) > n(Terms::Eq18, Chain::InternalTonesShock)
        );
    }
}
