//! Source mode (b) from the host's side: a scene's truth sent as Kinematics at a lower rate,
//! the [`ModelParams`] seeded from the scene, and every register image the device must serve,
//! predicted here on the host with the shared model.
//!
//! The prediction follows the device's contract (`docs/spec/link.md` §5.3.1, §5.7): at output
//! instant `t_k` the device holds the latest kinematics sample `j` with `t_j ≤ t_k` (zero-order
//! hold), steps one [`Marg`] seeded with the scene's seed at the output rate, scales the field to
//! µT with `(f64::from(m) * mag_ut_per_unit) as f32`, takes the die temperature of the
//! kinematics (21 °C, TEMP_OUT 0, when absent), and converts with
//! [`ImageRepr::from_physical`] under the register settings of the chip as Configure leaves it
//! (power-on, no overrides). Nothing here calls the firmware's own model path.
//!
//! The kinematics are the scene's truth at every `decimation`-th output sample, so they carry
//! the same instants as the scene's own truth: `truth_rate = output rate / decimation`. Each
//! is what `MargSim` would feed the model: the body-frame truth rounded to `f32`, with the
//! scene's `[sensors] temperature` at its instant.

use margemu::reference::ReferenceError;
use margemu::scene::Scene;
use margemu::stream::{rate_of, ImageSettings, WHO_AM_I};
use margemu_firmware::chip::Mpu9250;
use margemu_model::sensor::{Marg, Truth};
use margemu_protocol::link::{Configure, Image, ModelParams, Rate, Source, CRC32C};
use margemu_protocol::regmap::convert::TEMP_OFFSET_C;
use margemu_protocol::regmap::image::{ImageConfig, ImageRepr};

/// One scene prepared for source mode (b).
#[derive(Clone, Debug)]
pub struct ModelStream {
    /// The chip's output rate (the scene's rate).
    pub out_rate: Rate,
    /// What Configure carries: seed, truth rate, µT per field unit, the scene's model terms.
    pub params: ModelParams,
    /// The kinematics to send, at `params.truth_rate`.
    pub kinematics: Vec<Truth>,
    /// The image the device must serve at each output sample of the scene.
    pub images: Vec<Image>,
    /// The register settings the images were converted with.
    pub image_config: ImageConfig,
}

/// Why a scene cannot be streamed in source mode (b).
#[derive(Debug)]
pub enum ModelStreamError {
    /// The scene's rate is not an exact ratio the link can carry, or not a multiple of
    /// `decimation` times a representable truth rate.
    Rate(String),
    /// The scene has a magnetic perturbation, which the device does not generate.
    Perturbation,
    /// The shared model refused the scene's terms.
    Model(margemu_model::Error),
    /// The scene's motion could not be computed.
    Reference(ReferenceError),
}

impl std::fmt::Display for ModelStreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rate(why) => write!(f, "rate: {why}"),
            Self::Perturbation => write!(f, "a [perturbation] cannot run in source mode (b)"),
            Self::Model(e) => write!(f, "the sensor model refused the scene: {e:?}"),
            Self::Reference(e) => write!(f, "the scene's motion failed: {e}"),
        }
    }
}

impl std::error::Error for ModelStreamError {}

impl ModelStream {
    /// Prepares `scene`, sending one kinematics sample per `decimation` output samples.
    pub fn from_scene(scene: &Scene, decimation: u32) -> Result<Self, ModelStreamError> {
        if scene.spec.perturbation.is_some() {
            return Err(ModelStreamError::Perturbation);
        }
        let out_rate = rate_of(scene).map_err(|e| ModelStreamError::Rate(e.to_string()))?;
        let truth_rate = out_rate
            .den()
            .checked_mul(decimation)
            .and_then(|den| Rate::new(out_rate.num(), den))
            .ok_or_else(|| {
                ModelStreamError::Rate(format!("{out_rate:?} cannot be divided by {decimation}"))
            })?;
        let spec = &scene.spec;
        let mut params = ModelParams::new(spec.seed, truth_rate, spec.sensors.config());
        params.mag_ut_per_unit = ImageSettings::for_scene(scene).mag_ut_per_unit;

        let temperature = spec.sensors.temperature;
        let mut kinematics = Vec::new();
        let mut out_instants = Vec::with_capacity(scene.samples() as usize);
        margemu::run::for_each(scene, |t| {
            let k = out_instants.len() as u64;
            out_instants.push(t.t_ns);
            if k.is_multiple_of(u64::from(decimation)) {
                let f = |v: [f64; 3]| v.map(|x| x as f32);
                kinematics.push(Truth {
                    angular_rate: f(t.body_rate),
                    specific_force: f(t.specific_force),
                    magnetic_field: f(t.field_body),
                    angular_acceleration: f(t.angular_accel),
                    temperature_c: temperature
                        .map(|[start, slope]| (start + slope * t.t_ns as f64 * 1e-9) as f32),
                });
            }
        })
        .map_err(ModelStreamError::Reference)?;

        let image_config = Mpu9250::new().image_config();
        let mut marg = Marg::new(&params.marg, out_rate.as_hz_f64(), params.seed)
            .map_err(ModelStreamError::Model)?;
        let mut j = 0usize;
        let mut images = Vec::with_capacity(out_instants.len());
        for &t_k in &out_instants {
            // Zero-order hold: the latest kinematics sample at or before t_k.
            while j + 1 < kinematics.len() && truth_rate.sample_time_ns(j as u64 + 1) <= t_k {
                j += 1;
            }
            let truth = &kinematics[j];
            let s = marg.sample(truth);
            let mag_ut = s
                .mag
                .map(|m| (f64::from(m) * params.mag_ut_per_unit) as f32);
            let temp_c = truth.temperature_c.unwrap_or(TEMP_OFFSET_C);
            let repr = ImageRepr::from_physical(s.acc, s.gyr, temp_c, mag_ut, &image_config);
            images.push(repr.emit());
        }
        Ok(Self {
            out_rate,
            params,
            kinematics,
            images,
            image_config,
        })
    }

    /// The Configure that sets the device up for this stream.
    pub fn configure(&self, telemetry_period_ns: u64) -> Configure {
        Configure {
            source: Source::Model(self.params),
            telemetry_period_ns,
            ..Configure::new(WHO_AM_I, self.out_rate)
        }
    }

    /// The CRC-32C of every predicted image, as the device reports what it served.
    pub fn predicted_crcs(&self) -> Vec<u32> {
        self.images.iter().map(|i| CRC32C.checksum(i)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        Scene::parse_str(text, std::path::Path::new("inline.toml")).unwrap()
    }

    #[test]
    fn kinematics_are_every_nth_truth_and_held_over_the_outputs() {
        let s = scene(
            "duration = 0.02\nrate = 1000.0\nseed = 3\nmotion = \"kinematic\"\n\
             [joints.roll]\ntype = \"sine\"\namplitude = 0.5\nfrequency = 3.0\n",
        );
        let m = ModelStream::from_scene(&s, 5).unwrap();
        assert_eq!(m.params.truth_rate, Rate::new(1000, 5).unwrap());
        assert_eq!((m.kinematics.len(), m.images.len()), (4, 20));
        assert_eq!(m.kinematics[0].temperature_c, None);
        // Without noise the model is the truth rounded: outputs 0..5 hold the same kinematics,
        // so the same image; the roll rate changes between kinematics samples 0 and 1.
        assert!(m.images[..5].iter().all(|i| *i == m.images[0]));
        assert_ne!(m.images[4], m.images[5]);
        // Temperature absent: TEMP_OUT is 0 (21 °C).
        assert_eq!(&m.images[0][6..8], &[0, 0]);
    }

    #[test]
    fn refuses_what_the_device_cannot_do() {
        let perturbed = scene(
            "duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n\
             [perturbation]\nwindow = 0.02\ncutoff = 5.0\namplitude = [0.0, 1.0]\n\
             gap = [0.001, 0.002]\n",
        );
        assert!(matches!(
            ModelStream::from_scene(&perturbed, 5),
            Err(ModelStreamError::Perturbation)
        ));
        let s = scene("duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n");
        assert!(matches!(
            ModelStream::from_scene(&s, 0),
            Err(ModelStreamError::Rate(_))
        ));
    }
}
