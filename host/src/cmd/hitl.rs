//! `margemu hitl SCENE (--port PATH [--baud B] | --udp HOST:PORT [--bind ADDR])`: send a scene's
//! MARG samples as MAVLink HIL_SENSOR to a flight controller in HITL mode (PX4, `SYS_HITL = 1`),
//! read the attitude it sends back on the same link, and write the session directory
//! (library: `margemu::hitl`; guide: `docs/px4-hitl.md`).

use super::stream::finish_dut;
use anyhow::{Context, Result};
use margemu::dut::{DutConfig, DutProtocol};
use margemu::hitl::{HitlConfig, HitlSession, Link, Target};
use margemu::scene::FieldUnit;
use margemu::stream::clock::SystemClock;
use margemu::vfc::AttachedDut;
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("link").required(true).args(["port", "udp"])))]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
    scene: PathBuf,
    /// The flight controller's MAVLink serial port (e.g. /dev/ttyACM0, a TELEM UART's adapter,
    /// or a PTY path).
    #[arg(long, value_name = "PATH")]
    port: Option<String>,
    /// Line rate of --port (PX4's USB port ignores it).
    #[arg(long, default_value_t = 921_600, requires = "port")]
    baud: u32,
    /// Send to the flight controller over UDP at HOST:PORT, and read its replies on the same
    /// socket.
    #[arg(long, value_name = "HOST:PORT", conflicts_with = "port")]
    udp: Option<String>,
    /// The local address of the UDP socket.
    #[arg(
        long,
        value_name = "ADDR",
        default_value = "0.0.0.0:0",
        requires = "udp"
    )]
    bind: String,
    /// Gauss per unit of a scene whose field is in normalized units ("nu"); a field in µT is
    /// converted exactly (1 G = 100 µT).
    #[arg(long, value_name = "G", default_value_t = margemu::hitl::message::DEFAULT_GAUSS_PER_UNIT)]
    gauss_per_unit: f64,
    /// After the last sample, how long to keep reading the flight controller's replies (ms).
    #[arg(long, value_name = "MS", default_value_t = 500)]
    drain_ms: u64,
    // Default: sessions/<scene name>-hitl.
    #[command(flatten)]
    output: super::OutputArgs,
    #[command(flatten)]
    size: super::SizeArgs,
    #[command(flatten)]
    realtime: super::stream::RealtimeArgs,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let interrupt = super::Interrupt::install()?;
        let scene = super::load_scene(&self.scene)?;
        self.size.check(&scene)?;
        let target = match (&self.port, &self.udp) {
            (Some(path), _) => Target::Serial {
                path: path.clone(),
                baud: self.baud,
            },
            (None, Some(remote)) => Target::Udp {
                remote: remote.clone(),
                bind: self.bind.clone(),
            },
            (None, None) => unreachable!("clap requires --port or --udp"),
        };
        if scene.spec.field.unit == FieldUnit::Normalized {
            eprintln!(
                "warning: the scene's field is in normalized units; sent as {} gauss per unit (--gauss-per-unit)",
                self.gauss_per_unit
            );
        }
        let config = HitlConfig {
            target: target.clone(),
            gauss_per_unit: self.gauss_per_unit,
            realtime: self.realtime.realtime,
            ..HitlConfig::default()
        };
        // Checks the scene and the link before anything is written.
        if let Target::Serial { baud, .. } = &target {
            margemu::hitl::link::check_line(scene.clock.hz(), *baud)?;
        }
        let link = Link::open(&target)?;
        let dir = self.output.prepare(&scene, "sessions", "-hitl")?;
        let session = HitlSession::new(&scene, config, &dir)?;
        let origin = Instant::now();
        let clock = SystemClock::with_origin(origin);
        let dut = AttachedDut::start(
            link.receiver,
            DutConfig::new(DutProtocol::Mavlink),
            &dir,
            origin,
            Some(session.completion_record()),
        )?;
        let stop = interrupt.flag();
        println!(
            "hitl: sending {} samples at {} Hz to {} ...",
            scene.samples(),
            scene.clock.hz(),
            target.label()
        );
        let sent = session.run(link.sender, &clock, &stop);
        if sent.is_ok() {
            std::thread::sleep(Duration::from_millis(self.drain_ms));
        }
        let dut = finish_dut(dut);
        let summary = sent.with_context(|| format!("the session in {}", dir.display()))?;
        let dut = dut?;
        println!(
            "hitl: sent {} HIL_SENSOR and {} HEARTBEAT ({} bytes); latest write {:.3} ms after its instant",
            summary.samples,
            summary.heartbeats,
            summary.bytes,
            summary.max_late_ns as f64 * 1e-6
        );
        if dut.attitude_rows == 0 {
            eprintln!(
                "warning: the flight controller sent no ATTITUDE or ATTITUDE_QUATERNION (is SYS_HITL = 1 and is MAVLink on this link?)"
            );
        }
        println!("wrote {0}; score it: margemu evaluate {0}", dir.display());
        Ok(())
    }
}
