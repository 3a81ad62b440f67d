//! Peak memory and wall time of `margemu evaluate` and `margemu filter` on long files (10 M rows
//! by default): `cargo bench -p margemu --bench large_files`. Not run by CI (several GB of disk,
//! minutes of time).
//!
//! It writes, unless they are already there for the same row count, a run directory with a
//! `truth.csv` at 1 kHz and an estimates file `t_s,qw,qx,qy,qz` (the truth rolled by 0.01 rad,
//! 3 ms late), and an external recording `t_s,ax,…,mz,qw,qx,qy,qz` of the same motion (its
//! reference attitude last); then runs `margemu evaluate RUN --estimates FILE` (figures
//! included), `margemu filter --filter ekf RECORDING -o FILE` and `margemu evaluate --external
//! RECORDING --estimates FILE` (the filter's output, figures included) one after the other, and
//! prints each one's wall time and peak resident memory (GNU time's `%M`, the child's
//! `ru_maxrss`; `apt-get install time` if it is missing).
//!
//! Environment: `MARGEMU_LARGE_ROWS` (rows, default 10 000 000), `MARGEMU_LARGE_DIR` (where the
//! files go, default the target's temporary directory), `MARGEMU_BIN` (the binary measured,
//! default this build's; point it at another build to compare).

#![allow(missing_docs)]

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The motion: smooth roll, pitch and yaw (rad) at `t` (s).
fn euler(t: f64) -> [f64; 3] {
    use std::f64::consts::TAU;
    [
        0.6 * (TAU * 0.07 * t).sin(),
        0.4 * (TAU * 0.045 * t + 1.0).sin(),
        2.5 * (TAU * 0.023 * t).sin(),
    ]
}

fn quat(e: [f64; 3]) -> [f64; 4] {
    let q = nalgebra::UnitQuaternion::from_euler_angles(e[0], e[1], e[2]);
    [q.w, q.i, q.j, q.k]
}

fn write_row(out: &mut impl Write, first: &str, values: &[f64]) -> std::io::Result<()> {
    out.write_all(first.as_bytes())?;
    for v in values {
        write!(out, ",{v:.9}")?;
    }
    out.write_all(b"\n")
}

fn generate(dir: &Path, rows: u64) -> std::io::Result<()> {
    let marker = dir.join("rows.txt");
    let stamp = format!("{rows} rows, recording with its reference");
    if std::fs::read_to_string(&marker).ok().as_deref() == Some(&stamp) {
        println!("reusing the files in {}", dir.display());
        return Ok(());
    }
    let started = Instant::now();
    std::fs::create_dir_all(dir.join("run"))?;
    let open =
        |name: &str| File::create(dir.join(name)).map(|f| BufWriter::with_capacity(1 << 20, f));
    let mut truth = open("run/truth.csv")?;
    let mut est = open("estimates.csv")?;
    let mut rec = open("recording.csv")?;
    writeln!(
        truth,
        "t_ns,qw,qx,qy,qz,wx,wy,wz,fx,fy,fz,ax_b,ay_b,az_b,mx,my,mz"
    )?;
    writeln!(est, "t_s,qw,qx,qy,qz")?;
    writeln!(rec, "t_s,ax,ay,az,gx,gy,gz,mx,my,mz,qw,qx,qy,qz")?;
    for k in 0..rows {
        let t_ns = k * 1_000_000;
        let t = k as f64 * 1e-3;
        let e = euler(t);
        let q = quat(e);
        let u = nalgebra::UnitQuaternion::from_euler_angles(e[0], e[1], e[2]);
        let f = u.inverse_transform_vector(&nalgebra::Vector3::new(0.0, 0.0, 9.80665));
        let m = u.inverse_transform_vector(&nalgebra::Vector3::new(0.5, 0.0, -0.83));
        let w = [0.03, -0.02, 0.05];
        let mut body = [0.0; 16];
        body[..4].copy_from_slice(&q);
        body[4..7].copy_from_slice(&w);
        body[7..10].copy_from_slice(&[f.x, f.y, f.z]);
        body[13..16].copy_from_slice(&[m.x, m.y, m.z]);
        write_row(&mut truth, &t_ns.to_string(), &body)?;
        let late = euler(t - 0.003);
        let stamp = format!("{}.{:09}", t_ns / 1_000_000_000, t_ns % 1_000_000_000);
        write_row(&mut est, &stamp, &quat([late[0] + 0.01, late[1], late[2]]))?;
        let imu = [
            f.x, f.y, f.z, w[0], w[1], w[2], m.x, m.y, m.z, q[0], q[1], q[2], q[3],
        ];
        write_row(&mut rec, &stamp, &imu)?;
    }
    for mut w in [truth, est, rec] {
        w.flush()?;
    }
    std::fs::write(&marker, stamp)?;
    println!(
        "wrote {rows} rows each into {} in {:.1} s",
        dir.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// GNU time, which reports a child's peak resident memory.
const TIME: &str = "/usr/bin/time";

/// Wall time (s) and peak resident memory (MiB) of one command, which must succeed.
fn measure(bin: &Path, args: &[&str]) -> (f64, f64) {
    let output = Command::new(TIME)
        .args(["-f", "%e %M"])
        .arg(bin)
        .args(args)
        .stdout(std::process::Stdio::null())
        .output()
        .expect("GNU time runs (apt-get install time)");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "{} {args:?} failed: {stderr}",
        bin.display()
    );
    let last = stderr.lines().last().unwrap_or_default();
    let mut fields = last.split(' ').map(|f| f.parse::<f64>());
    match (fields.next(), fields.next()) {
        (Some(Ok(wall)), Some(Ok(kib))) => (wall, kib / 1024.0),
        _ => panic!("GNU time printed {last:?}"),
    }
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return; // `cargo bench -- --list` and test discovery: nothing to list
    }
    let rows: u64 = std::env::var("MARGEMU_LARGE_ROWS")
        .ok()
        .map(|r| r.parse().expect("MARGEMU_LARGE_ROWS is a row count"))
        .unwrap_or(10_000_000);
    let dir = std::env::var_os("MARGEMU_LARGE_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("large-files"));
    let bin = std::env::var_os("MARGEMU_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_margemu")));
    generate(&dir, rows).expect("the input files are written");
    let p = |name: &str| dir.join(name).display().to_string();
    let (run, est, rec) = (p("run"), p("estimates.csv"), p("recording.csv"));
    let (out, filtered) = (p("evaluation"), p("filtered.csv"));
    let external_out = p("external-evaluation");
    println!("binary: {}", bin.display());
    println!(
        "{:<54} {:>10} {:>14}",
        "command", "wall (s)", "peak RSS (MiB)"
    );
    let cases: [(&str, Vec<&str>); 3] = [
        (
            "evaluate RUN --estimates estimates.csv --out DIR",
            vec!["evaluate", &run, "--estimates", &est, "--out", &out],
        ),
        (
            "filter --filter ekf recording.csv -o filtered.csv",
            vec!["filter", "--filter", "ekf", &rec, "-o", &filtered],
        ),
        (
            "evaluate --external recording.csv --estimates filtered.csv",
            vec![
                "evaluate",
                "--external",
                &rec,
                "--estimates",
                &filtered,
                "--out",
                &external_out,
            ],
        ),
    ];
    for (name, args) in cases {
        let (wall, peak) = measure(&bin, &args);
        println!("{name:<54} {wall:>10.1} {peak:>14.1}");
    }
    println!("({rows} rows; delete {} when done)", dir.display());
}
