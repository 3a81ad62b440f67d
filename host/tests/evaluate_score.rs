//! Scores: eq. 27 on known errors, `q` and `−q` alike, yaw errors wrapped across ±π, a phase
//! split on a constructed run, and external recordings (estimate columns, an estimates file and
//! the filter seam `estimate_with`).

mod evaluate_common;

use evaluate_common::*;
use margemu::evaluate::quat::from_euler;
use margemu::evaluate::{
    estimate_with, evaluate, score, EvalOptions, Phase, ScoreOptions, Scores, Source,
};
use margemu_model::rng::stream;
use std::f64::consts::PI;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

#[test]
fn constant_errors_give_the_expected_mse_std_and_f() {
    let truth = truth_series(200.0, 5.0);
    // Estimate = truth followed by a fixed 0.02 rad roll about the body x axis: with pitch and
    // yaw from the same ZYX sequence, the roll error is exactly −0.02 and the others 0.
    let est: Vec<_> = truth
        .iter()
        .map(|&(t, _)| {
            let mut e = euler_at(t as f64 * 1e-9);
            e[0] += 0.02;
            (t, q_of(e))
        })
        .collect();
    let s = score(&truth, &est, &ScoreOptions::default()).unwrap();
    assert_eq!(s.count, 1000);
    assert!(close(s.angles[0].mse, 4e-4, 1e-9), "{s:?}");
    assert!(close(s.angles[0].mean, -0.02, 1e-9), "{s:?}");
    assert!(s.angles[0].std < 1e-9 && s.angles[1].mse < 1e-20, "{s:?}");
    assert_eq!(
        s.f,
        (s.angles[0].mse * s.angles[1].mse * s.angles[2].mse).cbrt()
    );
    assert!(close(s.geodesic_rms, 0.02, 1e-9), "{s:?}");
}

#[test]
fn q_and_minus_q_score_the_same() {
    let truth = truth_series(200.0, 10.0);
    let mut rng = stream(5, "test/noise");
    let est: Vec<_> = truth
        .iter()
        .map(|&(t, q)| (t + 2_500_000, noisy(q, &mut rng, 0.05)))
        .collect();
    // Every other estimate negated, and the truth negated too: same attitudes.
    let flipped: Vec<_> = est
        .iter()
        .enumerate()
        .map(|(k, &(t, q))| (t, if k % 2 == 0 { q.map(|c| -c) } else { q }))
        .collect();
    let neg_truth: Vec<_> = truth.iter().map(|&(t, q)| (t, q.map(|c| -c))).collect();
    let opts = ScoreOptions {
        latency_ns: 1_000_000,
        ..ScoreOptions::default()
    };
    let a = score(&truth, &est, &opts).unwrap();
    let b = score(&truth, &flipped, &opts).unwrap();
    let c = score(&neg_truth, &flipped, &opts).unwrap();
    let same = |x: &Scores, y: &Scores| {
        x.count == y.count
            && close(x.f, y.f, 1e-12)
            && close(x.geodesic_rms, y.geodesic_rms, 1e-12)
            && (0..3).all(|i| close(x.angles[i].mse, y.angles[i].mse, 1e-12))
    };
    assert!(same(&a, &b), "{a:?}\n{b:?}");
    assert!(same(&a, &c), "{a:?}\n{c:?}");
    assert!(a.geodesic_rms > 0.05, "{a:?}"); // the noise is there
}

#[test]
fn yaw_errors_wrap_across_plus_minus_pi() {
    // Truth at +179°, estimate at −179°: a 2° error, not 358°.
    let near = PI - 1f64.to_radians();
    let truth: Vec<_> = (0..100u64)
        .map(|k| (k * 10_000_000, q_of([0.0, 0.0, near])))
        .collect();
    let est: Vec<_> = (0..100u64)
        .map(|k| (k * 10_000_000, q_of([0.0, 0.0, -near])))
        .collect();
    let s = score(&truth, &est, &ScoreOptions::default()).unwrap();
    assert!(
        close(s.angles[2].mse.sqrt(), 2f64.to_radians(), 1e-9),
        "{s:?}"
    );
    // true − estimate = 358°, wrapped to −2°.
    assert!(close(s.angles[2].mean, -2f64.to_radians(), 1e-9), "{s:?}");
    // A truth spinning through ±180° and an estimate 3° behind it: every error is 3°.
    let spin = |t: f64| [0.1, 0.0, PI * (t - 1.0)];
    let truth: Vec<_> = (0..400u64)
        .map(|k| (k * 5_000_000, q_of(spin(k as f64 * 0.005))))
        .collect();
    let est: Vec<_> = truth
        .iter()
        .map(|&(t, _)| {
            let mut e = spin(t as f64 * 1e-9);
            e[2] -= 3f64.to_radians();
            (t, q_of(e))
        })
        .collect();
    let s = score(&truth, &est, &ScoreOptions::default()).unwrap();
    assert!(close(s.angles[2].max_abs, 3f64.to_radians(), 1e-9), "{s:?}");
    assert!(close(s.angles[2].std + 1.0, 1.0, 1e-12), "{s:?}");
}

/// A run directory: 0–2 s at rest, 2–4 s turning (1 rad/s), 4–6 s at rest with a magnetic
/// perturbation from 4.5 s to 5.5 s; estimates off in roll by 0.01 rad at rest, 0.05 rad while
/// turning and 0.2 rad under the perturbation.
#[test]
fn phases_split_a_constructed_run() {
    let dir = scratch("phases");
    let rate_hz = 100u64;
    let yaw = |t: f64| (t - 2.0).clamp(0.0, 2.0);
    let rows: Vec<_> = (0..6 * rate_hz)
        .map(|k| {
            let t = k as f64 / rate_hz as f64;
            let turning = (2.0..4.0).contains(&t);
            let rate = if turning { [0.0, 0.0, 1.0] } else { [0.0; 3] };
            truth_row(k * 10_000_000, [0.0, 0.0, yaw(t)], rate)
        })
        .collect();
    write_truth(&dir, &rows);
    let mut pert = String::from("t_ns,mag_x,mag_y,mag_z\n");
    for r in &rows {
        let t = r.t_ns as f64 * 1e-9;
        let d = if (4.5..5.5).contains(&t) { 0.6 } else { 0.0 };
        pert += &format!("{},{d},0.0,0.0\n", r.t_ns);
    }
    std::fs::write(dir.join("perturbation.csv"), pert).unwrap();
    let est: Vec<_> = rows
        .iter()
        .map(|r| {
            let t = r.t_ns as f64 * 1e-9;
            let off = if (4.5..5.5).contains(&t) {
                0.2
            } else if (2.0..4.0).contains(&t) {
                0.05
            } else {
                0.01
            };
            let q = from_euler(r.euler) * from_euler([off, 0.0, 0.0]);
            (r.t_ns, coords(&q))
        })
        .collect();
    let est_path = dir.join("est.csv");
    write_estimates(&est_path, &est);
    let source = Source::Estimates {
        dir: dir.clone(),
        estimates: est_path,
    };
    // No widening of the perturbed span, so the phases are exactly the constructed ones.
    let mut options = EvalOptions::default();
    options.rules.window_ns = 0;
    let eval = evaluate(&source, &options).unwrap();
    let get = |p: Phase| {
        eval.by_phase
            .iter()
            .find(|x| x.0 == p)
            .and_then(|x| x.1)
            .unwrap()
    };
    let (st, dy, ma) = (
        get(Phase::Static),
        get(Phase::Dynamic),
        get(Phase::Magnetic),
    );
    println!(
        "static N {} MSE φ {:.3e}; dynamic N {} MSE φ {:.3e}; magnetic N {} MSE φ {:.3e}",
        st.count, st.angles[0].mse, dy.count, dy.angles[0].mse, ma.count, ma.angles[0].mse
    );
    assert_eq!((st.count, dy.count, ma.count), (300, 200, 100));
    assert!(close(st.angles[0].mse, 1e-4, 1e-6));
    assert!(close(dy.angles[0].mse, 2.5e-3, 1e-6));
    assert!(close(ma.angles[0].mse, 4e-2, 1e-6));
    assert_eq!(eval.scores.count, 600);
    assert_eq!(
        eval.latency_applied_ns, 0,
        "offline runs are not shifted by default"
    );
}

/// An external recording of the test motion with its IMU columns (rates from finite
/// differences, a level field of unit norm, gravity only), and optional estimate columns.
fn recording(path: &std::path::Path, estimate: Option<f64>) {
    let mut text = String::from("t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz");
    if estimate.is_some() {
        text += ",qw_est,qx_est,qy_est,qz_est";
    }
    text += "\n";
    let dt = 0.01;
    for k in 0..1000 {
        let t = k as f64 * dt;
        let (q0, q1) = (from_euler(euler_at(t)), from_euler(euler_at(t + dt)));
        let w = (q0.inverse() * q1).scaled_axis() / dt;
        let g = q0.inverse() * nalgebra::Vector3::new(0.0, 0.0, 9.80665);
        let m = q0.inverse() * nalgebra::Vector3::new(0.6, 0.0, -0.8);
        let q = coords(&q0);
        text += &format!(
            "{t},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            g.x, g.y, g.z, w.x, w.y, w.z, m.x, m.y, m.z, q[0], q[1], q[2], q[3]
        );
        if let Some(off) = estimate {
            let e = coords(&(q0 * from_euler([0.0, off, 0.0])));
            // Rows 0..10: the filter had no output yet.
            if k < 10 {
                text += ",,,,";
            } else {
                text += &format!(",{},{},{},{}", e[0], e[1], e[2], e[3]);
            }
        }
        text += "\n";
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn external_recordings_are_scored_from_columns_a_file_or_a_filter() {
    let dir = scratch("external");
    let file = dir.join("rec.csv");
    recording(&file, Some(0.03));
    let source = Source::External {
        file: file.clone(),
        estimates: None,
    };
    let eval = evaluate(&source, &EvalOptions::default()).unwrap();
    assert_eq!(eval.scores.count, 990);
    assert!(
        close(eval.scores.geodesic_rms, 0.03, 1e-9),
        "{:?}",
        eval.scores
    );
    // No magnetic phase in a clean recording; the plate always moves.
    assert_eq!(
        eval.phases
            .iter()
            .filter(|&&p| p == Phase::Magnetic)
            .count(),
        0
    );

    // The same recording without estimate columns, scored through the filter seam: a gyro
    // integrator started from the reference.
    let plain = dir.join("plain.csv");
    recording(&plain, None);
    let rec = margemu::evaluate::input::read_external(&plain).unwrap();
    let mut q = from_euler(euler_at(0.0));
    let gyro_only = estimate_with(&rec.imu, |k, dt| {
        if k > 0 {
            let w = rec.imu.gyr[k - 1];
            q *= nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::from(w) * dt);
        }
        coords(&q)
    });
    let s = score(&rec.reference, &gyro_only, &ScoreOptions::default()).unwrap();
    println!(
        "gyro integration over 10 s: F {:.3e} rad², geodesic RMS {:.3e} rad",
        s.f, s.geodesic_rms
    );
    assert!(s.geodesic_rms < 1e-9, "{s:?}");
    // ...and through a file, as an offline filter run writes it.
    let est_file = dir.join("gyro.csv");
    write_estimates(&est_file, &gyro_only);
    let source = Source::External {
        file: plain,
        estimates: Some(est_file),
    };
    let eval = evaluate(&source, &EvalOptions::default()).unwrap();
    assert_eq!(eval.scores.count, 1000);
    assert!(eval.scores.geodesic_rms < 1e-6, "{:?}", eval.scores);
}
