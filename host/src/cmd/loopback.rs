//! `margemu loopback [SCENE] [-o DIR]`: the embedded default. The firmware's link handler runs on
//! the host behind a real pseudo-terminal pair, the scene streams to it exactly as to a board,
//! and every image the device reports serving is checked against the host's prediction. With
//! `--dut PORT` a device under test's output is logged beside the session; with `--vfc FILTER`
//! a virtual flight controller runs on the emulated chip and its MAVLink is read back and scored.

use super::stream::{finish_dut, prepare, stream_to, ChipArgs, DutArgs, SourceArgs};
use super::vfc::VfcArgs;
use anyhow::{bail, Context, Result};
use margemu::dut::{DutConfig, DutProtocol};
use margemu::stream::{ImageSettings, StreamConfig};
use serialport::{SerialPort, TTYPort};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
    #[arg(default_value = "figure3")]
    scene: PathBuf,
    // Default: sessions/<scene name>-loopback.
    #[command(flatten)]
    output: super::OutputArgs,
    #[command(flatten)]
    chip: ChipArgs,
    #[command(flatten)]
    source: SourceArgs,
    #[command(flatten)]
    dut: DutArgs,
    #[command(flatten)]
    size: super::SizeArgs,
    #[command(flatten)]
    vfc: VfcArgs,
    /// Also write `session.mcap` (ROS 2 messages for Foxglove and `ros2 bag`; docs/mcap.md).
    #[arg(long)]
    mcap: bool,
    #[command(flatten)]
    realtime: super::stream::RealtimeArgs,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let interrupt = super::Interrupt::install()?;
        let scene = self.chip.apply(super::load_scene(&self.scene)?)?;
        self.size.check(&scene)?;
        let vfc = self.vfc.config(&scene)?;
        let settings = match vfc {
            Some(_) => margemu::vfc::image_settings(&scene)?,
            None => ImageSettings::for_scene(&scene),
        };
        let (host_end, device_end) = TTYPort::pair().context("opening a pseudo-terminal pair")?;
        let dir = self.output.prepare(&scene, "sessions", "-loopback")?;
        let label = device_end
            .name()
            .unwrap_or_else(|| "a pseudo-terminal".into());
        let config = StreamConfig {
            port: label.clone(),
            images: Some(settings),
            source: self.source.mode()?,
            budget: self.source.budget().in_process(),
            mcap: self.mcap,
            realtime: self.realtime.realtime,
            ..StreamConfig::default()
        };
        let mut session = prepare(&scene, config, &dir)?;
        interrupt.watch(session.stop_flag());
        let (device, dut) = match vfc {
            Some(cfg) => {
                let expected = settings.chip;
                let (rig, port) = margemu::vfc::spawn(device_end, cfg, expected)?;
                let config = DutConfig::new(DutProtocol::Mavlink);
                let dut = margemu::vfc::attach(&mut session, port, config, &dir)?;
                (Device::Fc(rig), Some(dut))
            }
            None => {
                let device =
                    margemu::loopback::spawn_device(device_end).context("starting the device")?;
                (Device::Plain(device), self.dut.attach(&mut session, &dir)?)
            }
        };
        let streamed = stream_to(&scene, session, &dir, host_end, &label);
        let (report, fc) = match device {
            Device::Plain(device) => (device.stop(), None),
            Device::Fc(rig) => {
                let fc = rig.stop();
                (fc.device.clone(), Some(fc))
            }
        };
        if let (Some(dut), Some(fc)) = (&dut, &fc) {
            dut.wait_for_bytes(fc.uart.bytes, std::time::Duration::from_secs(2));
        }
        let dut = dut.map(finish_dut).transpose();
        if let Some(why) = fc.as_ref().and_then(|fc| fc.fc.error.as_ref()) {
            eprintln!("the virtual flight controller stopped the device: {why}");
        }
        let summary = streamed?;
        let dut = dut?;
        let s = summary.served;
        let overruns = summary.telemetry.map_or(0, |t| t.overruns);
        println!(
            "loopback: the device served {} samples ({} underruns, {overruns} overruns); \
             {} of {} predicted images confirmed byte for byte ({} mismatched, {} not reported, {} unverifiable); device {}",
            s.reported, s.underruns, s.byte_exact, s.samples, s.mismatched, s.unreported,
            s.unverifiable, report.ended
        );
        if let Some(k) = s.first_mismatch {
            bail!(
                "the device served sample {k} differently from the prediction; logs in {}",
                dir.display()
            );
        }
        if s.lost() > 0 {
            bail!(
                "only {} of {} images were confirmed as served; logs in {}",
                s.byte_exact,
                s.samples,
                dir.display()
            );
        }
        if let (Some(fc), Some(dut)) = (&fc, &dut) {
            super::vfc::report(fc, dut, &dir)?;
        }
        Ok(())
    }
}

/// The firmware device, bare or with a virtual flight controller on its chip.
enum Device {
    Plain(margemu::loopback::LoopbackDevice),
    Fc(margemu::vfc::VfcRig),
}
