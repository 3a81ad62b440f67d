//! Vibration in scenes: `[vibration]` and its `tones`, `random` and `shocks` sources, resolved
//! per device.
//!
//! Every source is given in plate axes and reaches every device, or only the device its
//! `device` key names; [`DeviceVibration`] holds what reaches one device, already turned into
//! that device's chip axes (tone and shock amplitudes rotated by the device's mounting
//! rotation; the random source keeps its gains in plate axes and carries the rotation in
//! [`RandomSource::axes`]). Times become integer nanoseconds (rounded to the nearest). The
//! schema is [`VibrationSpec`]; the user guide (`docs/scene-files.md`, "Vibration") lists every
//! key. Every refusal is located at the offending key; an `rpm_csv` problem also names the CSV
//! file and line.
//!
//! ```
//! let text = "duration = 1.0\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n\
//!     [[vibration.tones]]\nmotors = 2\nrpm_ramp = { from = 6000, to = 12000, start = 0.5, end = 1.0 }\n\
//!     [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 3.0]\n";
//! let scene = margemu_sim::scene::Scene::parse_str(text, std::path::Path::new("v.toml")).unwrap();
//! let tone = &scene.vibration[0].tones[0];
//! assert_eq!(tone.profile[1].t_ns, 1_000_000_000);
//! assert_eq!(tone.harmonics()[0].linear, [0.0, 0.0, 3.0]);
//! assert_eq!(tone.max_frequency_hz(), 200.0);
//! ```

mod at;
mod resolve;
mod rpm;
mod spec;
mod warn;

pub(crate) use resolve::resolve;
pub use resolve::CHECK_RATE_HZ;
pub use spec::{HarmonicSpec, RampSpec, RandomSpec, ShockSpec, ToneSpec, VibrationSpec};
pub(crate) use warn::collect as warnings;

use margemu_model::vibration::{RandomSource, RpmPoint, Shock, ToneSource};

/// Where a device's chain runs (`[vibration] path`: `"auto"`, `"internal"`, `"output"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SamplingPath {
    /// The internal-rate path when some vibration reaching the device has content above the
    /// output Nyquist frequency ([`DeviceVibration::max_frequency_hz`]), else the output path.
    #[default]
    Auto,
    /// Always the chip's internal rate, filters and decimation.
    Internal,
    /// Always at the output instants (vibration added, no chip filters).
    Output,
}

/// The vibration reaching one device, in its chip axes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DeviceVibration {
    /// Motor tone sources.
    pub tones: Vec<ToneSource<Vec<RpmPoint>>>,
    /// The random source (at most one reaches a device).
    pub random: Option<RandomSource>,
    /// Half-sine shocks.
    pub shocks: Vec<Shock>,
}

impl DeviceVibration {
    /// Whether nothing vibrates the device.
    pub fn is_empty(&self) -> bool {
        self.tones.is_empty() && self.random.is_none() && self.shocks.is_empty()
    }

    /// The highest frequency with content, Hz: a tone's highest, a PSD's last breakpoint, and
    /// 1.5 / duration for a shock (its half-sine's spectrum has fallen by 20 dB there).
    pub fn max_frequency_hz(&self) -> f64 {
        let tones = self.tones.iter().map(ToneSource::max_frequency_hz);
        let random = self.random.iter().map(RandomSource::max_frequency_hz);
        let shocks = self
            .shocks
            .iter()
            .map(|s| 1.5e9 / s.duration_ns.max(1) as f64);
        tones.chain(random).chain(shocks).fold(0.0, f64::max)
    }
}
