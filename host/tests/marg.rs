//! Raw MARG samples end to end: the ideal path, the perturbation as written, the noise a user
//! measures with `margemu analyze noise`, and sensor errors in scene files.

use margemu::analysis::{allan, psd, white_density_from_psd};
use margemu::marg::MargSim;
use margemu::run::collect;
use margemu::scene::Scene;
use std::path::Path;
use std::process::Command;

fn scene(text: &str) -> Scene {
    Scene::parse_str(text, Path::new("marg.toml")).unwrap_or_else(|e| panic!("{e}"))
}

const MOVING: &str = "duration = 2.0\nrate = 500.0\nseed = 3\nmotion = \"kinematic\"\n\
    [joints.x]\ntype = \"sine\"\namplitude = 0.2\nfrequency = 2.0\n\
    [joints.roll]\ntype = \"sine\"\namplitude = 1.0\nfrequency = 1.0\n\
    [joints.yaw]\ntype = \"sine\"\namplitude = 2.0\nfrequency = 0.5\n";

#[test]
fn without_sensor_terms_samples_are_the_truth_in_f32() {
    let s = scene(MOVING);
    let mut marg = MargSim::new(&s).unwrap();
    for t in collect(&s).unwrap() {
        let m = marg.sample(&t);
        assert_eq!(m.sample.acc, t.specific_force.map(|v| v as f32));
        assert_eq!(m.sample.gyr, t.body_rate.map(|v| v as f32));
        assert_eq!(m.sample.mag, t.field_body.map(|v| v as f32));
        assert_eq!(m.disturbance, [0.0; 3]);
    }
}

#[test]
fn the_perturbation_is_added_to_the_true_field_and_zero_between_bursts() {
    let s = scene(&format!(
        "{MOVING}[perturbation]\nwindow = 0.2\ngap = [0.1, 0.3]\n"
    ));
    let mut marg = MargSim::new(&s).unwrap();
    let (mut inside, mut outside) = (0, 0);
    for t in collect(&s).unwrap() {
        let m = marg.sample(&t);
        let field = t.field_body.map(|v| v as f32);
        assert_eq!(m.sample.mag, [0, 1, 2].map(|i| field[i] + m.disturbance[i]));
        if m.disturbance == [0.0; 3] {
            outside += 1;
        } else {
            inside += 1;
        }
    }
    assert!(
        inside > 100 && outside > 100,
        "inside {inside}, outside {outside}"
    );
}

#[test]
fn the_measured_noise_density_matches_the_scene() {
    // A level plate at rest with white noise only: what `analyze noise` reports must match.
    let density = [0.0224, 0.0224, 0.0022];
    let text = format!(
        "duration = 1000.0\nrate = 200.0\nseed = 11\nmotion = \"static\"\n\
         [sensors.gyro]\nnoise_density = [{0}, {0}, {0}]\n\
         [sensors.accel]\nnoise_density = [{1}, {1}, {1}]\n\
         [sensors.mag]\nnoise_density = [{2}, {2}, {2}]\n",
        density[0], density[1], density[2]
    );
    let s = scene(&text);
    let mut marg = MargSim::new(&s).unwrap();
    let samples: Vec<_> = collect(&s)
        .unwrap()
        .iter()
        .map(|t| marg.sample(t).sample)
        .collect();
    let columns: [(&str, Vec<f64>, f64); 3] = [
        (
            "gyr_x",
            samples.iter().map(|m| m.gyr[0] as f64).collect(),
            density[0],
        ),
        (
            "acc_y",
            samples.iter().map(|m| m.acc[1] as f64).collect(),
            density[1],
        ),
        (
            "mag_z",
            samples.iter().map(|m| m.mag[2] as f64).collect(),
            density[2],
        ),
    ];
    for (name, y, nd) in columns {
        let spectrum = psd::welch(&y, 200.0, 4096);
        let measured = white_density_from_psd(spectrum.mean_in(1.0, 99.0).unwrap());
        assert!(
            (measured / nd - 1.0).abs() < 0.03,
            "{name}: PSD density {measured} vs {nd}"
        );
        let adev = allan::at(&allan::overlapping(&y, 200.0), 1.0).unwrap();
        assert!(
            (adev / nd - 1.0).abs() < 0.05,
            "{name}: ADEV(1 s) {adev} vs {nd}"
        );
    }
}

#[test]
fn analyze_noise_reads_a_simulated_run_and_draws_it() {
    let work = std::env::temp_dir().join(format!("margemu-analyze-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let scene_path = work.join("noise.toml");
    let dir = work.join("run");
    std::fs::write(
        &scene_path,
        "duration = 200.0\nrate = 200.0\nseed = 5\nmotion = \"static\"\n[sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n",
    )
    .unwrap();
    let bin = env!("CARGO_BIN_EXE_margemu");
    let run = Command::new(bin)
        .args(["simulate", scene_path.to_str().unwrap(), "-o"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        !dir.join("perturbation.csv").exists(),
        "no perturbation, no file"
    );
    let svg = dir.join("gyr_y.svg");
    let out = Command::new(bin)
        .args(["analyze", "noise"])
        .arg(dir.join("marg.csv"))
        .args(["--column", "gyr_y", "--plot"])
        .arg(&svg)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}{}",
        text,
        String::from_utf8_lossy(&out.stderr)
    );
    let line = text
        .lines()
        .find(|l| l.starts_with("Allan deviation at τ = 1 s:"))
        .expect(&text);
    let adev: f64 = line.split_whitespace().nth(7).unwrap().parse().unwrap();
    assert!((adev / 0.01 - 1.0).abs() < 0.1, "{line}");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
    let missing = Command::new(bin)
        .args(["analyze", "noise"])
        .arg(dir.join("marg.csv"))
        .args(["--column", "gyr_w"])
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("no column `gyr_w`"));
}

#[test]
fn bad_sensor_sections_are_located() {
    let base = "duration = 1.0\nrate = 200.0\nseed = 1\n";
    let cases = [
        ("[sensors.gyro]\nnoise_density = [0.1, -0.1, 0.1]\n", "5:17", "gyro.noise_density is negative"),
        ("[sensors.gyro]\nlever_arm = [0.1, 0.0, 0.0]\n", "5:13", "`sensors.gyro.lever_arm`: does not apply to `gyro`"),
        ("[sensors.accel]\nbias_instability = { coefficient = [1, 1, 1], correlation_time = 0.0 }\n", "5:20", "must be positive"),
        ("[perturbation]\ncutoff = 150.0\n", "5:10", "`perturbation.cutoff`: low-pass cutoff is at or above the Nyquist frequency"),
        ("[perturbation]\nwindow = 0.01\n", "5:10", "shorter than 10 samples"),
        ("[perturbation]\namplitude = [0.0, 0.0]\n", "5:13", "amplitude range is zero"),
        ("[perturbation]\nplacement = \"direction\"\n", "5:13", "needs `direction = [x, y, z]`"),
        ("[sensors.mag]\nsoft_iron = [[1, 0], [0, 1], [0, 0]]\n", "5:14", "invalid length 2"),
        ("[sensors.gyro]\nbias = [0.1, 0.0]\n", "5:8", "invalid length 2, expected an array of length 3"),
        ("[sensors.accel]\nnoise = [0.1, 0.0, 0.0]\n", "5:1", "unknown field `noise`, expected one of `scale_factor`, `misalignment`, `bias`, `noise_density`, `bias_instability`, `rate_random_walk`, `temperature_bias`, `resolution`, `range`, `g_sensitivity`, `lever_arm`, `soft_iron`, `hard_iron`"),
        ("[sensors.mag]\ntemperature_bias = { coefficient = [1, 1, 1] }\n", "5:20", "missing field `reference`"),
        ("[sensors.gyro]\nbias_instability = { coefficient = [1, 1, 1], correlation_time_s = 1.0 }\n", "5:47", "unknown field `correlation_time_s`"),
    ];
    for (section, place, reason) in cases {
        let err = Scene::parse_str(&format!("{base}{section}"), Path::new("s.toml"))
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with(&format!("s.toml:{place}: ")),
            "place of {section:?}: {err}"
        );
        assert!(err.contains(reason), "reason of {section:?}: {err}");
    }
}

#[test]
fn analyze_noise_takes_t_s_as_the_time_column_like_filter() {
    let work = std::env::temp_dir().join(format!("margemu-analyze-t-s-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let scene_path = work.join("noise.toml");
    let dir = work.join("run");
    std::fs::write(
        &scene_path,
        "duration = 20.0\nrate = 200.0\nseed = 5\nmotion = \"static\"\n[sensors.gyro]\nnoise_density = [0.01, 0.01, 0.01]\n",
    )
    .unwrap();
    let bin = env!("CARGO_BIN_EXE_margemu");
    let run = Command::new(bin)
        .args(["simulate", scene_path.to_str().unwrap(), "-o"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // The same samples as an external recording: `t_s` in seconds, `filter`'s column names.
    let marg = std::fs::read_to_string(dir.join("marg.csv")).unwrap();
    let mut lines = marg.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, gy) = (col("t_ns"), col("gyr_y"));
    let mut recording = String::from("t_s,gy\n");
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let ns: u64 = f[t].parse().unwrap();
        recording += &format!(
            "{}.{:09},{}\n",
            ns / 1_000_000_000,
            ns % 1_000_000_000,
            f[gy]
        );
    }
    std::fs::write(dir.join("rec.csv"), recording).unwrap();
    let analyze = |file: &str, column: &str| {
        let out = Command::new(bin)
            .args(["analyze", "noise"])
            .arg(dir.join(file))
            .args(["--column", column])
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        // Everything after the line naming the file and column.
        text.lines().skip(1).collect::<Vec<_>>().join("\n")
    };
    let from_ns = analyze("marg.csv", "gyr_y");
    assert!(from_ns.contains("Allan deviation at τ = 1 s:"), "{from_ns}");
    assert_eq!(analyze("rec.csv", "gy"), from_ns);
}
