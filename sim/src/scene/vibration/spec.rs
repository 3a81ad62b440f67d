//! `[vibration]` as written in a scene file (plate axes, seconds, rpm, g²/Hz).

use super::SamplingPath;
use serde::Deserialize;
use std::path::PathBuf;

/// `[vibration]`: the sampling path and the sources.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct VibrationSpec {
    /// Where the devices' chains run (default `auto`).
    #[serde(default)]
    pub path: SamplingPath,
    /// `[[vibration.tones]]`: motor tones.
    #[serde(default)]
    pub tones: Vec<ToneSpec>,
    /// `[[vibration.random]]`: random vibration from a PSD.
    #[serde(default)]
    pub random: Vec<RandomSpec>,
    /// `[[vibration.shocks]]`: half-sine shocks.
    #[serde(default)]
    pub shocks: Vec<ShockSpec>,
}

/// `[[vibration.tones]]`: motors on one rpm profile, with their harmonics.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ToneSpec {
    /// Only this device (a device's name); absent: every device.
    pub device: Option<String>,
    /// Number of motors.
    pub motors: u64,
    /// Relative rpm spread between motors, in [0, 1).
    #[serde(default)]
    pub spread: f64,
    /// A constant rpm.
    pub rpm: Option<f64>,
    /// A linear ramp.
    pub rpm_ramp: Option<RampSpec>,
    /// `[time s, rpm]` steps.
    pub rpm_steps: Option<Vec<[f64; 2]>>,
    /// A CSV file with columns `t_s` and `rpm`, relative to the scene file.
    pub rpm_csv: Option<PathBuf>,
    /// `[[vibration.tones.harmonics]]`.
    #[serde(default)]
    pub harmonics: Vec<HarmonicSpec>,
}

/// `rpm_ramp = { from, to, start, end }`: `from` rpm until `start` s, linear to `to` rpm at
/// `end` s, `to` after.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RampSpec {
    /// Rpm before and at `start`.
    pub from: f64,
    /// Rpm at and after `end`.
    pub to: f64,
    /// Start of the ramp, s.
    pub start: f64,
    /// End of the ramp, s.
    pub end: f64,
}

/// `[[vibration.tones.harmonics]]`: one harmonic, amplitudes per motor in plate axes.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HarmonicSpec {
    /// Multiple of the rotation frequency.
    pub order: f64,
    /// Peak linear acceleration per motor, m/s².
    #[serde(default)]
    pub linear: [f64; 3],
    /// Peak angular rate per motor, rad/s.
    #[serde(default)]
    pub angular: [f64; 3],
}

/// `[[vibration.random]]`: a PSD, with amplitude gains per plate axis.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RandomSpec {
    /// Only this device; absent: every device.
    pub device: Option<String>,
    /// `[Hz, g²/Hz]` breakpoints.
    pub psd: Vec<[f64; 2]>,
    /// Amplitude factor per plate axis (default 1).
    #[serde(default = "unit_gains")]
    pub gains: [f64; 3],
}

fn unit_gains() -> [f64; 3] {
    [1.0; 3]
}

/// `[[vibration.shocks]]`: a half-sine pulse.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShockSpec {
    /// Only this device; absent: every device.
    pub device: Option<String>,
    /// Start, s.
    pub at: f64,
    /// Duration, s.
    pub duration: f64,
    /// Peak linear acceleration, m/s², plate axes.
    #[serde(default)]
    pub linear: [f64; 3],
    /// Peak angular rate, rad/s, plate axes.
    #[serde(default)]
    pub angular: [f64; 3],
}
