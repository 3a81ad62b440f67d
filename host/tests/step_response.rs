//! Each joint's closed-loop step response, with Table 1 and Table 2 defaults, meets Table 2:
//! overshoot ≤ 20 % and 2 % settling ≤ 1 s for joints 1–3, ≤ 40 % and ≤ 0.3 s for joints 4–6.

use margemu::bench::Bench;
use margemu::scene::{Scene, JOINT_NAMES};
use std::path::Path;

struct Response {
    overshoot: f64,
    settling: f64,
}

/// Steps joint `i` from `from` to `to` at t = 0 and measures the response at 10 kHz.
fn step_response(i: usize, from: f64, to: f64, extra: &str) -> Response {
    let mut initial = [0.0; 6];
    initial[i] = from;
    let text = format!(
        "duration = 3.0\nrate = 10000.0\nseed = 1\n[integrator]\nstep = 0.0001\n\
         [bench]\ninitial = {initial:?}\n{extra}\n[joints.{}]\ntype = \"steps\"\npoints = [[0.0, {to}]]\n",
        JOINT_NAMES[i]
    );
    let scene = Scene::parse_str(&text, Path::new("step.toml")).unwrap();
    let mut bench = Bench::new(&scene).unwrap();
    let delta = to - from;
    let (mut peak, mut settling) = (0.0f64, 0.0);
    for k in 0..scene.samples() {
        let t = scene.clock.instant(k);
        bench.advance_to(t);
        let q = bench.sample().q[i];
        peak = peak.max((q - from) / delta);
        if ((q - to) / delta).abs() > 0.02 {
            settling = t as f64 * 1e-9;
        }
    }
    Response {
        overshoot: peak - 1.0,
        settling,
    }
}

#[test]
fn prismatic_joints_meet_table2() {
    for i in 0..3 {
        for (from, to) in [(1.0, 1.1), (1.0, 0.5), (0.0, 2.0)] {
            let r = step_response(i, from, to, "");
            assert!(
                r.overshoot <= 0.20,
                "joint {}: overshoot {:.3}",
                i + 1,
                r.overshoot
            );
            assert!(
                r.overshoot > 0.05,
                "joint {}: the designed overshoot is missing",
                i + 1
            );
            assert!(
                r.settling <= 1.0,
                "joint {}: settling {:.3} s",
                i + 1,
                r.settling
            );
        }
    }
}

#[test]
fn revolute_joints_meet_table2() {
    for i in 3..6 {
        for (from, to) in [(0.0, 0.5), (0.3, -1.0)] {
            let r = step_response(i, from, to, "");
            assert!(
                r.overshoot <= 0.40,
                "joint {}: overshoot {:.3}",
                i + 1,
                r.overshoot
            );
            assert!(
                r.overshoot > 0.2,
                "joint {}: the designed overshoot is missing",
                i + 1
            );
            assert!(
                r.settling <= 0.3,
                "joint {}: settling {:.3} s",
                i + 1,
                r.settling
            );
        }
    }
}

#[test]
fn joint3_holds_its_position_against_gravity() {
    // With the feed-forward of eq. 14, a joint at its setpoint stays there exactly.
    let scene = Scene::parse_str(
        "duration = 1.0\nrate = 100.0\nseed = 1\n[bench]\ninitial = [0.0, 0.0, 1.5, 0.0, 0.0, 0.0]\n",
        Path::new("hold.toml"),
    )
    .unwrap();
    let mut bench = Bench::new(&scene).unwrap();
    // Without the feed-forward it would sag by about m·g / K_P ≈ 1.5 cm before the integrator
    // caught up.
    for k in 1..=100 {
        bench.advance_to(k * 10_000_000);
        let z = bench.sample().q[2];
        assert!((z - 1.5).abs() < 1e-9, "z = {z} at step {k}");
    }
}

#[test]
fn anti_windup_keeps_a_saturated_step_from_overshooting() {
    // A 1 m step with the effort limited to 5 kN (≈ 1 g for joint 1) saturates for most of a
    // second; a wound-up integrator overshoots far past the 20 % requirement (measured:
    // 159 % with conditional integration disabled, 25 % with it).
    let limited = "effort_limit = [5000.0, 5000.0, 5000.0, 1.0, 1.0, 1.0]";
    let r = step_response(0, 0.0, 1.0, limited);
    assert!(r.overshoot <= 0.30, "overshoot {:.3}", r.overshoot);
    assert!(r.settling <= 3.0, "settling {:.3} s", r.settling);
}
