//! [`VirtualFc`]: the flight controller's main loop, run at every turn of the loopback device's
//! loop ([`crate::loopback::spawn_device_with_local`]) with the firmware `Device` it sits on.
//!
//! 1. While the device is idle there is nothing to do. Once it is configured (the chip of the
//!    session exists), the board of the chip's model sets the chip up through its driver
//!    ([`Board::init`]) and checks that the chip now converts samples the way the host
//!    predicted its images; a mismatch ends the device loop with the reason (the session then
//!    fails with it). A new Hello (the device back to idle) starts over.
//! 2. At each turn, the INT pin: when it says data ready, the board reads every sample waiting
//!    in the chip's FIFO, oldest first (clearing INT; see [`board`] for each chip's FIFO). The
//!    board turns each into SI body axes ([`Board::to_body`]), and the filter takes every one,
//!    in order, with `dt` = the time between their instants (below). On a chip with a
//!    magnetometer the filter starts with the first sample that carries a measurement (the
//!    AK8963 delivers its first one a period of its own after set-up; a start without it would
//!    take yaw 0); the samples before are counted as warm-up.
//! 3. The output: at the configured rate on the device clock, or after every sample, an
//!    ATTITUDE and an ATTITUDE_QUATERNION (MAVLink 2, [`crate::dut::mavlink_out`]) with `time_boot_ms` =
//!    the sample's instant; a HEARTBEAT every second. Frames go to the UART queue.
//!
//! **With an external compass** (a rig's IST8310, QMC5883L or RM3100, [`super::compass`]) the compass
//! is set up once the rig is complete (the device running), then polled at every turn, before
//! the IMU: every 10 ms on the device clock it gives a measurement, turned into the IMU's axes
//! and stamped with the device-clock instant it was read at. Each IMU sample then goes to the
//! filter with the newest compass reading at or before its instant, as the MPU-9250's FIFO
//! carries the AK8963's latest measurement with every sample (sample-and-hold at the IMU's
//! rate); the board's own magnetometer, if any, is not used. The filter starts with the first
//! sample that has a compass reading (one compass period after set-up); the samples before
//! are warm-up. The compass's instants follow the flight controller's turns, as a real board's
//! periodic callback runs when its scheduler gets to it: a starved thread reads the compass
//! late and holds the previous reading longer (the IMU's samples keep their instants).
//!
//! **Without a magnetometer** (an ICM-42688-P without a compass) the filter gets a zero field
//! with every sample. The filters of `margemu-filters` take that as an unusable magnetometer:
//! they skip the magnetometer correction and count it (`skipped_mag`, one per sample), and the
//! first sample sets the tilt only, at yaw 0 (TRIAD without a field). So the heading reported
//! is the one the filters have without a magnetometer: 0 at the first sample, then the
//! integrated gyroscope (the EKF's bias estimate is then driven by gravity alone, which does
//! not observe the bias about the vertical). Roll and pitch are corrected by the accelerometer
//! as with a magnetometer; the yaw error is the truth's heading at the first sample plus the
//! drift, so compare roll and pitch (a geodesic score includes the yaw error).
//!
//! **Time.** The flight controller's clock is the device's scene clock. A sample's instant
//! comes from its index in the FIFO's stream at the configured rate: the first batch after
//! set-up anchors the stream (its newest sample is the one the device served last,
//! [`Device::last_served`](margemu_firmware::link::Device::last_served), each older one a period
//! earlier), and sample `k` is then `k` periods after the first, whenever the thread got to read
//! it. So a flight controller whose thread is starved reads the same samples with the same
//! instants, only later, and feeds its filter exactly what it would have on an idle machine.
//! Only a FIFO overflow (the thread starved for a whole FIFO: 24 samples on the MPU-9250, 102 on
//! the ICM-42688-P) loses samples: the board resets the FIFO and counts it
//! ([`FcReport::overflows`]), the clock is anchored again on the next batch, and the gap is
//! counted in [`FcReport::missed`] (the filter's `dt` spans it). A batch whose newest instant
//! disagrees with the device's by more than half a period (samples lost without an overflow)
//! anchors the clock again too, and is counted ([`FcReport::resyncs`]).

use super::axes::BodySample;
use super::board::{self, Board};
use super::compass::{Compass, CompassSetup};
use super::uart::UartTx;
use super::{OutputRate, VfcConfig};
use crate::dut::mavlink_out::{attitude, attitude_quaternion, MavlinkWriter};
use crate::loopback::Firmware;
use margemu_filters::{AttitudeFilter, Diagnostics, Imu, Initial};
use margemu_firmware::chip::EmulatedChip;
use margemu_protocol::chip::ChipSettings;
use margemu_protocol::link::DeviceState;
use margemu_sim::filter_params::ParamError;
use mavlink::dialects::common::{
    MavAutopilot, MavMessage, MavModeFlag, MavState, MavType, HEARTBEAT_DATA,
};
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::sync::{Arc, Mutex};

/// What the flight controller did (shared with the caller while it runs).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FcReport {
    /// The filter and its parameters.
    pub filter: String,
    /// The bus the driver used (`SPI` or `I2C`).
    pub bus: &'static str,
    /// What the board's driver did at set-up (the last set-up, if the device was configured
    /// again).
    pub setup: Option<board::Setup>,
    /// What the `mpu9250` driver found at set-up, on an MPU-9250 ([`board::Setup::mpu9250`]).
    pub init: Option<board::InitReport>,
    /// The rig's external compass as it answered at set-up ([`super::compass`]).
    pub compass: Option<CompassSetup>,
    /// Compass measurements read.
    pub compass_readings: u64,
    /// Compass polls that found no new measurement.
    pub compass_not_ready: u64,
    /// Compass polls whose transactions failed (a bus fault), each retried a period later.
    pub compass_failed: u64,
    /// Set-ups done.
    pub inits: u64,
    /// Samples read from the FIFO.
    pub samples: u64,
    /// Samples read before the first magnetometer measurement (not filtered; with a
    /// magnetometer only).
    pub warmup: u64,
    /// Samples never read: flushed with an overflowing FIFO (from the gaps between the
    /// instants of the samples read).
    pub missed: u64,
    /// FIFO overflows (each flushed the FIFO).
    pub overflows: u64,
    /// Times the sample clock disagreed with the device's last served instant and started
    /// again (0 unless samples were lost without an overflow).
    pub resyncs: u64,
    /// Frames queued per MAVLink message name.
    pub sent: BTreeMap<&'static str, u64>,
    /// Frames dropped because the UART queue was full.
    pub dropped: u64,
    /// The filter's counters.
    pub diagnostics: Diagnostics,
    /// Why the flight controller stopped the device loop, if it did.
    pub error: Option<String>,
}

impl FcReport {
    /// Frames queued, all messages.
    pub fn frames(&self) -> u64 {
        self.sent.values().sum()
    }
}

/// The flight controller: board, filter, output schedule, telemetry.
pub struct VirtualFc {
    config: VfcConfig,
    expected: ChipSettings,
    board: Option<Board>,
    /// The external compass, once set up.
    compass: Option<Compass>,
    /// Compass readings (µT, body axes) by their device-clock instant, oldest first: the newest
    /// one at or before a sample's instant goes with it.
    held: Vec<(u64, [f64; 3])>,
    filter: Box<dyn AttitudeFilter<f64> + Send>,
    /// Instant of the previous sample filtered, ns.
    last_ns: Option<u64>,
    /// Instant of the previous sample read, ns.
    last_read_ns: Option<u64>,
    /// The instants of the samples read, by their index in the FIFO's stream (`None` until the
    /// first batch after set-up or after an overflow).
    clock: Option<SampleClock>,
    /// Index of the next output instant (for [`OutputRate::Hz`]).
    next_out: u64,
    next_heartbeat_ns: u64,
    mavlink: MavlinkWriter,
    uart: UartTx,
    report: Arc<Mutex<FcReport>>,
}

impl VirtualFc {
    /// A flight controller of `config` that has not seen its chip yet; `expected` is the
    /// conversion the host predicted images with; frames go to `uart`; `report` is kept up to
    /// date.
    pub fn new(
        config: VfcConfig,
        expected: ChipSettings,
        uart: UartTx,
        report: Arc<Mutex<FcReport>>,
    ) -> Result<Self, ParamError> {
        let filter = config
            .filter
            .build(config.mag_reference, Initial::FirstSample)?;
        {
            let mut r = report.lock().unwrap_or_else(|e| e.into_inner());
            r.filter = format!(
                "{} ({})",
                config.filter.kind(),
                super::describe(&config.filter)
            );
            r.bus = board::bus(expected.model).unwrap_or("no bus");
        }
        Ok(Self {
            config,
            expected,
            board: None,
            compass: None,
            held: Vec::new(),
            filter,
            last_ns: None,
            last_read_ns: None,
            clock: None,
            next_out: 0,
            next_heartbeat_ns: 0,
            mavlink: MavlinkWriter::v2(),
            uart,
            report,
        })
    }

    /// One turn of the main loop (see the module docs); `Break` ends the device loop.
    pub fn step(&mut self, device: &mut Firmware, _now_ns: u64) -> ControlFlow<String> {
        let result = self.turn(device);
        if let Err(why) = &result {
            self.update(|r| r.error = Some(why.clone()));
        }
        match result {
            Ok(()) => ControlFlow::Continue(()),
            Err(why) => ControlFlow::Break(format!("virtual flight controller: {why}")),
        }
    }

    fn turn(&mut self, device: &mut Firmware) -> Result<(), String> {
        let state = device.state();
        if state == DeviceState::Idle {
            self.board = None;
            self.compass = None;
            return Ok(());
        }
        if self.board.is_none() {
            let board = self.set_up(device)?;
            self.board = Some(board);
        }
        let last_served_ns = device.last_served().map_or(0, |s| s.time_ns);
        self.read_compass(device, state, last_served_ns)?;
        let external = self.config.compass.is_some();
        let Some(board) = &mut self.board else {
            return Ok(());
        };
        board.sync_faults(device.faults());
        let chip: &mut EmulatedChip = device.chip_mut();
        if !board.data_ready(chip)? {
            return Ok(());
        }
        let overflows_before = board.overflows();
        let readings = board
            .read(chip)
            .map_err(|e| format!("reading the chip: {e}"))?;
        let overflows = board.overflows();
        let with_mag = board.has_magnetometer() || external;
        let bodies: Vec<BodySample> = readings
            .iter()
            .map(|r| board.to_body(r, &self.config.mag_alignment))
            .collect();
        if overflows != overflows_before {
            // Samples were lost: the index clock starts again from the next batch.
            self.clock = None;
            self.update(|r| r.overflows = overflows);
        }
        let Some(n) = u64::try_from(bodies.len()).ok().filter(|&n| n > 0) else {
            return Ok(());
        };
        let period_ns = 1e9 / self.config.sample_rate_hz;
        let anchored = SampleClock::anchored(last_served_ns, n, period_ns);
        let mut clock = self.clock.unwrap_or(anchored);
        let mut times: Vec<u64> = (0..n).map(|_| clock.next_ns()).collect();
        // The newest sample read is the last one the device served: if the index clock says
        // otherwise, samples were lost or doubled unseen; the clock starts again from this batch.
        if times
            .last()
            .is_some_and(|&t| t.abs_diff(last_served_ns) as f64 > period_ns / 2.0)
        {
            clock = anchored;
            times = (0..n).map(|_| clock.next_ns()).collect();
            self.update(|r| r.resyncs += 1);
        }
        self.clock = Some(clock);
        let newest_ns = times.last().copied().unwrap_or_default();
        for (t_ns, mut body) in times.into_iter().zip(bodies) {
            if external {
                body.mag_ut = self.held_at(t_ns).unwrap_or_default();
            }
            self.take(t_ns, body, with_mag);
        }
        if let Some(i) = self.held.iter().rposition(|(t, _)| *t <= newest_ns) {
            self.held.drain(..i);
        }
        Ok(())
    }

    /// Sets the rig's external compass up once the rig is complete (the device no longer
    /// `Configured`: AddDevice is refused once it runs), then polls it at the device-clock
    /// instant `now_ns`; a reading is held from that instant on.
    fn read_compass(
        &mut self,
        device: &mut Firmware,
        state: DeviceState,
        now_ns: u64,
    ) -> Result<(), String> {
        let Some(config) = &self.config.compass else {
            return Ok(());
        };
        if self.compass.is_none() {
            if state == DeviceState::Configured {
                return Ok(());
            }
            let (compass, setup) = Compass::init(device.rig_mut(), config, now_ns)?;
            self.compass = Some(compass);
            self.held.clear();
            self.update(|r| r.compass = Some(setup));
        }
        let Some(compass) = &mut self.compass else {
            return Ok(());
        };
        compass.sync_faults(device.rig(), device.faults());
        let before = (compass.not_ready(), compass.failed());
        let reading = compass.poll(device.rig_mut(), now_ns)?;
        let (not_ready, failed) = (compass.not_ready(), compass.failed());
        if let Some(mag) = reading {
            self.held.push((now_ns, mag));
        }
        if reading.is_some() || (not_ready, failed) != before {
            self.update(|r| {
                r.compass_readings += u64::from(reading.is_some());
                r.compass_not_ready = not_ready;
                r.compass_failed = failed;
            });
        }
        Ok(())
    }

    /// The compass reading held at `t_ns`: the newest one at or before it.
    fn held_at(&self, t_ns: u64) -> Option<[f64; 3]> {
        self.held
            .iter()
            .rev()
            .find(|(t, _)| *t <= t_ns)
            .map(|(_, mag)| *mag)
    }

    /// One sample read, at the instant `t_ns`: counted, then filtered and sent.
    fn take(&mut self, t_ns: u64, body: BodySample, with_mag: bool) {
        let period_ns = 1e9 / self.config.sample_rate_hz;
        // Samples since the previous read (the first instant of the device clock is 0).
        let gap_ns = match self.last_read_ns {
            Some(last) => t_ns.saturating_sub(last) as f64,
            None => t_ns as f64 + period_ns,
        };
        self.last_read_ns = Some(t_ns);
        let missed = ((gap_ns / period_ns).round() as u64).saturating_sub(1);
        let warmup = with_mag && self.last_ns.is_none() && body.mag_ut == [0.0; 3];
        self.update(|r| {
            r.samples += 1;
            r.missed += missed;
            r.warmup += u64::from(warmup);
        });
        if warmup {
            return;
        }
        let dt_ns = match self.last_ns {
            Some(last) => t_ns.saturating_sub(last) as f64,
            None => period_ns,
        };
        self.last_ns = Some(t_ns);
        let imu = Imu {
            gyro: body.gyro,
            acc: body.acc,
            mag: body.mag_ut,
        };
        self.filter.update(&imu, dt_ns * 1e-9);
        let diagnostics = self.filter.diagnostics();
        self.update(|r| r.diagnostics = diagnostics);
        self.output(t_ns, body.gyro);
    }

    /// Sets the device's chip up and checks its conversion against the host's prediction.
    fn set_up(&mut self, device: &mut Firmware) -> Result<Board, String> {
        let (board, setup) = Board::init(device.chip_mut(), self.config.sample_rate_hz)?;
        let configured = setup.configured;
        if configured.model != self.expected.model {
            return Err(format!(
                "the board set up a {:?}, but the host computed its images for a {:?}",
                configured.model, self.expected.model
            ));
        }
        if configured != self.expected {
            return Err(format!(
                "the driver configured the chip as {:?}, but the host computed its images for {:?}",
                configured.conversion, self.expected.conversion
            ));
        }
        self.filter = self
            .config
            .filter
            .build(self.config.mag_reference, Initial::FirstSample)
            .map_err(|e| e.to_string())?;
        self.last_ns = None;
        self.last_read_ns = None;
        self.clock = None;
        self.next_out = 0;
        self.next_heartbeat_ns = 0;
        self.update(|r| {
            r.init = setup.mpu9250;
            r.setup = Some(setup);
            r.inits += 1;
        });
        Ok(board)
    }

    /// Sends what is due at the sample instant `t_ns`.
    fn output(&mut self, t_ns: u64, body_rate: [f64; 3]) {
        if t_ns >= self.next_heartbeat_ns {
            self.next_heartbeat_ns = t_ns + 1_000_000_000;
            self.send("HEARTBEAT", &heartbeat());
        }
        let due = match self.config.output {
            OutputRate::EverySample => true,
            OutputRate::Hz(hz) => {
                let instant = |k: u64| (k as f64 * 1e9 / hz).floor() as u64;
                let due = t_ns >= instant(self.next_out);
                while instant(self.next_out) <= t_ns {
                    self.next_out += 1;
                }
                due
            }
        };
        if due {
            let q = self.filter.quaternion();
            let ms = u32::try_from(t_ns / 1_000_000).unwrap_or(u32::MAX);
            self.send("ATTITUDE", &attitude(ms, q, body_rate));
            self.send(
                "ATTITUDE_QUATERNION",
                &attitude_quaternion(ms, q, body_rate),
            );
        }
    }

    fn send(&mut self, name: &'static str, message: &MavMessage) {
        // MAVLink 2 carries every common message: encoding cannot fail.
        let Ok(frame) = self.mavlink.encode(message) else {
            return;
        };
        let queued = self.uart.send(frame);
        let dropped = self.uart.dropped();
        self.update(|r| {
            if queued {
                *r.sent.entry(name).or_default() += 1;
            }
            r.dropped = dropped;
        });
    }

    fn update(&self, f: impl FnOnce(&mut FcReport)) {
        f(&mut self.report.lock().unwrap_or_else(|e| e.into_inner()));
    }
}

/// The instants of the samples read from a FIFO: sample `k` of the stream is `first + k`
/// periods after the first (rounded to the ns), whenever the flight controller got to read it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SampleClock {
    first_ns: u64,
    period_ns: f64,
    next: u64,
}

impl SampleClock {
    /// The clock of a stream whose first batch holds `n` samples, the newest served at
    /// `newest_ns`.
    fn anchored(newest_ns: u64, n: u64, period_ns: f64) -> Self {
        let back_ns = ((n - 1) as f64 * period_ns).round() as u64;
        Self {
            first_ns: newest_ns.saturating_sub(back_ns),
            period_ns,
            next: 0,
        }
    }

    /// The next sample's instant.
    fn next_ns(&mut self) -> u64 {
        let t = self.first_ns + (self.next as f64 * self.period_ns).round() as u64;
        self.next += 1;
        t
    }
}

fn heartbeat() -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_QUADROTOR,
        autopilot: MavAutopilot::MAV_AUTOPILOT_GENERIC,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    })
}

/// `ecf (kp = 0.5, ki = 0) over SPI: WHO_AM_I 0x71, AK8963 0x48; 600 samples (0 late); sent
/// ATTITUDE 150, …; 0 dropped; filter: 0 skipped updates, 0 skipped accel, 0 skipped mag, 0
/// rejected`.
impl std::fmt::Display for FcReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} over {}: ", self.filter, self.bus)?;
        match (&self.init, &self.setup) {
            (Some(i), _) => write!(
                f,
                "WHO_AM_I {:#04x}, AK8963 {:#04x}",
                i.who_am_i, i.ak8963_wia
            )?,
            (None, Some(s)) => write!(
                f,
                "{} WHO_AM_I {:#04x}{}",
                s.model.part_name(),
                s.who_am_i,
                if s.model.has_magnetometer() || self.compass.is_some() {
                    ""
                } else {
                    ", no magnetometer (heading from the gyroscope alone)"
                }
            )?,
            (None, None) => f.write_str("chip never set up")?,
        }
        if let Some(c) = &self.compass {
            write!(
                f,
                "; compass {} at I2C {:#04x} (identity {:#04x}): {} readings, {} not ready, {} failed",
                c.model.part_name(),
                c.address,
                c.identity,
                self.compass_readings,
                self.compass_not_ready,
                self.compass_failed
            )?;
        }
        let sent: Vec<String> = self.sent.iter().map(|(m, n)| format!("{m} {n}")).collect();
        let d = &self.diagnostics;
        write!(
            f,
            "; {} samples read ({} warm-up), {} missed{}; sent {}; {} dropped; filter: {} skipped updates, {} skipped accel, {} skipped mag, {} rejected",
            self.samples,
            self.warmup,
            self.missed,
            match (self.overflows, self.resyncs) {
                (0, 0) => String::new(),
                (n, 0) => format!(" ({n} FIFO overflows)"),
                (n, r) => format!(" ({n} FIFO overflows, {r} clock resyncs)"),
            },
            if sent.is_empty() { "nothing".into() } else { sent.join(", ") },
            self.dropped,
            d.skipped_updates,
            d.skipped_accel,
            d.skipped_mag,
            d.rejected
        )?;
        if let Some(e) = &self.error {
            write!(f, "; stopped: {e}")?;
        }
        Ok(())
    }
}
