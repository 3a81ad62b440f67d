//! `margemu loopback SCENE [-o DIR]`: the embedded default. The firmware's link handler runs on
//! the host behind a real pseudo-terminal pair, the scene streams to it exactly as to a board,
//! and every image the device served is checked against the host's prediction.

use super::stream::{prepare, stream_to};
use anyhow::{bail, Context, Result};
use margemu::scene::Scene;
use margemu::stream::{ImageSettings, StreamConfig};
use margemu_protocol::link::CRC32C;
use serialport::{SerialPort, TTYPort};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Cmd {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Session directory (default: sessions/<scene name>-loopback).
    #[arg(short, long)]
    output: Option<PathBuf>,
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
            ..StreamConfig::default()
        };
        let session = prepare(&scene, config, &dir)?;
        let expected: Vec<u32> = session
            .samples()
            .iter()
            .map(|s| CRC32C.checksum(&s.image))
            .collect();
        let streamed = stream_to(&scene, session, &dir, host_end, &label);
        let report = device.stop();
        streamed?;
        let mut matched = 0usize;
        for &(index, crc, underrun) in &report.served {
            let Some(&predicted) = expected.get(index as usize) else {
                continue;
            };
            if underrun || crc != predicted {
                bail!(
                    "the device served sample {index} differently from the prediction ({}); logs in {}",
                    if underrun { "an underrun" } else { "CRC mismatch" },
                    dir.display()
                );
            }
            matched += 1;
        }
        let (served, underruns, overruns) = report.counters;
        println!(
            "loopback: the device served {served} samples ({underruns} underruns, {overruns} overruns); \
             {matched} of {} predicted images confirmed byte for byte",
            expected.len()
        );
        if matched != expected.len() {
            bail!(
                "only {matched} of {} images were confirmed as served",
                expected.len()
            );
        }
        Ok(())
    }
}
