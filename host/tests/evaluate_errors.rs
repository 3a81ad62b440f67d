//! Bad input gets an error naming the file, the line and the cause, never a panic.

mod evaluate_common;

use evaluate_common::*;
use margemu::evaluate::{evaluate, score, EvalOptions, ScoreError, ScoreOptions, Source};
use std::path::{Path, PathBuf};

const DUT_HEADER: &str = "host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz\n";

/// A session directory with 2 s of truth at 100 Hz, `start_host_ns = 1000` and the given
/// `dut_attitude.csv` text.
fn session(name: &str, dut: &str) -> PathBuf {
    let dir = scratch(name);
    let rows: Vec<_> = (0..200u64)
        .map(|k| truth_row(k * 10_000_000, euler_at(k as f64 * 0.01), [1.0, 0.0, 0.0]))
        .collect();
    write_truth(&dir, &rows);
    std::fs::write(dir.join("meta.toml"), "start_host_ns = 1000\n").unwrap();
    std::fs::write(dir.join("dut_attitude.csv"), dut).unwrap();
    dir
}

/// Writes `files` (name, text) into the session `dir` and returns the evaluation's error.
fn error_after(dir: PathBuf, files: &[(&str, &str)]) -> String {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    evaluate(&Source::Session(dir), &EvalOptions::default())
        .unwrap_err()
        .to_string()
}

fn session_error(name: &str, dut: &str) -> String {
    error_after(session(name, dut), &[])
}

fn ends(err: &str, file: &str, tail: &str) {
    assert!(err.contains(file) && err.ends_with(tail), "{err}");
}

#[test]
fn dut_attitude_errors_name_file_line_and_cause() {
    let good = "2000,serial,att,,0,0,0,1,0,0,0\n";
    let err = session_error("missing", "host_ns,protocol,message,roll\n");
    ends(
        &err,
        "dut_attitude.csv",
        "no column `device_time_us` in the header (columns: host_ns, protocol, message, roll)",
    );
    let err = session_error(
        "nan",
        &format!("{DUT_HEADER}{good}3000,serial,att,,0,0,0,1,abc,0,0\n"),
    );
    ends(&err, "dut_attitude.csv:3", "`qx` = \"abc\" is not a number");
    let err = session_error(
        "order",
        &format!("{DUT_HEADER}{good}1500,serial,att,,0,0,0,1,0,0,0\n"),
    );
    ends(
        &err,
        "dut_attitude.csv:3",
        "`host_ns` = 1500 does not increase (previous row: 2000)",
    );
    // A device's zero quaternion is skipped and counted, not refused: see evaluate_session.rs.
    let err = session_error(
        "zero",
        &format!("{DUT_HEADER}3000,serial,att,,0,0,0,0,0,0,0\n"),
    );
    ends(
        &err,
        "dut_attitude.csv",
        "no row with a usable quaternion (1 unusable)",
    );
    let err = session_error("short", &format!("{DUT_HEADER}{good}3000,serial,att\n"));
    assert!(
        err.contains("dut_attitude.csv") && err.contains("line: 3"),
        "{err}"
    );
    let err = session_error(
        "inf",
        &format!("{DUT_HEADER}{good}3000,serial,att,,0,0,inf,1,0,0,0\n"),
    );
    ends(&err, "dut_attitude.csv:3", "`yaw` = inf is not finite");
    let err = session_error("empty", DUT_HEADER);
    ends(&err, "dut_attitude.csv", "no data rows");
}

#[test]
fn no_overlap_between_truth_and_estimates_is_an_error() {
    // Stamped 60 s after a 2 s truth; a fixed latency so that no search is involved.
    let dut: String = (0..100)
        .map(|k| {
            format!(
                "{},serial,att,,0,0,0,1,0,0,0\n",
                60_000_001_000i64 + k * 10_000_000
            )
        })
        .collect();
    let dir = session("overlap", &format!("{DUT_HEADER}{dut}"));
    let options = EvalOptions {
        latency: Some(margemu::evaluate::LatencyMode::Fixed(0)),
        ..EvalOptions::default()
    };
    let err = evaluate(&Source::Session(dir), &options)
        .unwrap_err()
        .to_string();
    assert!(
        err.ends_with("no truth instant to score: the truth spans 0.000 s to 1.990 s, the estimates (shifted by the latency) span 60.000 s to 60.990 s, warm-up 0 s"),
        "{err}"
    );
    assert!(
        err.contains("truth.csv") && err.contains("dut_attitude.csv"),
        "{err}"
    );
}

#[test]
fn session_file_errors_are_located() {
    let good = format!("{DUT_HEADER}2000,serial,att,,0,0,0,1,0,0,0\n");
    // Truth time going backwards.
    let dir = session("truth-order", &good);
    let text = std::fs::read_to_string(dir.join("truth.csv")).unwrap();
    let text = text.replacen("\n20000000,", "\n5000,", 1);
    let err = error_after(dir, &[("truth.csv", &text)]);
    ends(
        &err,
        "truth.csv:4",
        "`t_ns` = 5000 does not increase (previous row: 10000000)",
    );
    // No start anywhere.
    let meta = ("meta.toml", "seed = 1\n");
    let events = ("events.csv", "host_ns,event,detail\n5,hello_ack,x\n");
    let err = error_after(session("no-start", &good), &[meta, events]);
    let cause = "no `start` row, and meta.toml has no start_host_ns: the session never started";
    ends(&err, "events.csv", cause);
    // A damaged register image in sent.csv.
    let sent = (
        "sent.csv",
        "index,t_ns,send_ns,late_ns,image\n0,0,5,,00zz\n",
    );
    let err = error_after(session("sent", &good), &[sent]);
    ends(
        &err,
        "sent.csv:2",
        "`image` = \"00zz\" is not 44 hex digits",
    );
    // A missing truth.
    let dir = session("no-truth", &good);
    std::fs::remove_file(dir.join("truth.csv")).unwrap();
    let err = error_after(dir, &[]);
    assert!(err.contains("truth.csv: cannot read:"), "{err}");
}

fn external_error(name: &str, text: &str, estimates: Option<&str>) -> String {
    let dir = scratch(name);
    let file = dir.join("rec.csv");
    std::fs::write(&file, text).unwrap();
    let estimates = estimates.map(|e| {
        let p = dir.join("est.csv");
        std::fs::write(&p, e).unwrap();
        p
    });
    evaluate(
        &Source::External { file, estimates },
        &EvalOptions::default(),
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn external_and_estimate_file_errors_are_located() {
    let header = "t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz";
    let row = |t: f64| format!("{t},0,0,9.8,0,0,0,0.5,0,-0.8,1,0,0,0");
    let err = external_error("ext-none", &format!("{header}\n{}\n", row(0.0)), None);
    ends(&err, "rec.csv", "no estimate: the file has no qw_est, qx_est, qy_est, qz_est columns and no estimates file was given (run a filter over it first)");
    let err = external_error(
        "ext-partial",
        &format!("{header},qw_est\n{},1\n", row(0.0)),
        None,
    );
    ends(&err, "rec.csv", "no column `qx_est` in the header (columns: t_s, ax, ay, az, gx, gy, gz, mx, my, mz, qw, qx, qy, qz, qw_est)");
    let err = external_error("ext-neg", &format!("{header}\n{}\n", row(-1.0)), None);
    ends(&err, "rec.csv:2", "`t_s` = -1 is outside 0 to 1.8e10 s");
    let text = format!("{header}\n{}\n{}\n", row(0.0), row(0.01));
    let err = external_error(
        "est-order",
        &text,
        Some("t_s,qw,qx,qy,qz\n0.01,1,0,0,0\n0.01,1,0,0,0\n"),
    );
    ends(
        &err,
        "est.csv:3",
        // In seconds, as the column has them (not the nanoseconds they are compared in).
        "`t_s` = 0.01 does not increase (previous row: 0.01)",
    );
    let err = external_error("est-cols", &text, Some("t,qw,qx,qy,qz\n"));
    ends(
        &err,
        "est.csv",
        "no column `t_s` in the header (columns: t, qw, qx, qy, qz)",
    );
}

#[test]
fn the_in_process_api_refuses_bad_samples_with_their_index() {
    let truth = [(0, [1.0, 0.0, 0.0, 0.0]), (10, [1.0, 0.0, 0.0, 0.0])];
    let opts = ScoreOptions::default();
    let err = score(
        &truth,
        &[(5, [1.0, 0.0, 0.0, 0.0]), (5, [1.0, 0.0, 0.0, 0.0])],
        &opts,
    );
    assert_eq!(
        err.unwrap_err(),
        ScoreError::NotIncreasing {
            what: "estimate",
            index: 1,
            t_ns: 5
        }
    );
    let err = score(&truth, &[(5, [f64::NAN, 0.0, 0.0, 0.0])], &opts).unwrap_err();
    assert_eq!(
        err.to_string(),
        "estimate sample 0: quaternion [NaN, 0.0, 0.0, 0.0] has no direction (zero or not finite)"
    );
    assert_eq!(
        score(&[], &truth, &opts).unwrap_err(),
        ScoreError::Empty { what: "truth" }
    );
}

#[test]
fn the_command_line_reports_bad_input_without_panicking() {
    let dir = session(
        "cli",
        &format!("{DUT_HEADER}2000,serial,att,,0,0,0,1,0,oops,0\n"),
    );
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_margemu"))
        .arg("evaluate")
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let expected = format!(
        "error: {}:2: `qy` = \"oops\" is not a number",
        Path::new(&dir).join("dut_attitude.csv").display()
    );
    assert_eq!(stderr.trim(), expected);
}
