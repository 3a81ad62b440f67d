//! The sampling-chain benchmark on the QEMU board: runs the board's `chain-bench` binary under
//! `-icount shift=0`, parses its semihosting lines ([`Report`]) and turns the instruction
//! counts into what a 96 MHz Cortex-M4F could sustain ([`Report::table`]).
//!
//! **Assumption.** QEMU counts instructions, not cycles. The table assumes
//! [`CYCLES_PER_INSTRUCTION`] = 1.25 cycles per instruction on average (the M4's single-cycle
//! ALU and FPU operations, 2-cycle loads, 3-cycle branches, plus flash wait states hidden by the
//! ART accelerator on an STM32F4), and a core at [`CORE_HZ`] doing nothing but the chain.
//!
//! ```no_run
//! use margemu_tests::{qemu, qemu_chain};
//! let elf = qemu::chain_bench_elf().unwrap();
//! let (status, report, _) = qemu_chain::run(&elf).unwrap();
//! assert!(status.success());
//! println!("{}", report.table());
//! ```

use std::fmt::Write;
use std::io;
use std::path::Path;
use std::process::ExitStatus;
use std::time::Duration;

use margemu_firmware::chain_bench::CASES;

use crate::qemu;

/// The core clock the table's rates assume, Hz.
pub const CORE_HZ: f64 = 96e6;
/// The cycles per instruction the table assumes.
pub const CYCLES_PER_INSTRUCTION: f64 = 1.25;
/// QEMU's arguments: one virtual nanosecond per instruction.
pub const ICOUNT: [&str; 2] = ["-icount", "shift=0"];
/// Generous: the whole run takes 5 s of host time on an idle machine.
pub const TIMEOUT: Duration = Duration::from_secs(600);

/// A calibration line: a loop of a known instruction count, timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Calibration {
    /// Instructions the loop executes.
    pub instructions: u64,
    /// Instructions measured through TIMER0.
    pub measured: u64,
}

/// The bench's own loop (truth and hash, no chain).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Harness {
    /// Samples run.
    pub samples: u32,
    /// Hash of the truth's bits.
    pub hash: u64,
    /// Instructions spent.
    pub instructions: u64,
}

/// One case as the device ran it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceCase {
    /// `family/path`.
    pub name: String,
    /// Output samples run.
    pub samples: u32,
    /// FNV-1a of every output sample's bits.
    pub hash: u64,
    /// Accelerometer front-end clips per axis.
    pub accel_clips: [u64; 3],
    /// Gyroscope front-end clips per axis.
    pub gyro_clips: [u64; 3],
    /// Internal samples run (accelerometer, gyroscope).
    pub internal: [u64; 2],
    /// Instructions spent in the sample loop.
    pub instructions: u64,
}

/// Everything the binary printed, parsed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// The calibration lines.
    pub calibration: Vec<Calibration>,
    /// The harness line.
    pub harness: Option<Harness>,
    /// The cases run.
    pub cases: Vec<DeviceCase>,
    /// Lines the parser did not take (errors, panics), verbatim.
    pub other: Vec<String>,
    /// Whether the closing line came.
    pub done: bool,
}

/// Runs `elf` (the chain-bench binary) under QEMU with [`ICOUNT`]; returns its exit status,
/// the parsed report and the raw output.
pub fn run(elf: &Path) -> io::Result<(ExitStatus, Report, String)> {
    let (status, output) = qemu::run_to_exit(elf, &ICOUNT, TIMEOUT)?;
    Ok((status, parse(&output), output))
}

/// Parses the binary's lines (see `firmware/boards/qemu-mps2-an386/src/bin/chain_bench.rs`).
pub fn parse(output: &str) -> Report {
    let mut report = Report::default();
    for line in output.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if line == "chain-bench: done" {
            report.done = true;
        } else if let Some(c) = parse_calibration(line) {
            report.calibration.push(c);
        } else if let Some(h) = parse_harness(line) {
            report.harness = Some(h);
        } else if let Some(c) = parse_case(line) {
            report.cases.push(c);
        } else {
            report.other.push(line.to_owned());
        }
    }
    report
}

/// The value of `key=` in `line`.
fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('='))
}

fn number<T: std::str::FromStr>(line: &str, key: &str) -> Option<T> {
    field(line, key)?.parse().ok()
}

fn hex(line: &str, key: &str) -> Option<u64> {
    u64::from_str_radix(field(line, key)?, 16).ok()
}

fn list<const N: usize>(line: &str, key: &str) -> Option<[u64; N]> {
    let values: Vec<u64> = field(line, key)?
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()
        .ok()?;
    values.try_into().ok()
}

fn parse_calibration(line: &str) -> Option<Calibration> {
    line.starts_with("calibration ").then_some(())?;
    Some(Calibration {
        instructions: number(line, "instructions")?,
        measured: number(line, "measured")?,
    })
}

fn parse_harness(line: &str) -> Option<Harness> {
    line.starts_with("harness ").then_some(())?;
    Some(Harness {
        samples: number(line, "samples")?,
        hash: hex(line, "hash")?,
        instructions: number(line, "instructions")?,
    })
}

fn parse_case(line: &str) -> Option<DeviceCase> {
    Some(DeviceCase {
        name: line
            .strip_prefix("case=")?
            .split_whitespace()
            .next()?
            .to_owned(),
        samples: number(line, "samples")?,
        hash: hex(line, "hash")?,
        accel_clips: list(line, "accel_clips")?,
        gyro_clips: list(line, "gyro_clips")?,
        internal: list(line, "internal")?,
        instructions: number(line, "instructions")?,
    })
}

impl Report {
    /// The harness's instructions per sample (0 without a harness line).
    pub fn harness_per_sample(&self) -> f64 {
        self.harness
            .filter(|h| h.samples > 0)
            .map_or(0.0, |h| h.instructions as f64 / f64::from(h.samples))
    }

    /// A Markdown table: per case, its output rate, instructions per output sample (the
    /// chain and the sensor model, the harness's share taken off), the highest output rate a
    /// [`CORE_HZ`] core sustains at [`CYCLES_PER_INSTRUCTION`], and the share of that core the
    /// case takes at its own rate (over 100 %: it does not fit).
    pub fn table(&self) -> String {
        let mut t = String::from(
            "| case | output rate | instructions / sample | max rate at 96 MHz | core at its rate |\n\
             |---|---|---|---|---|\n",
        );
        let harness = self.harness_per_sample();
        for c in &self.cases {
            let rate = CASES
                .iter()
                .find(|k| k.to_string() == c.name)
                .map_or(0.0, |k| k.family.output_rate_hz());
            let per = (c.instructions as f64 / f64::from(c.samples.max(1)) - harness).max(1.0);
            let max_rate = CORE_HZ / (CYCLES_PER_INSTRUCTION * per);
            let load = rate / max_rate * 100.0;
            let _ = writeln!(
                t,
                "| {} | {} | {:.0} | {} | {:.0} %{} |",
                c.name,
                hz(rate),
                per,
                hz(max_rate),
                load,
                if load > 100.0 { " (does not fit)" } else { "" }
            );
        }
        let _ = write!(
            t,
            "\nHarness (truth and hash, taken off above): {harness:.0} instructions / sample; \
             {CYCLES_PER_INSTRUCTION} cycles / instruction assumed.\n"
        );
        t
    }
}

/// `8 kHz`, `840 Hz`.
fn hz(f: f64) -> String {
    if f >= 1000.0 {
        format!("{:.1} kHz", f / 1000.0)
    } else {
        format!("{f:.0} Hz")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OUTPUT: &str = "\
calibration iterations=1000000 instructions=2000000 measured=2000040
harness samples=4000 hash=8c9b708b7daca9a3 instructions=1332000
case=bmi088/output samples=1000 hash=f3fb662e9796d392 accel_clips=0,0,0 gyro_clips=0,0,0 internal=1000,1000 instructions=1528400
case=bmi088/internal+tones+shock samples=1000 hash=7c985286152c0a8e accel_clips=0,0,2 gyro_clips=1,0,0 internal=800,1000 instructions=21511200
case=bmi088/internal+random error=chain bench: buffer too small
chain-bench: done
";

    #[test]
    fn parses_every_kind_of_line() {
        let r = parse(OUTPUT);
        assert_eq!(
            r.calibration,
            [Calibration {
                instructions: 2_000_000,
                measured: 2_000_040
            }]
        );
        assert_eq!(r.harness.map(|h| h.hash), Some(0x8c9b_708b_7dac_a9a3));
        assert_eq!(r.cases.len(), 2);
        assert_eq!(r.cases[1].name, "bmi088/internal+tones+shock");
        assert_eq!(
            (r.cases[1].accel_clips, r.cases[1].gyro_clips),
            ([0, 0, 2], [1, 0, 0])
        );
        assert_eq!(r.cases[1].internal, [800, 1000]);
        assert_eq!(r.other.len(), 1, "the error line is kept: {:?}", r.other);
        assert!(r.done);
    }

    #[test]
    fn the_table_takes_the_harness_off_and_says_what_does_not_fit() {
        let table = parse(OUTPUT).table();
        // 1528.4 − 333 = 1195 instructions: 96e6 / (1.25 · 1195.4) = 64.2 kHz, 3 % at 2 kHz.
        assert!(
            table.contains("| bmi088/output | 2.0 kHz | 1195 | 64.2 kHz | 3 % |"),
            "{table}"
        );
        // 21 511 − 333 = 21 178: 3.6 kHz, 55 % at 2 kHz.
        assert!(table.contains("| 21178 | 3.6 kHz | 55 % |"), "{table}");
        assert!(!table.contains("does not fit"), "{table}");
    }
}
