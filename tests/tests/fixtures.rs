//! The scenes in `hil-fixtures/scenes/` validate, run, and do what their names promise.

use margemu::motion::Motion;
use margemu::run::collect;
use margemu::scene::{MotionMode, Scene};
use margemu::truth::Truth;
use margemu_tests::fixture_scene;

fn load(name: &str) -> Scene {
    Scene::load(&fixture_scene(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn truths(scene: &Scene) -> Vec<Truth> {
    collect(scene).unwrap()
}

fn finite(t: &Truth) -> bool {
    let groups: [&[f64]; 10] = [
        &t.position,
        &t.velocity,
        &t.euler,
        &t.quaternion,
        &t.body_rate,
        &t.specific_force,
        &t.accel_world,
        &t.accel_body,
        &t.angular_accel,
        &t.field_body,
    ];
    groups.iter().all(|g| g.iter().all(|v| v.is_finite()))
}

fn max_abs(ts: &[Truth], f: impl Fn(&Truth) -> [f64; 3]) -> f64 {
    ts.iter().flat_map(f).fold(0.0, |m, v| m.max(v.abs()))
}

#[test]
fn every_fixture_scene_validates_and_runs() {
    let dir = margemu_tests::workspace_root().join("hil-fixtures/scenes");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    assert!(names.len() >= 4, "{names:?}");
    for path in names {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let ts = truths(&scene);
        assert_eq!(ts.len() as u64, scene.samples(), "{}", path.display());
        assert!(
            ts.iter().all(finite),
            "{}: non-finite output",
            path.display()
        );
    }
}

#[test]
fn gimbal_lock_scene_keeps_a_continuous_unit_quaternion() {
    let scene = load("gimbal-lock.toml");
    let ts = truths(&scene);
    assert_eq!(ts.len(), 10_000, "runs to the end");
    // It really sweeps through ±90° of pitch.
    let through_lock = ts
        .iter()
        .filter(|t| (t.euler[1].abs() - std::f64::consts::FRAC_PI_2).abs() < 0.01)
        .count();
    assert!(
        through_lock >= 4,
        "pitch never reached ±90° ({through_lock} samples near it)"
    );
    for t in &ts {
        assert!(finite(t), "non-finite at {}", t.t_ns);
        let n: f64 = t.quaternion.iter().map(|c| c * c).sum();
        assert!((n - 1.0).abs() < 1e-12, "|q|² = {n} at {}", t.t_ns);
        assert!(
            t.euler[1].abs() <= std::f64::consts::FRAC_PI_2,
            "pitch {} not canonical",
            t.euler[1]
        );
    }
    for pair in ts.windows(2) {
        let dot: f64 = pair[0]
            .quaternion
            .iter()
            .zip(&pair[1].quaternion)
            .map(|(a, b)| a * b)
            .sum();
        // 1 ms apart at < 10 rad/s: the attitude moves by < 0.01 rad, so ⟨q₀, q₁⟩ > cos(0.005).
        assert!(
            dot > 0.99995,
            "quaternion jumps at {}: ⟨q₀, q₁⟩ = {dot}",
            pair[1].t_ns
        );
    }
}

#[test]
fn case_study_scene_covers_the_papers_ranges() {
    let scene = load("case-study.toml");
    assert_eq!(scene.clock.hz(), 200.0);
    let ts = truths(&scene);
    let rate = max_abs(&ts, |t| t.body_rate);
    let accel = max_abs(&ts, |t| t.accel_world) / 9.80665;
    assert!(
        (35.0..=55.0).contains(&rate),
        "body rate peaks at {rate} rad/s, want about ±50"
    );
    assert!(
        (3.0..=5.0).contains(&accel),
        "external acceleration peaks at {accel} g, want about ±4"
    );
}

#[test]
fn figure3_scene_moves_like_the_paper() {
    // Figure 3: tens of g from the prismatic steps, about ±10 rad/s from the sinusoids.
    let ts = truths(&load("figure3.toml"));
    let accel = max_abs(&ts, |t| t.accel_world) / 9.80665;
    let rate = max_abs(&ts, |t| t.body_rate);
    assert!((20.0..=80.0).contains(&accel), "{accel} g");
    assert!((5.0..=20.0).contains(&rate), "{rate} rad/s");
}

#[test]
fn each_mode_builds_only_what_it_needs() {
    let modes = [
        ("static.toml", MotionMode::Static),
        ("figure3.toml", MotionMode::Bench),
    ];
    for (name, mode) in modes {
        let scene = load(name);
        assert_eq!(scene.spec.motion, mode);
        let motion = Motion::new(&scene).unwrap();
        match mode {
            MotionMode::Static => assert!(matches!(motion, Motion::Static(_))),
            _ => assert!(motion.bench().is_some()),
        }
    }
    let kinematic = Scene::parse_str(
        "duration = 1.0\nrate = 100.0\nseed = 1\nmotion = \"kinematic\"\n[joints.roll]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 1.0\n",
        std::path::Path::new("k.toml"),
    )
    .unwrap();
    let motion = Motion::new(&kinematic).unwrap();
    assert!(matches!(motion, Motion::Kinematic(_)) && motion.bench().is_none());
}

#[test]
fn a_csv_trajectory_drives_kinematic_motion() {
    let dir = std::env::temp_dir().join(format!("margemu-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut csv = String::from("t,pitch\n");
    for k in 0..=400 {
        let t = k as f64 * 0.005;
        csv.push_str(&format!("{t},{}\n", 0.5 * (3.0 * t).sin()));
    }
    std::fs::write(dir.join("pitch.csv"), csv).unwrap();
    let scene_path = dir.join("csv.toml");
    std::fs::write(
        &scene_path,
        "duration = 1.5\nrate = 100.0\nseed = 1\nmotion = \"kinematic\"\n[joints.pitch]\ntype = \"csv\"\nfile = \"pitch.csv\"\ncolumn = \"pitch\"\n",
    )
    .unwrap();
    let scene = Scene::load(&scene_path).unwrap();
    for t in truths(&scene).iter().skip(10) {
        let s = t.t_ns as f64 * 1e-9;
        assert!(
            (t.euler[1] - 0.5 * (3.0 * s).sin()).abs() < 1e-6,
            "pitch at {s}"
        );
        assert!(
            (t.body_rate[1] - 1.5 * (3.0 * s).cos()).abs() < 1e-3,
            "rate at {s}"
        );
        assert!(
            (t.angular_accel[1] + 4.5 * (3.0 * s).sin()).abs() < 0.05,
            "accel at {s}"
        );
    }
}

#[test]
fn the_guides_full_scene_example_is_a_valid_scene() {
    let guide =
        std::fs::read_to_string(margemu_tests::workspace_root().join("docs/scene-files.md"))
            .unwrap();
    let start = guide.find("```toml\n").expect("a TOML example") + "```toml\n".len();
    let end = start + guide[start..].find("```").unwrap();
    let scene = Scene::parse_str(
        &guide[start..end],
        std::path::Path::new("docs/scene-files.md"),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.spec.perturbation.is_some());
    assert!(scene.spec.sensors.gyro.errors.noise_density.is_some());
    assert_eq!(truths(&scene).len() as u64, scene.samples());
}
