//! Benchmark: sustained sample rates through the `qemu-mps2-an386` firmware over UART0's PTY,
//! in both source modes. Not a test: it prints figures.
//!
//! ```sh
//! cargo bench -p margemu-tests --bench qemu_rates
//! cargo bench -p margemu-tests --bench qemu_rates -- --seconds 5 --images 500,1000 --model 1000,8000
//! ```
//!
//! For every rate it boots QEMU, streams a kinematic scene ([`motion_scene`]: sines on all six
//! joints, the paper's noise densities and biases) for `--seconds` (default 5) and reports:
//! samples served byte-exact (from the device's Served reports against the host's prediction),
//! underruns, credit stalls, pacing lateness p50/p99/max of the host's batch writes, and the
//! link bytes per second the rate needs towards the device.
//!
//! - `--images R,…` (default 250,500,750,1000,1250): source (a) at output rate R, streamed by
//!   `margemu::stream::Session` (32 images per batch, `--lead-ms`, default 300).
//! - `--model R,…` (default 1000,2000,4000,8000): source (b), the model on the device at output
//!   rate R, kinematics at `--truth` Hz (default 200), streamed by [`margemu_tests::drive`]
//!   (10 per batch, `--lead-ms`).
//!
//! A rate is sustained when every sample is served byte-exact with no underrun.

use std::path::Path;
use std::time::{Duration, Instant};

use margemu::stream::{Session, StreamConfig};
use margemu_protocol::link::{image_batch_wire_len, CRC32C};
use margemu_tests::drive::{self, Samples, Script};
use margemu_tests::model_source::ModelStream;
use margemu_tests::qemu::{self, Qemu};
use margemu_tests::served::ServedTap;
use margemu_tests::{motion_scene, served::Check};

struct Options {
    seconds: f64,
    images: Vec<u32>,
    model: Vec<u32>,
    truth_hz: u32,
    lead: Duration,
}

fn options() -> Options {
    let mut o = Options {
        seconds: 5.0,
        images: vec![250, 500, 750, 1000, 1250],
        model: vec![1000, 2000, 4000, 8000],
        truth_hz: 200,
        lead: Duration::from_millis(300),
    };
    let list = |v: &str| -> Vec<u32> {
        v.split(',')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().expect("a rate in Hz"))
            .collect()
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().unwrap_or_else(|| panic!("{arg} needs a value"));
        match arg.as_str() {
            "--seconds" => o.seconds = value().parse().expect("seconds"),
            "--images" => o.images = list(&value()),
            "--model" => o.model = list(&value()),
            "--truth" => o.truth_hz = value().parse().expect("Hz"),
            "--lead-ms" => o.lead = Duration::from_millis(value().parse().expect("ms")),
            _ => {} // `cargo bench` passes `--bench`
        }
    }
    o
}

/// One line of the table.
struct Row {
    mode: &'static str,
    rate: u32,
    link_bytes_per_s: f64,
    check: Check,
    underruns: u64,
    stalls: u64,
    jitter: Option<(i64, i64, i64)>,
    wall: Duration,
    error: Option<String>,
}

impl Row {
    fn print(&self) {
        let jitter = self.jitter.map_or("-".into(), |(p50, p99, max)| {
            format!(
                "{:.0} / {:.0} / {:.0}",
                p50 as f64 / 1e3,
                p99 as f64 / 1e3,
                max as f64 / 1e3
            )
        });
        let sustained = self.error.is_none() && self.check.all_exact() && self.underruns == 0;
        println!(
            "| {} | {} | {:.1} | {} of {} | {} | {} | {} | {:.1} | {}{} |",
            self.mode,
            self.rate,
            self.link_bytes_per_s / 1e3,
            self.check.exact,
            self.check.expected,
            self.underruns,
            self.stalls,
            jitter,
            self.wall.as_secs_f64(),
            if sustained { "yes" } else { "no" },
            self.error
                .as_ref()
                .map_or(String::new(), |e| format!(": {e}")),
        );
    }
}

fn images(elf: &Path, rate: u32, o: &Options) -> Row {
    let scene = motion_scene(rate, o.seconds, 7);
    let dir = std::env::temp_dir().join(format!("margemu-bench-{}-{rate}", std::process::id()));
    let config = StreamConfig {
        port: "qemu mps2-an386 UART0 (pty)".into(),
        lead: o.lead,
        ..StreamConfig::default()
    };
    let batch = config.batch;
    let session = Session::new(&scene, config, &dir).expect("session");
    let predicted: Vec<u32> = session
        .samples()
        .iter()
        .map(|s| CRC32C.checksum(&s.image))
        .collect();
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).expect("boot QEMU");
    let port = uart0.into_port();
    let tap = ServedTap::new(port.try_clone_native().expect("clone the PTY"));
    let log = tap.log();
    let result = session.run(tap, port, |_| {});
    let wall = t.elapsed();
    drop(qemu);
    let _ = std::fs::remove_dir_all(&dir);
    let check = log.lock().expect("log").0.check(&predicted);
    let link = rate as f64 * image_batch_wire_len(batch) as f64 / batch as f64;
    match result {
        Ok(s) => Row {
            mode: "images (a)",
            rate,
            link_bytes_per_s: link,
            underruns: s.telemetry.map_or(0, |t| u64::from(t.underruns)),
            stalls: s.credit_stalls,
            jitter: Some((s.jitter.p50_ns, s.jitter.p99_ns, s.jitter.max_ns)),
            check,
            wall,
            error: None,
        },
        Err(e) => Row {
            mode: "images (a)",
            rate,
            link_bytes_per_s: link,
            underruns: 0,
            stalls: 0,
            jitter: None,
            check,
            wall,
            error: Some(e.to_string()),
        },
    }
}

fn model(elf: &Path, rate: u32, o: &Options) -> Row {
    let scene = motion_scene(rate, o.seconds, 7);
    let stream = ModelStream::from_scene(&scene, rate / o.truth_hz).expect("model stream");
    let predicted = stream.predicted_crcs();
    let script = Script {
        configure: stream.configure(50_000_000),
        samples: Samples::Kinematics(&stream.kinematics),
        sample_rate: stream.params.truth_rate,
        outputs: predicted.len() as u64,
        lead: o.lead,
        batch: 10,
        timeout: Duration::from_secs(5),
    };
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).expect("boot QEMU");
    let result = drive::run(uart0.into_port(), &script);
    let wall = t.elapsed();
    drop(qemu);
    match result {
        Ok(r) => {
            let check = r.served.check(&predicted);
            Row {
                mode: "model (b)",
                rate,
                link_bytes_per_s: r.bytes_sent as f64 / o.seconds,
                underruns: check.underruns.len() as u64,
                stalls: r.credit_stalls,
                jitter: Some({
                    let j = r.jitter();
                    (j.p50_ns, j.p99_ns, j.max_ns)
                }),
                check,
                wall,
                error: (!r.errors.is_empty()).then(|| format!("device errors {:?}", r.errors)),
            }
        }
        Err(e) => Row {
            mode: "model (b)",
            rate,
            link_bytes_per_s: 0.0,
            underruns: 0,
            stalls: 0,
            jitter: None,
            check: Check::default(),
            wall,
            error: Some(e.to_string()),
        },
    }
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .trim()
        .to_owned()
}

fn main() {
    if !qemu::prerequisites_or_skip("qemu_rates") {
        return;
    }
    let o = options();
    let elf = qemu::board_elf().unwrap_or_else(|e| panic!("board ELF: {e}"));
    println!(
        "qemu_rates: {} s per run, lead {} ms, kinematics at {} Hz in source (b); load before: {}",
        o.seconds,
        o.lead.as_millis(),
        o.truth_hz,
        loadavg()
    );
    println!(
        "\n| mode | rate (Hz) | link to device (KB/s) | byte-exact | underruns | credit stalls | \
         pacing late p50 / p99 / max (µs) | wall (s) | sustained |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for &rate in &o.images {
        images(&elf, rate, &o).print();
    }
    for &rate in &o.model {
        model(&elf, rate, &o).print();
    }
    println!("\nload after: {}", loadavg());
}
