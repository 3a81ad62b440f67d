//! Aliasing through each chip family's sampling chain: a tone above the output Nyquist frequency
//! folds to `|f − k·ODR|` with the amplitude the configured filters predict at the tone's own
//! frequency; a narrower anti-alias filter lowers it as predicted; a tone in band passes with the
//! documented delay. The chain runs as in a session (`margemu_model::chain::SensorPath` on the
//! chip's declared `ChipChain`), the tone comes from the vibration generator.

use margemu_model::chain::SensorPath;
use margemu_model::perturbation::Complex;
use margemu_model::vibration::{Harmonic, RpmPoint, Sense, ToneSource, Vibration};
use margemu_protocol::chip::chain::{ChainConfig, ChipChain, SensorChain};
use margemu_protocol::chip::{ChipModel, ChipSettings};
use margemu_protocol::link::Rate;

/// The chain of `model` at `hz` with `config` (or the model's default).
fn chain(model: ChipModel, hz: u32, config: Option<ChainConfig>) -> ChipChain {
    let rate = Rate::hz(hz).unwrap();
    let config = config.unwrap_or_else(|| ChainConfig::default_for(model, rate).unwrap());
    ChipChain::new(&ChipSettings::power_on(model), &config, rate).unwrap()
}

/// The gyroscope's output at `n` output samples (period `out_ns`) of a tone of `amplitude`
/// rad/s at `f_hz` on x through `spec` (or straight through, sampled at the output instants,
/// when `spec` is `None`), after `warmup` output samples.
fn tone_through(
    spec: Option<&SensorChain>,
    out_ns: u64,
    f_hz: f64,
    amplitude: f64,
    warmup: usize,
    n: usize,
) -> Vec<f64> {
    let profile = vec![RpmPoint {
        t_ns: 0,
        rpm: f_hz * 60.0,
    }];
    let mut tone = ToneSource::new(1, profile);
    tone.push(Harmonic {
        order: 1.0,
        linear: [0.0; 3],
        angular: [amplitude, 0.0, 0.0],
    })
    .unwrap();
    let mut path: SensorPath<Vec<RpmPoint>, Vec<Complex>> = match spec {
        Some(s) => {
            let mut vib = Vibration::new(Sense::Angular, s.period_ns, 1);
            vib.add_tones(tone).unwrap();
            SensorPath::new(s.period_ns, s.filter, s.range, vib).unwrap()
        }
        None => {
            let mut vib = Vibration::new(Sense::Angular, out_ns, 1);
            vib.add_tones(tone).unwrap();
            SensorPath::at_output(f32::INFINITY, vib).unwrap()
        }
    };
    (0..(warmup + n) as u64)
        .map(|j| f64::from(path.advance(j * out_ns, [0.0; 3])[0]))
        .skip(warmup)
        .collect()
}

/// The complex amplitude of `x` (sampled every `dt` s) at `f_hz`.
fn phasor(x: &[f64], f_hz: f64, dt: f64) -> (f64, f64) {
    let (mut re, mut im) = (0.0, 0.0);
    for (j, v) in x.iter().enumerate() {
        let a = std::f64::consts::TAU * f_hz * j as f64 * dt;
        re += v * a.cos();
        im -= v * a.sin();
    }
    let n = x.len() as f64;
    (2.0 * re / n, 2.0 * im / n)
}

fn db(ratio: f64) -> f64 {
    20.0 * ratio.log10()
}

/// A tone at ODR + Δ shows at Δ with amplitude `A · |H(ODR + Δ)|` within 1 dB.
fn folds_as_predicted(model: ChipModel, hz: u32, config: Option<ChainConfig>, delta: f64) -> f64 {
    let c = chain(model, hz, config);
    let odr = f64::from(hz);
    let f = odr + delta;
    let amplitude = 0.5 * f64::from(c.gyro.range);
    let dt = c.output_period_ns as f64 * 1e-9;
    let n = (odr / delta).round() as usize * 10;
    let out = tone_through(
        Some(&c.gyro),
        c.output_period_ns,
        f,
        amplitude,
        hz as usize,
        n,
    );
    let (re, im) = phasor(&out, delta, dt);
    let got = (re * re + im * im).sqrt();
    let predicted = amplitude * c.gyro.filter.gain_at(f);
    let error = db(got / predicted);
    assert!(
        error.abs() < 1.0,
        "{model:?} at {hz} Hz: a {f} Hz tone of {amplitude} shows {got:.3e} at {delta} Hz, \
         predicted {predicted:.3e} ({error:.2} dB)"
    );
    got / amplitude
}

#[test]
fn invensense_6xxx_folds_a_tone_above_the_output_rate_as_its_dlpf_predicts() {
    folds_as_predicted(ChipModel::Mpu6000, 1000, None, 40.0);
    folds_as_predicted(ChipModel::Icm20602, 8000, None, 125.0);
}

#[test]
fn icm42688p_folds_through_its_anti_alias_filter_and_a_narrower_one_lowers_it() {
    let wide = |delt| ChainConfig::Icm42688p {
        gyro_aaf_delt: delt,
        accel_aaf_delt: delt,
        gyro_ui_order: 1,
        gyro_ui_bw: 15,
        accel_ui_order: 1,
        accel_ui_bw: 15,
    };
    // AAF_DELT 21 (≈ 995 Hz) and 6 (≈ 258 Hz) at an 8 kHz ODR, 32 kHz inside.
    let loud = folds_as_predicted(ChipModel::Icm42688p, 8000, Some(wide(21)), 200.0);
    let quiet = folds_as_predicted(ChipModel::Icm42688p, 8000, Some(wide(6)), 200.0);
    let c = |delt| chain(ChipModel::Icm42688p, 8000, Some(wide(delt)));
    let predicted = c(6).gyro.filter.gain_at(8200.0) / c(21).gyro.filter.gain_at(8200.0);
    assert!(quiet < loud, "narrowing the AAF lowers the alias");
    assert!(db(quiet / loud / predicted).abs() < 1.0);
}

#[test]
fn bmi270_and_bmi088_fold_as_their_filters_predict() {
    folds_as_predicted(ChipModel::Bmi270, 3200, None, 100.0);
    folds_as_predicted(ChipModel::Bmi088, 2000, None, 50.0);
}

#[test]
fn a_tone_in_band_passes_with_the_documented_delay() {
    let cases = [
        (ChipModel::Mpu6000, 1000, None),
        (ChipModel::Icm20602, 1000, None),
        (ChipModel::Icm42688p, 8000, None),
        (ChipModel::Bmi270, 1600, None),
        (ChipModel::Bmi088, 1000, None),
    ];
    for (model, hz, config) in cases {
        let c = chain(model, hz, config);
        let f = (c.gyro.bandwidth_hz / 20.0).max(1.0);
        let dt = c.output_period_ns as f64 * 1e-9;
        let n = ((1.0 / f) / dt).round() as usize * 4;
        let amplitude = 0.25 * f64::from(c.gyro.range);
        let warm = hz as usize;
        let through = tone_through(Some(&c.gyro), c.output_period_ns, f, amplitude, warm, n);
        let direct = tone_through(None, c.output_period_ns, f, amplitude, warm, n);
        let (a, b) = (phasor(&through, f, dt), phasor(&direct, f, dt));
        let lag = (b.1.atan2(b.0) - a.1.atan2(a.0)).rem_euclid(std::f64::consts::TAU);
        let delay = lag / (std::f64::consts::TAU * f);
        let gain = (a.0.hypot(a.1)) / (b.0.hypot(b.1));
        let internal = c.gyro.period_ns as f64 * 1e-9;
        let tolerance = (0.05 * c.gyro.delay_s).max(internal);
        assert!(
            (delay - c.gyro.delay_s).abs() <= tolerance,
            "{model:?} at {hz} Hz: a {f:.1} Hz tone is {:.3} ms late, documented {:.3} ms",
            delay * 1e3,
            c.gyro.delay_s * 1e3
        );
        assert!((gain - 1.0).abs() < 0.02, "{model:?}: in band, gain {gain}");
    }
}
