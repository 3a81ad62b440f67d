//! The bench's ground truth, bit for bit: a digest of every truth value (the bits of each `f64`
//! column and the time stamp) of the shipped bench scenes, and of variants that reach the other
//! integration paths (other integrators and steps, landings between grid points, setpoint
//! smoothing, stiction, an effort limit). The digests were computed from the bench before its
//! fast paths existed, so a faster path that changes a single bit of `truth.csv` (and therefore
//! of `marg.csv`, which is drawn from the truth) fails here.

use margemu_sim::run::for_each;
use margemu_sim::scene::Scene;
use std::path::{Path, PathBuf};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../hil-fixtures/scenes/{name}.toml"))
}

fn scene_text(name: &str) -> String {
    std::fs::read_to_string(scene_path(name)).expect("a shipped scene")
}

/// FNV-1a over the time stamp and the bits of every truth column, with the friction event count.
fn truth_digest(text: &str, name: &str) -> (u64, u64) {
    let scene = Scene::parse_str(text, &scene_path(name)).expect("a valid scene");
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |word: u64| {
        for byte in word.to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    };
    let mut samples = 0;
    let summary = for_each(&scene, |t| {
        samples += 1;
        eat(t.t_ns);
        for v in t.columns() {
            eat(v.to_bits());
        }
    })
    .expect("the scene runs");
    assert_eq!(samples, scene.samples());
    eat(summary.friction_events.len() as u64);
    (hash, samples)
}

fn replaced(text: &str, pairs: &[(&str, &str)]) -> String {
    pairs.iter().fold(text.to_owned(), |t, (from, to)| {
        assert!(t.contains(from), "{from:?} is not in the scene");
        t.replacen(from, to, 1)
    })
}

#[test]
fn figure3_truth_is_unchanged_for_every_integrator() {
    let base = scene_text("figure3");
    let cases = [
        ("default", base.clone()),
        (
            "rk4-0.5ms",
            replaced(&base, &[("step = 0.001", "step = 0.0005")]),
        ),
        (
            "euler-1ms",
            replaced(&base, &[("\"rk4\"", "\"semi-implicit-euler\"")]),
        ),
        (
            "3khz",
            replaced(&base, &[("rate = 1000.0", "rate = 3000.0")]),
        ),
    ];
    let expected = [
        0xcb98_8bc9_79af_13f4u64,
        0x353f_89ff_2cbe_8f60,
        0x60e8_bfed_e071_6763,
        0x5b3c_d7be_0d4b_1498,
    ];
    let got: Vec<u64> = cases
        .iter()
        .map(|(label, text)| {
            let (got, n) = truth_digest(text, "figure3");
            println!("{label}: {got:#018x} ({n} samples)");
            got
        })
        .collect();
    assert_eq!(got, expected);
}

#[test]
fn shipped_bench_scenes_truth_is_unchanged() {
    let expected = [
        ("case-study", 0x83af_a9dc_2c4f_dcd5u64),
        ("gimbal-lock", 0x6be8_e273_d9b3_e45a),
    ];
    let got: Vec<_> = expected
        .iter()
        .map(|&(name, _)| {
            let (got, n) = truth_digest(&scene_text(name), name);
            println!("{name}: {got:#018x} ({n} samples)");
            (name, got)
        })
        .collect();
    assert_eq!(got, expected);
}

#[test]
fn nonlinear_and_smoothed_joints_truth_is_unchanged() {
    let base = scene_text("figure3");
    let smoothed = replaced(
        &base,
        &[
            (
                "points = [[0.1, 1.5], [1.1, 1.0], [2.1, 1.6]]",
                "points = [[0.1, 1.5], [1.1, 1.0], [2.1, 1.6]]\n\
                 smoothing = { natural_frequency = 46.0, damping = 0.869 }",
            ),
            (
                "initial = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]",
                "initial = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]\n\
                 static_friction = [0.0, 5.0, 0.0, 0.0, 0.0, 0.0]\n\
                 effort_limit = [1e9, 1e9, 2000.0, 1e9, 1e9, 1e9]",
            ),
        ],
    );
    let (got, n) = truth_digest(&smoothed, "figure3");
    println!("smoothed + stiction + limit: {got:#018x} ({n} samples)");
    assert_eq!(got, 0x7912_13a5_b643_977b);
}
