//! Built-in scenes through the real binary: `margemu scenes` lists the fixture scenes; with no
//! scene argument `loopback` runs figure3 and `demo` the case study from an empty directory
//! (no file of the repository is read), recording `builtin:NAME` and the fixture's text and
//! hash in `meta.toml`; files still work by path and come before names; an argument that is
//! neither says so and lists the names.

use margemu::scene::Scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// An empty directory of its own for one test.
fn empty_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-builtin-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `margemu ARGS` run in `dir`: its output and its stdout and stderr together.
fn margemu_in(dir: &Path, args: &[&str]) -> (Output, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, text)
}

/// The fixture scenes on disk: each file's stem and text.
fn fixtures() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-fixtures/scenes");
    let mut all: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| {
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            (stem, std::fs::read_to_string(&p).unwrap())
        })
        .collect();
    all.sort();
    all
}

fn fixture(name: &str) -> String {
    let all = fixtures();
    all.into_iter().find(|(n, _)| n == name).unwrap().1
}

/// The `meta.toml` of a run or session directory, parsed.
fn meta(dir: &Path) -> toml::Table {
    std::fs::read_to_string(dir.join("meta.toml"))
        .unwrap()
        .parse()
        .unwrap()
}

fn string<'a>(meta: &'a toml::Table, key: &str) -> &'a str {
    meta[key].as_str().unwrap()
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn scenes_lists_every_fixture_scene_and_prints_its_text() {
    let dir = empty_dir("list");
    let (out, text) = margemu_in(&dir, &["scenes"]);
    assert!(out.status.success(), "{text}");
    let fixtures = fixtures();
    assert_eq!(fixtures.len(), 9);
    for (name, source) in &fixtures {
        let scene = Scene::parse_str(source, Path::new(name)).unwrap();
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name.as_str()))
            .unwrap_or_else(|| panic!("{name} is not listed: {text}"));
        let description = scene.spec.description.as_deref().unwrap();
        for part in [
            format!("{} s", scene.spec.duration),
            format!("{} Hz", scene.clock.hz()),
            description.to_owned(),
        ] {
            assert!(line.contains(&part), "{part}: {line}");
        }
        let (out, shown) = margemu_in(&dir, &["scenes", name]);
        assert!(out.status.success(), "{shown}");
        assert_eq!(&shown, source);
    }
    let line = |name: &str| text.lines().find(|l| l.starts_with(name)).unwrap();
    assert!(
        line("icm42688p ").contains(" kinematic  icm42688p "),
        "{text}"
    );
    assert!(line("static ").contains(" static     mpu9250 "), "{text}");
    assert!(line("bmi270 ").contains(" kinematic  bmi270 "), "{text}");
}

#[test]
fn loopback_without_a_scene_streams_figure3_from_an_empty_directory() {
    let dir = empty_dir("loopback");
    let (out, text) = margemu_in(&dir, &["loopback"]);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("3000 of 3000 predicted images confirmed byte for byte"),
        "{text}"
    );
    assert_eq!(listing(&dir), ["sessions"]);
    assert_eq!(listing(&dir.join("sessions")), ["figure3-loopback"]);
    let meta = meta(&dir.join("sessions/figure3-loopback"));
    let source = fixture("figure3");
    let hash = Scene::parse_str(&source, Path::new("figure3.toml"))
        .unwrap()
        .hash();
    assert_eq!(string(&meta, "scene_file"), "builtin:figure3");
    assert_eq!(string(&meta, "scene_text"), source);
    assert_eq!(string(&meta, "scene_sha256"), hash);
}

#[test]
fn demo_without_a_scene_runs_the_case_study_from_an_empty_directory() {
    let dir = empty_dir("demo");
    // The default scene, shortened; the cheapest tuning that still runs the tuner.
    let args = [
        "demo",
        "--duration",
        "2",
        "--filters",
        "ecf",
        "--seeds",
        "1",
        "--max-evals",
        "3",
        "--no-plots",
    ];
    let (out, text) = margemu_in(&dir, &args);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("demo: builtin:case-study (2 s at 200 Hz)"),
        "{text}"
    );
    assert_eq!(
        text.matches("served 400/400 byte for byte").count(),
        2,
        "{text}"
    );
    assert_eq!(listing(&dir), ["demo"]);
    assert_eq!(
        listing(&dir.join("demo")),
        ["ecf-initial", "ecf-tuned", "table3.md"]
    );
    let meta = meta(&dir.join("demo/ecf-initial"));
    assert_eq!(string(&meta, "scene_file"), "builtin:case-study");
    // The case study's text with the duration edited, and that text's hash.
    let text = string(&meta, "scene_text");
    let scene = Scene::parse_str(text, Path::new("recorded")).unwrap();
    assert_eq!(scene.spec.duration, 2.0);
    assert_eq!(
        scene.spec.description.as_deref(),
        Some("Odry 2021, section 3.2: random bench motion, 200 Hz")
    );
    assert_eq!(string(&meta, "scene_sha256"), scene.hash());
}

#[test]
fn an_argument_that_is_neither_a_file_nor_a_built_in_scene_lists_the_names() {
    let dir = empty_dir("unknown");
    let names =
        "bmi270, case-study, figure3, gimbal-lock, icm42688p, mpu6000, rig, static, vibration";
    for (arg, reason) in [
        (
            "figure4",
            "no such file, and no built-in scene has that name (built-in scenes: ",
        ),
        (
            "scenes/figure3.toml",
            "no such file (built-in scenes, by name: ",
        ),
        (
            "builtin:figure3.toml",
            "no built-in scene has that name (built-in scenes: ",
        ),
    ] {
        let (out, text) = margemu_in(&dir, &["simulate", arg]);
        assert!(!out.status.success(), "{text}");
        assert_eq!(text, format!("error: {arg}: {reason}{names})\n"));
    }
    let (out, text) = margemu_in(&dir, &["scenes", "figure4"]);
    assert!(!out.status.success(), "{text}");
    assert!(text.contains(names), "{text}");
    assert!(listing(&dir).is_empty(), "{:?}", listing(&dir));
}

#[test]
fn files_work_by_path_and_come_before_names() {
    let dir = empty_dir("files");
    let own = "duration = 0.5\nrate = 100.0\nseed = 3\nmotion = \"static\"\n";
    std::fs::write(dir.join("mine.toml"), own).unwrap();
    // A file named like a built-in scene is that file; `builtin:` asks for the built-in one.
    std::fs::write(dir.join("static"), own).unwrap();
    let subdir = dir.join("sub");
    std::fs::create_dir(&subdir).unwrap();
    let absolute = dir.join("mine.toml");
    for (cwd, arg, run, file, text) in [
        (&dir, "mine.toml", "runs/mine", "mine.toml", own.to_owned()),
        (
            &subdir,
            absolute.to_str().unwrap(),
            "runs/mine",
            absolute.to_str().unwrap(),
            own.to_owned(),
        ),
        (&dir, "static", "runs/static", "static", own.to_owned()),
        (
            &dir,
            "builtin:static",
            "runs/static-2",
            "builtin:static",
            fixture("static"),
        ),
    ] {
        let (out, output) = margemu_in(cwd, &["simulate", arg]);
        assert!(out.status.success(), "{output}");
        let meta = meta(&cwd.join(run));
        assert_eq!(string(&meta, "scene_file"), file, "{arg}");
        assert_eq!(string(&meta, "scene_text"), text, "{arg}");
    }
}
