//! Speed against error, measured on this machine (`margemu bench`).
//!
//! - [`integrator_sweep`]: for each integrator and step, the largest attitude error (geodesic
//!   angle, rad) and position error (m) against a converged reference run (RK4 at a step far
//!   below any in the sweep), and the simulated seconds per wall second of dynamics + ground
//!   truth (no file output).
//! - [`mode_costs`]: the cost per output sample of a static, a kinematic and a bench scene.

use crate::reference::ReferenceError;
use crate::run::for_each;
use crate::scene::{Method, Scene};
use crate::truth::geodesic_angle;
use margemu_model::time::nanos_from_seconds;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// One row of the integrator table.
#[derive(Clone, Copy, Debug)]
pub struct IntegratorRow {
    /// Method.
    pub method: Method,
    /// Largest internal step (s).
    pub step: f64,
    /// Largest attitude error against the reference (rad).
    pub max_attitude_error: f64,
    /// Largest position error against the reference (m).
    pub max_position_error: f64,
    /// Simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// One row of the mode table.
#[derive(Clone, Debug)]
pub struct ModeRow {
    /// Scene name.
    pub name: String,
    /// Motion mode.
    pub mode: String,
    /// Wall time per output sample (ns).
    pub ns_per_sample: f64,
    /// Simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// `scene` with another integrator.
pub fn with_integrator(scene: &Scene, method: Method, step: f64) -> Scene {
    let mut s = scene.clone();
    s.spec.integrator.method = method;
    s.spec.integrator.step = step;
    s.step_ns = nanos_from_seconds(step).expect("a valid step");
    s
}

/// Attitude quaternion and position at every output sample.
type Trajectory = Vec<([f64; 4], [f64; 3])>;

fn trajectory(scene: &Scene) -> Result<Trajectory, ReferenceError> {
    let mut out = Vec::with_capacity(scene.samples() as usize);
    for_each(scene, |t| out.push((t.quaternion, t.position)))?;
    Ok(out)
}

/// Times full runs of `scene` (truth computed, nothing written) for at least `min_wall`;
/// returns wall seconds per run. One untimed run first warms caches and the per-process PID
/// synthesis memo, so the figure is the steady per-sample cost.
pub fn time_run(scene: &Scene, min_wall: Duration) -> Result<f64, ReferenceError> {
    for_each(scene, |_| {})?;
    let mut runs = 0u32;
    let start = Instant::now();
    while runs == 0 || start.elapsed() < min_wall {
        let mut acc = 0.0;
        for_each(scene, |t| acc += t.quaternion[0] + t.specific_force[2])?;
        black_box(acc);
        runs += 1;
    }
    Ok(start.elapsed().as_secs_f64() / runs as f64)
}

/// Errors and speed of each `(method, step)` on `scene`, against RK4 at `reference_step`.
pub fn integrator_sweep(
    scene: &Scene,
    configs: &[(Method, f64)],
    reference_step: f64,
    min_wall: Duration,
) -> Result<Vec<IntegratorRow>, ReferenceError> {
    let reference = trajectory(&with_integrator(scene, Method::Rk4, reference_step))?;
    configs
        .iter()
        .map(|&(method, step)| {
            let s = with_integrator(scene, method, step);
            let traj = trajectory(&s)?;
            let (mut att, mut pos) = (0.0f64, 0.0f64);
            for ((q, p), (qr, pr)) in traj.iter().zip(&reference) {
                att = att.max(geodesic_angle(q, qr));
                let d = [p[0] - pr[0], p[1] - pr[1], p[2] - pr[2]];
                pos = pos.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
            }
            let wall = time_run(&s, min_wall)?;
            Ok(IntegratorRow {
                method,
                step,
                max_attitude_error: att,
                max_position_error: pos,
                realtime_factor: s.spec.duration / wall,
            })
        })
        .collect()
}

/// Cost per output sample of each scene.
pub fn mode_costs(scenes: &[Scene], min_wall: Duration) -> Result<Vec<ModeRow>, ReferenceError> {
    scenes
        .iter()
        .map(|s| {
            let wall = time_run(s, min_wall)?;
            Ok(ModeRow {
                name: s
                    .spec
                    .name
                    .clone()
                    .unwrap_or_else(|| s.path.display().to_string()),
                mode: format!("{:?}", s.spec.motion).to_lowercase(),
                ns_per_sample: wall * 1e9 / s.samples() as f64,
                realtime_factor: s.spec.duration / wall,
            })
        })
        .collect()
}
