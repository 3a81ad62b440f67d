//! Source mode (b): the host sends true kinematics at a lower rate and the device runs the shared
//! sensor model itself, seeded from the scene, at the chip's output rate.
//!
//! [`predict_model`] plans such a session and predicts, byte for byte and lazily in order (a
//! [`Predictions`] iterator), every register image the device will serve:
//!
//! - **kinematics**: output sample `k` of the scene has truth at `t_k`; the kinematics rate is
//!   the output rate divided by a whole number `hold` (so kinematics instants fall on output
//!   instants: `truth_rate.sample_time_ns(j) = rate.sample_time_ns(j·hold)`), and kinematics
//!   sample `j` is the truth of output sample `j·hold` in `f32` (body rate, specific force,
//!   field, angular acceleration; the scene's `[sensors] temperature` ramp at that instant, or
//!   none);
//! - **the device** (`margemu_firmware::link`, `docs/spec/link.md` §5.3.1) serves output
//!   sample `k` from the latest kinematics at or before `t_k`, i.e. `j = k / hold` (zero-order
//!   hold), steps its model ([`Marg`] with the scene's terms and seed at `rate.as_hz_f64()`)
//!   once per output instant, scales the field to µT as `(f64::from(mag) * mag_ut_per_unit) as
//!   f32`, takes the die temperature of the kinematics (21 °C without one) and converts with
//!   the settings of the chip the scene's Configure builds (the firmware's own
//!   `setup::build_chip` and `setup::model_image`, so host and device share every step).
//!
//! [`model_images`] is that last step alone, for a caller with its own kinematics (a QEMU test,
//! say). The prediction holds while the device under test leaves the full-scale and offset
//! registers where Configure put them (the device converts with the chip's current settings).
//!
//! Scenes the device cannot run are refused before anything is sent ([`StreamError::Model`]):
//! a magnetic perturbation (its generator's FFT buffers do not fit a no-alloc device), image
//! settings other than those of the configured chip, and a kinematics rate that does not divide
//! the output rate.
//!
//! ```
//! use margemu_sim::scene::Scene;
//! use margemu_hil::stream::{predict_model, ImageSettings};
//! let scene = Scene::parse_str(
//!     "duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! let p = predict_model(&scene, &ImageSettings::for_scene(&scene), Some(250.0)).unwrap();
//! let samples: Vec<_> = p.samples.collect::<Result<_, _>>().unwrap();
//! let kinematics = samples.iter().filter(|s| s.kinematics.is_some()).count();
//! assert_eq!((p.hold, kinematics, samples.len()), (4, 3, 10));
//! assert_eq!(p.params.truth_rate.as_hz_f64(), 250.0);
//! ```

use super::clipping::Clips;
use super::images::{in_chip_axes, ImageSettings, PredictedSample};
use super::predictor::{run_scene, Predictions};
use super::session::rate_of;
use super::StreamError;
use margemu_firmware::chip::{Chip, EmulatedChip};
use margemu_firmware::link::setup::{self, DeviceModel};
use margemu_model::sensor;
use margemu_protocol::link::{Image, ModelParams, Rate};
use margemu_sim::scene::chip::ChipSetup;
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;

/// The kinematics rate when none is asked for: the output rate over the smallest whole
/// `hold ≥ 2` that brings it to at most this.
pub const DEFAULT_MAX_KINEMATICS_HZ: f64 = 1000.0;

/// A planned source mode (b) session and its prediction.
pub struct ModelPrediction {
    /// Output samples per kinematics sample.
    pub hold: u32,
    /// What Configure carries: seed, kinematics rate, µT per unit, the model terms.
    pub params: ModelParams,
    /// Every output sample in order: its truth, the image the device will serve, and the
    /// kinematics sample due at its instant (every `hold`-th sample's, from sample 0).
    pub samples: Predictions<ModelSample>,
}

/// One output sample of source mode (b).
#[derive(Clone, Copy, Debug)]
pub struct ModelSample {
    /// Its truth and the image the device serves.
    pub sample: PredictedSample,
    /// The kinematics sample the host sends for this instant, if one is due (index `k / hold`
    /// at the kinematics rate).
    pub kinematics: Option<sensor::Truth>,
}

/// Plans source mode (b) for `scene` with kinematics at `kinematics_hz` (default: see
/// [`DEFAULT_MAX_KINEMATICS_HZ`]) and predicts every image (see the module docs).
pub fn predict_model(
    scene: &Scene,
    settings: &ImageSettings,
    kinematics_hz: Option<f64>,
) -> Result<ModelPrediction, StreamError> {
    if scene.is_rig() {
        return Err(StreamError::Model {
            reason: "the scene is a rig of several [[device]]s: a rig streams register images \
                     (source images), each device's model running on the host"
                .into(),
        });
    }
    if scene.spec.perturbation.is_some() {
        return Err(StreamError::Model {
            reason: "the scene has a [perturbation]: the device cannot run the perturbation \
                     generator (its FFT buffers do not fit a no-alloc device); stream it as \
                     register images"
                .into(),
        });
    }
    if let Some(reason) = vibration_refusal(scene) {
        return Err(StreamError::Model { reason });
    }
    let rate = rate_of(scene)?;
    let chip = device_chip(&scene.chip, rate)?;
    if settings.chip != chip.settings() {
        return Err(StreamError::Model {
            reason: "the device converts with the settings Configure gives its chip (the \
                     scene's [chip]); the images asked for others"
                .into(),
        });
    }
    let hold = kinematics_hold(rate, kinematics_hz)?;
    let truth_rate = Rate::new(rate.num(), rate.den() * hold).expect("checked by the hold");
    let params = ModelParams {
        mag_ut_per_unit: settings.mag_ut_per_unit,
        ..ModelParams::new(scene.spec.seed, truth_rate, scene.spec.sensors.config())
    };
    let scene = scene.clone();
    let samples = Predictions::spawn(move |emit| {
        let mut model = DeviceModel::new(&params.marg, rate.as_hz_f64(), params.seed, &chip)
            .map_err(margemu_sim::run::RunError::Model)?;
        let temperature = scene.spec.sensors.temperature;
        let (mut k, mut held) = (0u64, None);
        run_scene(&scene, |truth| {
            let kinematics = (k % u64::from(hold) == 0)
                .then(|| kinematics_of(&in_chip_axes(truth, &scene.chip), temperature));
            held = kinematics.or(held);
            let t = held.as_ref().expect("sample 0 brings kinematics");
            let image =
                setup::model_image(&mut model, truth.t_ns, t, params.mag_ut_per_unit, &chip);
            k += 1;
            let [accel, gyro] = model.clips();
            let mut clips = Clips::default();
            clips[0] = Some(margemu_sim::marg::ClipCounts { accel, gyro })
                .filter(|_| chip.settings().front_end_ranges().is_some());
            Ok(emit(ModelSample {
                sample: PredictedSample {
                    truth: *truth,
                    image,
                    clips,
                },
                kinematics,
            })?)
        })
    });
    Ok(ModelPrediction {
        hold,
        params,
        samples,
    })
}

/// Why source mode (b) cannot run `scene`'s sampling chain, if it cannot: vibration, or the
/// chip's internal-rate path asked for. The device's model runs at the output rate from held
/// kinematics; the vibration sources and the internal-rate filters are not carried by the link.
pub fn vibration_refusal(scene: &Scene) -> Option<String> {
    let vibrates = scene.vibration.iter().any(|v| !v.is_empty());
    let internal = scene.sampling == margemu_sim::scene::vibration::SamplingPath::Internal;
    (vibrates || internal).then(|| {
        format!(
            "the scene has {}: source mode (b) runs the sensor model on the device at the \
             output rate from held kinematics, without vibration or the chip's internal-rate \
             filters (the chain costs the Cortex-M4F {}; see the guide's sampling-chain \
             figures); stream it as register images (source images), where the host runs the \
             chain",
            if vibrates {
                "[vibration]"
            } else {
                "[vibration] path = \"internal\""
            },
            "thousands of instructions per output sample at 8 kHz"
        )
    })
}

/// The chip a device builds from the Configure of `chip` at `rate`: what it converts with.
pub fn device_chip(chip: &ChipSetup, rate: Rate) -> Result<EmulatedChip, StreamError> {
    setup::build_chip(&chip.configure(rate)).map_err(|code| StreamError::Model {
        reason: format!(
            "the firmware refuses the {} as configured ({code:?})",
            chip.model.part_name()
        ),
    })
}

/// The images the device serves at output samples `0 .. samples` in source mode (b), from
/// `kinematics` held for `hold` output samples each, converted by `chip` (see the module docs).
pub fn model_images(
    params: &ModelParams,
    rate: Rate,
    hold: u32,
    kinematics: &[sensor::Truth],
    samples: usize,
    chip: &impl Chip,
) -> Result<Vec<Image>, StreamError> {
    let mut model = DeviceModel::new(&params.marg, rate.as_hz_f64(), params.seed, chip)
        .map_err(margemu_sim::run::RunError::Model)?;
    let held = (0..samples).filter_map(|k| {
        let t = kinematics.get(k / hold.max(1) as usize)?;
        Some((rate.sample_time_ns(k as u64), t))
    });
    Ok(held
        .map(|(t_ns, t)| setup::model_image(&mut model, t_ns, t, params.mag_ut_per_unit, chip))
        .collect())
}

/// How many output samples each kinematics sample is held for: `rate / kinematics_hz`, which
/// must be a whole number.
pub fn kinematics_hold(rate: Rate, kinematics_hz: Option<f64>) -> Result<u32, StreamError> {
    let out_hz = rate.as_hz_f64();
    let hold = match kinematics_hz {
        None => ((out_hz / DEFAULT_MAX_KINEMATICS_HZ).ceil() as u32).max(2),
        Some(hz) => {
            let hold = (out_hz / hz).round();
            let whole = hz > 0.0 && hold >= 1.0 && ((out_hz / hold) - hz).abs() <= 1e-9 * hz;
            if !whole || hold > f64::from(u32::MAX) {
                return Err(StreamError::KinematicsRate {
                    hz,
                    out_hz,
                    hint: divisors_hint(out_hz),
                });
            }
            hold as u32
        }
    };
    match rate.den().checked_mul(hold) {
        Some(_) => Ok(hold),
        None => Err(StreamError::KinematicsRate {
            hz: kinematics_hz.unwrap_or(out_hz / f64::from(hold)),
            out_hz,
            hint: divisors_hint(out_hz),
        }),
    }
}

/// Whole-number kinematics rates the output rate allows (hold 2 to 10), for error messages.
fn divisors_hint(out_hz: f64) -> String {
    let rates: Vec<String> = (2..=10)
        .map(|m| out_hz / f64::from(m))
        .filter(|hz| hz.fract() == 0.0)
        .map(|hz| hz.to_string())
        .collect();
    match rates.is_empty() {
        true => format!("{} / n Hz for a whole n", out_hz),
        false => format!("{} Hz", rates.join(", ")),
    }
}

/// Kinematics sample of `t`: what the device's model needs, in `f32`.
fn kinematics_of(t: &Truth, temperature: Option<[f64; 2]>) -> sensor::Truth {
    let f = |v: [f64; 3]| v.map(|x| x as f32);
    sensor::Truth {
        angular_rate: f(t.body_rate),
        specific_force: f(t.specific_force),
        magnetic_field: f(t.field_body),
        angular_acceleration: f(t.angular_accel),
        temperature_c: temperature
            .map(|[start, slope]| (start + slope * t.t_ns as f64 * 1e-9) as f32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_device_chip_converts_as_the_scene_says() {
        use margemu_protocol::chip::{ChipModel, ChipSettings, FullScale};
        for model in ChipModel::ALL {
            let Ok(chip) = device_chip(&ChipSetup::power_on(model), Rate::hz(1000).unwrap()) else {
                continue; // not emulated by this firmware
            };
            assert_eq!(chip.settings(), ChipSettings::power_on(model), "{model:?}");
            let fs = FullScale {
                accel_g: ChipSettings::accel_ranges_g(model).last().unwrap_or(0.0),
                gyro_dps: ChipSettings::gyro_ranges_dps(model).last().unwrap_or(0.0),
            };
            let settings = if model.is_magnetometer_only() {
                let gauss = ChipSettings::mag_ranges_gauss(model).last().copied();
                let power_on = ChipSettings::power_on(model);
                gauss.map_or(power_on, |g| power_on.with_mag_range(g).unwrap())
            } else {
                ChipSettings::with_full_scale(model, fs).unwrap()
            };
            let setup = ChipSetup {
                settings,
                ..ChipSetup::power_on(model)
            };
            let chip = device_chip(&setup, Rate::hz(1000).unwrap()).unwrap();
            assert_eq!(
                chip.settings(),
                setup.settings,
                "{model:?} at its largest ranges"
            );
        }
    }

    #[test]
    fn holds_divide_the_output_rate() {
        let khz = Rate::hz(1000).unwrap();
        assert_eq!(kinematics_hold(khz, None).unwrap(), 2);
        assert_eq!(kinematics_hold(Rate::hz(8000).unwrap(), None).unwrap(), 8);
        assert_eq!(kinematics_hold(khz, Some(250.0)).unwrap(), 4);
        assert_eq!(kinematics_hold(khz, Some(1000.0)).unwrap(), 1);
        let third = Rate::new(1000, 3).unwrap();
        assert_eq!(kinematics_hold(third, Some(1000.0 / 9.0)).unwrap(), 3);
        for bad in [300.0, 0.0, -5.0, 2000.0, f64::NAN] {
            let err = kinematics_hold(khz, Some(bad)).unwrap_err().to_string();
            assert!(err.contains("does not divide"), "{bad}: {err}");
        }
    }
}
