//! Output directories that cannot lie: an explicit `-o` that is not empty is refused unless
//! `--force` (which clears margemu's own files), a default directory is fresh each run, and a
//! run killed outright leaves a directory `evaluate` refuses as incomplete. The real binary.

mod common;

use common::{completion, has_event, long_scene, scratch, spawn_margemu, wait_until};
use margemu::rundir::Status;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../hil-fixtures/scenes/{name}.toml"))
}

/// Runs margemu with `args` in `cwd`; returns the output, whatever the exit status.
fn run_in(cwd: &Path, args: &[&OsStr]) -> Output {
    std::fs::create_dir_all(cwd).unwrap();
    Command::new(env!("CARGO_BIN_EXE_margemu"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn simulate_refuses_a_used_directory_and_force_replaces_the_first_runs_files() {
    let work = scratch("simulate-reuse");
    let dir = work.join("d");
    let case_study = fixture("case-study");
    let figure3 = fixture("figure3");
    let simulate = |scene: &Path, more: &[&str]| {
        let mut args: Vec<&OsStr> = vec!["simulate".as_ref(), scene.as_os_str()];
        args.extend(["-o".as_ref(), dir.as_os_str()]);
        args.extend(more.iter().map(OsStr::new));
        run_in(&work, &args)
    };
    assert!(simulate(&case_study, &[]).status.success());
    assert!(dir.join("perturbation.csv").exists());
    let refused = simulate(&figure3, &[]);
    assert!(!refused.status.success());
    assert!(
        stderr(&refused).contains("is not empty"),
        "{}",
        stderr(&refused)
    );
    // Nothing of the first run was touched.
    assert!(completion(&dir).unwrap().status == Status::Complete);
    let forced = simulate(&figure3, &["--force"]);
    assert!(forced.status.success(), "{}", stderr(&forced));
    assert!(
        !dir.join("perturbation.csv").exists(),
        "the case study's perturbation.csv outlived --force"
    );
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    assert!(meta.contains("scene_file = ") && meta.contains("figure3.toml"));
    assert_eq!(meta.matches("[completion]").count(), 1, "{meta}");
}

#[test]
fn force_refuses_a_directory_holding_files_margemu_did_not_write() {
    let work = scratch("simulate-foreign");
    let dir = work.join("d");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let figure3 = fixture("figure3");
    let out = run_in(
        &work,
        &[
            "simulate".as_ref(),
            figure3.as_os_str(),
            "-o".as_ref(),
            dir.as_os_str(),
            "--force".as_ref(),
        ],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("notes.txt"), "{}", stderr(&out));
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn simulate_without_output_writes_a_fresh_directory_each_run() {
    let work = scratch("simulate-default");
    let figure3 = fixture("figure3");
    for expected in ["runs/figure3", "runs/figure3-2"] {
        let out = run_in(&work, &["simulate".as_ref(), figure3.as_os_str()]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(String::from_utf8_lossy(&out.stdout).contains(expected));
        let record = completion(&work.join(expected)).unwrap();
        assert_eq!(record.status, Status::Complete);
        assert_eq!(
            (record.samples_written, record.samples_expected),
            (3000, Some(3000))
        );
    }
}

#[test]
fn loopback_twice_without_output_writes_two_sessions() {
    let work = scratch("loopback-default");
    let scene = fixture("mpu6000");
    for expected in ["sessions/mpu6000-loopback", "sessions/mpu6000-loopback-2"] {
        let out = run_in(&work, &["loopback".as_ref(), scene.as_os_str()]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(String::from_utf8_lossy(&out.stdout).contains(expected));
        assert_eq!(
            completion(&work.join(expected)).unwrap().status,
            Status::Complete
        );
    }
}

#[test]
fn loopback_into_a_device_under_test_session_does_not_keep_its_attitude() {
    let work = scratch("loopback-dut");
    let dir = work.join("session");
    let scene = fixture("figure3");
    let loopback = |more: &[&str]| {
        let mut args: Vec<&OsStr> = vec!["loopback".as_ref(), scene.as_os_str()];
        args.extend(["-o".as_ref(), dir.as_os_str()]);
        args.extend(more.iter().map(OsStr::new));
        run_in(&work, &args)
    };
    let first = loopback(&["--vfc", "ecf"]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(dir.join("dut_attitude.csv").exists());
    let refused = loopback(&[]);
    assert!(!refused.status.success());
    assert!(
        stderr(&refused).contains("is not empty"),
        "{}",
        stderr(&refused)
    );
    let forced = loopback(&["--force"]);
    assert!(forced.status.success(), "{}", stderr(&forced));
    assert!(!dir.join("dut_attitude.csv").exists());
    // So evaluate has nothing of the old device to score against the new truth.
    let eval = run_in(&work, &["evaluate".as_ref(), dir.as_os_str()]);
    assert!(!eval.status.success());
    assert!(
        stderr(&eval).contains("dut_attitude.csv"),
        "{}",
        stderr(&eval)
    );
}

/// Asserts `evaluate` refuses `args` (a run directory) as incomplete, naming why.
fn assert_refused_as_incomplete(work: &Path, args: &[&OsStr], why: &str) {
    let out = run_in(work, args);
    assert!(!out.status.success());
    let text = stderr(&out);
    assert!(text.contains("incomplete") && text.contains(why), "{text}");
}

#[test]
fn kill_9_during_simulate_leaves_a_run_evaluate_refuses() {
    let work = scratch("kill-simulate");
    let (mut child, dir) = common::simulating(&work);
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(completion(&dir), None);
    assert!(
        !dir.join("truth.csv").exists(),
        "a partial file under the final name"
    );
    let estimates = work.join("estimates.csv");
    std::fs::write(&estimates, "t_s,qw,qx,qy,qz\n0,1,0,0,0\n").unwrap();
    let args: Vec<&OsStr> = vec![
        "evaluate".as_ref(),
        dir.as_os_str(),
        "--estimates".as_ref(),
        estimates.as_os_str(),
    ];
    assert_refused_as_incomplete(&work, &args, "no completion record");
}

#[test]
fn kill_9_during_loopback_leaves_a_session_evaluate_refuses() {
    let work = scratch("kill-loopback");
    let scene = long_scene(&work, 30.0);
    let dir = work.join("session");
    let args: Vec<&OsStr> = vec![
        "loopback".as_ref(),
        scene.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
    ];
    let mut child = spawn_margemu(&args, &work);
    wait_until(&mut child, "the session's start row", || {
        has_event(&dir, "start")
    });
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(completion(&dir), None);
    assert_refused_as_incomplete(
        &work,
        &["evaluate".as_ref(), dir.as_os_str()],
        "no completion record",
    );
}

#[test]
fn evaluate_scores_an_interrupted_run_only_when_allowed_and_says_so() {
    let work = scratch("interrupted-simulate");
    let dir = work.join("run");
    let figure3 = fixture("figure3");
    let out = run_in(
        &work,
        &[
            "simulate".as_ref(),
            figure3.as_os_str(),
            "-o".as_ref(),
            dir.as_os_str(),
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let estimates = work.join("estimates.csv");
    let out = run_in(
        &work,
        &[
            "filter".as_ref(),
            "--filter".as_ref(),
            "ecf".as_ref(),
            dir.as_os_str(),
            "-o".as_ref(),
            estimates.as_os_str(),
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // The record of a run stopped early, as margemu writes it for an interrupted run.
    let meta = std::fs::read_to_string(dir.join("meta.toml")).unwrap();
    let at = meta.find("\n[completion]").unwrap();
    std::fs::write(dir.join("meta.toml"), &meta[..at]).unwrap();
    let record = margemu::rundir::Completion {
        status: Status::Interrupted,
        samples_written: 3000,
        samples_expected: Some(3000),
        ended: "interrupted".into(),
    };
    margemu::rundir::write_completion(&dir, &record).unwrap();
    let mut args: Vec<&OsStr> = vec![
        "evaluate".as_ref(),
        dir.as_os_str(),
        "--estimates".as_ref(),
        estimates.as_os_str(),
        "--no-plots".as_ref(),
    ];
    assert_refused_as_incomplete(&work, &args, "interrupted, 3000 samples written of 3000");
    args.push("--allow-incomplete".as_ref());
    let out = run_in(&work, &args);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("INCOMPLETE RUN"), "{stdout}");
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(report.contains("INCOMPLETE RUN"));
}

#[test]
fn a_run_that_cannot_write_its_files_records_that_it_failed() {
    // A directory where `marg.csv.partial` must go stands in for a full disk: the file cannot
    // be created, and the record says why.
    let dir = scratch("write-fails");
    std::fs::create_dir_all(dir.join("marg.csv.partial")).unwrap();
    let scene = margemu::scene::Scene::load(&fixture("figure3")).unwrap();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let e = margemu::run::simulate_to_dir(&scene, &dir, &stop, |_, _| {}).unwrap_err();
    let record = completion(&dir).expect("a completion record");
    assert_eq!(record.status, Status::Failed);
    assert_eq!(record.samples_written, 0);
    assert_eq!(record.ended, e.to_string());
    assert!(
        record.ended.contains("marg.csv.partial"),
        "{}",
        record.ended
    );
    let truth = dir.join("truth.csv");
    assert_refused_as_incomplete(
        &dir,
        &[
            "evaluate".as_ref(),
            dir.as_os_str(),
            "--estimates".as_ref(),
            truth.as_os_str(),
        ],
        "failed, 0 samples written of 3000",
    );
}
