//! `margemu bench stream`: streaming speed against error, measured here and now.

use anyhow::Result;
use margemu::perf::{link_table, stream_sweep, StreamLoad, StreamRow, Streamed};
use margemu::realtime::Realtime;
use margemu::stream::{JitterStats, SourceMode};
use margemu_protocol::chip::ChipModel;
use std::path::PathBuf;

const BAUDS: [u32; 3] = [921_600, 2_000_000, 3_000_000];

#[derive(clap::Args)]
pub struct Cmd {
    /// Seconds of scene per row (streamed in real time).
    #[arg(long, default_value_t = 5.0)]
    seconds: f64,
    /// Output rates to stream, Hz.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,2000,4000,8000,16000,32000,64000,128000,256000"
    )]
    rates: Vec<f64>,
    /// Keep the sessions' logs here (one directory per row; at 256 kHz a row writes about a GB).
    /// Without it they go to a temporary directory, removed after each row.
    #[arg(long)]
    keep: Option<PathBuf>,
    /// The chip model the device emulates (power-on settings; `margemu chips` lists them).
    #[arg(long, default_value = "mpu9250")]
    chip: String,
    /// Stream a rig instead of one chip: an ICM-42688-P and an MPU-6000 on SPI and an IST8310
    /// on I2C, 52-byte images (register images only; rates both IMUs have, up to 8 kHz).
    #[arg(long, conflicts_with = "chip")]
    rig: bool,
    /// Also stream every row with N CPU-bound hog threads at normal priority running (2 if N
    /// is left out), and each of those with the pacing thread at normal priority and at
    /// `--realtime`: four rows per rate and source.
    #[arg(long, value_name = "N", num_args = 0..=1, default_missing_value = "2")]
    loaded: Option<usize>,
    #[command(flatten)]
    realtime: super::stream::RealtimeArgs,
}

impl Cmd {
    /// The conditions each rate and source is streamed under.
    fn loads(&self) -> Vec<StreamLoad> {
        let asked = self.realtime.realtime;
        match self.loaded {
            None => vec![StreamLoad {
                hogs: 0,
                realtime: asked,
            }],
            Some(n) => [0, n]
                .into_iter()
                .flat_map(|hogs| {
                    [Realtime::Off, asked]
                        .into_iter()
                        .map(move |realtime| StreamLoad { hogs, realtime })
                })
                .collect(),
        }
    }
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        anyhow::ensure!(
            self.seconds > 0.0 && self.rates.iter().all(|r| *r > 0.0),
            "--seconds and --rates must be > 0"
        );
        let chip = ChipModel::from_name(&self.chip).ok_or_else(|| {
            anyhow::anyhow!(
                "no chip model {:?}; margemu emulates {}",
                self.chip,
                margemu::scene::chip::model_names()
            )
        })?;
        let model = SourceMode::Model {
            kinematics_hz: None,
        };
        let (what, sources, served) = if self.rig {
            let len = margemu::perf::rig_stream_scene(1000.0, 1.0)
                .map_err(anyhow::Error::msg)?
                .devices()
                .iter()
                .map(|d| d.chip.model.image_len())
                .sum::<usize>();
            let served = format!(
                "a rig of an emulated ICM-42688-P and MPU-6000 on SPI and an IST8310 compass on \
                 I2C (measuring on its own schedule), {len} B images"
            );
            (Streamed::Rig, vec![SourceMode::Images], served)
        } else {
            let served = format!(
                "an emulated {}, {} B images",
                chip.part_name(),
                chip.image_len()
            );
            (
                Streamed::Chip(chip),
                vec![SourceMode::Images, model],
                served,
            )
        };
        println!(
            "Each row streams a {} s kinematic scene (noise on every sensor, {served}) in real \
             time through a PTY pair to the firmware's link handler (loopback device, buffer {} \
             samples), and checks the CRC-32C of every image it served against the host's \
             prediction. Lost = scene samples not served byte for byte (underruns, mismatches, \
             unreported). Pacing: how late each batch's write started against the scene clock; \
             written: how late it completed (the PTY write included). Hogs: CPU-bound threads at \
             normal priority running meanwhile; pacing thread: the real-time priority the \
             session obtained.\n",
            self.seconds,
            margemu::loopback::BUFFER,
        );
        println!(
            "| source | rate (Hz) | hogs | pacing thread | samples | sent | served byte-exact | lost | of which mismatched | lead (ms) | batch | pacing late p50 / p99 / max (µs) | written late p50 / p99 / max (µs) | credit stalls | resends | link efficiency |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        let dir = self.keep.clone().unwrap_or_else(|| {
            std::env::temp_dir().join(format!("margemu-bench-stream-{}", std::process::id()))
        });
        for &source in &sources {
            for &rate in &self.rates {
                for load in self.loads() {
                    let row = stream_sweep(what, &[rate], &[source], self.seconds, load, &dir)?;
                    if self.keep.is_none() {
                        std::fs::remove_dir_all(&dir)?;
                    }
                    row.iter().for_each(print_row);
                }
            }
        }
        println!(
            "\nWorst-case link efficiency of a batch frame (header, first index, image length, items, CRC, \
             worst-case COBS, both delimiters) and the items per second a UART carries at 10 line \
             bits per byte (8N1; line bytes/s: {}):\n",
            BAUDS.map(|b| format!("{} at {b} baud", b / 10)).join(", ")
        );
        println!("| batch | items | wire bytes | item bytes / wire byte | 921 600 baud | 2 Mbaud | 3 Mbaud |");
        println!("|---|---|---|---|---|---|---|");
        for l in link_table() {
            let kind = match l.chip {
                Some(chip) => format!("{} images ({} B)", chip.part_name(), l.item_len),
                None if l.rig => format!(
                    "rig images ({} B: ICM-42688-P + MPU-6000 + IST8310)",
                    l.item_len
                ),
                None => "kinematics".to_owned(),
            };
            let rates = BAUDS.map(|b| format!("{:.0} /s", l.items_per_s(b)));
            println!(
                "| {kind} | {} | {} | {:.1} % | {} |",
                l.items,
                l.wire_bytes,
                100.0 * l.efficiency(),
                rates.join(" | ")
            );
        }
        println!(
            "\nIn source model each kinematics sample is held for a whole number of output samples, \
             so the output rate is that many times the kinematics rate the line carries."
        );
        Ok(())
    }
}

fn print_row(r: &StreamRow) {
    let source = match r.source {
        SourceMode::Images => "images".to_string(),
        SourceMode::Model { kinematics_hz } => {
            format!("model, kinematics {} Hz", kinematics_hz.unwrap_or(0.0))
        }
    };
    let s = r.served;
    let us = |j: JitterStats| {
        let [a, b, c] = [j.p50_ns, j.p99_ns, j.max_ns].map(|ns| ns as f64 / 1e3);
        format!("{a:.1} / {b:.1} / {c:.1}")
    };
    println!(
        "| {source} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0} | {} | {} | {} | {} | {} | {:.1} % |{}",
        r.rate_hz,
        r.hogs,
        r.pacing,
        r.samples,
        r.sent,
        s.byte_exact,
        s.lost(),
        s.mismatched,
        r.lead.as_secs_f64() * 1e3,
        r.batch,
        us(r.jitter),
        us(r.written_jitter),
        r.credit_stalls,
        r.resends,
        100.0 * r.efficiency,
        r.error
            .as_deref()
            .map_or(String::new(), |e| format!(" ended: {e}")),
    );
}
