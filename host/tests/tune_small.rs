//! Tuning on a small scene: it improves the objective over the defaults, it is deterministic
//! (the same twice, and the same on one thread as on several), and the command line prints the
//! table and writes a parameters file that `margemu filter` takes.

mod filter_common;

use filter_common::{failed, margemu, ok, scene_in, scratch, simulated, SMALL_SCENE};
use margemu::offline::{FilterKind, FilterParams};
use margemu::tune::{tune, tune_dataset, AttitudeStart, Dataset, Objective, TuneOptions};

fn options(max_evals: usize) -> TuneOptions {
    TuneOptions {
        seeds: 2,
        max_evals,
        ..TuneOptions::default()
    }
}

/// A start far from good: gains a factor of 20 too low, noise statistics 20 times too high.
fn poor_start(kind: FilterKind) -> FilterParams {
    let mut p = FilterParams::defaults(kind);
    let set = |p: &mut FilterParams, name: &str, v: f64| p.set(name, v).unwrap();
    match kind {
        FilterKind::Ecf => set(&mut p, "kp", 0.025),
        FilterKind::Gda => set(&mut p, "beta", 0.005),
        FilterKind::Ekf => {
            set(&mut p, "accel_noise", 10.0);
            set(&mut p, "mag_noise", 10.0);
        }
    }
    p
}

#[test]
fn tuning_improves_f_over_the_initial_parameters_for_every_filter() {
    let dir = scratch("tune-improves");
    let (_, scene) = scene_in(&dir, "small.toml", SMALL_SCENE);
    let data = Dataset::simulate(&scene, 2).unwrap();
    assert_eq!(data.seeds(), vec![7, 8]);
    for kind in FilterKind::ALL {
        let opts = TuneOptions {
            initial_params: Some(poor_start(kind)),
            ..options(40)
        };
        let r = tune_dataset(&data, kind, &opts, &|_| {}).unwrap();
        assert_eq!(r.initial.params, poor_start(kind));
        assert_eq!(r.initial.per_seed.len(), 2);
        // Scored after the 1 s warm-up: 500 instants per seed.
        assert!(r.initial.per_seed.iter().all(|s| s.count == 500));
        let (before, after) = (r.initial.objective, r.tuned.objective);
        println!("{kind}: {before} → {after}");
        assert!(after < 0.75 * before, "{kind}: {before} → {after}");
        // The objective is the mean of the per-seed F.
        assert_eq!(after, r.tuned.mean(|s| s.f));
        assert!(
            r.search.evaluations <= 40 + kind.params().len() + 1,
            "{kind}: {:?}",
            r.search
        );
        // From the defaults (close to the best on this mild scene) it never gets worse.
        let r = tune_dataset(&data, kind, &options(20), &|_| {}).unwrap();
        assert_eq!(r.initial.params, FilterParams::defaults(kind));
        assert!(r.tuned.objective <= r.initial.objective, "{kind}: {r:?}");
    }
}

#[test]
fn tuning_is_deterministic_whatever_the_threads() {
    let dir = scratch("tune-deterministic");
    let (_, scene) = scene_in(&dir, "small.toml", SMALL_SCENE);
    let opts = TuneOptions {
        objective: Objective::Geodesic,
        attitude_start: AttitudeStart::Truth,
        ..options(25)
    };
    let a = tune(&scene, FilterKind::Ekf, &opts).unwrap();
    let b = tune(&scene, FilterKind::Ekf, &opts).unwrap();
    assert_eq!(a, b);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let c = one.install(|| tune(&scene, FilterKind::Ekf, &opts).unwrap());
    assert_eq!(a, c);
    assert!(a.tuned.objective < a.initial.objective);
    assert_eq!(a.tuned.objective, a.tuned.mean(|s| s.geodesic_rms));
}

#[test]
fn options_that_cannot_work_are_refused() {
    let dir = scratch("tune-refused");
    let (_, scene) = scene_in(&dir, "small.toml", SMALL_SCENE);
    let opts = TuneOptions {
        seeds: 0,
        ..TuneOptions::default()
    };
    let e = tune(&scene, FilterKind::Gda, &opts)
        .unwrap_err()
        .to_string();
    assert_eq!(e, "at least one seed is needed");
    let opts = TuneOptions {
        initial_params: Some(FilterParams::defaults(FilterKind::Ecf)),
        ..options(10)
    };
    let e = tune(&scene, FilterKind::Gda, &opts)
        .unwrap_err()
        .to_string();
    assert_eq!(e, "the start is for ecf, not gda");
    let opts = TuneOptions {
        warmup_s: f64::NAN,
        ..options(10)
    };
    let e = tune(&scene, FilterKind::Gda, &opts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("warm-up"), "{e}");
}

#[test]
fn cli_prints_the_table_and_writes_parameters_filter_takes() {
    let dir = scratch("tune-cli");
    let (scene, _) = scene_in(&dir, "small.toml", SMALL_SCENE);
    let params = dir.join("tuned.toml");
    std::fs::write(&params, "# kept\n[ekf]\nmag_noise = 3.0\n").unwrap();
    let out = ok(&margemu(&[
        "tune",
        scene.to_str().unwrap(),
        "--filter",
        "gda,ecf",
        "--seeds",
        "2",
        "--max-evals",
        "20",
        "--write-params",
        params.to_str().unwrap(),
    ]));
    for line in [
        "GDA",
        "ECF",
        "beta",
        "kp",
        "ki",
        "F (rad²)",
        "MSE (ψ)",
        "STD (θ)",
        "geodesic RMS",
    ] {
        assert!(out.contains(line), "no `{line}` in\n{out}");
    }
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(
        text.contains("# kept") && text.contains("mag_noise = 3.0"),
        "{text}"
    );
    let path = params.as_path();
    let gda = FilterParams::from_toml(&text, path, FilterKind::Gda).unwrap();
    assert_ne!(gda, FilterParams::defaults(FilterKind::Gda));
    let ecf = FilterParams::from_toml(&text, path, FilterKind::Ecf).unwrap();
    assert_ne!(ecf, FilterParams::defaults(FilterKind::Ecf));
    let (_, run) = simulated(&dir, "small.toml", SMALL_SCENE);
    let estimates = dir.join("gda.csv");
    let filtered = ok(&margemu(&[
        "filter",
        "--filter",
        "gda",
        "--params",
        params.to_str().unwrap(),
        run.to_str().unwrap(),
        "-o",
        estimates.to_str().unwrap(),
    ]));
    assert!(
        filtered.contains(&format!("beta={}", gda.get("beta").unwrap())),
        "{filtered}"
    );

    let e = failed(&margemu(&[
        "tune",
        scene.to_str().unwrap(),
        "--filter",
        "kalman",
    ]));
    assert!(
        e.contains("unknown filter `kalman` (ecf, gda or ekf)"),
        "{e}"
    );
    let e = failed(&margemu(&["tune", "missing.toml", "--filter", "ekf"]));
    assert!(
        e.contains("missing.toml: no such file (built-in scenes, by name: "),
        "{e}"
    );
    std::fs::write(&params, "[gda\n").unwrap();
    let e = failed(&margemu(&[
        "tune",
        scene.to_str().unwrap(),
        "--filter",
        "gda",
        "--seeds",
        "1",
        "--max-evals",
        "5",
        "--write-params",
        params.to_str().unwrap(),
    ]));
    assert!(e.contains("tuned.toml: not a parameters file"), "{e}");
}
