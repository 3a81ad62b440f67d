//! Scenes that would produce NaN, runs too large to finish, input files that never end, and
//! legal but likely wrong inputs: each gets a clear refusal, error or warning from the real CLI.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BASE: &str = "duration = 1.0\nrate = 100.0\nseed = 1\n";

/// A fresh folder under the system temp dir for one test.
fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "margemu-scene-guards-{}-{test}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .unwrap()
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs and asserts failure; returns stderr.
fn fails(args: &[&str]) -> String {
    let out = margemu(args);
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?} succeeded; stderr: {err}");
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    err
}

#[test]
fn absurd_bench_inputs_are_refused_with_their_range() {
    let dir = folder("bench");
    let scene = write(
        &dir,
        "nan.toml",
        "duration=1.0\nrate=100.0\nseed=1\n[bench]\nlink_mass=[1e300,1e300,1e300]\nplate_mass=1e308\n",
    );
    let expected = format!(
        "error: {}:5:12: `bench.link_mass[0]`: 1e300 is outside the plausible range [1e-6, 1e6] kg\n",
        s(&scene)
    );
    assert_eq!(fails(&["scene", "check", s(&scene)]), expected);
    let out = dir.join("run");
    assert_eq!(fails(&["simulate", s(&scene), "-o", s(&out)]), expected);
    assert!(!out.exists(), "nothing is written for a refused scene");
    let scene = write(
        &dir,
        "plate.toml",
        &format!("{BASE}[bench]\nplate_mass = 1e308\n"),
    );
    assert!(fails(&["scene", "check", s(&scene)]).contains(
        ":5:14: `bench.plate_mass`: 1e308 is outside the plausible range [1e-6, 1e6] kg"
    ));
}

#[test]
fn absurd_durations_and_rates_are_refused_with_their_range() {
    let dir = folder("duration");
    let scene = write(
        &dir,
        "long.toml",
        "duration = 1e9\nrate = 100.0\nseed = 1\n",
    );
    assert!(fails(&["scene", "check", s(&scene)])
        .contains(":1:12: `duration`: 1e9 is outside the plausible range [0, 1e7] s"));
    let scene = write(&dir, "fast.toml", "duration = 1.0\nrate = 1e9\nseed = 1\n");
    assert!(fails(&["loopback", s(&scene)])
        .contains(":2:8: `rate`: 1e9 is outside the plausible range [0.001, 1e6] Hz"));
}

#[test]
fn csv_sources_out_of_range_are_refused_at_their_row_and_scene_key() {
    let dir = folder("csv-range");
    write(&dir, "big.csv", "t,v\n0,1e308\n0.5,-1e308\n");
    let scene = write(
        &dir,
        "scene.toml",
        &format!("{BASE}[joints.x]\ntype = \"csv\"\nfile = \"big.csv\"\ncolumn = \"v\"\n"),
    );
    let expected = format!(
        "error: {}:6:8: joint `x`: {}:2: `v` = 1e308 is outside the plausible range [-1e6, 1e6] m or rad\n",
        s(&scene),
        s(&dir.join("big.csv"))
    );
    assert_eq!(fails(&["scene", "check", s(&scene)]), expected);
    let out = dir.join("run");
    assert_eq!(fails(&["simulate", s(&scene), "-o", s(&out)]), expected);
}

#[test]
fn csv_source_errors_say_their_cause_once() {
    let dir = folder("csv-cause");
    let scene = write(
        &dir,
        "scene.toml",
        &format!("{BASE}[joints.x]\ntype = \"csv\"\nfile = \"missing.csv\"\ncolumn = \"v\"\n"),
    );
    let err = fails(&["scene", "check", s(&scene)]);
    assert!(
        err.starts_with(&format!(
            "error: {}:6:8: joint `x`: {}: cannot read: ",
            s(&scene),
            s(&dir.join("missing.csv"))
        )),
        "{err}"
    );
    assert_eq!(err.matches("No such file or directory").count(), 1, "{err}");
    write(&dir, "q.csv", "t,q\n0,1\n");
    let scene = write(
        &dir,
        "column.toml",
        &format!("{BASE}[joints.x]\ntype = \"csv\"\nfile = \"q.csv\"\ncolumn = \"v\"\n"),
    );
    let err = fails(&["scene", "check", s(&scene)]);
    assert_eq!(err.matches("no column `v`").count(), 1, "{err}");
}

/// A CSV source or a scene that is a FIFO, a device or a directory is refused by its type,
/// before anything opens it (opening a FIFO would block this test forever).
#[test]
fn input_files_must_be_regular_files() {
    let dir = folder("special");
    let fifo = dir.join("fifo.csv");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success(), "mkfifo failed");
    for (file, kind) in [
        (s(&fifo), "a FIFO"),
        ("/dev/zero", "a character device"),
        (s(&dir), "a directory"),
    ] {
        let scene = write(
            &dir,
            "scene.toml",
            &format!("{BASE}[joints.x]\ntype = \"csv\"\nfile = \"{file}\"\ncolumn = \"v\"\n"),
        );
        let err = fails(&["scene", "check", s(&scene)]);
        assert_eq!(
            err,
            format!(
                "error: {}:6:8: joint `x`: {file}: is {kind}, not a regular file\n",
                s(&scene)
            )
        );
    }
    for (scene, kind) in [(s(&fifo), "a FIFO"), ("/dev/zero", "a character device")] {
        let err = fails(&["scene", "check", scene]);
        assert_eq!(
            err,
            format!("error: {scene}: is {kind}, not a regular file\n")
        );
    }
}

#[test]
fn a_scene_that_is_not_utf8_is_located() {
    let dir = folder("utf8");
    let path = dir.join("latin1.toml");
    std::fs::write(
        &path,
        b"duration = 1.0\nrate = 100.0\nseed = 1\nname = \"caf\xe9\"\n",
    )
    .unwrap();
    let err = fails(&["scene", "check", s(&path)]);
    assert_eq!(
        err,
        format!(
            "error: {}:4:12: byte 0xe9 at offset 48 is not UTF-8\n",
            s(&path)
        )
    );
}

#[test]
fn large_runs_are_sized_and_refused_without_allow_large() {
    let dir = folder("large");
    let scene = write(
        &dir,
        "large.toml",
        "duration = 1e5\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n",
    );
    let out = margemu(&["scene", "check", s(&scene)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("size: 100000000 samples, about 7") && text.contains("truth.csv "),
        "{text}"
    );
    assert!(
        text.contains("simulate, loopback and stream need --allow-large"),
        "{text}"
    );
    let refusal = "the run is too large: 100000000 samples, about ";
    let limit = "; the limit is 10000000 samples and 2.0 GiB of output without --allow-large \
                 (pass --allow-large to run it anyway)\n";
    let run = dir.join("run");
    for args in [
        vec!["simulate", s(&scene), "-o", s(&run)],
        vec!["loopback", s(&scene), "-o", s(&run)],
        vec![
            "stream",
            s(&scene),
            "--port",
            "/nonexistent/tty",
            "-o",
            s(&run),
        ],
    ] {
        let err = fails(&args);
        assert!(
            err.starts_with(&format!("error: {refusal}")),
            "{args:?}: {err}"
        );
        assert!(err.ends_with(limit), "{args:?}: {err}");
    }
    assert!(!run.exists(), "a refused run writes nothing");
    let small = write(&dir, "small.toml", &format!("{BASE}motion = \"static\"\n"));
    let out = margemu(&["simulate", s(&small), "-o", s(&run), "--allow-large"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn likely_mistakes_are_warned_once_with_their_place() {
    let dir = folder("warnings");
    let scene = write(
        &dir,
        "warn.toml",
        &format!(
            "{BASE}[field]\nreference = [0.0, 0.0, 0.0]\n\
             [joints.roll]\ntype = \"sine\"\namplitude = 0.1\nfrequency = 80.0\n\
             [perturbation]\nwindow = 2.0\n"
        ),
    );
    let p = s(&scene);
    let warnings = [
        format!("warning: {p}:5:13: `field.reference`: the reference field is zero"),
        format!(
            "warning: {p}:9:13: `joints.roll.frequency`: 80 Hz is above the output Nyquist \
             frequency 50 Hz (rate 100 Hz): the samples alias it"
        ),
        format!(
            "warning: {p}:11:10: `perturbation.window`: the 2 s burst window is longer than \
             the scene (1 s): no burst ends within the run"
        ),
    ];
    let check = margemu(&["scene", "check", p]);
    assert!(check.status.success(), "{}", stderr(&check));
    let run = dir.join("run");
    let simulate = margemu(&["simulate", p, "-o", s(&run)]);
    assert!(simulate.status.success(), "{}", stderr(&simulate));
    for out in [check, simulate] {
        let err = stderr(&out);
        for w in &warnings {
            assert_eq!(
                err.matches(w.as_str()).count(),
                1,
                "{w:?} not once in:\n{err}"
            );
        }
    }
}

/// Two CSV rows 1e-310 s apart make the spline's curvature infinite: the run stops at the first
/// sample, naming the rows, and writes no non-finite value.
#[test]
fn a_non_finite_truth_stops_the_run_at_its_csv_rows() {
    let dir = folder("csv-inf");
    let csv = write(&dir, "close.csv", "t,v\n0,0\n1e-310,1\n1,1\n");
    let scene = write(
        &dir,
        "scene.toml",
        &format!(
            "{BASE}motion = \"kinematic\"\n[joints.x]\ntype = \"csv\"\nfile = \"close.csv\"\ncolumn = \"v\"\n"
        ),
    );
    let run = dir.join("run");
    let err = fails(&["simulate", s(&scene), "-o", s(&run)]);
    assert!(
        err.contains(&format!(
            "sample 0 (t = 0 ns): joint x position is NaN, not finite; it comes from the csv \
             source of joint x ({}:5:1, {} lines 2–3)",
            s(&scene),
            s(&csv)
        )),
        "{err}"
    );
    assert_no_non_finite(&run);
}

/// Explicit gains far too stiff for the integrator step blow the bench up: the run stops at the
/// first non-finite value and names the bench dynamics of the joint.
#[test]
fn a_non_finite_truth_stops_the_run_at_the_bench() {
    let dir = folder("bench-inf");
    let gains = "[[1e12, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [1, 0, 0]]";
    let scene = write(
        &dir,
        "scene.toml",
        &format!(
            "{BASE}[control]\ngains = {gains}\n[joints.x]\ntype = \"constant\"\nvalue = 0.1\n"
        ),
    );
    let run = dir.join("run");
    let err = fails(&["simulate", s(&scene), "-o", s(&run)]);
    assert!(
        err.contains("; it comes from the [bench] dynamics of joint x"),
        "{err}"
    );
    assert!(
        err.contains("tracking the constant source of joint x"),
        "{err}"
    );
    assert_no_non_finite(&run);
}

fn assert_no_non_finite(run: &Path) {
    for name in ["truth.csv", "marg.csv"] {
        if let Ok(text) = std::fs::read_to_string(run.join(name)) {
            assert!(
                !text.contains("NaN") && !text.contains("inf"),
                "{name} holds a non-finite value"
            );
        }
    }
}

/// A sample the sensor model cannot make finite is refused by `try_sample`, naming the sensor.
#[test]
fn a_non_finite_sample_names_its_sensor() {
    use margemu::marg::MargSim;
    let scene = margemu::scene::Scene::parse_str(
        &format!("{BASE}[sensors.gyro]\nbias = [0.1, 0.0, 0.0]\n"),
        Path::new("gyro.toml"),
    )
    .unwrap();
    let mut sim = MargSim::new(&scene).unwrap();
    let mut truth = margemu::truth::Truth::default();
    assert!(sim.try_sample(&scene, &truth).is_ok());
    truth.t_ns = 10_000_000;
    truth.body_rate = [f64::NAN, 0.0, 0.0];
    let e = sim.try_sample(&scene, &truth).unwrap_err().to_string();
    assert_eq!(
        e,
        "sample 1 (t = 10000000 ns): gyr_x is NaN, not finite; it comes from [sensors.gyro] (gyro.toml:4:1)"
    );
}
