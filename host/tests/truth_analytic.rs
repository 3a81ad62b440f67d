//! Ground truth against closed forms: constant-rate rotations, a level static plate, a
//! sinusoidal translation, and the body rate against the finite difference of the attitude.

use margemu::run::collect;
use margemu::scene::Scene;
use margemu::truth::Truth;
use std::f64::consts::PI;
use std::path::Path;

const G: f64 = 9.80665;

fn truths(text: &str) -> Vec<Truth> {
    collect(&Scene::parse_str(text, Path::new("analytic.toml")).unwrap()).unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn assert_all_close(got: &[f64], want: &[f64], tol: f64, what: &str) {
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(close(*g, *w, tol), "{what}, component {i}: {g} vs {w}");
    }
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
            assert_all_close(
                &t.quaternion,
                &expected_q,
                1e-12,
                &format!("{joint} q at {}", t.t_ns),
            );
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
            assert_all_close(
                &t.specific_force,
                &f,
                1e-12,
                &format!("{joint} f at {}", t.t_ns),
            );
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
        let mean = |x: &[f64; 3], y: &[f64; 3]| [0, 1, 2].map(|k| 0.5 * (x[k] + y[k]));
        let slope = |x: &[f64; 3], y: &[f64; 3]| [0, 1, 2].map(|k| (y[k] - x[k]) / dt);
        let at = a.t_ns;
        assert_all_close(
            &fd,
            &mean(&a.body_rate, &b.body_rate),
            rate_tol,
            &format!("rate at {at}"),
        );
        let (accel, fd_accel) = (
            mean(&a.angular_accel, &b.angular_accel),
            slope(&a.body_rate, &b.body_rate),
        );
        assert_all_close(
            &fd_accel,
            &accel,
            accel_tol,
            &format!("angular accel at {at}"),
        );
        let (lin, fd_lin) = (
            mean(&a.accel_world, &b.accel_world),
            slope(&a.velocity, &b.velocity),
        );
        assert_all_close(&fd_lin, &lin, accel_tol, &format!("accel at {at}"));
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
