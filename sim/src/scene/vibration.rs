//! Vibration in scenes: `[vibration]` and its `tones`, `random` and `shocks` sources, resolved
//! per device (CONTRACT: the types below are fixed; the parsing lands with the scene schema).
//!
//! Every source is given in plate axes and reaches every device, or only the device its
//! `device` key names; [`DeviceVibration`] holds what reaches one device, already turned into
//! that device's chip axes (tone and shock amplitudes rotated; the random source carries the
//! rotation in [`RandomSource::axes`]).

use margemu_model::vibration::{RandomSource, RpmPoint, Shock, ToneSource};

/// Where a device's chain runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
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
