//! Shared by the `evaluate_*` tests: an analytic motion, noisy copies of it, and scratch files.
#![allow(dead_code)]

use margemu::evaluate::quat::from_euler;
use margemu::evaluate::Stamped;
use margemu::output::TruthWriter;
use margemu::truth::Truth;
use margemu_model::rng::{standard_normal, StreamRng};
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

/// Roll, pitch and yaw of a smooth test motion at `t` s (yaw sweeps ±143°).
pub fn euler_at(t: f64) -> [f64; 3] {
    [
        0.6 * (TAU * 0.7 * t).sin(),
        0.4 * (TAU * 0.45 * t + 1.0).sin(),
        2.5 * (TAU * 0.23 * t).sin(),
    ]
}

/// `[w, x, y, z]` of ZYX Euler angles.
pub fn q_of(e: [f64; 3]) -> [f64; 4] {
    coords(&from_euler(e))
}

/// `[w, x, y, z]` of a unit quaternion.
pub fn coords(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// The test motion sampled at `rate` Hz for `seconds`, instants `floor(k·10⁹/rate)`.
pub fn truth_series(rate: f64, seconds: f64) -> Vec<Stamped> {
    let n = (rate * seconds).round() as u64;
    (0..n)
        .map(|k| {
            let t_ns = (k as f64 * 1e9 / rate).floor() as u64;
            (t_ns, q_of(euler_at(t_ns as f64 * 1e-9)))
        })
        .collect()
}

/// `q` turned by a random rotation with `sigma` rad per body axis.
pub fn noisy(q: [f64; 4], rng: &mut StreamRng, sigma: f64) -> [f64; 4] {
    let mut d = || f64::from(standard_normal(rng)) * sigma;
    let delta = UnitQuaternion::from_scaled_axis(Vector3::new(d(), d(), d()));
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
    coords(&(q * delta))
}

/// An empty scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-evaluate-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A truth row with attitude `e`, body rate `rate`, no external acceleration and the
/// author's reference field (rotated into the body, so its norm is that of the reference).
pub fn truth_row(t_ns: u64, e: [f64; 3], rate: [f64; 3]) -> Truth {
    let q = from_euler(e);
    let field = q.inverse() * Vector3::new(0.5, 0.0, -0.83);
    let force = q.inverse() * Vector3::new(0.0, 0.0, 9.80665);
    Truth {
        t_ns,
        euler: e,
        quaternion: coords(&q),
        body_rate: rate,
        specific_force: force.into(),
        field_body: field.into(),
        ..Truth::default()
    }
}

/// Writes `dir/truth.csv`.
pub fn write_truth(dir: &Path, rows: &[Truth]) {
    let file = std::fs::File::create(dir.join("truth.csv")).unwrap();
    let mut w = TruthWriter::new(std::io::BufWriter::new(file)).unwrap();
    for r in rows {
        w.write(r).unwrap();
    }
    w.finish().unwrap();
}

/// Writes an estimates file `t_s,qw,qx,qy,qz`.
pub fn write_estimates(path: &Path, est: &[Stamped]) {
    let mut text = String::from("t_s,qw,qx,qy,qz\n");
    for (t, q) in est {
        text += &format!("{},{},{},{},{}\n", *t as f64 * 1e-9, q[0], q[1], q[2], q[3]);
    }
    std::fs::write(path, text).unwrap();
}
