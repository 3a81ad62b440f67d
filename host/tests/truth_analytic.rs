//! Ground truth against closed forms: constant-rate rotations, a level static plate, a
//! sinusoidal translation, and the body rate against the finite difference of the attitude.

use margemu::run::run;
use margemu::scene::Scene;
use margemu::truth::Truth;
use std::f64::consts::PI;
use std::path::Path;

const G: f64 = 9.80665;

fn truths(text: &str) -> Vec<Truth> {
    let scene = Scene::parse_str(text, Path::new("analytic.toml")).unwrap();
    let mut out = Vec::new();
    run(
        &scene,
        |t: &Truth| -> Result<(), ()> { Ok(out.push(*t)) },
        |_, _| {},
    )
    .unwrap()
    .unwrap();
    out
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn constant_rate_rotation_about_each_axis_matches_the_closed_form() {
    let w = 2.5; // rad/s, through several full turns (and through ±90° of pitch)
    for (axis, joint) in ["roll", "pitch", "yaw"].iter().enumerate() {
        let text = format!(
            "duration = 6.0\nrate = 100.0\nseed = 1\nmotion = \"kinematic\"\n\
             [joints.{joint}]\ntype = \"polynomial\"\ncoefficients = [0.0, {w}]\n"
        );
        for t in truths(&text) {
            let angle = w * t.t_ns as f64 * 1e-9;
            let (s, c) = (0.5 * angle).sin_cos();
            let mut expected_q = [c, 0.0, 0.0, 0.0];
            expected_q[axis + 1] = s;
            for i in 0..4 {
                assert!(
                    close(t.quaternion[i], expected_q[i], 1e-12),
                    "{joint} q at {}: {:?}",
                    t.t_ns,
                    t.quaternion
                );
            }
            let mut rate = [0.0; 3];
            rate[axis] = w;
            assert_eq!(t.body_rate, rate, "{joint} body rate");
            assert_eq!(t.angular_accel, [0.0; 3]);
            // Gravity seen from the rotating plate.
            let (sa, ca) = angle.sin_cos();
            let f = match axis {
                0 => [0.0, G * sa, G * ca],
                1 => [-G * sa, 0.0, G * ca],
                _ => [0.0, 0.0, G],
            };
            for i in 0..3 {
                assert!(
                    close(t.specific_force[i], f[i], 1e-12),
                    "{joint} f at {}: {:?}",
                    t.t_ns,
                    t.specific_force
                );
            }
        }
    }
}

#[test]
fn a_level_static_plate_reads_plus_g() {
    for t in truths("duration = 1.0\nrate = 50.0\nseed = 1\nmotion = \"static\"\n") {
        assert_eq!(t.specific_force, [0.0, 0.0, G]);
        assert_eq!(t.quaternion, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(t.body_rate, [0.0; 3]);
        assert_eq!(t.euler, [0.0; 3]);
        assert_eq!(t.field_body, [0.5, 0.0, -0.83]);
    }
}

#[test]
fn a_sinusoidal_translation_gives_the_closed_form_acceleration() {
    let (a, f) = (0.2, 3.0);
    let text = format!(
        "duration = 2.0\nrate = 1000.0\nseed = 1\nmotion = \"kinematic\"\n\
         [joints.y]\ntype = \"sine\"\namplitude = {a}\nfrequency = {f}\noffset = 1.0\n"
    );
    let w = 2.0 * PI * f;
    for t in truths(&text) {
        let s = t.t_ns as f64 * 1e-9;
        let accel = -a * w * w * (w * s).sin();
        assert!(close(t.position[1], 1.0 + a * (w * s).sin(), 1e-12));
        assert!(close(t.velocity[1], a * w * (w * s).cos(), 1e-12));
        assert!(close(t.accel_world[1], accel, 1e-9));
        assert!(close(t.accel_body[1], accel, 1e-9));
        assert!(close(t.specific_force[1], accel, 1e-9));
        assert_eq!(t.specific_force[2], G);
    }
}

/// Body rate from two attitudes: `q_{k+1} = q_k ⊗ exp(ω dt / 2)`, so `ω ≈ 2 vec(q_k* ⊗ q_{k+1}) / dt`.
fn rate_from_attitudes(q0: &[f64; 4], q1: &[f64; 4], dt: f64) -> [f64; 3] {
    let [w0, x0, y0, z0] = *q0;
    let [w1, x1, y1, z1] = *q1;
    let x = w0 * x1 - x0 * w1 - y0 * z1 + z0 * y1;
    let y = w0 * y1 + x0 * z1 - y0 * w1 - z0 * x1;
    let z = w0 * z1 - x0 * y1 + y0 * x1 - z0 * w1;
    [2.0 * x / dt, 2.0 * y / dt, 2.0 * z / dt]
}

fn check_finite_differences(ts: &[Truth], rate_tol: f64, accel_tol: f64) {
    for pair in ts.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        let dt = (b.t_ns - a.t_ns) as f64 * 1e-9;
        let fd = rate_from_attitudes(&a.quaternion, &b.quaternion, dt);
        for i in 0..3 {
            let mid = 0.5 * (a.body_rate[i] + b.body_rate[i]);
            assert!(
                close(fd[i], mid, rate_tol),
                "rate {i} at {}: fd {} vs {}",
                a.t_ns,
                fd[i],
                mid
            );
            let fd_accel = (b.body_rate[i] - a.body_rate[i]) / dt;
            let mid_accel = 0.5 * (a.angular_accel[i] + b.angular_accel[i]);
            assert!(
                close(fd_accel, mid_accel, accel_tol),
                "ang. accel {i} at {}: {fd_accel} vs {mid_accel}",
                a.t_ns
            );
            let fd_lin = (b.velocity[i] - a.velocity[i]) / dt;
            let mid_lin = 0.5 * (a.accel_world[i] + b.accel_world[i]);
            assert!(
                close(fd_lin, mid_lin, accel_tol),
                "accel {i} at {}: {fd_lin} vs {mid_lin}",
                a.t_ns
            );
        }
    }
}

#[test]
fn body_rate_agrees_with_the_attitude_kinematic() {
    // Pitch swings past ±90°, where the Euler rates are singular but the body rate is not.
    let text = "duration = 4.0\nrate = 20000.0\nseed = 1\nmotion = \"kinematic\"\n\
        [joints.x]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 1.5\n\
        [joints.roll]\ntype = \"sine\"\namplitude = 1.2\nfrequency = 1.3\n\
        [joints.pitch]\ntype = \"sine\"\namplitude = 1.9\nfrequency = 0.7\nphase = 0.4\n\
        [joints.yaw]\ntype = \"sine\"\namplitude = 2.0\nfrequency = 0.9\nphase = 1.0\n";
    check_finite_differences(&truths(text), 1e-5, 1e-4);
}

#[test]
fn body_rate_agrees_with_the_attitude_on_the_bench() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../hil-fixtures/scenes/gimbal-lock.toml"
    ))
    .unwrap();
    let text = text
        .replace("rate = 1000.0", "rate = 10000.0")
        .replace("duration = 10.0", "duration = 4.0");
    let text = text.replacen("seed = 1", "seed = 1\n[integrator]\nstep = 0.0001", 1);
    // Skip the first 0.2 s: yaw's sine starts at 0.42 rad, a step the PID answers with a jerk
    // no finite difference at 0.1 ms resolves.
    let ts = truths(&text);
    check_finite_differences(&ts[2000..], 1e-4, 2e-2);
}
