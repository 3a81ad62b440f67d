//! External recordings scored first-class: BROAD's heading and inclination split, reference
//! rows missing (empty or NaN) skipped and counted, masks (a column, rest or motion), the
//! magnetic reference estimated from a rest phase, and the command-line options and their
//! errors.

mod evaluate_common;

use evaluate_common::{coords, euler_at, scratch};
use margemu::evaluate::quat::from_euler;
use margemu::evaluate::{evaluate, evaluate_writing, EvalOptions, Mask, Source};
use margemu::offline::mag_estimate;
use nalgebra::{UnitQuaternion, Vector3};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const HEADER: &str = "t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz";

/// A 100 Hz recording of `n` rows of the test motion; `row(k)` gives the extra cells after the
/// reference (the reference itself replaced by `reference(k)` when it returns text).
fn write_recording(
    path: &Path,
    extra_header: &str,
    n: usize,
    reference: impl Fn(usize) -> Option<String>,
    extra: impl Fn(usize, &UnitQuaternion<f64>) -> String,
) {
    let mut text = format!("{HEADER}{extra_header}\n");
    for k in 0..n {
        let t = k as f64 * 0.01;
        let q = from_euler(euler_at(t));
        let r = reference(k).unwrap_or_else(|| {
            let c = coords(&q);
            format!("{},{},{},{}", c[0], c[1], c[2], c[3])
        });
        let _ = writeln!(
            text,
            "{t},0,0,9.80665,0,0,0,0.36,0,-0.93,{r}{}",
            extra(k, &q)
        );
    }
    std::fs::write(path, text).unwrap();
}

/// `,qw_est,qx_est,qy_est,qz_est` cells of `error ⊗ q` (the error in the world frame).
fn estimate_cells(error: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> String {
    let c = coords(&(error * q));
    format!(",{},{},{},{}", c[0], c[1], c[2], c[3])
}

const EST: &str = ",qw_est,qx_est,qy_est,qz_est";

fn about(axis: Vector3<f64>, degrees: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(axis.normalize() * degrees.to_radians())
}

fn external(file: PathBuf) -> Source {
    Source::External {
        file,
        estimates: None,
    }
}

#[test]
fn heading_only_and_inclination_only_errors_are_scored_exactly() {
    let dir = scratch("ext-split");
    let cases = [
        ("heading", about(Vector3::z(), 3.0), [3.0, 0.0]),
        (
            "inclination",
            about(Vector3::new(1.0, 2.0, 0.0), 2.0),
            [0.0, 2.0],
        ),
    ];
    for (name, error, expected) in cases {
        let file = dir.join(format!("{name}.csv"));
        write_recording(&file, EST, 500, |_| None, |_, q| estimate_cells(&error, q));
        let errors = dir.join(format!("{name}-errors.csv"));
        let eval =
            evaluate_writing(&external(file), &EvalOptions::default(), Some(&errors)).unwrap();
        let s = eval.scores;
        assert_eq!(s.count, 500);
        for (i, want) in expected.iter().enumerate() {
            let [rms, max] = [s.heading_inclination_rms[i], s.heading_inclination_max[i]];
            assert!((rms.to_degrees() - want).abs() < 1e-9, "{name} {i}: {s:?}");
            assert!((max.to_degrees() - want).abs() < 1e-9, "{name} {i}: {s:?}");
        }
        // The geodesic is the whole of the one error there is.
        let whole = expected[0] + expected[1];
        assert!((s.geodesic_rms.to_degrees() - whole).abs() < 1e-9, "{s:?}");
        let text = std::fs::read_to_string(&errors).unwrap();
        let mut lines = text.lines();
        assert!(lines
            .next()
            .unwrap()
            .ends_with(",e_yaw,geodesic,heading,inclination"));
        let cells: Vec<f64> = lines
            .next()
            .unwrap()
            .rsplit(',')
            .take(2)
            .map(|c| c.parse().unwrap())
            .collect();
        assert!(
            (cells[1].to_degrees() - expected[0]).abs() < 1e-9,
            "{text:.300}"
        );
        assert!(
            (cells[0].to_degrees() - expected[1]).abs() < 1e-9,
            "{text:.300}"
        );
        assert!(
            eval.latency_reason.contains("a search is optional"),
            "{}",
            eval.latency_reason
        );
    }
}

/// 100 rows: rows 10 to 19 have a NaN reference and row 30 an empty one; the mask column `keep`
/// is 1 on rows below 60; the estimate is 1° off in heading where kept, 10° elsewhere.
fn masked_recording(dir: &Path) -> PathBuf {
    let file = dir.join("masked.csv");
    let small = about(Vector3::z(), 1.0);
    let large = about(Vector3::z(), 10.0);
    write_recording(
        &file,
        &format!("{EST},keep"),
        100,
        |k| match k {
            10..=19 => Some("NaN,NaN,NaN,NaN".into()),
            30 => Some(",,,".into()),
            _ => None,
        },
        |k, q| {
            let e = if k < 60 { &small } else { &large };
            format!("{},{}", estimate_cells(e, q), u8::from(k < 60))
        },
    );
    file
}

#[test]
fn missing_reference_rows_and_a_mask_column_leave_only_the_right_rows_scored() {
    let dir = scratch("ext-mask");
    let file = masked_recording(&dir);
    // Without a mask: 89 rows with a reference, all scored.
    let all = evaluate(&external(file.clone()), &EvalOptions::default()).unwrap();
    assert_eq!(all.scores.count, 89);
    assert!(
        all.notes
            .iter()
            .any(|n| n.contains("11 of 100 rows have no reference quaternion")),
        "{:?}",
        all.notes
    );
    let options = EvalOptions {
        mask: Mask::Column("keep".into()),
        ..EvalOptions::default()
    };
    let eval = evaluate(&external(file), &options).unwrap();
    // Rows 0..60 less the 11 without a reference.
    assert_eq!(eval.scores.count, 49);
    let h = eval.scores.heading_inclination_rms[0].to_degrees();
    assert!((h - 1.0).abs() < 1e-9, "{:?}", eval.scores);
    assert!(
        eval.notes.iter().any(|n| n.contains(
            "mask (column `keep` nonzero): 60 of 100 rows kept, 49 of them with a reference"
        )),
        "{:?}",
        eval.notes
    );
}

/// A 100 Hz recording at rest for 3 s in a tilted attitude, then turning, in a world field of
/// 69° dip and 10° declination, measured with a little noise; `with_reference`: the reference
/// attitude columns too.
fn dip_recording(path: &Path, with_reference: bool) {
    let dip = 69f64.to_radians();
    let dec = 10f64.to_radians();
    let world = Vector3::new(dip.cos() * dec.cos(), dip.cos() * dec.sin(), -dip.sin());
    let mut text = String::from("t_s,ax,ay,az,gx,gy,gz,mx,my,mz");
    text += if with_reference {
        ",qw,qx,qy,qz\n"
    } else {
        "\n"
    };
    let tilt = from_euler([0.3, -0.2, 1.0]);
    for k in 0..600 {
        let t = k as f64 * 0.01;
        let (q, w) = if t < 3.0 {
            (tilt, 0.0)
        } else {
            (
                tilt * about(Vector3::z(), 40.0 * (t - 3.0)),
                40f64.to_radians(),
            )
        };
        let f = q.inverse() * Vector3::new(0.0, 0.0, 9.80665);
        let wobble = 0.01 * ((k * 7919) % 13) as f64 / 13.0 - 0.005;
        let m = q.inverse() * world + Vector3::repeat(wobble);
        let _ = write!(
            text,
            "{t},{},{},{},0,0,{w},{},{},{}",
            f.x, f.y, f.z, m.x, m.y, m.z
        );
        if with_reference {
            let c = coords(&q);
            let _ = write!(text, ",{},{},{},{}", c[0], c[1], c[2], c[3]);
        }
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn the_magnetic_reference_is_recovered_from_a_rest_phase() {
    let dir = scratch("ext-dip");
    for with_reference in [true, false] {
        let file = dir.join(format!("dip-{with_reference}.csv"));
        dip_recording(&file, with_reference);
        let e = mag_estimate::estimate(&file).unwrap();
        assert!((e.dip.to_degrees() - 69.0).abs() < 0.5, "{e}");
        assert_eq!(e.from_attitude, with_reference);
        assert_eq!(e.lines, (2, 301), "{e}");
        let heading = e.reference[1].atan2(e.reference[0]).to_degrees();
        let expected = if with_reference { 10.0 } else { 0.0 };
        assert!((heading - expected).abs() < 0.5, "{e}");
    }
}

fn margemu(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .output()
        .expect("runs margemu")
}

fn stdout(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    assert!(
        !o.status.success(),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn the_command_line_takes_the_new_options_and_names_them_in_its_errors() {
    let dir = scratch("ext-cli");
    let rec = dir.join("dip.csv");
    dip_recording(&rec, false);
    let (r, out) = (rec.to_str().unwrap(), dir.join("est.csv"));
    let o = out.to_str().unwrap();
    // The default for a CSV: estimated, printed with its rows.
    let printed = stdout(&margemu(&["filter", "--filter", "ecf", r, "-o", o]));
    assert!(
        printed.contains("magnetic reference estimated:"),
        "{printed}"
    );
    assert!(printed.contains("lines 2–301"), "{printed}");
    for form in [
        vec!["--mag-reference=-0.36,0,-0.93"],
        vec!["--mag-reference", "-0.36,0,-0.93"],
        vec!["--mag-reference", "-0.36, 0, -0.93"],
        vec!["--mag-reference", "auto"],
    ] {
        let mut args = vec!["filter", "--filter", "ecf", r, "-o", o];
        args.extend(form.iter().copied());
        stdout(&margemu(&args));
    }
    // Every filter option from the command line, the filter's name as an optional prefix.
    let printed = stdout(&margemu(&[
        "filter",
        "--filter",
        "gda",
        r,
        "-o",
        o,
        "--param",
        "gda.normalization=xio",
        "--param",
        "beta=0.2",
    ]));
    assert!(
        printed.contains("gda (beta=0.2, normalization=xio)"),
        "{printed}"
    );
    let printed = stdout(&margemu(&[
        "filter",
        "--filter",
        "ekf",
        r,
        "-o",
        o,
        "--param",
        "ekf.initial_attitude_std=0.3",
    ]));
    assert!(
        printed.contains("initial_attitude_std=0.3, initial_bias_std=0.05"),
        "{printed}"
    );
    for (extra, expected) in [
        ("1,2", "--mag-reference needs three finite numbers X,Y,Z"),
        ("1,x,2", "--mag-reference needs three finite numbers X,Y,Z"),
        (
            "1,inf,2",
            "--mag-reference needs three finite numbers X,Y,Z",
        ),
    ] {
        let e = stderr(&margemu(&[
            "filter",
            "--filter",
            "ecf",
            r,
            "-o",
            o,
            "--mag-reference",
            extra,
        ]));
        assert!(e.contains(expected), "{extra}: {e}");
    }
    // evaluate: masks.
    let masked = masked_recording(&dir);
    let m = masked.to_str().unwrap();
    let eval_out = dir.join("evaluation");
    let e_out = eval_out.to_str().unwrap();
    let base = ["evaluate", "--no-plots", "--out", e_out, "--external", m];
    let printed = stdout(&margemu(&[&base[..], &["--mask-column", "keep"]].concat()));
    let n = printed
        .lines()
        .find_map(|l| l.strip_prefix("N "))
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_default();
    assert_eq!(n, "49", "{printed}");
    assert!(printed.contains("heading RMS (°)"), "{printed}");
    assert!(!printed.contains("host arrival"), "{printed}");
    let report = std::fs::read_to_string(eval_out.join("report.md")).unwrap();
    assert!(report.contains("49 of them with a reference"), "{report}");
    assert!(report.contains("inclination RMS (°)"), "{report}");
    // Gyro zero throughout: every row at rest, none in motion.
    let printed = stdout(&margemu(&[&base[..], &["--mask", "rest"]].concat()));
    assert!(
        printed.contains("100 of 100 rows kept, 89 of them"),
        "{printed}"
    );
    let e = stderr(&margemu(&[&base[..], &["--mask", "motion"]].concat()));
    assert!(e.contains("no truth instant to score"), "{e}");
    for (extra, expected) in [
        (vec!["--mask-column", "nope"], "no column `nope`"),
        (vec!["--mask", "still"], "--mask"),
        (
            vec!["--mask", "rest", "--rest-rate", "-1"],
            "--rest-rate must be",
        ),
        (vec!["--mask", "rest", "--mask-column", "keep"], "--mask"),
    ] {
        let e = stderr(&margemu(&[&base[..], &extra[..]].concat()));
        assert!(e.contains(expected), "{extra:?}: {e}");
    }
}

#[test]
fn a_filter_starts_from_a_recordings_reference_attitude() {
    let dir = scratch("ext-start");
    let rec = dir.join("dip.csv");
    dip_recording(&rec, true);
    let out = dir.join("est.csv");
    let (r, o) = (rec.to_str().unwrap(), out.to_str().unwrap());
    // A reference without the recording's 10° declination: a start from the first sample
    // (TRIAD) is 10° off in heading; a start from the reference is not.
    let first_estimate = |start: &str| {
        let args = [
            "filter",
            "--filter",
            "gda",
            "--mag-reference",
            "0.36,0,-0.93",
            "--attitude-start",
            start,
            r,
            "-o",
            o,
        ];
        stdout(&margemu(&args));
        let q = margemu::evaluate::input::read_estimates(&out).unwrap()[0].1;
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
    };
    let tilt = from_euler([0.3, -0.2, 1.0]);
    let truth = first_estimate("truth").angle_to(&tilt);
    let triad = first_estimate("first-sample").angle_to(&tilt);
    assert!(truth < 0.01 && triad > 0.1, "{truth} {triad}");
    // Without reference columns, starting from the truth is refused, naming what is missing.
    let plain = dir.join("plain.csv");
    dip_recording(&plain, false);
    let e = stderr(&margemu(&[
        "filter",
        "--filter",
        "gda",
        "--attitude-start",
        "truth",
        plain.to_str().unwrap(),
        "-o",
        o,
    ]));
    assert!(e.contains("needs the reference columns qw,qx,qy,qz"), "{e}");
}

/// A BROAD-like recording at 100 Hz: 3 s at rest, then turning at a constant body rate, in a
/// field of 69° dip and 20° declination against the reference's x; the reference lost on rows
/// 700 to 719; `movement` 1 after the rest.
fn broad_like(path: &Path) {
    let dip = 69f64.to_radians();
    let dec = 20f64.to_radians();
    let world = Vector3::new(dip.cos() * dec.cos(), dip.cos() * dec.sin(), -dip.sin()) * 50.0;
    let start = from_euler([0.1, 0.2, 0.3]);
    let rate = Vector3::new(0.3, -0.2, 0.8);
    let mut text = format!("{HEADER},movement\n");
    for k in 0..1500 {
        let t = k as f64 * 0.01;
        let moving = t >= 3.0;
        let turned = if moving {
            (t - 3.0) * rate
        } else {
            Vector3::zeros()
        };
        let q = start * UnitQuaternion::from_scaled_axis(turned);
        let w = if moving { rate } else { Vector3::zeros() };
        let f = q.inverse() * Vector3::new(0.0, 0.0, 9.80665);
        let m = q.inverse() * world;
        let c = coords(&q);
        let reference = if (700..720).contains(&k) {
            "nan,nan,nan,nan".to_string()
        } else {
            format!("{},{},{},{}", c[0], c[1], c[2], c[3])
        };
        let _ = writeln!(
            text,
            "{t},{},{},{},{},{},{},{},{},{},{reference},{}",
            f.x,
            f.y,
            f.z,
            w.x,
            w.y,
            w.z,
            m.x,
            m.y,
            m.z,
            u8::from(moving)
        );
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn the_public_recording_recipe_runs_as_written() {
    let dir = scratch("ext-recipe");
    broad_like(&dir.join("broad.csv"));
    let page = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/recipe-public-recording.md");
    let text = std::fs::read_to_string(page).unwrap();
    let mut in_sh = false;
    let mut ran = 0;
    for line in text.lines() {
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        let Some(command) = line.strip_prefix("margemu ").filter(|_| in_sh) else {
            continue;
        };
        let args: Vec<&str> = command.split_whitespace().collect();
        let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let printed = stdout(&out);
        if args[0] == "filter" {
            assert!(printed.contains("dip 69.0"), "{line}: {printed}");
        } else {
            assert!(
                printed.contains("20 of 1500 rows have no reference"),
                "{line}: {printed}"
            );
            assert!(printed.contains("heading RMS (°)"), "{line}: {printed}");
        }
        ran += 1;
    }
    assert_eq!(ran, 4);
    let report = std::fs::read_to_string(dir.join("gda-evaluation/report.md")).unwrap();
    assert!(
        report.contains("mask (column `movement` nonzero): 1200 of 1500 rows kept"),
        "{report}"
    );
}

/// `text` (a recording in NWU, margemu's) rewritten in `frame`: body vectors and quaternions
/// converted back out of margemu's axes.
fn in_frame(text: &str, frame: margemu::frame::Frame) -> String {
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let names: Vec<&str> = header.split(',').collect();
    let at = |n: &str| names.iter().position(|c| *c == n);
    let mut out = format!("{header}\n");
    for line in lines {
        let mut v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        for group in [["ax", "ay", "az"], ["gx", "gy", "gz"], ["mx", "my", "mz"]] {
            let i = group.map(|n| at(n).unwrap());
            // The body conversion is its own inverse (identity or a half turn).
            let b = frame.body_in([v[i[0]], v[i[1]], v[i[2]]]);
            (v[i[0]], v[i[1]], v[i[2]]) = (b[0], b[1], b[2]);
        }
        if let Some(w) = at("qw") {
            let q = frame.quat_out([v[w], v[w + 1], v[w + 2], v[w + 3]]);
            v[w..w + 4].copy_from_slice(&q);
        }
        let cells: Vec<String> = v.iter().map(|x| x.to_string()).collect();
        out += &cells.join(",");
        out.push('\n');
    }
    out
}

#[test]
fn a_recording_in_enu_or_ned_gives_the_nwu_results_in_its_own_frame() {
    use margemu::frame::Frame;
    let dir = scratch("ext-frame");
    let nwu = dir.join("nwu.csv");
    dip_recording(&nwu, true);
    let text = std::fs::read_to_string(&nwu).unwrap();
    let reference = [0.36, 0.0, -0.93];
    let run = |file: &Path, frame: Frame, out: &Path| {
        let r = frame_text(reference, frame);
        stdout(&margemu(&[
            "filter",
            "--filter",
            "ekf",
            "--frame",
            &frame.to_string(),
            "--mag-reference",
            &r,
            file.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]));
        margemu::evaluate::input::read_estimates(out).unwrap()
    };
    let base = run(&nwu, Frame::Nwu, &dir.join("nwu-est.csv"));
    for frame in [Frame::Enu, Frame::Ned] {
        let file = dir.join(format!("{frame}.csv"));
        std::fs::write(&file, in_frame(&text, frame)).unwrap();
        let est_path = dir.join(format!("{frame}-est.csv"));
        let est = run(&file, frame, &est_path);
        for (a, b) in base.iter().zip(&est) {
            let back = frame.quat_in(b.1);
            let dot: f64 = a.1.iter().zip(back).map(|(x, y)| x * y).sum();
            assert!(
                (dot.abs() - 1.0).abs() < 1e-9,
                "{frame} at {}: {a:?} {back:?}",
                a.0
            );
        }
        // evaluate reads both in the frame: the same geodesic, heading and inclination.
        let score = |file: &Path, est: &Path, frame: Frame| {
            let options = EvalOptions {
                frame,
                ..EvalOptions::default()
            };
            let source = Source::External {
                file: file.to_path_buf(),
                estimates: Some(est.to_path_buf()),
            };
            evaluate(&source, &options).unwrap()
        };
        let a = score(&nwu, &dir.join("nwu-est.csv"), Frame::Nwu);
        let b = score(&file, &est_path, frame);
        assert!((a.scores.geodesic_rms - b.scores.geodesic_rms).abs() < 1e-9);
        for i in 0..2 {
            let (x, y) = (
                a.scores.heading_inclination_rms[i],
                b.scores.heading_inclination_rms[i],
            );
            assert!((x - y).abs() < 1e-9, "{frame} {i}: {x} {y}");
        }
        assert!(
            b.notes
                .iter()
                .any(|n| n.starts_with(&format!("frame {frame}:"))),
            "{:?}",
            b.notes
        );
    }
    let e = stderr(&margemu(&[
        "filter", "--filter", "ekf", "--frame", "xyz", "a.csv", "-o", "b.csv",
    ]));
    assert!(e.contains("unknown frame `xyz` (nwu, enu or ned)"), "{e}");
}

/// `reference` (NWU) as `--mag-reference` text in `frame`.
fn frame_text(reference: [f64; 3], frame: margemu::frame::Frame) -> String {
    // world_in is a rotation: its inverse is its transpose, found by converting the axes.
    let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(|e| frame.world_in(e));
    let v: Vec<String> = (0..3)
        .map(|j| {
            (0..3)
                .map(|i| axes[j][i] * reference[i])
                .sum::<f64>()
                .to_string()
        })
        .collect();
    v.join(",")
}
