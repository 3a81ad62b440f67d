//! Bad input to `margemu filter` and `margemu::offline::read`: each error names the file, the
//! line (and column where there is one) and the cause, and no estimates file is written.

mod filter_common;

use filter_common::{failed, margemu, ok, scratch, simulated, STATIC_SCENE};
use margemu::offline;
use std::path::Path;

const HEADER: &str = "t_s,ax,ay,az,gx,gy,gz,mx,my,mz\n";
const ROW: &str = "0,0,0,9.8,0,0,0,0.5,0,-0.83\n";

fn read_error(path: &Path) -> String {
    offline::read(path, None).unwrap_err().to_string()
}

#[test]
fn external_recordings_with_bad_rows_are_refused_at_their_line() {
    let dir = scratch("filter-errors-csv");
    let file = dir.join("rec.csv");
    let cases = [
        (
            format!("{HEADER}{ROW}0.01,0,0,9.8,0,x,0,0.5,0,-0.83\n"),
            "rec.csv:3: `gy`: invalid float literal",
        ),
        (
            format!("{HEADER}{ROW}0.01,0,0,inf,0,0,0,0.5,0,-0.83\n"),
            "rec.csv:3: `az` = inf is not finite",
        ),
        (
            format!(
                "{HEADER}{ROW}0.01,0,0,9.8,0,0,0,0.5,0,-0.83\n0.01,0,0,9.8,0,0,0,0.5,0,-0.83\n"
            ),
            "rec.csv:4: `t_s` = 0.01 does not increase (previous row: 0.01)",
        ),
        (
            format!("{HEADER}-1,0,0,9.8,0,0,0,0.5,0,-0.83\n"),
            "rec.csv:2: `t_s` = -1 is outside 0 to 1.8e10 s",
        ),
        (
            format!("{HEADER}{ROW}0.01,0,0,9.8\n"),
            "rec.csv: cannot read",
        ),
        (
            "t_s,ax,ay,az,gx,gy,gz,mx,my\n".to_string(),
            "rec.csv: no column `mz` in the header (columns: t_s, ax, ay, az, gx, gy, gz, mx, my)",
        ),
        (HEADER.to_string(), "rec.csv: no samples"),
    ];
    for (text, expected) in cases {
        std::fs::write(&file, &text).unwrap();
        let e = read_error(&file);
        assert!(e.contains(expected), "{e}\nexpected: {expected}");
    }
    assert!(read_error(&dir.join("absent.csv")).ends_with("absent.csv: no such file or directory"));
}

#[test]
fn run_directories_with_bad_files_are_refused_with_their_location() {
    let dir = scratch("filter-errors-run");
    let (_, run) = simulated(&dir, "static.toml", STATIC_SCENE);
    let marg = run.join("marg.csv");
    let text = std::fs::read_to_string(&marg).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    lines[3] = lines[3].replacen(",", ",oops", 1);
    std::fs::write(&marg, lines.join("\n")).unwrap();
    let e = read_error(&run);
    assert!(e.contains("marg.csv:4: `acc_x` = \"oops"), "{e}");
    std::fs::remove_file(&marg).unwrap();
    let e = read_error(&run);
    assert!(
        e.ends_with("no marg.csv here (expected a `simulate` run directory)"),
        "{e}"
    );
    std::fs::write(run.join("sent.csv"), "index,t_ns,send_ns,late_ns,image\n").unwrap();
    let e = read_error(&run);
    assert!(
        e.contains("a session directory: filtering sessions is not supported yet"),
        "{e}"
    );
}

#[test]
fn the_command_line_refuses_bad_parameters_and_writes_nothing() {
    let dir = scratch("filter-errors-cli");
    let input = dir.join("rec.csv");
    std::fs::write(
        &input,
        format!("{HEADER}{ROW}0.01,0,0,9.8,0,0,0,0.5,0,-0.83\n"),
    )
    .unwrap();
    let out = dir.join("est.csv");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "filter",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        margemu(&args)
    };
    let params = dir.join("p.toml");
    std::fs::write(&params, "[ecf]\nkp = -0.5\n").unwrap();
    let p = params.to_str().unwrap();
    let cases: [(&[&str], &str); 10] = [
        (
            &["--filter", "ecf", "--params", p],
            "p.toml:2:6: -0.5 is not a finite number ≥ 0",
        ),
        (
            &["--filter", "ecf", "--param", "kp=-1"],
            "--param kp=-1: `kp` = -1: must be finite and ≥ 0",
        ),
        (
            &["--filter", "gda", "--param", "kp=1"],
            "gda has no parameter `kp` (it has: beta, normalization)",
        ),
        (
            &["--filter", "gda", "--param", "gda.beta=x"],
            "--param gda.beta=x: `gda.beta=x`: expected NAME=VALUE",
        ),
        (
            &["--filter", "gda", "--param", "gda.normalization=fast"],
            "--param gda.normalization=fast: `normalization`: `fast` is not gradient, residual or xio",
        ),
        (
            &["--filter", "ekf", "--param", "initial_bias_std=-1"],
            "--param initial_bias_std=-1: `initial_bias_std`: `-1` is not a finite number > 0",
        ),
        (
            &["--filter", "ekf", "--param", "mag_noise"],
            "`mag_noise`: expected NAME=VALUE",
        ),
        (
            &["--filter", "ekf", "--param", "mag_noise=0"],
            "parameter `mag_noise` must be > 0",
        ),
        (
            &["--filter", "ecf", "--mag-reference", "0,0,-1"],
            "the magnetic reference field is vertical",
        ),
        (
            &["--filter", "ecf", "--attitude-start", "truth"],
            "starting from the truth needs the reference columns qw,qx,qy,qz",
        ),
    ];
    for (extra, expected) in cases {
        let e = failed(&run(extra));
        assert!(e.contains(expected), "{extra:?}: {e}");
        assert!(!out.exists(), "{extra:?} wrote {}", out.display());
    }
    ok(&run(&["--filter", "ecf"]));
    assert!(out.exists());
}

#[test]
fn a_bad_row_after_estimates_were_written_leaves_no_estimates_file() {
    let dir = scratch("filter-errors-late");
    let input = dir.join("rec.csv");
    let good: String = (0..50)
        .map(|k| format!("{},0,0,9.8,0,0,0,0.5,0,-0.83\n", f64::from(k) * 0.01))
        .collect();
    std::fs::write(
        &input,
        format!("{HEADER}{good}0.5,0,0,9.8,0,0,0,0.5,0,nan\n"),
    )
    .unwrap();
    let out = dir.join("est.csv");
    let args = ["filter", "--filter", "ekf", input.to_str().unwrap(), "-o"];
    let e = failed(&margemu(&[&args[..], &[out.to_str().unwrap()]].concat()));
    assert!(e.contains("rec.csv:52: `mz` = NaN is not finite"), "{e}");
    assert!(!out.exists(), "a partial estimates file was left");
}

#[test]
fn all_zero_accelerometer_or_magnetometer_data_is_warned_about() {
    let dir = scratch("filter-warnings");
    let run = |name: &str, acc: &str, mag: &str| {
        let input = dir.join(format!("{name}.csv"));
        let rows: String = (0..20)
            .map(|k| format!("{},{acc},0.01,0,0,{mag}\n", f64::from(k) * 0.01))
            .collect();
        std::fs::write(&input, format!("{HEADER}{rows}")).unwrap();
        let out = dir.join(format!("{name}-est.csv"));
        let args = ["filter", "--filter", "ecf", input.to_str().unwrap(), "-o"];
        let output = margemu(&[&args[..], &[out.to_str().unwrap()]].concat());
        ok(&output);
        assert!(out.exists());
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    let acc_warning = "every accelerometer sample is zero";
    let mag_warning = "every magnetometer sample is zero";
    let both = run("both", "0,0,0", "0,0,0");
    assert!(
        both.contains(acc_warning) && both.contains(mag_warning),
        "{both}"
    );
    assert!(
        both.contains("warning: ") && both.contains("both.csv"),
        "{both}"
    );
    let mag = run("mag", "0,0,9.8", "0,0,0");
    assert!(
        !mag.contains(acc_warning) && mag.contains(mag_warning),
        "{mag}"
    );
    let acc = run("acc", "0,0,0", "0.5,0,-0.83");
    assert!(
        acc.contains(acc_warning) && !acc.contains(mag_warning),
        "{acc}"
    );
    // One zero sample among good ones is no warning.
    let fine = run("fine", "0,0,9.8", "0.5,0,-0.83");
    assert!(!fine.contains("warning"), "{fine}");
}
