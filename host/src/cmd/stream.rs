//! `margemu stream SCENE --port PATH [--baud N] [-o DIR] [--dut PORT --dut-protocol P]`: stream a
//! scene to a device in real time and write the session directory; with `--dut`, log the device
//! under test's own output beside it.

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use margemu::dut::{open_dut_port, DutConfig, DutProtocol, DutSummary};
use margemu::scene::Scene;
use margemu::stream::budget::{BoardKind, BudgetPolicy};
use margemu::stream::{open_port, Progress, Session, SourceMode, StreamConfig};
use margemu::vfc::{attach, AttachedDut};
use std::path::{Path, PathBuf};
use std::time::Duration;

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
    scene: PathBuf,
    /// The device's serial port (e.g. /dev/ttyACM0, or a PTY path).
    #[arg(long)]
    port: String,
    /// Line rate (ignored by USB CDC and pseudo-terminals).
    #[arg(long, default_value_t = 921_600)]
    baud: u32,
    // Default: sessions/<scene name>.
    #[command(flatten)]
    output: super::OutputArgs,
    /// Write each batch this many milliseconds before its first sample's instant (at most 3/8
    /// of the device's buffer).
    #[arg(long, default_value_t = 200.0)]
    lead_ms: f64,
    /// Most register images per batch.
    #[arg(long, default_value_t = 32)]
    batch: usize,
    /// µT per unit of the scene's field (default: 1 for µT scenes, 50 for normalized ones).
    #[arg(long)]
    mag_ut_per_unit: Option<f64>,
    #[command(flatten)]
    chip: ChipArgs,
    #[command(flatten)]
    source: SourceArgs,
    #[command(flatten)]
    dut: DutArgs,
    #[command(flatten)]
    size: super::SizeArgs,
    /// Also write `session.mcap` (ROS 2 messages for Foxglove and `ros2 bag`; docs/mcap.md).
    #[arg(long)]
    mcap: bool,
    #[command(flatten)]
    realtime: RealtimeArgs,
}

/// Real-time pacing of the thread that writes to the device (`margemu::realtime`).
#[derive(clap::Args)]
pub struct RealtimeArgs {
    /// `off`, `auto` (SCHED_FIFO priority 10 and memory locked where permitted; otherwise one
    /// warning and normal priority) or a SCHED_FIFO priority from 1 to 99.
    #[arg(long, value_name = "off|auto|PRIO", default_value = "auto")]
    pub realtime: margemu::realtime::Realtime,
}

/// Which chip the device emulates.
#[derive(clap::Args)]
pub struct ChipArgs {
    /// Emulate this chip model instead of the scene's `[chip]` (power-on settings, on SPI);
    /// `margemu chips` lists them.
    #[arg(long, value_name = "MODEL")]
    chip: Option<String>,
}

impl ChipArgs {
    /// `scene` with `--chip` applied.
    pub fn apply(&self, scene: Scene) -> Result<Scene> {
        match &self.chip {
            None => Ok(scene),
            Some(name) => {
                margemu::scene::chip::with_model(&scene, name).map_err(anyhow::Error::msg)
            }
        }
    }
}

/// The device under test's own output port.
#[derive(clap::Args)]
pub struct DutArgs {
    /// The device under test's telemetry port (its attitude as MAVLink or MSP), read during the
    /// session into dut_*.csv on the session's clock.
    #[arg(long, value_name = "PORT")]
    dut: Option<String>,
    /// What the device under test speaks on --dut: mavlink or msp.
    #[arg(long, value_name = "mavlink|msp", default_value_t = DutProtocol::Mavlink, requires = "dut")]
    dut_protocol: DutProtocol,
    /// Line rate of --dut (ignored by USB CDC and pseudo-terminals).
    #[arg(long, default_value_t = 115_200, requires = "dut")]
    dut_baud: u32,
}

impl DutArgs {
    /// Opens --dut and starts its reader on `session`'s clock, in `dir`; `None` without --dut.
    pub fn attach(&self, session: &mut Session, dir: &Path) -> Result<Option<AttachedDut>> {
        let Some(path) = &self.dut else {
            return Ok(None);
        };
        let port = open_dut_port(path, self.dut_baud)?;
        let config = DutConfig::new(self.dut_protocol);
        Ok(Some(attach(session, port, config, dir)?))
    }
}

/// Stops the device-under-test reader, records its summary in the session and prints it.
pub fn finish_dut(dut: AttachedDut) -> Result<DutSummary> {
    let summary = dut.finish().context("the device-under-test reader")?;
    println!("device under test: {summary}");
    Ok(summary)
}

/// Where the device's samples come from.
#[derive(clap::Args)]
pub struct SourceArgs {
    /// `images`: the host sends every register image; `model`: the host sends true kinematics
    /// and the device runs the shared sensor model (scenes without a perturbation).
    #[arg(long, value_enum, default_value_t = Source::Images)]
    source: Source,
    /// Kinematics rate for `--source model`, Hz: the output rate divided by a whole number
    /// (default: the output rate / max(2, ceil(rate / 1000 Hz))).
    #[arg(long, value_name = "HZ")]
    kinematics_rate: Option<f64>,
    /// The device, for source mode (b)'s budget: `auto` (from the device ID it reports: the
    /// QEMU board and host-run devices are not budgeted, any other is taken for the Black Pill),
    /// `blackpill-f411`, `qemu` or `loopback`.
    #[arg(long, value_enum, default_value_t = Board::Auto)]
    board: Board,
    /// Stream a source mode (b) scene even beyond a real board's budget (the device may fall
    /// behind and underrun).
    #[arg(long)]
    over_budget: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Board {
    Auto,
    #[value(name = "blackpill-f411")]
    BlackpillF411,
    Qemu,
    Loopback,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum Source {
    Images,
    Model,
}

impl SourceArgs {
    /// The library's source mode; a kinematics rate without `--source model` is an error.
    pub fn mode(&self) -> Result<SourceMode> {
        match self.source {
            Source::Images => {
                anyhow::ensure!(
                    self.kinematics_rate.is_none(),
                    "--kinematics-rate needs --source model"
                );
                Ok(SourceMode::Images)
            }
            Source::Model => Ok(SourceMode::Model {
                kinematics_hz: self.kinematics_rate,
            }),
        }
    }

    /// Source mode (b)'s budget policy: `--board` and `--over-budget`.
    pub fn budget(&self) -> BudgetPolicy {
        BudgetPolicy {
            board: match self.board {
                Board::Auto => BoardKind::Auto,
                Board::BlackpillF411 => BoardKind::BlackpillF411,
                Board::Qemu => BoardKind::Qemu,
                Board::Loopback => BoardKind::Loopback,
            },
            over_budget: self.over_budget,
        }
    }
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let interrupt = super::Interrupt::install()?;
        let scene = self.chip.apply(super::load_scene(&self.scene)?)?;
        self.size.check(&scene)?;
        let mut images = margemu::stream::ImageSettings::for_scene(&scene);
        if let Some(v) = self.mag_ut_per_unit {
            anyhow::ensure!(v.is_finite() && v > 0.0, "--mag-ut-per-unit must be > 0");
            images.mag_ut_per_unit = v;
        }
        anyhow::ensure!(
            self.lead_ms.is_finite() && self.lead_ms >= 0.0,
            "--lead-ms must be ≥ 0"
        );
        let batch = self.batch.max(1);
        let config = StreamConfig {
            port: self.port.clone(),
            baud: self.baud,
            images: Some(images),
            source: self.source.mode()?,
            budget: self.source.budget(),
            lead: Duration::from_secs_f64(self.lead_ms / 1000.0),
            batch,
            resend_after: resend_after(batch, self.baud),
            mcap: self.mcap,
            realtime: self.realtime.realtime,
            ..StreamConfig::default()
        };
        let port =
            open_port(&self.port, self.baud).with_context(|| format!("opening {}", self.port))?;
        let dir = self.output.prepare(&scene, "sessions", "")?;
        let mut session = prepare(&scene, config, &dir)?;
        interrupt.watch(session.stop_flag());
        let dut = self.dut.attach(&mut session, &dir)?;
        let streamed = stream_to(&scene, session, &dir, port, &self.port);
        let dut = dut.map(finish_dut).transpose();
        streamed?;
        dut?;
        Ok(())
    }
}

/// A batch counts as lost 20 ms plus two line times of the largest batch after its write (the
/// batch before it may still be on the line).
fn resend_after(batch: usize, baud: u32) -> Duration {
    use margemu::stream::batch_wire_len;
    use margemu_protocol::link::{
        max_images_per_batch, IMAGE_BATCH_HEADER_LEN, MAX_IMAGE_LEN, MAX_KINEMATICS_PER_BATCH,
        TRUTH_LEN,
    };
    let images = batch.min(max_images_per_batch(MAX_IMAGE_LEN));
    let kinematics = batch.min(MAX_KINEMATICS_PER_BATCH);
    let bytes = batch_wire_len(images, MAX_IMAGE_LEN, IMAGE_BATCH_HEADER_LEN)
        .max(batch_wire_len(kinematics, TRUTH_LEN, 8));
    let line = Duration::from_secs_f64(10.0 * bytes as f64 / f64::from(baud.max(1)));
    Duration::from_millis(20) + 2 * line
}

/// Prepares the session of `scene` in `dir` (every image predicted).
pub fn prepare(scene: &Scene, config: StreamConfig, dir: &std::path::Path) -> Result<Session> {
    Session::new(scene, config, dir)
        .with_context(|| format!("preparing the session in {}", dir.display()))
}

/// Runs `session` of `scene` over `port` (named `label` in messages) with a progress line,
/// prints the summary, and returns it; the session directory is `dir`. The caller hands the
/// session's stop flag to its [`super::Interrupt`].
pub fn stream_to(
    scene: &Scene,
    session: Session,
    dir: &std::path::Path,
    port: serialport::TTYPort,
    label: &str,
) -> Result<margemu::stream::Summary> {
    let images = session.image_settings();
    let ranges = match (images.chip.full_scale(), images.chip.mag_range_gauss()) {
        (Some(fs), _) => format!("±{} g, ±{} °/s", fs.accel_g, fs.gyro_dps),
        (None, Some(gauss)) => format!("±{gauss} G"),
        (None, None) => "its fixed range".to_string(),
    };
    eprintln!(
        "images: {}, {ranges}, {} µT per field unit",
        images.chip.model.part_name(),
        images.mag_ut_per_unit
    );
    let bar = ProgressBar::new(session.sample_count());
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} sent {msg}").expect("valid template"),
    );
    let summary = session
        .run_on_port(port, |p| show(&bar, p))
        .with_context(|| {
            format!(
                "streaming {} to {} (logs in {})",
                scene.path.display(),
                label,
                dir.display()
            )
        });
    bar.finish_and_clear();
    let summary = summary?;
    let t = summary.telemetry;
    println!(
        "sent {}/{} {} in {:.2} s to {}; served {}, underruns {}, overruns {}, device CRC errors {}, host receive errors {}",
        summary.sent,
        summary.stream_len,
        match summary.source {
            SourceMode::Images => "images",
            SourceMode::Model { .. } => "kinematics samples",
        },
        summary.elapsed.as_secs_f64(),
        label,
        t.map_or(0, |t| t.samples_served),
        t.map_or(0, |t| t.underruns),
        t.map_or(0, |t| t.overruns),
        t.map_or(0, |t| t.crc_errors),
        summary.host_rx.crc_errors + summary.host_rx.framing_errors,
    );
    let s = summary.served;
    println!(
        "served as predicted, byte for byte: {} of {} samples ({} underruns, {} mismatched, {} not reported, {} unverifiable; served.csv)",
        s.byte_exact, s.samples, s.underruns, s.mismatched, s.unreported, s.unverifiable
    );
    let j = summary.jitter;
    println!(
        "pacing jitter over {} batches ({}): p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; logs in {}",
        j.batches,
        summary.pacing,
        j.p50_ns as f64 / 1e3,
        j.p99_ns as f64 / 1e3,
        j.max_ns as f64 / 1e3,
        summary.dir.display()
    );
    Ok(summary)
}

fn show(bar: &ProgressBar, p: &Progress) {
    bar.set_length(p.total);
    bar.set_position(p.sent);
    let secs = p.elapsed.as_secs_f64();
    let t = p.telemetry;
    let served = t.map_or(0, |t| t.samples_served);
    let rate = if secs > 0.0 {
        served as f64 / secs
    } else {
        0.0
    };
    bar.set_message(format!(
        "| {rate:.0} samples/s served | {} byte-exact, {} mismatched | underruns {} | CRC errors dev {} host {} | jitter {:.0} µs (max {:.0})",
        p.served.byte_exact,
        p.served.mismatched,
        t.map_or(0, |t| t.underruns),
        t.map_or(0, |t| t.crc_errors),
        p.host_rx.crc_errors,
        p.last_late_ns as f64 / 1e3,
        p.max_late_ns as f64 / 1e3,
    ));
}
