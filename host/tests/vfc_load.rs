//! The virtual flight controller does not depend on machine load: it reads the chip's FIFO and
//! stamps each sample from its index, so a run beside two CPU-bound processes serves the same
//! images and sends exactly the same estimates, with the same instants, as a run on a quiet
//! machine. The case study (the demo's scene, shortened), the EKF with the demo's tuned
//! parameters, every sample's estimate sent, as `margemu demo` runs it.

use margemu::offline::{FilterKind, FilterParams};
use margemu::scene::Scene;
use margemu::stream::StreamConfig;
use margemu::vfc::{run_loopback, FcReport, OutputRate, VfcConfig};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::AtomicBool;

const CASE_STUDY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../hil-fixtures/scenes/case-study.toml"
);

/// The demo's tuned EKF (`docs/demo.md`).
const TUNED_EKF: &str =
    "[ekf]\ngyro_noise = 0.0111\ngyro_bias_walk = 6.9e-4\naccel_noise = 0.180\nmag_noise = 0.484\n";

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("margemu-vfc-load-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Two CPU-bound processes (`yes` into /dev/null), killed when dropped.
struct Hogs(Vec<Child>);

impl Hogs {
    fn start() -> Self {
        Self(
            (0..2)
                .map(|_| {
                    Command::new("yes")
                        .stdout(Stdio::null())
                        .spawn()
                        .expect("yes")
                })
                .collect(),
        )
    }
}

impl Drop for Hogs {
    fn drop(&mut self) {
        for child in &mut self.0 {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// One flight-controller session of `scene` into `dir`: the flight controller's report and the
/// session's F.
fn session(scene: &Scene, params: &FilterParams, dir: &Path) -> (FcReport, f64) {
    let config = VfcConfig {
        output: OutputRate::EverySample,
        ..VfcConfig::for_scene(scene, params.clone())
    };
    // The demo's stream settings.
    let stream = StreamConfig {
        port: "pty".into(),
        lead: margemu::demo::DEMO_LEAD,
        ..StreamConfig::default()
    };
    let run = run_loopback(scene, config, stream, dir, &AtomicBool::new(false), |_| {}).unwrap();
    let summary = run.session.as_ref().unwrap();
    assert_eq!(summary.served.byte_exact, summary.samples, "{summary:?}");
    run.fc.check_delivery(run.dut.as_ref().unwrap()).unwrap();
    assert!(run.fc.fc.error.is_none(), "{}", run.fc.fc);
    let eval = margemu::vfc_score::evaluate_session(dir).unwrap();
    (run.fc.fc, eval.scores.f)
}

/// `served.csv` without its host times: (index, time_ns, crc32c, underrun, empty, match).
fn served(dir: &Path) -> Vec<String> {
    column_rows(dir, "served.csv", 1)
}

/// `dut_attitude.csv` without its host times: message, device time, Euler angles, quaternion.
fn estimates(dir: &Path) -> Vec<String> {
    column_rows(dir, "dut_attitude.csv", 2)
}

/// The rows of `file` (header skipped) from column `from` on.
fn column_rows(dir: &Path, file: &str, from: usize) -> Vec<String> {
    std::fs::read_to_string(dir.join(file))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(from).collect::<Vec<_>>().join(","))
        .collect()
}

/// The case study shortened to 2 s, on `chip`.
fn case_study(chip: &str) -> Scene {
    let scene = Scene::load(Path::new(CASE_STUDY)).unwrap();
    let scene = margemu::demo::shorten(&scene, 2.0).unwrap();
    margemu::scene::chip::with_model(&scene, chip).unwrap()
}

/// Runs `scene` quiet, then beside two CPU hogs, and checks that both served the same images
/// and sent the same estimates, every sample read; returns the two runs' F.
fn quiet_and_loaded(name: &str, scene: &Scene, params: &FilterParams) -> (f64, f64) {
    let quiet_dir = scratch(&format!("{name}-quiet"));
    let (quiet, quiet_f) = session(scene, params, &quiet_dir);
    let loaded_dir = scratch(&format!("{name}-loaded"));
    let (loaded, loaded_f) = {
        let _hogs = Hogs::start();
        session(scene, params, &loaded_dir)
    };
    println!("{name} quiet:  F {quiet_f:.6}; {quiet}");
    println!("{name} loaded: F {loaded_f:.6}; {loaded}");
    for fc in [&quiet, &loaded] {
        assert_eq!((fc.missed, fc.overflows, fc.resyncs), (0, 0, 0), "{fc}");
        assert_eq!(fc.samples, 400, "{fc}");
    }
    assert_eq!(served(&quiet_dir), served(&loaded_dir), "served images");
    let (a, b) = (estimates(&quiet_dir), estimates(&loaded_dir));
    assert_eq!(a.len(), b.len());
    assert!(a == b, "the estimates differ");
    assert_eq!(quiet.diagnostics, loaded.diagnostics);
    (quiet_f, loaded_f)
}

#[test]
fn a_run_beside_two_cpu_hogs_gives_the_same_images_and_estimates_as_a_quiet_one() {
    let params =
        FilterParams::from_toml(TUNED_EKF, Path::new("tuned.toml"), FilterKind::Ekf).unwrap();
    let (quiet, loaded) = quiet_and_loaded("mpu9250", &case_study("mpu9250"), &params);
    // The estimates are the same; the scores differ only by the evaluation's fit of the device
    // clock to the host's arrival times.
    assert!(
        (loaded - quiet).abs() < 0.05 * quiet,
        "F {quiet} quiet, {loaded} loaded"
    );
}

#[test]
fn on_the_icm42688p_too() {
    let params = FilterParams::defaults(FilterKind::Gda);
    quiet_and_loaded("icm42688p", &case_study("icm42688p"), &params);
}
