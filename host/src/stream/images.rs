//! The host's prediction: every register image of a scene, computed before streaming.
//!
//! Per output sample `k`: truth → [`MargSim`] (the shared `model` crate, as `simulate` runs it)
//! → physical units of the chip (field × [`ImageSettings::mag_ut_per_unit`] µT, die temperature
//! from `[sensors] temperature` or [`ImageSettings::default_temp_c`]) →
//! [`ImageRepr::from_physical`] with the explicit [`ImageSettings::image`] register settings.
//! The chip is mounted with the plate's axes (identity rotation).
//!
//! ```
//! use margemu::scene::Scene;
//! use margemu::stream::{predict, ImageSettings};
//! let scene = Scene::parse_str(
//!     "duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! let samples = predict(&scene, &ImageSettings::for_scene(&scene)).unwrap();
//! assert_eq!(samples.len(), 10);
//! // Level at rest: +1 g on z at ±2 g full scale is 16384 = 0x4000, big-endian.
//! assert_eq!(&samples[0].image[4..6], &[0x40, 0x00]);
//! ```

use crate::marg::MargSim;
use crate::scene::{FieldUnit, Scene};
use crate::truth::Truth;
use margemu_protocol::link::Image;
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};

/// µT per normalized field unit ("nu") unless told otherwise: the author's reference field has
/// about unit norm, and 50 µT is a typical geomagnetic magnitude.
pub const DEFAULT_UT_PER_NU: f64 = 50.0;

/// How physical samples become register images. Every field is written to `meta.toml`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSettings {
    /// Full scales, magnetometer resolution, fuse ROM ASA and offsets assumed for the chip.
    /// The emulated chip's power-on state ([`chip_power_on`]) unless the caller says otherwise.
    pub image: ImageConfig,
    /// µT per unit of the scene's magnetic field.
    pub mag_ut_per_unit: f64,
    /// Die temperature when the scene names none, °C.
    pub default_temp_c: f32,
}

impl ImageSettings {
    /// The emulated chip's power-on settings ([`chip_power_on`]); 1 µT per unit for µT scenes, [`DEFAULT_UT_PER_NU`] for
    /// normalized ones; 25 °C.
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            image: chip_power_on(),
            mag_ut_per_unit: match scene.spec.field.unit {
                FieldUnit::Microtesla => 1.0,
                FieldUnit::Normalized => DEFAULT_UT_PER_NU,
            },
            default_temp_c: 25.0,
        }
    }
}

/// The conversion of the emulated chip at power-on, as the firmware's chip reports it: ±2 g,
/// ±250 °/s, AK8963 14-bit, the AK8963's fuse ROM sensitivity adjustment (ASA, so a driver that
/// applies it reads the true field), no offsets.
pub fn chip_power_on() -> ImageConfig {
    margemu_firmware::chip::Mpu6xxx::new().image_config()
}

/// One output sample: its truth and the register image the device should serve for it.
#[derive(Clone, Copy, Debug)]
pub struct PredictedSample {
    /// Ground truth at the latch instant (`truth.t_ns`).
    pub truth: Truth,
    /// The 22-byte register image.
    pub image: Image,
}

/// Every sample of `scene`, in order.
pub fn predict(
    scene: &Scene,
    settings: &ImageSettings,
) -> Result<Vec<PredictedSample>, crate::run::RunError> {
    let mut marg = MargSim::new(scene).map_err(crate::run::RunError::Model)?;
    let temperature = scene.spec.sensors.temperature;
    let mut out = Vec::with_capacity(scene.samples() as usize);
    crate::run::for_each(scene, |truth| {
        let s = marg.sample(truth).sample;
        // Same expression as `MargSim`, so the temperature the model sees is the one sent.
        let temp_c = temperature.map_or(settings.default_temp_c, |[start, slope]| {
            (start + slope * truth.t_ns as f64 * 1e-9) as f32
        });
        let mag_ut = s
            .mag
            .map(|v| (f64::from(v) * settings.mag_ut_per_unit) as f32);
        let repr = ImageRepr::from_physical(s.acc, s.gyr, temp_c, mag_ut, &settings.image);
        out.push(PredictedSample {
            truth: *truth,
            image: repr.emit(),
        });
    })?;
    Ok(out)
}

/// Lowercase hex of an image (44 characters), as in `sent.csv`.
pub fn image_hex(image: &Image) -> String {
    image.iter().map(|b| format!("{b:02x}")).collect()
}

/// Parses [`image_hex`] back; `None` unless exactly 44 hex digits.
pub fn parse_image_hex(hex: &str) -> Option<Image> {
    let bytes = hex.as_bytes();
    if bytes.len() != 2 * margemu_protocol::link::IMAGE_LEN {
        return None;
    }
    let mut out = [0u8; margemu_protocol::link::IMAGE_LEN];
    for (i, pair) in bytes.chunks(2).enumerate() {
        out[i] = u8::from_str_radix(std::str::from_utf8(pair).ok()?, 16).ok()?;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_round_trips() {
        let mut image = [0u8; 22];
        image[0] = 0xAB;
        image[21] = 0x01;
        let hex = image_hex(&image);
        assert_eq!(&hex[..4], "ab00");
        assert_eq!(parse_image_hex(&hex), Some(image));
        assert_eq!(parse_image_hex("zz"), None);
    }
}
