//! The virtual flight controller: a device under test that reads the emulated chip through a
//! third-party driver crate over the virtual bus (`mpu9250` for the MPU-9250, `icm426xx` for the
//! ICM-42688-P) and, on a rig, its external compass over I2C, runs a reference filter, and sends
//! MAVLink ATTITUDE and ATTITUDE_QUATERNION over a pseudo-terminal, like a real board would.
//!
//! In loopback the firmware's link handler ([`crate::loopback`]) runs in a thread and latches
//! the host's register images into its chip at their instants. The flight controller
//! ([`fc::VirtualFc`]) runs in that same thread, at every turn of the device's loop, and sees
//! the chips only as a board does:
//!
//! - [`board`]: one board per chip model, chosen by the model of the device's chip. On the
//!   MPU-9250 ([`board::mpu9250`]) the unmodified `mpu9250` crate initialises the chip (reset,
//!   WHO_AM_I, ±16 g, ±2000 °/s, DLPF, sample-rate divider, the AK8963 through the driver's own
//!   path), then the board latches INT on data ready and sets the FIFO up with raw register
//!   writes on the same bus (the auxiliary master's slave 0 reads the AK8963 into it), and reads
//!   every sample from the FIFO as ArduPilot's Invensense driver does (SPI). On the ICM-42688-P ([`board::icm42688p`]) the unmodified `icm426xx`
//!   crate initialises the chip (reset, WHO_AM_I, ±16 g, ±2000 °/s, the scene's ODR, 20-bit
//!   FIFO packets, INT1 on the FIFO watermark) and the board drains the FIFO on INT1 through
//!   the driver (SPI). Every value comes from the chip's registers through margemu's
//!   embedded-hal adapters, never from the host's predicted samples, and is converted by the
//!   chip module (`margemu_protocol::regmap`) or the driver, never by the board;
//! - [`compass`]: a rig's external compass (an IST8310 or a QMC5883L among the scene's
//!   `[[device]]`s), found at its I2C address in the device's rig, identified, set up and read
//!   at 100 Hz with raw register transactions as ArduPilot's compass backends do, each reading
//!   turned from the compass's axes into the IMU's with both devices' scene rotations
//!   ([`CompassConfig`]: what a real flight controller's configuration tells it);
//! - [`axes`]: the body frame, and the magnetometer's axes turned into it ([`MagAlignment`], by
//!   default the chip module's own mapping of the AK8963);
//! - the filter: ECF, GDA or EKF of `margemu-filters` in `f64`, with the parameters of
//!   [`margemu_sim::filter_params::FilterParams`] (defaults, or a parameters file as `margemu tune` writes
//!   it), starting from its first sample;
//! - [`uart`]: the MAVLink 2 frames ([`crate::dut::mavlink_out`]) are queued to a thread that
//!   writes them to one end of a second pseudo-terminal pair;
//! - [`rig`]: the device with its flight controller on a PTY, the host end of the flight
//!   controller's UART, a device-under-test reader ([`crate::dut`]) sharing the session's clock
//!   and directory ([`rig::attach`]), and one whole loopback run ([`rig::run_loopback`]).
//!
//! The host must compute its register images for the full scales the driver sets:
//! [`image_settings`]. The flight controller checks, after set-up, that the chip converts
//! exactly that way, and stops the device with the reason if not.
//!
//! **The magnetometer.** When the scene's rig has an external compass, the filter takes its
//! field with every IMU sample (the newest reading, held between the compass's 10 ms
//! readings; see [`fc`]) and the board's own magnetometer is not used, as a flight controller
//! prefers its external compass. Otherwise the MPU-9250's AK8963 comes with every FIFO record.
//! **The ICM-42688-P has no magnetometer:** alone, the filters run on gyroscope and
//! accelerometer (see [`fc`]): roll and pitch as with a magnetometer, the heading from the
//! gyroscope alone, 0 at the first sample. A score of such a run carries the truth's initial
//! heading and the yaw drift in its yaw and geodesic errors; roll and pitch are the comparable
//! ones. With the rig's compass (the built-in scene `rig`: an ICM-42688-P and an IST8310
//! mounted upside down) the heading is the compass's, and the whole attitude is comparable.
//!
//! A compass the configuration names but the device does not have (nothing answers its
//! address, or another identity does) stops the flight controller with the reason once the
//! device runs.

pub mod axes;
pub mod board;
pub mod compass;
pub mod fc;
pub mod rig;
pub mod uart;

pub use axes::MagAlignment;
pub use compass::CompassConfig;
pub use fc::{FcReport, VirtualFc};
pub use rig::{attach, run_loopback, spawn, AttachedDut, FcOutcome, VfcError, VfcRig, VfcRun};

use crate::stream::ImageSettings;
use margemu_sim::filter_params::FilterParams;
use margemu_sim::scene::Scene;
use std::fmt;
use std::str::FromStr;

/// How often the flight controller sends its attitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutputRate {
    /// At this rate on the device clock (instants `floor(k·10⁹/hz)` ns; each output goes with
    /// the first sample read at or after its instant).
    Hz(f64),
    /// After every sample read.
    EverySample,
}

impl Default for OutputRate {
    /// 50 Hz, a typical telemetry rate for ATTITUDE.
    fn default() -> Self {
        Self::Hz(50.0)
    }
}

impl fmt::Display for OutputRate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Hz(hz) => write!(f, "{hz} Hz"),
            Self::EverySample => f.write_str("every sample"),
        }
    }
}

/// `50` (Hz, > 0) or `every`.
impl FromStr for OutputRate {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if s == "every" {
            return Ok(Self::EverySample);
        }
        match s.parse::<f64>() {
            Ok(hz) if hz.is_finite() && hz > 0.0 => Ok(Self::Hz(hz)),
            _ => Err(format!("`{s}`: expected a rate in Hz (> 0) or `every`")),
        }
    }
}

/// What the flight controller runs and sends.
#[derive(Clone, Debug, PartialEq)]
pub struct VfcConfig {
    /// The filter and its parameters.
    pub filter: FilterParams,
    /// World-frame magnetic reference the filter uses (only its direction matters).
    pub mag_reference: [f64; 3],
    /// Attitude output rate.
    pub output: OutputRate,
    /// How the magnetometer's axes map to the body's (the MPU-9250's AK8963; unused on a chip
    /// without a magnetometer).
    pub mag_alignment: MagAlignment,
    /// The sample rate the board asks of the chip (Hz): the scene's output rate.
    pub sample_rate_hz: f64,
    /// The rig's external compass, read instead of the board's magnetometer
    /// ([`compass`]); `None`: the board's own (or none).
    pub compass: Option<CompassConfig>,
}

impl VfcConfig {
    /// `filter` on `scene`: the scene's field direction and rate, 50 Hz output, the MPU-9250's
    /// magnetometer alignment, and the rig's external compass if it has one
    /// ([`CompassConfig::for_scene`]).
    pub fn for_scene(scene: &Scene, filter: FilterParams) -> Self {
        Self {
            filter,
            mag_reference: scene.spec.field.reference,
            output: OutputRate::default(),
            mag_alignment: MagAlignment::default(),
            sample_rate_hz: scene.clock.hz(),
            compass: CompassConfig::for_scene(scene),
        }
    }
}

/// `kp = 0.5, ki = 0`: a filter's parameters, for reports.
pub fn describe(params: &FilterParams) -> String {
    let parts: Vec<String> = params
        .iter()
        .map(|(spec, v)| format!("{} = {v}", spec.name))
        .collect();
    parts.join(", ")
}

/// The image settings for the scene's chip as the flight controller's board sets it up: the
/// full scales its driver configures ([`board::chip_settings`] of the scene's model), otherwise
/// those of [`ImageSettings::for_scene`]. An error if there is no board for the scene's chip.
pub fn image_settings(scene: &Scene) -> Result<ImageSettings, board::NoBoard> {
    Ok(ImageSettings {
        chip: board::chip_settings(scene.chip.model)?,
        ..ImageSettings::for_scene(scene)
    })
}

/// Whether the flight controller of the session in `dir` had a magnetometer: its chip's own
/// (`meta.toml`'s `[chip] model`) or a rig's external compass (a magnetometer among
/// `[[other_devices]]`); `true` when that cannot be read (the MPU-9250, the default chip, has
/// one).
pub fn session_has_magnetometer(dir: &std::path::Path) -> bool {
    use margemu_protocol::chip::ChipModel;
    let Some(meta) = margemu_sim::meta::read(dir).ok() else {
        return true;
    };
    let Some(session) = meta.session() else {
        return true;
    };
    let model = |name: &str| ChipModel::from_name(name);
    let external = session
        .other_devices
        .iter()
        .any(|d| model(&d.model).is_some_and(ChipModel::is_magnetometer_only));
    external || model(&session.chip.model).is_none_or(ChipModel::has_magnetometer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_rates_parse() {
        assert_eq!("every".parse(), Ok(OutputRate::EverySample));
        assert_eq!("12.5".parse(), Ok(OutputRate::Hz(12.5)));
        for bad in ["0", "-3", "inf", "fast"] {
            assert!(bad.parse::<OutputRate>().is_err(), "{bad}");
        }
    }
}
