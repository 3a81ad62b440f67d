//! Alignment: a known latency injected into estimates is recovered to within one sample, and a
//! device clock's offset and drift are recovered from a session's `dut_attitude.csv`.

mod evaluate_common;

use evaluate_common::*;
use margemu::evaluate::run::Clock;
use margemu::evaluate::{
    estimate_latency, evaluate, Estimates, EvalOptions, LatencySearch, Reference, Source,
};
use margemu_model::rng::{stream, uniform};

/// Estimates on the truth's own 200 Hz grid that describe the truth `lag_ns` earlier, with
/// 0.01 rad of rotation noise per axis.
fn delayed(truth_rate: f64, seconds: f64, lag_ns: i64, seed: u64) -> Vec<(u64, [f64; 4])> {
    let mut rng = stream(seed, "test/noise");
    let n = (truth_rate * seconds) as u64;
    (0..n)
        .map(|k| {
            let t_ns = (k as f64 * 1e9 / truth_rate) as u64;
            let seen = (t_ns as i64 - lag_ns) as f64 * 1e-9;
            (t_ns, noisy(q_of(euler_at(seen)), &mut rng, 0.01))
        })
        .collect()
}

#[test]
fn injected_latency_is_recovered_within_one_sample() {
    let truth = truth_series(200.0, 20.0);
    let reference = Reference::new(&truth).unwrap();
    let period_ns = 5_000_000i64;
    println!("injected (ms)  recovered (ms)  error (ms)  contrast");
    for (seed, lag_ns) in [0i64, 2_500_000, 37_000_000, 123_400_000, -12_000_000]
        .into_iter()
        .enumerate()
    {
        let est = Estimates::new(&delayed(200.0, 20.0, lag_ns, seed as u64)).unwrap();
        let found = estimate_latency(&reference, &est, &LatencySearch::default()).unwrap();
        let error = found.lag_ns - lag_ns;
        println!(
            "{:>13.3} {:>15.3} {:>11.3} {:>9.3}",
            lag_ns as f64 * 1e-6,
            found.lag_ns as f64 * 1e-6,
            error as f64 * 1e-6,
            found.contrast
        );
        assert!(found.observable, "{found:?}");
        assert!(
            error.abs() < period_ns,
            "lag {lag_ns} ns found as {}",
            found.lag_ns
        );
    }
}

#[test]
fn latency_at_rest_is_reported_unobservable() {
    let still: Vec<(u64, [f64; 4])> = (0..2000u64)
        .map(|k| (k * 5_000_000, q_of([0.1, -0.2, 1.0])))
        .collect();
    let mut rng = stream(3, "test/noise");
    let est: Vec<(u64, [f64; 4])> = still
        .iter()
        .map(|&(t, q)| (t + 20_000_000, noisy(q, &mut rng, 0.01)))
        .collect();
    let found = estimate_latency(
        &Reference::new(&still).unwrap(),
        &Estimates::new(&est).unwrap(),
        &LatencySearch::default(),
    )
    .unwrap();
    assert!(!found.observable, "{found:?}");
    assert!(found.contrast < 0.2, "{found:?}");
}

/// A session directory with `truth.csv`, a `meta.toml` naming `start_host_ns`, and a
/// `dut_attitude.csv` whose rows left the device `latency` after their truth instant, on a
/// device clock that reads `(host − offset) / (1 + drift)`, arriving with up to 400 µs of
/// jitter.
fn session(name: &str, offset_ns: f64, drift: f64, latency_ns: f64) -> std::path::PathBuf {
    let dir = scratch(name);
    let rows: Vec<_> = (0..6000u64)
        .map(|k| {
            let t = k * 5_000_000;
            truth_row(t, euler_at(t as f64 * 1e-9), [1.0, 0.0, 0.0])
        })
        .collect();
    write_truth(&dir, &rows);
    let start = 987_654_321i64;
    std::fs::write(dir.join("meta.toml"), format!("start_host_ns = {start}\n")).unwrap();
    let mut rng = stream(9, "test/jitter");
    let mut noise = stream(9, "test/noise");
    let mut text =
        String::from("host_ns,protocol,message,device_time_us,roll,pitch,yaw,qw,qx,qy,qz\n");
    for r in &rows {
        let sent = r.t_ns as f64 + latency_ns;
        let device_us = (sent - offset_ns) / (1.0 + drift) / 1e3;
        let host = start + (sent + uniform(&mut rng, 0.0, 400e3)) as i64;
        let q = noisy(r.quaternion, &mut noise, 0.005);
        let e = margemu::evaluate::quat::euler(&margemu::evaluate::quat::normalize(q).unwrap());
        text += &format!(
            "{host},serial,attitude,{device_us:.3},{},{},{},{},{},{},{}\n",
            e[0], e[1], e[2], q[0], q[1], q[2], q[3]
        );
    }
    std::fs::write(dir.join("dut_attitude.csv"), text).unwrap();
    dir
}

#[test]
fn clock_offset_and_drift_are_recovered_from_device_times() {
    let (offset, drift, latency) = (-3.25e9, 150e-6, 37e6);
    let dir = session("clock", offset, drift, latency);
    let eval = evaluate(&Source::Session(dir), &EvalOptions::default()).unwrap();
    let Clock::Fitted(fit, used) = eval.clock else {
        panic!("no clock fit: {:?}", eval.clock)
    };
    // The fit is the lower envelope of the arrivals: the offset as set (arrival jitter 0-400 µs
    // above it), the residual RMS that of the jitter, 400/√3 µs.
    println!(
        "offset {:.3} ms (set {:.3}), drift {:.3} ppm (set {}), residual RMS {:.1} µs, latency {:.3} ms (set 37)",
        fit.offset_ns * 1e-6,
        offset * 1e-6,
        fit.drift_ppm,
        drift * 1e6,
        fit.residual_rms_ns * 1e-3,
        eval.latency_applied_ns as f64 * 1e-6
    );
    assert!(used);
    assert!((fit.drift_ppm - 150.0).abs() < 2.0, "{fit:?}");
    assert!((fit.offset_ns - offset).abs() < 20e3, "{fit:?}");
    assert!(
        (fit.residual_rms_ns - 400e3 / 3f64.sqrt()).abs() < 10e3,
        "{fit:?}"
    );
    assert!((eval.latency_applied_ns as f64 - 37e6).abs() < 0.5e6);
    // Host arrival stamps give the same latency, only noisier.
    let options = EvalOptions {
        device_time: false,
        ..EvalOptions::default()
    };
    let dir = session("clock-host", offset, drift, latency);
    let eval = evaluate(&Source::Session(dir), &options).unwrap();
    assert!(matches!(eval.clock, Clock::Fitted(_, false)));
    assert!((eval.latency_applied_ns as f64 - 37.2e6).abs() < 1e6);
}
