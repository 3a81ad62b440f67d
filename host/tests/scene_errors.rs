//! Bad scenes are refused with the file, line, column and reason.

use margemu::scene::Scene;
use std::path::Path;

const BASE: &str = "duration = 1.0\nrate = 100.0\nseed = 1\n";

fn error(text: &str) -> String {
    Scene::parse_str(text, Path::new("scenes/bad.toml"))
        .unwrap_err()
        .to_string()
}

fn assert_error(text: &str, place: &str, reason: &str) {
    let e = error(text);
    assert!(
        e.starts_with(&format!("scenes/bad.toml:{place}: ")),
        "wrong place in: {e}"
    );
    assert!(e.contains(reason), "reason {reason:?} missing in: {e}");
}

#[test]
fn unknown_key() {
    assert_error(
        &format!("{BASE}duraton = 2.0\n"),
        "4:1",
        "unknown field `duraton`",
    );
    assert_error(
        &format!("{BASE}[bench]\nplate_mas = 1.0\n"),
        "5:1",
        "unknown field `plate_mas`",
    );
    assert_error(
        &format!(
            "{BASE}[joints.x]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 1.0\nphse = 0.0\n"
        ),
        "4:1",
        "unknown field `phse`",
    );
}

#[test]
fn wrong_type() {
    assert_error(
        "duration = 1.0\nrate = \"fast\"\nseed = 1\n",
        "2:8",
        "invalid type: string \"fast\"",
    );
    assert_error(
        &format!("{BASE}[bench]\ninitial = [0, 0, 0]\n"),
        "5:11",
        "invalid length 3",
    );
    assert_error(
        &format!("{BASE}motion = \"flying\"\n"),
        "4:10",
        "unknown variant `flying`",
    );
}

#[test]
fn negative_mass() {
    assert_error(
        &format!("{BASE}[bench]\nplate_mass = -0.2\n"),
        "5:14",
        "`bench.plate_mass`: must be finite and > 0, not -0.2",
    );
    assert_error(
        &format!("{BASE}[bench]\nlink_mass = [500.0, -1.0, 200.0]\n"),
        "5:21",
        "`bench.link_mass[1]`: a mass must be finite and > 0, not -1",
    );
}

#[test]
fn not_a_number() {
    assert_error(
        "duration = 1.0\nrate = nan\nseed = 1\n",
        "2:8",
        "`rate`: must be finite and > 0, not NaN",
    );
    assert_error(
        &format!("{BASE}[field]\nreference = [0.5, inf, 0.0]\n"),
        "5:19",
        "`field.reference[1]`: must be finite, not inf",
    );
    assert_error(
        &format!("{BASE}[joints.roll]\ntype = \"sine\"\namplitude = nan\nfrequency = 1.0\n"),
        "6:13",
        "`joints.roll.amplitude`: must be finite",
    );
}

#[test]
fn zero_rate() {
    assert_error(
        "duration = 1.0\nrate = 0.0\nseed = 1\n",
        "2:8",
        "`rate`: must be finite and > 0, not 0",
    );
}

#[test]
fn duration_not_a_multiple_of_the_step() {
    assert_error(
        "duration = 1.0005\nrate = 100.0\nseed = 1\n",
        "1:12",
        "`duration`: 1.0005 s is not a whole number of integrator steps of 0.001 s",
    );
    assert_error(
        &format!("{BASE}[integrator]\nstep = 0.0\n"),
        "5:8",
        "`integrator.step`: must be finite and > 0",
    );
}

#[test]
fn sources_that_do_not_fit_the_mode_or_joint() {
    assert_error(
        &format!("{BASE}[joints.w]\ntype = \"constant\"\nvalue = 1.0\n"),
        "4:1",
        "unknown joint",
    );
    assert_error(
        &format!("{BASE}motion = \"static\"\n[joints.x]\ntype = \"constant\"\nvalue = 1.0\n"),
        "5:1",
        "a static scene takes no joint sources",
    );
    assert_error(
        &format!(
            "{BASE}motion = \"kinematic\"\n[joints.x]\ntype = \"steps\"\npoints = [[0.5, 1.0]]\n"
        ),
        "6:8",
        "`steps` cannot prescribe motion directly",
    );
    assert_error(
        &format!("{BASE}[joints.x]\ntype = \"steps\"\npoints = [[0.5, 1.0], [0.2, 2.0]]\n"),
        "6:24",
        "times must be finite, ≥ 0 and increasing",
    );
    assert_error(
        &format!("{BASE}[joints.y]\ntype = \"random-setpoints\"\nrange = [1.0, 0.0]\nhold = [1.0, 2.0]\n"),
        "6:9",
        "lo ≤ hi",
    );
}

#[test]
fn a_missing_file_is_named() {
    let e = Scene::load(Path::new("/nonexistent/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("/nonexistent/scene.toml: cannot read:"),
        "{e}"
    );
}
