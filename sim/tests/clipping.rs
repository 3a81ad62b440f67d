//! Front-end clipping: a vibration peak beyond the range clips before the filters, the mean
//! shifts when the clipping is asymmetric (as on silicon), and every clipped internal sample is
//! counted on its axis.

use margemu_model::chain::SensorPath;
use margemu_model::perturbation::Complex;
use margemu_model::vibration::{Harmonic, RpmPoint, Sense, ToneSource, Vibration};
use margemu_protocol::chip::chain::{ChainConfig, ChipChain};
use margemu_protocol::chip::{ChipModel, ChipSettings, FullScale};
use margemu_protocol::link::Rate;

const G: f64 = 9.80665;

#[test]
fn an_asymmetric_clip_shifts_the_mean_and_is_counted() {
    // ICM-42688-P at 1 kHz, ±2 g: level (+1 g on z) with a 2 g, 300 Hz tone on z. The top of the
    // tone clips at +2 g, its bottom (−1 g) does not: the mean falls from 1 g to
    // 1 + 2·E[min(sin, ½)] = 1 − (√3 − π/3)/π ≈ 0.782 g, and a third of the samples clip.
    let model = ChipModel::Icm42688p;
    let rate = Rate::hz(1000).unwrap();
    let fs = FullScale {
        accel_g: 2.0,
        gyro_dps: 2000.0,
    };
    let settings = ChipSettings::with_full_scale(model, fs).unwrap();
    let config = ChainConfig::default_for(model, rate).unwrap();
    let c = ChipChain::new(&settings, &config, rate).unwrap();
    assert!((f64::from(c.accel.range) - 2.0 * G).abs() < 1e-4);
    let profile = vec![RpmPoint {
        t_ns: 0,
        rpm: 300.0 * 60.0,
    }];
    let mut tone = ToneSource::new(1, profile);
    tone.push(Harmonic {
        order: 1.0,
        linear: [0.0, 0.0, 2.0 * G],
        angular: [0.0; 3],
    })
    .unwrap();
    let mut vib = Vibration::new(Sense::Linear, c.accel.period_ns, 3);
    vib.add_tones(tone).unwrap();
    let mut path: SensorPath<Vec<RpmPoint>, Vec<Complex>> =
        SensorPath::new(c.accel.period_ns, c.accel.filter, c.accel.range, vib).unwrap();
    let level = [0.0, 0.0, G as f32];
    let seconds = 2;
    let out: Vec<f64> = (0..1000 * seconds)
        .map(|j| f64::from(path.advance(j * 1_000_000, level)[2]))
        .collect();
    let mean = out[500..].iter().sum::<f64>() / (out.len() - 500) as f64;
    let expected = 1.0 - (3f64.sqrt() - std::f64::consts::PI / 3.0) / std::f64::consts::PI;
    assert!(
        (mean / G - expected).abs() < 0.01,
        "mean {} g, expected {expected} g",
        mean / G
    );
    let [x, y, z] = path.clips();
    let internal = path.internal_samples() as f64;
    assert_eq!((x, y), (0, 0));
    assert!(
        (z as f64 / internal - 1.0 / 3.0).abs() < 0.01,
        "{z} of {internal} clipped"
    );
    // Without the tone's top beyond the range nothing clips and the mean stays.
    let mut calm = Vibration::new(Sense::Linear, c.accel.period_ns, 3);
    let mut tone = ToneSource::new(
        1,
        vec![RpmPoint {
            t_ns: 0,
            rpm: 300.0 * 60.0,
        }],
    );
    tone.push(Harmonic {
        order: 1.0,
        linear: [0.0, 0.0, 0.9 * G],
        angular: [0.0; 3],
    })
    .unwrap();
    calm.add_tones(tone).unwrap();
    let mut path: SensorPath<Vec<RpmPoint>, Vec<Complex>> =
        SensorPath::new(c.accel.period_ns, c.accel.filter, c.accel.range, calm).unwrap();
    let out: Vec<f64> = (0..2000u64)
        .map(|j| f64::from(path.advance(j * 1_000_000, level)[2]))
        .collect();
    let mean = out[500..].iter().sum::<f64>() / 1500.0;
    assert!((mean / G - 1.0).abs() < 0.002 && path.clips() == [0; 3]);
}
