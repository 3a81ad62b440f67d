//! Benchmark: sustained sample rates through the `qemu-mps2-an386` firmware over UART0's PTY,
//! in both source modes. Not a test: it prints figures.
//!
//! ```sh
//! cargo bench -p margemu-tests --bench qemu_rates
//! cargo bench -p margemu-tests --bench qemu_rates -- --seconds 5 --images 500,1000 --model 1000,8000
//! ```
//!
//! First the raw receive path: 60 000 bytes of garbage then a Hello, written as fast as the PTY
//! takes them, timed to the HelloAck (3 runs): bytes per second into the firmware, and QEMU's
//! host CPU time per byte.
//!
//! Then, for every rate, it boots QEMU, streams a kinematic scene ([`motion_scene`]: sines on all six
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

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use margemu::stream::{predict_images, Session, StreamConfig};
use margemu_protocol::link::{
    image_batch_wire_len, Encoder, Hello, Message, Telemetry, CRC32C, MAX_WIRE_LEN,
};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_tests::drive::{self, Samples, Script};
use margemu_tests::model_source::ModelStream;
use margemu_tests::qemu::{self, LinkDecoder, Qemu};
use margemu_tests::served::ServedTap;
use margemu_tests::{motion_scene, served::Check};
use serialport::SerialPort;

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
    /// The device's last Telemetry.
    telemetry: Option<Telemetry>,
    /// QEMU's host CPU time over the run, as a fraction of one core.
    qemu_cpu: f64,
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
        let rx_errors = self.telemetry.map_or("-".into(), |t| {
            format!("{} / {}", t.crc_errors, t.framing_errors)
        });
        println!(
            "| {} | {} | {:.1} | {} of {} | {} | {} | {} | {} | {:.0} % | {:.1} | {}{} |",
            self.mode,
            self.rate,
            self.link_bytes_per_s / 1e3,
            self.check.exact,
            self.check.expected,
            self.underruns,
            rx_errors,
            self.stalls,
            jitter,
            self.qemu_cpu * 100.0,
            self.wall.as_secs_f64(),
            if sustained { "yes" } else { "no" },
            match &self.error {
                Some(e) => format!(": {e}"),
                None if !sustained => format!(": {}", self.check.summary()),
                None => String::new(),
            },
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
    let predicted: Vec<u32> = predict_images(&scene, session.image_settings())
        .map(|s| CRC32C.checksum(&s.expect("the scene's prediction").image))
        .collect();
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).expect("boot QEMU");
    let mut port = uart0.into_port();
    let tap = ServedTap::new(port.try_clone_native().expect("clone the PTY"));
    let log = tap.log();
    // As in tests/tests/qemu_stream.rs: the PTY may stay full longer than 50 ms under QEMU.
    port.set_timeout(Duration::from_secs(2))
        .expect("write timeout");
    let cpu0 = qemu.cpu_time().unwrap_or_default();
    let result = session.run(tap, port, |_| {});
    let wall = t.elapsed();
    let qemu_cpu = cpu_share(&qemu, cpu0, t);
    drop(qemu);
    let _ = std::fs::remove_dir_all(&dir);
    let check = log.lock().expect("log").0.check(&predicted);
    let link = rate as f64 * image_batch_wire_len(batch, 22) as f64 / batch as f64;
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
            telemetry: s.telemetry,
            qemu_cpu,
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
            telemetry: None,
            qemu_cpu,
        },
    }
}

fn model(elf: &Path, rate: u32, o: &Options) -> Row {
    let scene = motion_scene(rate, o.seconds, 7);
    let stream = ModelStream::from_scene(&scene, rate / o.truth_hz).expect("model stream");
    let predicted = stream.predicted_crcs();
    let script = Script {
        configure: stream.configure(50_000_000),
        vibration: stream.vibration.clone(),
        faults: stream.faults.clone(),
        samples: Samples::Kinematics(&stream.kinematics),
        sample_rate: stream.params.truth_rate,
        outputs: predicted.len() as u64,
        lead: o.lead,
        batch: 10,
        timeout: Duration::from_secs(5),
    };
    let t = Instant::now();
    let (qemu, uart0) = Qemu::boot(elf).expect("boot QEMU");
    let cpu0 = qemu.cpu_time().unwrap_or_default();
    let result = drive::run(uart0.into_port(), &script);
    let wall = t.elapsed();
    let qemu_cpu = cpu_share(&qemu, cpu0, t);
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
                telemetry: r.telemetry,
                qemu_cpu,
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
            telemetry: None,
            qemu_cpu,
        },
    }
}

/// Garbage bytes in front of the Hello of the receive-path measurement.
const GARBAGE: usize = 60_000;

/// Writes [`GARBAGE`] bytes and a Hello to a freshly booted board and times the HelloAck:
/// (bytes per second, QEMU CPU µs per byte).
fn rx_throughput(elf: &Path) -> Result<(f64, f64), String> {
    let (qemu, mut uart0) = Qemu::boot(elf).map_err(|e| format!("boot: {e}"))?;
    let mut decoder = LinkDecoder::default();
    let mut acks = 0;
    let mut wait_for = |uart0: &mut qemu::SerialLink, frames: usize| -> Result<(), String> {
        let deadline = Instant::now() + Duration::from_secs(30);
        while acks < frames {
            let left = deadline.saturating_duration_since(Instant::now());
            let bytes = uart0.read_exact(1, left).map_err(|e| e.to_string())?;
            decoder.feed(&bytes, &mut |m: &Message<'_>| {
                if matches!(m, Message::Reset(_) | Message::HelloAck(_)) {
                    acks += 1;
                }
            });
        }
        Ok(())
    };
    wait_for(&mut uart0, 1)?; // the power-on Reset
    let mut data = vec![0x01u8; GARBAGE];
    let mut wire = [0u8; MAX_WIRE_LEN];
    let hello = Hello {
        protocol_version: PROTOCOL_VERSION,
        session: 1,
    };
    let n = Encoder::new()
        .encode(&Message::Hello(hello), &mut wire)
        .map_err(|e| format!("{e:?}"))?;
    data.extend_from_slice(&wire[..n]);
    let port = uart0.port_mut();
    port.set_timeout(Duration::from_secs(10))
        .map_err(|e| e.to_string())?;
    let cpu0 = qemu.cpu_time().map_err(|e| e.to_string())?;
    let t = Instant::now();
    port.write_all(&data).map_err(|e| e.to_string())?;
    port.set_timeout(Duration::from_millis(50))
        .map_err(|e| e.to_string())?;
    wait_for(&mut uart0, 2)?;
    let elapsed = t.elapsed().as_secs_f64();
    let cpu = (qemu.cpu_time().map_err(|e| e.to_string())? - cpu0).as_secs_f64();
    Ok((data.len() as f64 / elapsed, cpu / data.len() as f64 * 1e6))
}

/// QEMU's CPU time since `cpu0` (read at `since`), per second of wall time.
fn cpu_share(qemu: &Qemu, cpu0: Duration, since: Instant) -> f64 {
    let cpu = qemu.cpu_time().unwrap_or_default().saturating_sub(cpu0);
    cpu.as_secs_f64() / since.elapsed().as_secs_f64()
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
    println!("\nUART0 receive path: {GARBAGE} bytes + Hello → HelloAck");
    for run in 1..=3 {
        match rx_throughput(&elf) {
            Ok((rate, cpu)) => println!(
                "  run {run}: {:.1} KB/s, QEMU host CPU {cpu:.1} µs per byte",
                rate / 1e3
            ),
            Err(e) => println!("  run {run}: failed: {e}"),
        }
    }
    println!(
        "\n| mode | rate (Hz) | link to device (KB/s) | byte-exact | underruns | device CRC / framing errors | credit stalls | \
         pacing late p50 / p99 / max (µs) | QEMU CPU | wall (s) | sustained |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for &rate in &o.images {
        images(&elf, rate, &o).print();
    }
    for &rate in &o.model {
        model(&elf, rate, &o).print();
    }
    println!("\nload after: {}", loadavg());
}
