//! `margemu demo` on the case-study scene shortened to one second: six loopback runs with the
//! virtual flight controller (three filters, initial and tuned), the Table 3 analogue with the
//! paper's figures, and each run's report and figures.

use std::path::PathBuf;
use std::process::{Command, Output};

const CASE_STUDY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../hil-fixtures/scenes/case-study.toml"
);

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-demo-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `margemu demo` on the case study shortened to 1 s, with `tuned` as the tuned parameters
/// file, into `<scratch>/out`: the process's output, its text, and the output directory.
fn demo(name: &str, tuned: &str) -> (Output, String, PathBuf) {
    let dir = scratch(name);
    std::fs::write(dir.join("tuned.toml"), tuned).unwrap();
    let tuned = dir.join("tuned.toml");
    demo_with(&dir, &["--tuned", tuned.to_str().unwrap()])
}

/// `margemu demo` on the case study shortened to 1 s with `args`, into `dir/out`.
fn demo_with(dir: &std::path::Path, args: &[&str]) -> (Output, String, PathBuf) {
    let out_dir = dir.join("out");
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .arg("demo")
        .args(["--scene", CASE_STUDY, "--duration", "1"])
        .args(args)
        .arg("-o")
        .arg(&out_dir)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, text, out_dir)
}

#[test]
fn the_case_study_demo_prints_table_3_and_writes_each_runs_report() {
    // Parameters in the spirit of tuning (faster corrections); the tuner's come later.
    let tuned = "[ecf]\nkp = 2.0\nki = 0.01\n[gda]\nbeta = 0.4\n[ekf]\naccel_noise = 1.0\nmag_noise = 1.0\n";
    let (out, text, out_dir) = demo("full", tuned);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("(1 s at 200 Hz)"), "{text}");
    assert!(text.contains("6 run(s) in real time"), "{text}");
    for (column, paper_f) in [
        ("ECF initial", "(0.5237)"),
        ("ECF tuned", "(0.1471)"),
        ("GDA initial", "(1.1950)"),
        ("GDA tuned", "(0.1812)"),
        ("EKF initial", "(0.2891)"),
        ("EKF tuned", "(0.1033)"),
    ] {
        assert!(text.contains(column), "{column}: {text}");
        let f_row = text.lines().find(|l| l.starts_with("F (rad²)")).unwrap();
        assert!(f_row.contains(paper_f), "{paper_f}: {f_row}");
    }
    assert!(text.contains("initial by F: "), "{text}");
    assert!(text.contains("tuned by F: "), "{text}");
    // Every run served all 200 images as predicted and was scored from the flight controller's
    // own MAVLink.
    assert_eq!(
        text.matches("served 200/200 byte for byte").count(),
        6,
        "{text}"
    );
    let table = std::fs::read_to_string(out_dir.join("table3.md")).unwrap();
    assert!(
        table.starts_with("| | ECF initial | ECF tuned | GDA initial"),
        "{table}"
    );
    assert_eq!(table.lines().count(), 2 + 9);
    for run in [
        "ecf-initial",
        "ecf-tuned",
        "gda-initial",
        "gda-tuned",
        "ekf-initial",
        "ekf-tuned",
    ] {
        for file in [
            "dut_attitude.csv",
            "report.md",
            "errors.csv",
            "attitude.png",
            "attitude.svg",
        ] {
            assert!(
                out_dir.join(run).join(file).is_file(),
                "{run}/{file} missing"
            );
        }
    }
}

#[test]
fn a_tuned_file_without_a_filters_table_stops_the_demo_before_streaming() {
    let (out, text, out_dir) = demo("missing-table", "[ecf]\nkp = 2.0\n");
    assert!(!out.status.success());
    assert!(text.contains("the tuned parameters of gda: "), "{text}");
    assert!(text.contains("tuned.toml has no [gda] table"), "{text}");
    assert!(!out_dir.join("ecf-initial").exists(), "nothing streamed");
}

#[test]
fn without_a_file_the_demo_tunes_in_process_first() {
    let dir = scratch("tuner");
    let (out, text, out_dir) = demo_with(
        &dir,
        &["--filters", "gda", "--seeds", "2", "--max-evals", "12"],
    );
    assert!(out.status.success(), "{text}");
    // The tuner ran on the shortened scene, seeds 2021 and 2022, before streaming.
    let line = text
        .lines()
        .find(|l| l.starts_with("tuned gda on seeds [2021, 2022] in "))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("mean F "), "{line}");
    let f: Vec<f64> = line
        .split("mean F ")
        .nth(1)
        .unwrap()
        .split(" (")
        .next()
        .unwrap()
        .split(" -> ")
        .map(|v| v.parse().unwrap())
        .collect();
    assert!(f[1] <= f[0], "{line}");
    assert!(text.contains("GDA initial"), "{text}");
    assert!(text.contains("GDA tuned"), "{text}");
    assert!(out_dir.join("gda-tuned/report.md").is_file());
}
