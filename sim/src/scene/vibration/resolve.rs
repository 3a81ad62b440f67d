//! Resolution of `[vibration]`: each source checked, routed to the devices it reaches and turned
//! into their chip axes; then each device's set checked by the model itself.

use super::at::At;
use super::rpm::{instant, profile};
use super::spec::{RandomSpec, ShockSpec, ToneSpec, VibrationSpec};
use super::DeviceVibration;
use crate::scene::error::Violation;
use crate::scene::ranges;
use crate::scene::rig::Device;
use crate::scene::validate;
use margemu_model::perturbation::Complex;
use margemu_model::vibration::{self as model, Harmonic, PsdPoint, RandomSource, Sense, Shock};
use margemu_model::vibration::{ToneSource, Vibration, MAX_HARMONICS, MAX_MOTORS};
use margemu_model::vibration::{MAX_PSD_POINTS, MAX_SHOCKS, MAX_TONE_SOURCES};
use std::path::Path;

/// The lowest internal rate the sources are checked at, Hz: the highest internal rate of the
/// emulated chips (a scene whose output rate is higher is checked at that). The random
/// synthesis needs a PSD's lowest breakpoint at or above `rate / 4096` at the rate it runs at.
pub const CHECK_RATE_HZ: f64 = 32_000.0;

type Check = Result<(), Violation>;

/// One device's sources and where each came from.
#[derive(Default)]
struct Reached {
    vibration: DeviceVibration,
    tones: Vec<At>,
    random: Option<At>,
    shocks: Vec<At>,
}

/// The vibration reaching each of `devices` (in order), for a scene at output `rate` Hz whose
/// relative paths resolve against `base`.
pub(crate) fn resolve(
    spec: &VibrationSpec,
    devices: &[Device],
    rate: f64,
    base: &Path,
) -> Result<Vec<DeviceVibration>, Violation> {
    let mut reached: Vec<Reached> = devices.iter().map(|_| Reached::default()).collect();
    let root = At::root();
    for (i, tone) in spec.tones.iter().enumerate() {
        let at = root.key("tones").index(i);
        let source = tone_source(tone, &at, base)?;
        for d in targets(tone.device.as_deref(), devices, &at)? {
            let here = &mut reached[d];
            if here.vibration.tones.len() == MAX_TONE_SOURCES {
                return Err(at.error(format!(
                    "device `{}` would take more than {MAX_TONE_SOURCES} tone sources (the most \
                     one device takes)",
                    devices[d].name
                )));
            }
            here.vibration.tones.push(tone_in(&source, &devices[d]));
            here.tones.push(at.clone());
        }
    }
    for (i, random) in spec.random.iter().enumerate() {
        let at = root.key("random").index(i);
        let source = random_source(random, &at, rate)?;
        for d in targets(random.device.as_deref(), devices, &at)? {
            let here = &mut reached[d];
            if let Some(j) = here.random.as_ref().and_then(At::last_index) {
                return Err(at.error(format!(
                    "device `{}` has a random source already (`vibration.random[{j}]`): at most \
                     one reaches a device",
                    devices[d].name
                )));
            }
            let mut chip = source;
            chip.axes = devices[d].chip.rotation;
            here.vibration.random = Some(chip);
            here.random = Some(at.clone());
        }
    }
    for (i, shock) in spec.shocks.iter().enumerate() {
        let at = root.key("shocks").index(i);
        let plate = shock_of(shock, &at)?;
        for d in targets(shock.device.as_deref(), devices, &at)? {
            let here = &mut reached[d];
            if here.vibration.shocks.len() == MAX_SHOCKS {
                return Err(at.error(format!(
                    "device `{}` would take more than {MAX_SHOCKS} shocks (the most one device \
                     takes)",
                    devices[d].name
                )));
            }
            let chip = &devices[d].chip;
            here.vibration.shocks.push(Shock {
                linear: chip.to_chip(plate.linear),
                angular: chip.to_chip(plate.angular),
                ..plate
            });
            here.shocks.push(at.clone());
        }
    }
    let check_rate = rate.max(CHECK_RATE_HZ);
    for here in &reached {
        model_check(here, check_rate)?;
    }
    Ok(reached.into_iter().map(|r| r.vibration).collect())
}

/// The indices of the devices a source with `device` reaches.
fn targets(device: Option<&str>, devices: &[Device], at: &At) -> Result<Vec<usize>, Violation> {
    let Some(name) = device else {
        return Ok((0..devices.len()).collect());
    };
    match devices.iter().position(|d| d.name == name) {
        Some(d) => Ok(vec![d]),
        None => {
            let names: Vec<&str> = devices.iter().map(|d| d.name.as_str()).collect();
            Err(at.key("device").error(format!(
                "no device is named `{name}`; the devices are {}",
                names.join(", ")
            )))
        }
    }
}

/// A tone source in plate axes.
fn tone_source(
    tone: &ToneSpec,
    at: &At,
    base: &Path,
) -> Result<ToneSource<Vec<model::RpmPoint>>, Violation> {
    let motors = match u8::try_from(tone.motors) {
        Ok(m @ 1..) if usize::from(m) <= MAX_MOTORS => m,
        _ => {
            return Err(at.key("motors").error(format!(
                "must be 1 to {MAX_MOTORS} (the most one tone source drives), not {}",
                tone.motors
            )))
        }
    };
    let spread = tone.spread;
    if !(spread.is_finite() && (0.0..1.0).contains(&spread)) {
        return Err(at
            .key("spread")
            .error(format!("must be finite, ≥ 0 and < 1, not {spread}")));
    }
    let mut source = ToneSource::new(motors, profile(tone, at, base)?);
    source.spread = spread;
    if tone.harmonics.is_empty() {
        return Err(at.error("a tone source needs at least one `[[vibration.tones.harmonics]]`"));
    }
    for (h, harmonic) in tone.harmonics.iter().enumerate() {
        let at = at.key("harmonics").index(h);
        if h == MAX_HARMONICS {
            return Err(at.error(format!(
                "a tone source has at most {MAX_HARMONICS} harmonics"
            )));
        }
        at.key("order").check(validate::finite_positive(
            harmonic.order,
            &[],
            ranges::HARMONIC_ORDER,
        ))?;
        at.key("linear")
            .vector(&harmonic.linear, ranges::VIBRATION_LINEAR)?;
        at.key("angular")
            .vector(&harmonic.angular, ranges::VIBRATION_ANGULAR)?;
        source
            .push(Harmonic {
                order: harmonic.order,
                linear: harmonic.linear,
                angular: harmonic.angular,
            })
            .map_err(|e| at.model(e))?;
    }
    Ok(source)
}

/// `source` with its amplitudes in `device`'s chip axes.
fn tone_in(
    source: &ToneSource<Vec<model::RpmPoint>>,
    device: &Device,
) -> ToneSource<Vec<model::RpmPoint>> {
    let mut chip = ToneSource::new(source.motors, source.profile.clone());
    chip.spread = source.spread;
    for h in source.harmonics() {
        // Within MAX_HARMONICS: the plate source holds as many.
        let _ = chip.push(Harmonic {
            linear: device.chip.to_chip(h.linear),
            angular: device.chip.to_chip(h.angular),
            ..*h
        });
    }
    chip
}

/// A random source in plate axes (its `axes` are set per device).
fn random_source(random: &RandomSpec, at: &At, rate: f64) -> Result<RandomSource, Violation> {
    let psd = at.key("psd");
    if !(2..=MAX_PSD_POINTS).contains(&random.psd.len()) {
        return Err(psd.error(format!(
            "a PSD has 2 to {MAX_PSD_POINTS} `[Hz, g²/Hz]` breakpoints, not {}",
            random.psd.len()
        )));
    }
    let mut points = Vec::with_capacity(random.psd.len());
    for (i, &[f_hz, g2_per_hz]) in random.psd.iter().enumerate() {
        let f_at = psd.index(i).index(0);
        f_at.check(validate::finite_positive(f_hz, &[], ranges::FREQUENCY))?;
        if let Some(last) = points
            .last()
            .map(|p: &PsdPoint| p.f_hz)
            .filter(|&l| f_hz <= l)
        {
            return Err(f_at.error(format!(
                "breakpoint frequencies must increase: {f_hz} Hz does not come after {last} Hz"
            )));
        }
        psd.index(i).index(1).check(validate::finite_positive(
            g2_per_hz,
            &[],
            ranges::PSD_VALUE,
        ))?;
        points.push(PsdPoint { f_hz, g2_per_hz });
    }
    at.key("gains").check(validate::all_non_negative(
        &random.gains,
        &[],
        ranges::VIBRATION_GAIN,
    ))?;
    let mut source = RandomSource::new(&points).map_err(|e| psd.model(e))?;
    source.gains = random.gains;
    let check_rate = rate.max(CHECK_RATE_HZ);
    if source.fft_len(check_rate).is_err() {
        return Err(psd.index(0).index(0).error(format!(
            "the lowest breakpoint, {} Hz, is too low for the synthesis at {check_rate} Hz: it \
             must be at least {} Hz (the rate / 4096)",
            points[0].f_hz,
            check_rate / 4096.0
        )));
    }
    Ok(source)
}

/// A shock in plate axes.
fn shock_of(shock: &ShockSpec, at: &At) -> Result<Shock, Violation> {
    let t_ns = instant(shock.at, &at.key("at"))?;
    let duration_ns = validate::positive_nanos(shock.duration, &[], ranges::TIME)
        .map_err(|v| at.key("duration").error(v.reason))?;
    at.key("linear")
        .vector(&shock.linear, ranges::VIBRATION_LINEAR)?;
    at.key("angular")
        .vector(&shock.angular, ranges::VIBRATION_ANGULAR)?;
    Ok(Shock {
        t_ns,
        duration_ns,
        linear: shock.linear,
        angular: shock.angular,
    })
}

/// Builds the model's vibration of both senses of one device at `rate_hz`, so whatever the
/// model refuses is refused here, at the source it concerns.
fn model_check(here: &Reached, rate_hz: f64) -> Check {
    let period_ns = (1e9 / rate_hz).round().max(1.0) as u64;
    for sense in [Sense::Linear, Sense::Angular] {
        let mut vib = Vibration::<Vec<model::RpmPoint>, Vec<Complex>>::new(sense, period_ns, 0);
        for (tone, at) in here.vibration.tones.iter().zip(&here.tones) {
            vib.add_tones(tone.clone()).map_err(|e| at.model(e))?;
        }
        for (shock, at) in here.vibration.shocks.iter().zip(&here.shocks) {
            vib.add_shock(shock).map_err(|e| at.model(e))?;
        }
        if let (Sense::Linear, Some(source), Some(at)) =
            (sense, &here.vibration.random, &here.random)
        {
            let rate = 1e9 / period_ns as f64;
            let len = source.buffer_len(rate).map_err(|e| at.model(e))?;
            vib.add_random(source, vec![Complex::ZERO; len])
                .map_err(|e| at.model(e))?;
        }
    }
    Ok(())
}
