//! Source mode (b): the host sends true kinematics at a lower rate and the device runs the shared
//! sensor model itself, seeded from the scene, at the chip's output rate.
//!
//! [`predict_model`] plans such a session and predicts, byte for byte, every register image the
//! device will serve:
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
//!   f32`, takes the die temperature of the kinematics (21 °C, TEMP_OUT 0, without one) and
//!   converts with the chip's power-on register settings ([`chip_power_on`]).
//!
//! [`model_images`] is that last step alone, for a caller with its own kinematics (a QEMU test,
//! say). The prediction holds while the device under test leaves the full-scale and offset
//! registers at their power-on values (the device converts with the chip's current settings).
//!
//! Scenes the device cannot run are refused before anything is sent ([`StreamError::Model`]):
//! a magnetic perturbation (its generator's FFT buffers do not fit a no-alloc device), register
//! settings other than the chip's power-on ones, and a kinematics rate that does not divide the
//! output rate.
//!
//! ```
//! use margemu::scene::Scene;
//! use margemu::stream::{predict_model, ImageSettings};
//! let scene = Scene::parse_str(
//!     "duration = 0.01\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! let p = predict_model(&scene, &ImageSettings::for_scene(&scene), Some(250.0)).unwrap();
//! assert_eq!((p.hold, p.kinematics.len(), p.samples.len()), (4, 3, 10));
//! assert_eq!(p.params.truth_rate.as_hz_f64(), 250.0);
//! ```

use super::images::{chip_power_on, ImageSettings, PredictedSample};
use super::session::rate_of;
use super::StreamError;
use crate::scene::Scene;
use crate::truth::Truth;
use margemu_model::sensor::{self, Marg};
use margemu_protocol::link::{Image, ModelParams, Rate};
use margemu_protocol::regmap::mpu6xxx::convert::TEMP_OFFSET_C;
use margemu_protocol::regmap::mpu6xxx::image::ImageRepr;

/// The kinematics rate when none is asked for: the output rate over the smallest whole
/// `hold ≥ 2` that brings it to at most this.
pub const DEFAULT_MAX_KINEMATICS_HZ: f64 = 1000.0;

/// A planned source mode (b) session and its prediction.
#[derive(Clone, Debug)]
pub struct ModelPrediction {
    /// Output samples per kinematics sample.
    pub hold: u32,
    /// What Configure carries: seed, kinematics rate, µT per unit, the model terms.
    pub params: ModelParams,
    /// The kinematics samples, at `params.truth_rate`.
    pub kinematics: Vec<sensor::Truth>,
    /// Every output sample: its truth and the image the device will serve.
    pub samples: Vec<PredictedSample>,
}

/// Plans source mode (b) for `scene` with kinematics at `kinematics_hz` (default: see
/// [`DEFAULT_MAX_KINEMATICS_HZ`]) and predicts every image (see the module docs).
pub fn predict_model(
    scene: &Scene,
    settings: &ImageSettings,
    kinematics_hz: Option<f64>,
) -> Result<ModelPrediction, StreamError> {
    if scene.spec.perturbation.is_some() {
        return Err(StreamError::Model {
            reason: "the scene has a [perturbation]: the device cannot run the perturbation \
                     generator (its FFT buffers do not fit a no-alloc device); stream it as \
                     register images"
                .into(),
        });
    }
    if settings.image != chip_power_on() {
        return Err(StreamError::Model {
            reason: "the device converts with the chip's power-on register settings; the \
                     images asked for others"
                .into(),
        });
    }
    let rate = rate_of(scene)?;
    let hold = kinematics_hold(rate, kinematics_hz)?;
    let truth_rate = Rate::new(rate.num(), rate.den() * hold).expect("checked by the hold");
    let truths = crate::run::collect(scene).map_err(crate::run::RunError::from)?;
    let temperature = scene.spec.sensors.temperature;
    let kinematics: Vec<sensor::Truth> = truths
        .iter()
        .step_by(hold as usize)
        .map(|t| kinematics_of(t, temperature))
        .collect();
    let params = ModelParams {
        mag_ut_per_unit: settings.mag_ut_per_unit,
        ..ModelParams::new(scene.spec.seed, truth_rate, scene.spec.sensors.config())
    };
    let images = model_images(&params, rate, hold, &kinematics, truths.len())?;
    let samples = truths
        .into_iter()
        .zip(images)
        .map(|(truth, image)| PredictedSample { truth, image })
        .collect();
    Ok(ModelPrediction {
        hold,
        params,
        kinematics,
        samples,
    })
}

/// The images the device serves at output samples `0 .. samples` in source mode (b), from
/// `kinematics` held for `hold` output samples each (see the module docs).
pub fn model_images(
    params: &ModelParams,
    rate: Rate,
    hold: u32,
    kinematics: &[sensor::Truth],
    samples: usize,
) -> Result<Vec<Image>, StreamError> {
    let mut marg = Marg::new(&params.marg, rate.as_hz_f64(), params.seed)
        .map_err(crate::run::RunError::Model)?;
    let config = chip_power_on();
    let held = (0..samples).filter_map(|k| kinematics.get(k / hold.max(1) as usize));
    Ok(held
        .map(|t| {
            let s = marg.sample(t);
            let mag = s
                .mag
                .map(|m| (f64::from(m) * params.mag_ut_per_unit) as f32);
            let temp = t.temperature_c.unwrap_or(TEMP_OFFSET_C);
            ImageRepr::from_physical(s.acc, s.gyr, temp, mag, &config).emit()
        })
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
    fn the_power_on_conversion_is_nominal_but_for_the_fuse_rom() {
        use margemu_protocol::regmap::mpu6xxx::image::ImageConfig;
        let c = chip_power_on();
        assert_eq!(ImageConfig { asa: [128; 3], ..c }, ImageConfig::NOMINAL);
        assert_ne!(c.asa, [128; 3], "the emulated AK8963 has real fuse values");
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
