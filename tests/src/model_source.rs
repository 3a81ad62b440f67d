//! Source mode (b) from the host's side, for the QEMU tests and benches: a scene's truth sent
//! as Kinematics at a lower rate, the [`ModelParams`] seeded from the scene, and every register
//! image the device must serve — the host's own prediction,
//! [`margemu::stream::predict_model`] (zero-order hold of the kinematics, one `Marg` seeded
//! with the scene's seed at the output rate, the chip's power-on conversion; see its module
//! docs). Nothing here calls the firmware's own model path, so a served image equal to the
//! prediction shows the device's model bit-identical to the host's.
//!
//! The kinematics are the scene's truth at every `decimation`-th output sample, so they carry
//! the same instants as the scene's own truth: `truth_rate = output rate / decimation`.

use margemu::scene::chip::ChipSetup;
use margemu::scene::Scene;
use margemu::stream::{fault_messages, predict_model, rate_of, ImageSettings, StreamError};
use margemu_model::sensor::Truth;
use margemu_protocol::link::{
    AddFault, AddVibration, Configure, Image, ModelParams, Rate, Source, CRC32C,
};

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
    /// The scene's chip, whose Configure settings the images were converted with.
    pub chip: ChipSetup,
    /// The AddVibration messages that follow Configure (the chain the device runs).
    pub vibration: Vec<AddVibration>,
    /// The AddFault messages that follow them (the scene's fault schedule; device 0's sensor
    /// faults are in `images`).
    pub faults: Vec<AddFault>,
}

/// Why a scene cannot be streamed in source mode (b).
#[derive(Debug)]
pub enum ModelStreamError {
    /// `decimation` is zero.
    Rate(String),
    /// The host's planner refused the scene (a perturbation, a rate that does not divide, a
    /// model term the model refuses, the scene's motion failing).
    Stream(StreamError),
}

impl std::fmt::Display for ModelStreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rate(why) => write!(f, "rate: {why}"),
            Self::Stream(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for ModelStreamError {}

impl ModelStream {
    /// Prepares `scene`, sending one kinematics sample per `decimation` output samples.
    pub fn from_scene(scene: &Scene, decimation: u32) -> Result<Self, ModelStreamError> {
        if decimation == 0 {
            return Err(ModelStreamError::Rate("decimation 0".into()));
        }
        let out_rate = rate_of(scene).map_err(ModelStreamError::Stream)?;
        let kinematics_hz = out_rate.as_hz_f64() / f64::from(decimation);
        let prediction =
            predict_model(scene, &ImageSettings::for_scene(scene), Some(kinematics_hz))
                .map_err(ModelStreamError::Stream)?;
        let (mut kinematics, mut images) = (Vec::new(), Vec::new());
        for s in prediction.samples {
            let s = s.map_err(|e| ModelStreamError::Stream(e.into()))?;
            kinematics.extend(s.kinematics);
            images.push(s.sample.image);
        }
        Ok(Self {
            out_rate,
            params: prediction.params,
            vibration: prediction.vibration,
            faults: fault_messages(scene),
            kinematics,
            images,
            chip: scene.chip,
        })
    }

    /// The Configure that sets the device up for this stream.
    pub fn configure(&self, telemetry_period_ns: u64) -> Configure {
        Configure {
            source: Source::Model(self.params),
            telemetry_period_ns,
            ..self.chip.configure(self.out_rate)
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
            Err(ModelStreamError::Stream(StreamError::Model { .. }))
        ));
        let s = scene("duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n");
        assert!(matches!(
            ModelStream::from_scene(&s, 0),
            Err(ModelStreamError::Rate(_))
        ));
    }
}
