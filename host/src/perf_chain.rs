//! `margemu bench chain`: what each chip family's sampling chain costs per output sample on
//! the host, on the output path and on the internal-rate path, and what skipping the internal
//! path gets wrong on a vibration scene.
//!
//! Every row times the sensor model alone ([`MargSim::sample`] over the scene's truth, computed
//! once beforehand), so the figures are the chain's and the error terms', not the bench
//! dynamics'.

use margemu_sim::marg::MargSim;
use margemu_sim::run::collect;
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;
use std::path::Path;
use std::time::{Duration, Instant};

/// The chips and output rates of the table.
pub const CHIPS: [(&str, u32); 5] = [
    ("mpu6000", 1000),
    ("icm20602", 8000),
    ("icm42688p", 8000),
    ("bmi270", 3200),
    ("bmi088", 2000),
];

/// Motor tones (4 motors ramping 9000 → 15000 rpm, two harmonics, linear and angular), a random
/// PSD to 2 kHz and one shock: a multirotor frame.
pub const VIBRATION: &str = "[[vibration.tones]]\nmotors = 4\nspread = 0.02\n\
rpm_ramp = { from = 9000, to = 15000, start = 0.0, end = 1.0 }\n\
[[vibration.tones.harmonics]]\norder = 1.0\nlinear = [1.5, 1.5, 4.0]\nangular = [0.02, 0.02, 0.01]\n\
[[vibration.tones.harmonics]]\norder = 2.0\nlinear = [0.8, 0.8, 2.0]\nangular = [0.01, 0.01, 0.005]\n\
[[vibration.random]]\npsd = [[20.0, 0.0001], [80.0, 0.0005], [350.0, 0.0005], [2000.0, 0.0001]]\n\
[[vibration.shocks]]\nat = 0.5\nduration = 0.011\nlinear = [0.0, 0.0, 100.0]\nangular = [0.5, 0.0, 0.0]\n";

/// One row: a chip at its rate, one case.
#[derive(Clone, Debug)]
pub struct ChainRow {
    /// The scene's chip model name.
    pub chip: &'static str,
    /// Output rate, Hz.
    pub rate_hz: u32,
    /// What the row measures.
    pub case: &'static str,
    /// Host time per output sample, ns.
    pub ns_per_sample: f64,
    /// RMS difference from the internal path of the same scene, accelerometer (m/s²) and
    /// gyroscope (rad/s): the error skipping the internal path costs (output-path rows only).
    pub skip_error: Option<[f64; 2]>,
}

fn scene(chip: &str, rate: u32, vibration: &str) -> Result<Scene, String> {
    let text = format!(
        "duration = 1.0\nrate = {rate}.0\nseed = 9\nmotion = \"static\"\n\
         [chip]\nmodel = \"{chip}\"\n\
         [sensors.gyro]\nnoise_density = [0.003, 0.003, 0.003]\n\
         [sensors.accel]\nnoise_density = [0.02, 0.02, 0.02]\n{vibration}"
    );
    Scene::parse_str(&text, Path::new("bench-chain.toml")).map_err(|e| e.to_string())
}

fn samples(scene: &Scene, truth: &[Truth]) -> Result<Vec<[f32; 6]>, String> {
    let mut marg = MargSim::new(scene).map_err(|e| e.to_string())?;
    Ok(truth
        .iter()
        .map(|t| {
            let s = marg.sample(t).sample;
            [s.acc[0], s.acc[1], s.acc[2], s.gyr[0], s.gyr[1], s.gyr[2]]
        })
        .collect())
}

fn time(scene: &Scene, truth: &[Truth], min_wall: Duration) -> Result<f64, String> {
    let start = Instant::now();
    let mut n = 0u64;
    while n == 0 || start.elapsed() < min_wall {
        let mut marg = MargSim::new(scene).map_err(|e| e.to_string())?;
        for t in truth {
            std::hint::black_box(marg.sample(std::hint::black_box(t)));
        }
        n += truth.len() as u64;
    }
    Ok(start.elapsed().as_secs_f64() * 1e9 / n as f64)
}

/// The sensor model alone, without any chain in front (what an output sample cost before the
/// chain existed).
fn time_model_alone(scene: &Scene, truth: &[Truth], min_wall: Duration) -> Result<f64, String> {
    use margemu_model::sensor::{self, Marg};
    let f = |v: [f64; 3]| v.map(|x| x as f32);
    let truth: Vec<sensor::Truth> = truth
        .iter()
        .map(|t| sensor::Truth {
            angular_rate: f(t.body_rate),
            specific_force: f(t.specific_force),
            magnetic_field: f(t.field_body),
            angular_acceleration: f(t.angular_accel),
            temperature_c: None,
        })
        .collect();
    let config = scene.spec.sensors.config();
    let start = Instant::now();
    let mut n = 0u64;
    while n == 0 || start.elapsed() < min_wall {
        let mut marg =
            Marg::new(&config, scene.clock.hz(), scene.spec.seed).map_err(|e| e.to_string())?;
        for t in &truth {
            std::hint::black_box(marg.sample(std::hint::black_box(t)));
        }
        n += truth.len() as u64;
    }
    Ok(start.elapsed().as_secs_f64() * 1e9 / n as f64)
}

fn rms_difference(a: &[[f32; 6]], b: &[[f32; 6]]) -> [f64; 2] {
    let rms = |axes: std::ops::Range<usize>| {
        let sum: f64 = a
            .iter()
            .zip(b)
            .flat_map(|(x, y)| axes.clone().map(move |i| f64::from(x[i] - y[i]).powi(2)))
            .sum();
        (sum / (3 * a.len()) as f64).sqrt()
    };
    [rms(0..3), rms(3..6)]
}

/// The table: per chip, the sensor model alone, no vibration on either path, and the
/// vibration scene on the output path and on the internal path; each row timed for at least
/// `min_wall`.
pub fn chain_costs(min_wall: Duration) -> Result<Vec<ChainRow>, String> {
    let mut rows = Vec::new();
    for (chip, rate) in CHIPS {
        let calm = scene(chip, rate, "")?;
        let truth = collect(&calm).map_err(|e| e.to_string())?;
        let skipped = scene(
            chip,
            rate,
            &format!("[vibration]\npath = \"output\"\n{VIBRATION}"),
        )?;
        let full = scene(
            chip,
            rate,
            &format!("[vibration]\npath = \"internal\"\n{VIBRATION}"),
        )?;
        let calm_internal = scene(chip, rate, "[vibration]\npath = \"internal\"\n")?;
        let reference = samples(&full, &truth)?;
        let error = rms_difference(&samples(&skipped, &truth)?, &reference);
        rows.push(ChainRow {
            chip,
            rate_hz: rate,
            case: "the sensor model alone (no chain)",
            ns_per_sample: time_model_alone(&calm, &truth, min_wall)?,
            skip_error: None,
        });
        for (case, s, skip_error) in [
            ("no vibration, output path", &calm, None),
            ("no vibration, internal path", &calm_internal, None),
            ("vibration, output path (skipped)", &skipped, Some(error)),
            ("vibration, internal path", &full, None),
        ] {
            rows.push(ChainRow {
                chip,
                rate_hz: rate,
                case,
                ns_per_sample: time(s, &truth, min_wall)?,
                skip_error,
            });
        }
    }
    Ok(rows)
}
