//! Static friction (eq. 5–8): a stuck joint stays put until its net effort exceeds τ_s, slides,
//! sticks again only at a velocity zero crossing, and never chatters.

use margemu::bench::{joint::FrictionChange, Bench};
use margemu::scene::Scene;
use std::path::Path;

const STICTION: f64 = 2000.0; // N

fn ramp_scene() -> Scene {
    // Joint 1 follows a slow ramp (2 cm/s) from rest: the PID's effort grows until it breaks
    // the joint free; the joint then catches up, overshoots and comes to rest again.
    let text = format!(
        "duration = 6.0\nrate = 1000.0\nseed = 1\n\
         [bench]\ninitial = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]\nstatic_friction = [{STICTION}, 0, 0, 0, 0, 0]\n\
         [joints.x]\ntype = \"polynomial\"\ncoefficients = [1.0, 0.02]\n"
    );
    Scene::parse_str(&text, Path::new("stiction.toml")).unwrap()
}

#[test]
fn stick_then_slip_at_the_threshold() {
    let scene = ramp_scene();
    let mut bench = Bench::new(&scene).unwrap();
    assert!(bench.joints()[0].is_stuck(), "a joint starts stuck");
    let mut previous_net = 0.0f64;
    let mut slipped = false;
    for k in 1..scene.samples() {
        let net_before = {
            let r = bench.reference(0);
            bench.joints()[0].net_effort(r)
        };
        bench.advance_to(scene.clock.instant(k));
        let joint = &bench.joints()[0];
        if joint.is_stuck() && !slipped {
            assert_eq!(joint.position(), 1.0, "a stuck joint does not move");
            assert_eq!(joint.velocity(), 0.0);
            assert!(
                net_before.abs() <= STICTION,
                "still stuck at |u| = {net_before}"
            );
        } else if !slipped {
            slipped = true;
            // Broke free in the first step whose starting effort exceeded τ_s.
            assert!(net_before.abs() > STICTION, "slipped at |u| = {net_before}");
            assert!(
                previous_net.abs() <= STICTION,
                "should have slipped a step earlier"
            );
            // The PID effort grows by K_I·e·dt per step, a tiny fraction of τ_s.
            assert!(
                net_before.abs() < STICTION * 1.01,
                "slipped late at |u| = {net_before}"
            );
        }
        previous_net = net_before;
    }
    assert!(slipped, "never slipped");
}

#[test]
fn no_chattering() {
    // Two small steps (1 mm, then back): the proportional effort stays below τ_s, the integral
    // breaks the joint free, and it comes to rest again at a velocity zero crossing.
    let text = format!(
        "duration = 8.0\nrate = 1000.0\nseed = 1\n\
         [bench]\ninitial = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]\nstatic_friction = [{STICTION}, 0, 0, 0, 0, 0]\n\
         [joints.x]\ntype = \"steps\"\npoints = [[0.1, 1.001], [4.0, 1.0]]\n"
    );
    let scene = Scene::parse_str(&text, Path::new("steps.toml")).unwrap();
    let mut bench = Bench::new(&scene).unwrap();
    bench.advance_to(scene.duration_ns);
    let log = bench.friction_log();
    assert!(log.len() >= 2, "expected stick-slip cycles, got {log:?}");
    assert_eq!(log[0].change, FrictionChange::Slip);
    for pair in log.windows(2) {
        assert_ne!(pair[0].change, pair[1].change, "modes alternate");
        let gap_ms = (pair[1].t_ns - pair[0].t_ns) as f64 * 1e-6;
        assert!(
            gap_ms >= 20.0,
            "mode changes {gap_ms} ms apart: chattering ({log:?})"
        );
    }
    for event in log.iter().filter(|e| e.change == FrictionChange::Stick) {
        assert_eq!(event.joint, 0);
    }
}

#[test]
fn zero_stiction_never_changes_mode() {
    let text = "duration = 2.0\nrate = 1000.0\nseed = 1\n[joints.x]\ntype = \"sine\"\namplitude = 0.1\nfrequency = 1.0\n";
    let scene = Scene::parse_str(text, Path::new("free.toml")).unwrap();
    let mut bench = Bench::new(&scene).unwrap();
    bench.advance_to(scene.duration_ns);
    assert!(bench.friction_log().is_empty());
    assert!(bench.joints().iter().all(|j| !j.is_stuck()));
}
