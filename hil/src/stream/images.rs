//! The host's prediction: the register image of every sample of a scene, computed in order
//! as it is read ([`predict_images`]: a [`Predictions`] iterator, so a scene of any length
//! takes the same memory).
//!
//! Per output sample `k`: truth, turned into the chip's axes by the scene's `[chip] rotation` →
//! [`MargSim`] (the shared `model` crate, as `simulate` runs it) → physical units of the chip
//! (field × [`ImageSettings::mag_ut_per_unit`] µT, die temperature from `[sensors] temperature`
//! or [`ImageSettings::default_temp_c`]) → the chip module's conversion with the explicit
//! [`ImageSettings::chip`] register settings ([`ChipSettings::image`]).
//!
//! The scene's sensor faults act in [`MargSim`] (each device's own), and a dropout marks the
//! sensor's registers with the chip's invalid value ([`ChipSettings::faulted_image`]).
//!
//! A rig (`[[device]]`) does this for every device, each with its own model
//! ([`MargSim::for_device`]: its seed and lever arm), in its own axes, with its own settings
//! (the first device's are [`ImageSettings::chip`]), and the sample's image is every device's
//! image in device order, back to back: what the link carries.
//!
//! ```
//! use margemu_sim::scene::Scene;
//! use margemu_hil::stream::{predict_images, ImageSettings};
//! let scene = Scene::parse_str(
//!     "duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! let samples: Vec<_> = predict_images(&scene, &ImageSettings::for_scene(&scene))
//!     .collect::<Result<_, _>>()
//!     .unwrap();
//! assert_eq!(samples.len(), 10);
//! // Level at rest: +1 g on z at ±2 g full scale is 16384 = 0x4000, big-endian.
//! assert_eq!(&samples[0].image[4..6], &[0x40, 0x00]);
//! ```

use super::clipping::Clips;
use super::predictor::{run_scene, Halt, Predictions};
use margemu_protocol::chip::{ChipSettings, PhysicalSample};
use margemu_protocol::link::Image;
use margemu_sim::marg::MargSim;
use margemu_sim::scene::chip::ChipSetup;
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;

/// µT per normalized field unit ("nu") unless told otherwise: the author's reference field has
/// about unit norm, and 50 µT is a typical geomagnetic magnitude.
pub const DEFAULT_UT_PER_NU: f64 = margemu_sim::mcap::UT_PER_NU;

/// How physical samples become register images. Every field is written to `meta.toml`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageSettings {
    /// The chip model and the register settings (full scales, magnetometer resolution, fuse
    /// ROM, offsets) its images are computed with: the scene's `[chip]` unless the caller says
    /// otherwise.
    pub chip: ChipSettings,
    /// µT per unit of the scene's magnetic field.
    pub mag_ut_per_unit: f64,
    /// Die temperature when the scene names none, °C.
    pub default_temp_c: f32,
}

impl ImageSettings {
    /// The scene's chip settings (`[chip]`: power-on with its full scales); 1 µT per unit for µT
    /// scenes, [`DEFAULT_UT_PER_NU`] for normalized ones; 25 °C.
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            chip: scene.chip.settings,
            mag_ut_per_unit: margemu_sim::mcap::ut_per_unit(scene.spec.field.unit),
            default_temp_c: 25.0,
        }
    }
}

/// One output sample: its truth and the register image the device should serve for it.
#[derive(Clone, Copy, Debug)]
pub struct PredictedSample {
    /// Ground truth at the latch instant (`truth.t_ns`).
    pub truth: Truth,
    /// The register image, of the chip model's length.
    pub image: Image,
    /// Each device's front-end clipping so far ([`super::clipping`]).
    pub clips: Clips,
}

/// Every sample of `scene`, in order, predicted lazily on a thread of its own (see
/// [`Predictions`]); an error (the scene's references, its sensor model) ends the iteration.
pub fn predict_images(scene: &Scene, settings: &ImageSettings) -> Predictions<PredictedSample> {
    let (scene, settings) = (scene.clone(), *settings);
    Predictions::spawn(move |emit| {
        let mut devices = Vec::new();
        for (i, device) in scene.devices().into_iter().enumerate() {
            let marg = MargSim::for_device(&scene, i)
                .unwrap_or_else(|| MargSim::new(&scene))
                .map_err(margemu_sim::run::RunError::Model)?;
            let chip_settings = if i == 0 {
                settings.chip
            } else {
                device.chip.settings
            };
            devices.push((marg, device.chip, chip_settings));
        }
        let temperature = scene.spec.sensors.temperature;
        run_scene(&scene, |truth| {
            // Same expression as `MargSim`, so the temperature the model sees is the one sent.
            let temp_c = temperature.map_or(settings.default_temp_c, |[start, slope]| {
                (start + slope * truth.t_ns as f64 * 1e-9) as f32
            });
            let mut image = [0u8; margemu_protocol::chip::MAX_IMAGE_LEN];
            let mut len = 0;
            let mut clips = Clips::default();
            for ((marg, chip, chip_settings), clip) in devices.iter_mut().zip(&mut clips) {
                let marg_sample = marg
                    .try_sample(&scene, &in_chip_axes(truth, chip))
                    .map_err(|e| Halt::Failed(margemu_sim::run::RunError::NonFinite(e)))?;
                let s = marg_sample.sample;
                let sample = PhysicalSample {
                    acc: s.acc,
                    gyr: s.gyr,
                    mag: s
                        .mag
                        .map(|v| (f64::from(v) * settings.mag_ut_per_unit) as f32),
                    temp_c,
                };
                *clip = marg.clips();
                let one = chip_settings.faulted_image(&sample, marg_sample.dropout);
                let end = (len + one.len()).min(image.len());
                image[len..end].copy_from_slice(&one[..end - len]);
                len = end;
            }
            Ok(emit(PredictedSample {
                truth: *truth,
                image: Image::new(&image[..len]).unwrap_or_default(),
                clips,
            })?)
        })
    })
}

/// The truth's body-frame vectors (rate, specific force, field, angular acceleration) in the
/// chip's axes (`[chip] rotation`); the rest as it is.
pub fn in_chip_axes(truth: &Truth, chip: &ChipSetup) -> Truth {
    if chip.rotation.is_none() {
        return *truth;
    }
    Truth {
        body_rate: chip.to_chip(truth.body_rate),
        specific_force: chip.to_chip(truth.specific_force),
        field_body: chip.to_chip(truth.field_body),
        angular_accel: chip.to_chip(truth.angular_accel),
        accel_body: chip.to_chip(truth.accel_body),
        ..*truth
    }
}
