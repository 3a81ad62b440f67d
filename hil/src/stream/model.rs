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
//!   hold), steps its model ([`Marg`](margemu_model::sensor::Marg) with the scene's terms and
//!   seed at `rate.as_hz_f64()`, behind the scene's sampling chain) once per output instant, scales the field to µT as `(f64::from(mag) * mag_ut_per_unit) as
//!   f32`, takes the die temperature of the kinematics (21 °C without one) and converts with
//!   the settings of the chip the scene's Configure builds (the firmware's own
//!   `setup::build_chip` and `setup::model_image`, so host and device share every step).
//!
//! [`model_images`] is that last step alone, for a caller with its own kinematics (a QEMU test,
//! say). The prediction holds while the device under test leaves the full-scale and offset
//! registers where Configure put them (the device converts with the chip's current settings).
//!
//! **The sampling chain.** The device's model runs behind the scene's chain
//! ([`model_chain_setup`]: device 0's tones and shocks in the chip's axes, on the path the host
//! would take), which the session sends after Configure as AddVibration messages
//! ([`ModelPrediction::vibration`]); host and device build it with the one constructor
//! `setup::model_chain`, so the images stay bit-identical.
//!
//! **Faults.** Device 0's faults of the scene's schedule go into the model ([`push_faults`],
//! as the device does on AddFault, with the scene's seed), so its sensor faults act in
//! `setup::model_image` on both sides alike; the session sends the schedule
//! ([`fault_messages`](super::fault_messages)).
//!
//! Scenes the device cannot run are refused before anything is sent ([`StreamError::Model`]):
//! a magnetic perturbation or random vibration (their FFT buffers do not fit a no-alloc
//! device), more rpm points, tone sources or shocks than the device holds, a chain too slow for
//! a 96 MHz Cortex-M4F at the scene's rate ([`chain_cost`]), image settings other than those of
//! the configured chip, and a kinematics rate that does not divide the output rate.
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
use margemu_firmware::link::setup::{self, ChainSetup, DeviceModel, ModelFront};
use margemu_model::chain::Front;
use margemu_model::fault::Fault;
use margemu_model::sensor;
use margemu_model::vibration::{Sense, ToneSource, MAX_SHOCKS, MAX_TONE_SOURCES};
use margemu_protocol::link::{AddVibration, Image, ModelParams, Rate, RpmProfile, MAX_RPM_POINTS};
use margemu_sim::sampling::uses_internal_path;
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
    /// The AddVibration messages that follow Configure: the chain's path, each tone source,
    /// each shock ([`model_chain_setup`]).
    pub vibration: Vec<AddVibration>,
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
    let rate = rate_of(scene)?;
    let chain = model_chain_setup(scene, rate).map_err(|reason| StreamError::Model { reason })?;
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
    let vibration = chain.messages().collect();
    let samples = Predictions::spawn(move |emit| {
        let mut model = DeviceModel::new(&params.marg, rate, params.seed, &chip, &chain)
            .map_err(margemu_sim::run::RunError::Model)?;
        push_faults(&mut model, &scene.faults, scene.spec.seed);
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
        vibration,
        samples,
    })
}

/// Why source mode (b) cannot run `scene`'s sampling chain, if it cannot
/// ([`model_chain_setup`]'s refusal).
pub fn vibration_refusal(scene: &Scene) -> Option<String> {
    let rate = rate_of(scene).ok()?;
    model_chain_setup(scene, rate).err()
}

/// Instructions per output sample of the sensor model and the bookkeeping of an output-path
/// chain without vibration, on the Cortex-M4F (`docs/figures.md`, "Sampling chain on the
/// Cortex-M4F": 1 459 on the output path, 1 666 on the ICM-20602's internal path, 4 931 on the
/// ICM-42688-P's, fitted with the costs below).
pub const COST_BASE: f64 = 1000.0;
/// Instructions per sensor and step of the output path (2 × 230 + 1 000 ≈ 1 459).
pub const COST_OUTPUT_STEP: f64 = 230.0;
/// Instructions per sensor and internal sample of the internal path, filters and clipping
/// ((4 931 − 1 666) / (8 + 8 − 1 − 0.5) ≈ 500 per step).
pub const COST_FILTER_STEP: f64 = 500.0;
/// Instructions per tone (source × motor × harmonic) or shock, per sensor sample: the f32 sine
/// of the phase in cycles, as measured on the M4F since tones use it (output path with
/// 4 motors × 2 harmonics on both sensors at 8 kHz: 3 500–4 000; the ICM-42688-P's internal
/// path with them and a shock: ≈ 14 500; the figures table's tone rows predate that sine).
pub const COST_TONE: f64 = 150.0;
/// Instructions per second of a 96 MHz Cortex-M4F at 1.25 cycles per instruction, doing
/// nothing else.
pub const M4F_INSTRUCTIONS_PER_S: f64 = 96e6 / 1.25;

/// What source mode (b)'s chain is on the device for `scene` at `rate` (device 0's vibration in
/// the chip's axes, the path `margemu_sim::sampling::uses_internal_path` picks, the chip's
/// declared filters), or why the device cannot run it, before anything is sent:
///
/// - random vibration (its synthesis needs FFT buffers the device does not have);
/// - a tone source of more than [`MAX_RPM_POINTS`] rpm points, more than
///   [`MAX_TONE_SOURCES`] tone sources or [`MAX_SHOCKS`] shocks;
/// - a chain the model refuses;
/// - a chain too slow for a 96 MHz Cortex-M4F at the scene's rate: [`chain_cost`] instructions
///   per output sample above [`M4F_INSTRUCTIONS_PER_S`] / rate.
pub fn model_chain_setup(scene: &Scene, rate: Rate) -> Result<ChainSetup, String> {
    let advice = "stream it as register images (source images), where the host runs the chain";
    let vibration = scene.vibration.first().cloned().unwrap_or_default();
    if vibration.random.is_some() {
        return Err(format!(
            "the scene has random vibration ([[vibration.random]]): its synthesis needs FFT \
             buffers (tens of KB) the device does not have; {advice}"
        ));
    }
    let mut setup = ChainSetup {
        internal: match uses_internal_path(scene, &vibration) {
            true => scene.chip.chain,
            false => None,
        },
        ..ChainSetup::default()
    };
    for (i, t) in vibration.tones.iter().enumerate() {
        let profile = RpmProfile::from_slice(&t.profile).map_err(|_| {
            format!(
                "tone source {} has {} rpm points: the device holds at most {MAX_RPM_POINTS} per \
                 source; {advice}",
                i + 1,
                t.profile.len()
            )
        })?;
        let mut tones = ToneSource::new(t.motors, profile);
        tones.spread = t.spread;
        for h in t.harmonics() {
            tones.push(*h).map_err(|e| e.to_string())?;
        }
        setup.tones.push(tones).map_err(|_| {
            format!(
                "the scene has {} tone sources: the device holds at most {MAX_TONE_SOURCES}; \
                 {advice}",
                vibration.tones.len()
            )
        })?;
    }
    for shock in &vibration.shocks {
        setup.shocks.push(*shock).map_err(|_| {
            format!(
                "the scene has {} shocks: the device holds at most {MAX_SHOCKS}; {advice}",
                vibration.shocks.len()
            )
        })?;
    }
    let chain = setup::model_chain(&scene.chip.settings, rate, scene.spec.seed, &setup);
    if let Some(chain) = chain {
        let chain = chain.map_err(|e| format!("the device's model refuses the chain: {e}"))?;
        let cost = chain_cost(&setup, &chain, rate);
        let hz = rate.as_hz_f64();
        let share = cost * hz / M4F_INSTRUCTIONS_PER_S;
        if share > 1.0 {
            return Err(format!(
                "the chain needs ≈ {} instructions per output sample, {:.0} % of a 96 MHz \
                 Cortex-M4F at {hz} Hz (cost model: {COST_BASE} + per sensor sample \
                 {COST_FILTER_STEP} on the internal path or {COST_OUTPUT_STEP} on the output \
                 path + {COST_TONE} per tone (source × motor × harmonic) or shock and sensor \
                 sample; 1.25 cycles per instruction); {advice}",
                grouped(cost.round() as u64),
                share * 100.0
            ));
        }
    }
    Ok(setup)
}

/// Instructions per output sample of `chain` (built from `setup`) on the Cortex-M4F at `rate`
/// (the cost model of [`COST_BASE`], [`COST_OUTPUT_STEP`], [`COST_FILTER_STEP`],
/// [`COST_TONE`]): per sensor, its samples per output sample times its step's cost and its
/// tones and shocks.
pub fn chain_cost(setup: &ChainSetup, chain: &ModelFront, rate: Rate) -> f64 {
    let out_ns = 1e9 / rate.as_hz_f64();
    let sensor = |sense: Sense, period_ns: u64| {
        let (samples, step) = match period_ns {
            0 => (1.0, COST_OUTPUT_STEP),
            p => (out_ns / p as f64, COST_FILTER_STEP),
        };
        samples * (step + COST_TONE * setup.sources_moving(sense) as f64)
    };
    let (accel_ns, gyro_ns) = match chain {
        Front::Clip(_) => (0, 0),
        Front::Chain(c) => (c.accel.period_ns(), c.gyro.period_ns()),
    };
    COST_BASE + sensor(Sense::Linear, accel_ns) + sensor(Sense::Angular, gyro_ns)
}

/// `n` with its thousands apart: `14 500`.
fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
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
/// `kinematics` held for `hold` output samples each, behind the chain `chain` builds, converted
/// by `chip` (see the module docs).
pub fn model_images(
    params: &ModelParams,
    rate: Rate,
    chain: &ChainSetup,
    hold: u32,
    kinematics: &[sensor::Truth],
    samples: usize,
    chip: &impl Chip,
) -> Result<Vec<Image>, StreamError> {
    let mut model = DeviceModel::new(&params.marg, rate, params.seed, chip, chain)
        .map_err(margemu_sim::run::RunError::Model)?;
    let held = (0..samples).filter_map(|k| {
        let t = kinematics.get(k / hold.max(1) as usize)?;
        Some((rate.sample_time_ns(k as u64), t))
    });
    Ok(held
        .map(|(t_ns, t)| setup::model_image(&mut model, t_ns, t, params.mag_ut_per_unit, chip))
        .collect())
}

/// Gives `model` (device 0's, in source (b)) every fault of device 0 in `faults`, in order,
/// with device 0's seed (the scene's `seed`), as the device does on AddFault: its sensor faults
/// then act in [`setup::model_image`]. At most `MAX_FAULTS` are taken (the device refuses
/// more).
pub fn push_faults(model: &mut DeviceModel, faults: &[Fault], seed: u64) {
    let seed = margemu_sim::marg::device_seed(seed, 0);
    for f in faults.iter().filter(|f| f.device == 0) {
        if model.push_fault(f, seed).is_err() {
            break;
        }
    }
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
    fn the_prediction_runs_the_scenes_chain_and_sends_it() {
        let base = "duration = 0.1\nrate = 1000.0\nseed = 3\nmotion = \"static\"\n\
                    [chip]\nmodel = \"icm20602\"\n";
        let tone = "[[vibration.tones]]\nmotors = 2\nrpm = 6000\n\
                    [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 5.0]\n\
                    [[vibration.shocks]]\nat = 0.05\nduration = 0.01\nangular = [1.0, 0.0, 0.0]\n";
        let images = |text: &str| {
            let scene = Scene::parse_str(text, std::path::Path::new("s.toml")).unwrap();
            let p = predict_model(&scene, &ImageSettings::for_scene(&scene), None).unwrap();
            let images: Vec<Image> = p.samples.map(|s| s.unwrap().sample.image).collect();
            (p.vibration, images)
        };
        let (quiet_msgs, quiet) = images(base);
        assert_eq!(quiet_msgs, [AddVibration::Path(None)]);
        let (msgs, shaken) = images(&format!("{base}{tone}"));
        assert!(matches!(
            msgs.as_slice(),
            [AddVibration::Path(None), AddVibration::Tones(t), AddVibration::Shock(_)]
                if t.motors == 2 && t.profile.len() == 1
        ));
        let differ = quiet.iter().zip(&shaken).filter(|(a, b)| a != b).count();
        assert!(differ > 90, "{differ} of 100 images differ");
        let (msgs, _) = images(&format!("{base}[vibration]\npath = \"internal\"\n{tone}"));
        assert!(matches!(msgs.first(), Some(AddVibration::Path(Some(_)))));
    }

    #[test]
    fn the_cost_model_matches_the_measured_cases() {
        // The measured cases: 4 motors × 2 harmonics on both sensors and a shock, 8 kHz.
        let base = "duration = 0.01\nrate = 8000.0\nseed = 3\nmotion = \"static\"\n";
        let tones = "[[vibration.tones]]\nmotors = 4\nrpm = 6000\n\
                     [[vibration.tones.harmonics]]\norder = 1.0\nlinear = [0.0, 0.0, 1.0]\n\
                     angular = [0.1, 0.0, 0.0]\n\
                     [[vibration.tones.harmonics]]\norder = 2.0\nlinear = [1.0, 0.0, 0.0]\n\
                     angular = [0.1, 0.0, 0.0]\n";
        let cost = |chip: &str, path: &str, extra: &str| {
            let text = format!(
                "{base}[chip]\nmodel = \"{chip}\"\n[vibration]\npath = \"{path}\"\n{extra}"
            );
            let scene = Scene::parse_str(&text, std::path::Path::new("s.toml")).unwrap();
            let rate = rate_of(&scene).unwrap();
            let mut setup = ChainSetup {
                internal: (path == "internal").then_some(scene.chip.chain).flatten(),
                ..ChainSetup::default()
            };
            for t in &scene.vibration[0].tones {
                let mut tones =
                    ToneSource::new(t.motors, RpmProfile::from_slice(&t.profile).unwrap());
                t.harmonics().iter().for_each(|h| tones.push(*h).unwrap());
                setup.tones.push(tones).unwrap();
            }
            let chain = setup::model_chain(&scene.chip.settings, rate, 3, &setup);
            chain_cost(&setup, &chain.unwrap().unwrap(), rate)
        };
        // Measured: 1 459, 1 666, 4 931 quiet; ≈ 3 500–4 000 with tones at 8 kHz; ≈ 14 500 on
        // the ICM-42688-P's internal path with tones.
        assert_eq!(cost("icm20602", "output", ""), 1460.0);
        assert_eq!(cost("icm20602", "internal", ""), 1750.0);
        assert_eq!(cost("icm42688p", "internal", ""), 5000.0);
        assert_eq!(cost("icm20602", "output", tones), 3860.0);
        assert_eq!(cost("icm20602", "internal", tones), 3550.0);
        assert_eq!(cost("icm42688p", "internal", tones), 14600.0);
        assert_eq!(grouped(14600), "14 600");
        assert_eq!(grouped(999), "999");
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
