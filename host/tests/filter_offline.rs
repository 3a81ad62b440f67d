//! `margemu filter` and `margemu::offline`: the reference filters run over recordings. On a
//! noise-free static run they sit on the truth, and from a wrong start they converge to it; a
//! run directory and the same samples as an external CSV give the same estimates; the scores of
//! a filtered run directory equal those the tuner computes in process.

mod filter_common;

use filter_common::{margemu, ok, scratch, simulated, SMALL_SCENE, STATIC_SCENE};
use margemu::evaluate::input::{read_estimates, read_truth};
use margemu::evaluate::{evaluate, EvalOptions, LatencySearch, ScoreOptions, Source};
use margemu::offline::{self, AttitudeStart, FilterKind, FilterParams, Initial};
use margemu::scene::Scene;
use margemu::tune::Dataset;
use margemu_filters::quat::{from_euler_zyx, geodesic_angle, mul};

#[test]
fn on_a_noise_free_static_run_every_filter_converges_to_the_truth() {
    let dir = scratch("filter-static");
    let (_, run) = simulated(&dir, "static.toml", STATIC_SCENE);
    let truth = read_truth(&run.join("truth.csv")).unwrap().attitude[0].1;
    let rec = offline::read(&run, None).unwrap();
    assert_eq!(rec.imu.t_ns.len(), 4000);
    for kind in FilterKind::ALL {
        let mut params = FilterParams::defaults(kind);
        // From the first sample (TRIAD) the filter starts on the truth and stays there.
        let est = offline::run(&params, &rec.imu, rec.mag_reference, Initial::FirstSample).unwrap();
        let worst = est
            .iter()
            .map(|e| geodesic_angle(e.1, truth))
            .fold(0.0, f64::max);
        // The inputs are the truth rounded to f32; the GDA dithers within 2β·dt = 1e-3 rad.
        let tolerance = if kind == FilterKind::Gda {
            1.1e-3
        } else {
            1e-5
        };
        assert!(worst < tolerance, "{kind}: {worst}");
        // From about 65° off it converges within the run to within 1e-3 rad, with gains that
        // trust the vectors (at their defaults the heading of the ECF and the EKF converges with
        // time constants of several seconds: 0.26 and 0.02 rad are left after 20 s; the EKF's
        // bias states take up part of the start error and give it back slowly).
        match kind {
            FilterKind::Ecf => params.set("kp", 5.0).unwrap(),
            FilterKind::Ekf => {
                params.set("accel_noise", 0.05).unwrap();
                params.set("mag_noise", 0.05).unwrap();
            }
            FilterKind::Gda => {}
        }
        let start = mul(truth, from_euler_zyx([0.9, 0.5, 0.8]));
        let est = offline::run(
            &params,
            &rec.imu,
            rec.mag_reference,
            Initial::Attitude(start),
        )
        .unwrap();
        let first = geodesic_angle(start, truth);
        let last = geodesic_angle(est[3999].1, truth);
        assert!(first > 1.1, "{kind}: {first}");
        assert!(last < 1.1e-3, "{kind}: {first} → {last}");
    }
}

#[test]
fn a_run_directory_and_the_same_samples_as_csv_give_the_same_estimates() {
    let dir = scratch("filter-csv");
    let (_, run) = simulated(&dir, "small.toml", SMALL_SCENE);
    // The external format: t_s and the nine columns, in another order, with an extra column.
    let marg = std::fs::read_to_string(run.join("marg.csv")).unwrap();
    let mut csv = String::from("t_s,gx,gy,gz,ax,ay,az,mx,my,mz,note\n");
    for line in marg.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let t_ns: u64 = f[0].parse().unwrap();
        let t = format!("{}.{:09}", t_ns / 1_000_000_000, t_ns % 1_000_000_000);
        csv += &format!(
            "{t},{},{},{},{},{},{},{},{},{},x\n",
            f[4], f[5], f[6], f[1], f[2], f[3], f[7], f[8], f[9]
        );
    }
    let external = dir.join("external.csv");
    std::fs::write(&external, csv).unwrap();
    let (a, b) = (dir.join("a.csv"), dir.join("b.csv"));
    // A CSV's reference is estimated from a rest phase unless given: the scene's, given here,
    // makes the two runs the same.
    let scene_field = "0.5,0,-0.83";
    for (input, out) in [(&run, &a), (&external, &b)] {
        let printed = ok(&margemu(&[
            "filter",
            "--filter",
            "ekf",
            "--param",
            "accel_noise=0.3",
            "--mag-reference",
            scene_field,
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ]));
        assert!(
            printed.contains("accel_noise=0.3") && printed.contains("600 samples"),
            "{printed}"
        );
    }
    let (ta, tb) = (
        std::fs::read_to_string(&a).unwrap(),
        std::fs::read_to_string(&b).unwrap(),
    );
    assert_eq!(ta.lines().next(), Some("t_s,qw,qx,qy,qz,roll,pitch,yaw"));
    assert_eq!(ta.lines().count(), 601);
    assert_eq!(ta, tb);
    // What `margemu evaluate` reads back.
    let est = read_estimates(&a).unwrap();
    assert_eq!(est.len(), 600);
    assert_eq!(est[1].0, 10_000_000);
}

#[test]
fn scores_of_a_filtered_run_directory_equal_the_tuners() {
    let dir = scratch("filter-scores");
    let (scene_path, run) = simulated(&dir, "small.toml", SMALL_SCENE);
    let scene = Scene::load(&scene_path).unwrap();
    let mut params = FilterParams::defaults(FilterKind::Ecf);
    params.set("kp", 1.5).unwrap();
    let estimates = dir.join("ecf.csv");
    ok(&margemu(&[
        "filter",
        "--filter",
        "ecf",
        "--param",
        "kp=1.5",
        "--attitude-start",
        "truth",
        run.to_str().unwrap(),
        "-o",
        estimates.to_str().unwrap(),
    ]));
    let score = ScoreOptions {
        warmup_ns: 1_000_000_000,
        ..ScoreOptions::default()
    };
    let options = EvalOptions {
        search: LatencySearch {
            score,
            ..LatencySearch::default()
        },
        ..EvalOptions::default()
    };
    let source = Source::Estimates {
        dir: run.clone(),
        estimates,
    };
    let from_files = evaluate(&source, &options).unwrap().scores;
    let data = Dataset::simulate(&scene, 1).unwrap();
    let in_process = data.score(&params, AttitudeStart::Truth, &score).unwrap()[0];
    assert_eq!(from_files.count, in_process.count);
    // marg.csv holds the f32 samples in shortest form, read back as f64: equal to 1e-7.
    assert!(
        (from_files.f / in_process.f - 1.0).abs() < 1e-6,
        "{from_files:?} {in_process:?}"
    );
}
