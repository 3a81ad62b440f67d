//! `session.mcap` (with [`StreamConfig::mcap`](super::StreamConfig::mcap)): the session's
//! truth, each device's samples and the events as ROS 2 messages ([`margemu_sim::mcap`] has
//! the channels), written by the log writer thread with the CSV files and flushed with them,
//! so a failing write ends the session as a failing CSV write does, and an interrupted session
//! leaves every complete chunk readable.
//!
//! - The truth: as `truth.csv`, every predicted sample.
//! - `/<device>/imu` and `/<device>/mag`: each device's part of every register image written
//!   (source mode images; first copies, not resends), decoded to physical values by its chip's
//!   module ([`ChipSettings::decode`], as `evaluate` decodes `sent.csv`), in the chip's axes
//!   (frame: the device's name), at the sample's latch instant. The device serves these very
//!   images, each at its instant (`served.csv` checks their CRCs). In source mode model the
//!   device computes its own samples: no device channels.
//! - `/dut/attitude` and `/tf` world→dut: each attitude row of the device under test's reader
//!   (`dut_attitude.csv`), given to the log writer through a [`LogSink`](super::LogSink), at its
//!   host reception time minus `start_host_ns`, while the session's logs are open (the rows
//!   after its end are in `dut_attitude.csv` only).
//! - `/events`: every row of `events.csv`, at its host time minus `start_host_ns` (scene time;
//!   0 for the events before Start).
//!
//! Every time is scene time (ns): the latch instant of a sample, the host's monotonic clock
//! shifted by `start_host_ns` for events.

use margemu_protocol::chip::ChipSettings;
use margemu_sim::mcap::{MargReading, McapLog, McapSetup, SESSION_MCAP};
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;
use std::io;
use std::path::Path;

/// The open `session.mcap`.
pub(super) struct SessionMcap {
    log: McapLog,
    /// Host time of Start, once sent.
    start_host_ns: Option<i64>,
    /// Each device's chip settings and image length, in image order (empty: no images).
    devices: Vec<(ChipSettings, usize)>,
}

impl SessionMcap {
    /// Creates `dir/session.mcap` for `scene`; `images`: the session sends register images,
    /// device 0's encoded with `settings` and `ut_per_unit` µT per field unit.
    pub(super) fn create(
        dir: &Path,
        scene: &Scene,
        images: bool,
        settings: ChipSettings,
        ut_per_unit: f64,
    ) -> io::Result<Self> {
        let rig = scene.devices();
        let devices: Vec<(ChipSettings, usize)> = match images {
            true => rig
                .iter()
                .enumerate()
                .map(|(i, d)| {
                    let s = if i == 0 { settings } else { d.chip.settings };
                    (s, d.chip.model.image_len())
                })
                .collect(),
            false => Vec::new(),
        };
        let names = match images {
            true => rig
                .iter()
                .map(|d| (d.name.clone(), d.name.clone()))
                .collect(),
            false => Vec::new(),
        };
        let setup = McapSetup {
            scene: scene.stem(),
            seed: scene.spec.seed,
            field_unit: scene.spec.field.unit,
            ut_per_unit,
            devices: names,
            clock:
                "scene time (ns): samples at their latch instant, events at host_ns - start_host_ns"
                    .to_string(),
        };
        Ok(Self {
            log: McapLog::create(&dir.join(SESSION_MCAP), &setup)?,
            start_host_ns: None,
            devices,
        })
    }

    /// Truth samples, in order.
    pub(super) fn truth(&mut self, truths: &[Truth]) -> io::Result<()> {
        truths.iter().try_for_each(|t| self.log.truth(t))
    }

    /// A register image written for the sample latched at `t_ns` (every device's part).
    pub(super) fn image(&mut self, t_ns: u64, image: &[u8]) -> io::Result<()> {
        let mut rest = image;
        for (i, (settings, len)) in self.devices.iter().enumerate() {
            let (own, others) = rest.split_at((*len).min(rest.len()));
            rest = others;
            let r = settings.decode(own).ok_or_else(|| {
                io::Error::other(format!(
                    "device {i}'s image of sample at {t_ns} ns has {} bytes, not {len}",
                    own.len()
                ))
            })?;
            let reading = MargReading {
                t_ns,
                acc: r.acc,
                gyr: r.gyr,
                mag_ut: r.mag_ut,
            };
            self.log.marg(i, &reading)?;
        }
        Ok(())
    }

    /// Start was sent at `host_ns`: scene time 0 of the events from now on.
    pub(super) fn started(&mut self, host_ns: i64) {
        self.start_host_ns = Some(host_ns);
    }

    /// An event at host time `host_ns`.
    pub(super) fn event(&mut self, host_ns: i64, event: &str, detail: &str) -> io::Result<()> {
        let t_ns = scene_time(host_ns, self.start_host_ns);
        self.log.event(t_ns, event, detail)
    }

    /// The device under test's attitude `q`, received at host time `host_ns`.
    pub(super) fn dut_attitude(&mut self, host_ns: i64, q: [f64; 4]) -> io::Result<()> {
        let t_ns = scene_time(host_ns, self.start_host_ns);
        self.log.dut_attitude(t_ns, &q)
    }

    /// Ends the open chunk and flushes the file.
    pub(super) fn flush(&mut self) -> io::Result<()> {
        self.log.flush()
    }

    /// Writes the summary and the footer, and flushes.
    pub(super) fn finish(self) -> io::Result<()> {
        let mut out = self.log.finish()?;
        io::Write::flush(&mut out)
    }
}

/// Scene time of host time `host_ns`: `host_ns − start` (0 before Start or without one).
fn scene_time(host_ns: i64, start: Option<i64>) -> u64 {
    start.map_or(0, |s| host_ns.saturating_sub(s).max(0) as u64)
}

#[cfg(test)]
mod tests {
    use super::scene_time;

    #[test]
    fn events_before_start_are_at_scene_time_zero() {
        assert_eq!(scene_time(500, None), 0);
        assert_eq!(scene_time(500, Some(700)), 0);
        assert_eq!(scene_time(1_700, Some(700)), 1_000);
    }
}
