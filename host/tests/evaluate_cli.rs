//! `margemu evaluate` end to end: a real session from `margemu loopback` (the firmware link
//! handler behind a pseudo-terminal pair) with a `dut_attitude.csv` synthesised from its truth
//! (37 ms late, on a device clock 80 ppm slow, with arrival jitter and attitude noise); and a
//! `simulate` run of the paper's case study scored from an estimates file.

mod common;
mod evaluate_common;

use common::margemu;
use evaluate_common::*;
use margemu::evaluate::input::read_truth;
use margemu::evaluate::quat::{euler, normalize};
use margemu_model::rng::{stream, uniform};
use std::path::Path;

/// The number after `key` in `text` (up to the next space).
fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text
        .find(key)
        .unwrap_or_else(|| panic!("no {key:?} in {text}"))
        + key.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

fn assert_outputs(dir: &Path) {
    for f in [
        "report.md",
        "errors.csv",
        "attitude.png",
        "attitude.svg",
        "alignment.png",
        "alignment.svg",
    ] {
        let bytes = std::fs::read(dir.join(f)).unwrap_or_else(|_| panic!("{f} missing"));
        assert!(bytes.len() > 1000, "{f} is too short");
    }
    assert!(std::fs::read(dir.join("attitude.png"))
        .unwrap()
        .starts_with(b"\x89PNG"));
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(
        report.contains("![attitude.png](attitude.png)") && report.contains("| F (rad²) |"),
        "{report}"
    );
}

const SCENE: &str = "duration = 3.0\nrate = 200.0\nseed = 11\nmotion = \"kinematic\"\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 0.7\nfrequency = 0.6\n\
    [joints.pitch]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 0.9\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 2.8\nfrequency = 0.3\n\
    [sensors.mag]\nnoise_density = [0.0022, 0.0022, 0.0022]\n\
    [perturbation]\nwindow = 0.8\ncutoff = 5.0\namplitude = [1.0, 2.0]\ngap = [0.4, 0.6]\n";

#[test]
fn a_loopback_session_is_aligned_and_scored() {
    let dir = scratch("cli-session");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let session = dir.join("session");
    margemu(&[
        "loopback".as_ref(),
        scene.as_ref(),
        "-o".as_ref(),
        session.as_ref(),
    ]);
    // Scene time 0 on the host clock, from events.csv (meta.toml does not carry it).
    let events = std::fs::read_to_string(session.join("events.csv")).unwrap();
    let start: i64 = events
        .lines()
        .find(|l| l.contains(",start,"))
        .and_then(|l| l.split("start_host_ns ").nth(1))
        .and_then(|r| r.split(';').next())
        .unwrap()
        .parse()
        .unwrap();
    let truth = read_truth(&session.join("truth.csv")).unwrap();
    let (latency, drift, offset) = (37e6, 80e-6, 1.5e9);
    let (mut jitter, mut noise) = (stream(1, "test/jitter"), stream(1, "test/noise"));
    let mut dut =
        String::from("host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz\n");
    for &(t, q) in &truth.attitude {
        let sent = t as f64 + latency;
        let host = start + (sent + uniform(&mut jitter, 0.0, 300e3)) as i64;
        let device_us = (sent + offset) / (1.0 + drift) / 1e3;
        let q = noisy(q, &mut noise, 0.01);
        let e = euler(&normalize(q).unwrap());
        dut += &format!(
            "{host},mavlink,ATTITUDE_QUATERNION,{device_us:.1},{},{},{},{},{},{},{}\n",
            e[0], e[1], e[2], q[0], q[1], q[2], q[3]
        );
    }
    std::fs::write(session.join("dut_attitude.csv"), dut).unwrap();
    let out = margemu(&["evaluate".as_ref(), session.as_ref()]);
    println!("{out}");
    let found = number_after(&out, "; estimate ");
    let ppm = number_after(&out, "drift ");
    // The fit is the arrivals' lower envelope, so the arrival jitter stays out of the latency.
    assert!(
        (found - 37.0).abs() < 5.0,
        "latency {found} ms: more than one sample off"
    );
    assert!((found - 37.0).abs() < 0.1, "latency {found} ms");
    assert!((ppm - 80.0).abs() < 2.0, "drift {ppm} ppm");
    assert!(out.contains("rows stamped through the fit"), "{out}");
    // The perturbation reaches the magnetic phase through the decoded register images.
    let magnetic_n = out
        .lines()
        .find(|l| l.starts_with("N "))
        .and_then(|l| l.split_whitespace().nth(4))
        .unwrap();
    assert!(magnetic_n.parse::<usize>().unwrap() > 50, "{out}");
    assert_outputs(&session);
}

#[test]
fn a_simulated_case_study_is_scored_from_an_estimates_file() {
    let dir = scratch("cli-simulate");
    let run = dir.join("run");
    let scene = format!(
        "{}/../hil-fixtures/scenes/case-study.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    margemu(&[
        "simulate".as_ref(),
        scene.as_ref(),
        "-o".as_ref(),
        run.as_ref(),
    ]);
    let truth = read_truth(&run.join("truth.csv")).unwrap();
    let mut noise = stream(2, "test/noise");
    let est: Vec<_> = truth
        .attitude
        .iter()
        .map(|&(t, q)| (t, noisy(q, &mut noise, 0.02)))
        .collect();
    let est_path = dir.join("filter.csv");
    write_estimates(&est_path, &est);
    let out_dir = dir.join("evaluation");
    let out = margemu(&[
        "evaluate".as_ref(),
        run.as_ref(),
        "--estimates".as_ref(),
        est_path.as_ref(),
        "--out".as_ref(),
        out_dir.as_ref(),
    ]);
    println!("{out}");
    assert!(
        out.contains("latency 0.000 ms applied (fixed by the caller)")
            || out.contains("latency 0.000 ms applied"),
        "{out}"
    );
    let n_all = number_after(&out, "\nN ");
    assert_eq!(n_all as usize, truth.attitude.len());
    // 0.02 rad per axis: geodesic RMS ≈ 0.02·√3.
    let g = number_after(&out, "geodesic RMS (rad) ");
    assert!((g - 0.02 * 3f64.sqrt()).abs() < 0.002, "{out}");
    assert_outputs(&out_dir);
    let report = std::fs::read_to_string(out_dir.join("report.md")).unwrap();
    assert!(
        report.contains("perturbation.csv (magnetic phases)"),
        "{report}"
    );
    assert!(report.contains("Norms from marg.csv"), "{report}");
}
