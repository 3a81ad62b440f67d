//! Vibration end to end: a random PSD recovered from `marg.csv` with `analyze`'s Welch
//! estimate, a session's `clipping.csv` with the counters the host's chain kept, the
//! internal-rate path served byte for byte over the loopback, and source mode model running
//! tones and shocks on the device byte for byte, or refusing (random vibration, too many rpm
//! points, a chain too slow for the Cortex-M4F) before sending anything.

mod common;

use margemu::analysis::{psd, Series};
use margemu::marg::MargSim;
use margemu::run::collect;
use margemu::scene::Scene;
use std::ffi::OsStr;
use std::path::Path;
use std::process::Command;

const G2: f64 = 9.80665 * 9.80665;

/// An ICM-42688-P at 8 kHz, level, with a random PSD (`psd` TOML) on every axis.
fn random_scene(psd: &str, extra: &str) -> String {
    format!(
        "duration = 8.0\nrate = 8000.0\nseed = 21\nmotion = \"static\"\n\
         [chip]\nmodel = \"icm42688p\"\n{extra}\
         [[vibration.random]]\npsd = {psd}\n"
    )
}

#[test]
fn a_random_psd_is_recovered_in_band_from_the_samples() {
    let dir = common::scratch("vibration-psd");
    std::fs::create_dir_all(&dir).unwrap();
    // The internal path (32 kHz, the AAF at 258 Hz), as `auto` would not take it for content
    // below the output Nyquist frequency.
    let text = random_scene(
        "[[40.0, 0.002], [150.0, 0.008], [1500.0, 0.008]]",
        "[vibration]\npath = \"internal\"\n",
    );
    std::fs::write(dir.join("scene.toml"), &text).unwrap();
    let run = dir.join("run");
    common::margemu(&[
        OsStr::new("simulate"),
        dir.join("scene.toml").as_os_str(),
        OsStr::new("-o"),
        run.as_os_str(),
    ]);
    let scene = Scene::parse_str(&text, Path::new("scene.toml")).unwrap();
    let source = scene.vibration[0].random.unwrap();
    let chain = margemu::sampling::chip_chain(&scene, &scene.chip)
        .unwrap()
        .unwrap();
    for column in ["acc_x", "acc_y", "acc_z"] {
        let series = Series::from_csv(&run.join("marg.csv"), column).unwrap();
        let spectrum = psd::welch(&series.values, series.rate, 2048);
        // In band (above the lowest breakpoint, where the AAF at 258 Hz still passes most of
        // it), averaged over bands of 8 bins (31 Hz) so the estimate's own scatter (about
        // 0.55 dB per bin with 62 segments) stays well inside the 1 dB; the prediction
        // includes the chain's response.
        let bins: Vec<(f64, f64)> = spectrum
            .frequency
            .iter()
            .zip(&spectrum.density)
            .filter(|(f, _)| (60.0..=310.0).contains(*f))
            .map(|(f, p)| {
                let gain = chain.accel.filter.gain_at(*f);
                (*p, source.psd_at(*f) * G2 * gain * gain)
            })
            .collect();
        for band in bins.chunks(8) {
            let got: f64 = band.iter().map(|b| b.0).sum();
            let predicted: f64 = band.iter().map(|b| b.1).sum();
            let db = 10.0 * (got / predicted).log10();
            assert!(db.abs() < 1.0, "{column}: {db:.2} dB off in a band");
        }
        assert!(bins.len() > 60, "{} bins checked", bins.len());
    }
}

#[test]
fn the_internal_path_costs_what_skipping_it_gets_wrong() {
    // A 7.9 kHz tone (ODR − 100 Hz) on an 8 kHz ICM-42688-P: the internal path's AAF takes it
    // down to a trace at 100 Hz; the output path samples it at the output instants and folds
    // it to 100 Hz at full amplitude.
    let tone = "[[vibration.tones]]\nmotors = 1\nrpm = 474000\n\
                [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 5.0]\n";
    let base = "duration = 0.5\nrate = 8000.0\nseed = 2\nmotion = \"static\"\n\
                [chip]\nmodel = \"icm42688p\"\n";
    let peak = |path: &str| {
        let text = format!("{base}[vibration]\npath = \"{path}\"\n{tone}");
        let scene = Scene::parse_str(&text, Path::new("tone.toml")).unwrap();
        let mut marg = MargSim::new(&scene).unwrap();
        assert_eq!(marg.runs_internal_path(), path == "internal");
        collect(&scene)
            .unwrap()
            .iter()
            .skip(800)
            .map(|t| (f64::from(marg.sample(t).sample.acc[2]) - 9.80665).abs())
            .fold(0.0, f64::max)
    };
    let (internal, output) = (peak("internal"), peak("output"));
    assert!(
        output > 4.9,
        "the output path folds the tone whole: {output}"
    );
    assert!(internal < 0.05, "the AAF removes it: {internal}");
    // `auto` takes the internal path for content above the output Nyquist frequency.
    let text = format!("{base}{tone}");
    let scene = Scene::parse_str(&text, Path::new("tone.toml")).unwrap();
    assert!(MargSim::new(&scene).unwrap().runs_internal_path());
}

#[test]
fn a_session_logs_the_clipping_counters_and_serves_the_chain_byte_for_byte() {
    // ±2 g with a 2 g, 300 Hz tone on z over gravity: the top third of each cycle clips.
    let dir = common::scratch("vibration-clip");
    std::fs::create_dir_all(&dir).unwrap();
    let text = "duration = 1.0\nrate = 1000.0\nseed = 5\nmotion = \"static\"\n\
        [chip]\nmodel = \"icm42688p\"\naccel_range = 2.0\n\
        [vibration]\npath = \"internal\"\n\
        [[vibration.tones]]\nmotors = 1\nrpm = 18000\n\
        [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 19.6133]\n";
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    let session = dir.join("session");
    let out = common::margemu(&[
        OsStr::new("loopback"),
        dir.join("scene.toml").as_os_str(),
        OsStr::new("-o"),
        session.as_os_str(),
    ]);
    assert!(out.contains("served 1000 samples (0 underruns"), "{out}");
    let served = std::fs::read_to_string(session.join("served.csv")).unwrap();
    assert!(
        served.lines().skip(1).all(|l| l.ends_with(",1")),
        "every image as predicted"
    );
    let clipping = std::fs::read_to_string(session.join("clipping.csv")).unwrap();
    let mut lines = clipping.lines();
    assert_eq!(
        lines.next(),
        Some("t_ns,device,accel_x,accel_y,accel_z,gyro_x,gyro_y,gyro_z")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let last = rows.last().unwrap();
    assert_eq!(last[0], "999000000", "the totals at the last sample");
    assert_eq!(&last[2..4], ["0", "0"]);
    let z: f64 = last[4].parse().unwrap();
    // The chip samples at 32 kHz: about a third of 32 000 internal samples clipped on z.
    assert!((z / 32_000.0 - 1.0 / 3.0).abs() < 0.01, "{z} clipped");
    assert_eq!(&last[5..], ["0", "0", "0"]);
    // The counts only grow, row after row.
    let counts: Vec<u64> = rows.iter().map(|r| r[4].parse().unwrap()).collect();
    assert!(counts.windows(2).all(|w| w[0] <= w[1]) && rows.len() > 100);
}

/// `margemu loopback --source model` of `text` into a fresh `name` directory: the session
/// directory, stdout and stderr, and whether it succeeded.
fn loopback_model(text: &str, name: &str) -> (std::path::PathBuf, String, String, bool) {
    let dir = common::scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(["loopback", "--source", "model", "-o"])
        .arg(dir.join("session"))
        .arg(dir.join("scene.toml"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (dir.join("session"), stdout, stderr, out.status.success())
}

/// Four motors on an rpm ramp (two harmonics, linear and angular) and a shock, on `chip` at
/// `rate` for 0.5 s, on `path`.
fn tones_and_shock(chip: &str, rate: u32, path: &str) -> String {
    format!(
        "duration = 0.5\nrate = {rate}.0\nseed = 9\nmotion = \"static\"\n\
         [chip]\nmodel = \"{chip}\"\n[vibration]\npath = \"{path}\"\n\
         [[vibration.tones]]\nmotors = 4\nspread = 0.02\n\
         rpm_ramp = {{ from = 6000, to = 18000, start = 0.1, end = 0.4 }}\n\
         [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.5, 0.0, 3.0]\n\
         angular = [0.0, 0.2, 0.0]\n\
         [[vibration.tones.harmonics]]\norder = 2.0\nlinear = [0.0, 1.0, 0.0]\n\
         [[vibration.shocks]]\nat = 0.2\nduration = 0.011\nlinear = [0.0, 0.0, 200.0]\n\
         angular = [1.0, 0.0, 0.0]\n"
    )
}

#[test]
fn source_model_runs_tones_and_shocks_on_the_device_byte_for_byte() {
    for (chip, path) in [
        ("icm20602", "output"),
        ("icm20602", "internal"),
        ("bmi088", "internal"),
    ] {
        let text = tones_and_shock(chip, 1000, path);
        let (session, stdout, stderr, ok) = loopback_model(&text, &format!("model-{chip}-{path}"));
        assert!(ok, "{chip} {path}: {stdout}{stderr}");
        assert!(
            stdout.contains("served 500 samples (0 underruns"),
            "{chip} {path}: {stdout}"
        );
        let served = std::fs::read_to_string(session.join("served.csv")).unwrap();
        assert_eq!(served.lines().count(), 501, "{chip} {path}");
        assert!(
            served.lines().skip(1).all(|l| l.ends_with(",1")),
            "{chip} {path}: every image as predicted"
        );
    }
}

#[test]
fn source_model_refuses_what_the_device_cannot_run_before_sending_anything() {
    // Nine steps: 17 points (each step after the first is two points at one instant).
    let steps: Vec<String> = (0..9)
        .map(|i| format!("[{}.0, {}]", i, 6000 + 100 * i))
        .collect();
    let points = tones_and_shock("icm20602", 1000, "output").replace(
        "rpm_ramp = { from = 6000, to = 18000, start = 0.1, end = 0.4 }",
        &format!("rpm_steps = [{}]", steps.join(", ")),
    );
    let cases = [
        (
            tones_and_shock("icm42688p", 8000, "internal"),
            "the chain needs ≈ 15 800 instructions per output sample, 165 % of a 96 MHz \
             Cortex-M4F at 8000 Hz",
        ),
        (
            points,
            "tone source 1 has 17 rpm points: the device holds at most 16 per source",
        ),
        (
            random_scene("[[40.0, 0.002], [1500.0, 0.008]]", "")
                .replace("duration = 8.0", "duration = 0.5"),
            "the scene has random vibration ([[vibration.random]]): its synthesis needs FFT \
             buffers",
        ),
    ];
    for (i, (text, reason)) in cases.into_iter().enumerate() {
        let (session, stdout, stderr, ok) = loopback_model(&text, &format!("model-refused-{i}"));
        assert!(!ok, "{stdout}");
        assert!(
            stderr.contains(&format!(
                "source mode model cannot run this scene: {reason}"
            )),
            "{stderr}"
        );
        assert!(!session.join("sent.csv").exists());
    }
}
