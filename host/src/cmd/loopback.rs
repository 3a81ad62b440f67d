//! `margemu loopback SCENE [-o DIR]`: the embedded default. The firmware's link handler runs on
//! the host behind a real pseudo-terminal pair, the scene streams to it exactly as to a board,
//! and every image the device reports serving is checked against the host's prediction.

use super::stream::{prepare, stream_to, SourceArgs};
use anyhow::{bail, Context, Result};
use margemu::scene::Scene;
use margemu::stream::{ImageSettings, StreamConfig};
use serialport::{SerialPort, TTYPort};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Session directory (default: sessions/<scene name>-loopback).
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    source: SourceArgs,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let scene = Scene::load(&self.scene)?;
        let dir = self.output.clone().unwrap_or_else(|| {
            let stem = self.scene.file_stem().unwrap_or_default().to_string_lossy();
            PathBuf::from("sessions").join(format!("{stem}-loopback"))
        });
        let settings = ImageSettings::for_scene(&scene);
        let (host_end, device_end) = TTYPort::pair().context("opening a pseudo-terminal pair")?;
        let label = device_end
            .name()
            .unwrap_or_else(|| "a pseudo-terminal".into());
        let device = margemu::loopback::spawn_device(device_end).context("starting the device")?;
        let config = StreamConfig {
            port: label.clone(),
            images: Some(settings),
            source: self.source.mode()?,
            ..StreamConfig::default()
        };
        let session = prepare(&scene, config, &dir)?;
        let streamed = stream_to(&scene, session, &dir, host_end, &label);
        let report = device.stop();
        let summary = streamed?;
        let s = summary.served;
        let overruns = summary.telemetry.map_or(0, |t| t.overruns);
        println!(
            "loopback: the device served {} samples ({} underruns, {overruns} overruns); \
             {} of {} predicted images confirmed byte for byte ({} mismatched, {} not reported); device {}",
            s.reported, s.underruns, s.byte_exact, s.samples, s.mismatched, s.unreported, report.ended
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
        Ok(())
    }
}
