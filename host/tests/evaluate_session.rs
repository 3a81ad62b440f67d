//! A session's device output as devices send it: one sample's attitude in several messages
//! with one device time stamp, and the odd unusable quaternion (NaN, zero, near zero), which is
//! skipped and counted rather than refusing the session.

mod evaluate_common;

use evaluate_common::*;
use margemu::evaluate::run::Clock;
use margemu::evaluate::{evaluate, EvalOptions, Source};
use std::path::PathBuf;

const DUT_HEADER: &str = "host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz\n";

/// A session directory with 2 s of truth at 100 Hz, `start_host_ns = 0` and `dut` rows.
fn session(name: &str, dut: &[String]) -> PathBuf {
    let dir = scratch(name);
    let rows: Vec<_> = (0..200u64)
        .map(|k| truth_row(k * 10_000_000, euler_at(k as f64 * 0.01), [1.0, 0.0, 0.0]))
        .collect();
    write_truth(&dir, &rows);
    std::fs::write(dir.join("meta.toml"), "start_host_ns = 0\n").unwrap();
    std::fs::write(
        dir.join("dut_attitude.csv"),
        format!("{DUT_HEADER}{}", dut.concat()),
    )
    .unwrap();
    dir
}

/// A `dut_attitude.csv` row of `message` for the true attitude at sample `k` (10 ms apart),
/// arriving 1 ms after it, with the device time of the sample; `q` replaces the quaternion.
fn row(k: u64, message: &str, q: Option<&str>) -> String {
    let e = euler_at(k as f64 * 0.01);
    let [w, x, y, z] = q_of(e);
    let q = q.map_or(format!("{w},{x},{y},{z}"), str::to_owned);
    format!(
        "{},mavlink,{message},{},{},{},{},{q}\n",
        k * 10_000_000 + 1_000_000,
        k * 10_000,
        e[0],
        e[1],
        e[2]
    )
}

#[test]
fn one_message_stream_is_scored_by_default() {
    // From the second truth sample: a latency estimated a hair over the true one puts the
    // first aligned instant before the truth.
    let dut: Vec<String> = (1..=150)
        .flat_map(|k| {
            [
                row(k, "ATTITUDE", None),
                row(k, "ATTITUDE_QUATERNION", None),
            ]
        })
        .collect();
    let dir = session("streams", &dut);
    let eval = evaluate(&Source::Session(dir), &EvalOptions::default()).unwrap();
    assert!(
        matches!(eval.clock, Clock::Fitted(_, true)),
        "device times used: {:?}",
        eval.clock
    );
    assert_eq!(
        eval.scores.count, 150,
        "every sample once: {:?}",
        eval.notes
    );
    assert!(
        eval.notes
            .iter()
            .any(|n| n.contains("scored mavlink/ATTITUDE_QUATERNION")),
        "{:?}",
        eval.notes
    );
    assert!(eval.scores.geodesic_rms < 1e-6, "{:?}", eval.scores);
    // The other stream on request.
    let options = EvalOptions {
        message: Some("ATTITUDE".into()),
        ..EvalOptions::default()
    };
    let eval = evaluate(
        &Source::Session(scratch_copy(&dut, "streams-attitude")),
        &options,
    )
    .unwrap();
    assert_eq!(eval.scores.count, 150);
}

fn scratch_copy(dut: &[String], name: &str) -> PathBuf {
    session(name, dut)
}

#[test]
fn unusable_quaternions_are_skipped_and_counted() {
    let mut dut: Vec<String> = (1..=150)
        .map(|k| row(k, "ATTITUDE_QUATERNION", None))
        .collect();
    dut[20] = row(20, "ATTITUDE_QUATERNION", Some("NaN,NaN,NaN,NaN"));
    dut[40] = row(40, "ATTITUDE_QUATERNION", Some("0,0,0,0"));
    // Near zero: normalised it would be a valid 90° roll; it is rejected instead.
    dut[60] = row(60, "ATTITUDE_QUATERNION", Some("1e-30,1e-30,0,0"));
    let dir = session("unusable", &dut);
    let eval = evaluate(&Source::Session(dir), &EvalOptions::default()).unwrap();
    assert_eq!(eval.scores.count, 147);
    assert!(
        eval.notes
            .iter()
            .any(|n| n
                == "3 rows with an unusable quaternion (zero, near zero or not finite) skipped"),
        "{:?}",
        eval.notes
    );
    assert!(
        eval.scores.geodesic_max < 1e-6,
        "no row scored as a 90° roll: {:?}",
        eval.scores
    );
}
