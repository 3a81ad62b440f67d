//! `margemu bench faults`: what a sensor-fault schedule costs per output sample of the host's
//! sensor model ([`MargSim::sample`] over the scene's truth, computed once beforehand), against
//! the same scene without faults.
//!
//! The schedule has four sensor faults (a gyro bias step, an accelerometer scale change, gyro
//! noise, magnetometer spikes); the timed samples are the first second of a 2 s, 1 kHz static
//! scene with white noise on every sensor. In the "idle" row every window starts at 1.5 s, so
//! each timed sample checks the four windows and applies none; in the "one active" row the bias
//! step covers the whole run.

use margemu_sim::marg::MargSim;
use margemu_sim::run::collect;
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;
use std::path::Path;
use std::time::{Duration, Instant};

const BASE: &str = "duration = 2.0\nrate = 1000.0\nseed = 9\nmotion = \"static\"\n\
    [sensors.gyro]\nnoise_density = [0.003, 0.003, 0.003]\n\
    [sensors.accel]\nnoise_density = [0.02, 0.02, 0.02]\n\
    [sensors.mag]\nnoise_density = [0.001, 0.001, 0.001]\n";

/// The four faults, the first (the bias step) starting at `first_start` s, the others at 1.5 s.
fn schedule(first_start: f64) -> String {
    format!(
        "[[fault]]\nkind = \"bias_step\"\nsensor = \"gyro\"\nbias = 0.01\nstart = {first_start}\nuntil_end = true\n\
         [[fault]]\nkind = \"scale\"\nsensor = \"accel\"\nfactor = 1.05\nstart = 1.5\nduration = 0.2\n\
         [[fault]]\nkind = \"noise\"\nsensor = \"gyro\"\nstd = 0.1\nstart = 1.5\nduration = 0.2\n\
         [[fault]]\nkind = \"spikes\"\nsensor = \"mag\"\nrate = 10.0\namplitude = 1.0\nstart = 1.5\nduration = 0.2\n"
    )
}

/// One row of the table.
#[derive(Clone, Debug)]
pub struct FaultRow {
    /// What the row measures.
    pub case: &'static str,
    /// Host time per output sample, ns.
    pub ns_per_sample: f64,
}

/// One pass of a fresh model over `truth`: ns per sample.
fn time_once(scene: &Scene, truth: &[Truth]) -> Result<f64, String> {
    let mut marg = MargSim::new(scene).map_err(|e| e.to_string())?;
    let start = Instant::now();
    for t in truth {
        std::hint::black_box(marg.sample(std::hint::black_box(t)));
    }
    Ok(start.elapsed().as_secs_f64() * 1e9 / truth.len() as f64)
}

/// The rows: no faults, four idle, four with one active. One pass (1000 samples, about 0.1 ms)
/// of each in turn, repeated for at least `min_wall`, the fastest pass of each kept: short
/// interleaved passes keep the machine's other work from weighing on one row more than on
/// another.
pub fn fault_costs(min_wall: Duration) -> Result<Vec<FaultRow>, String> {
    let parse = |text: &str| {
        Scene::parse_str(text, Path::new("bench-faults.toml")).map_err(|e| e.to_string())
    };
    let none = parse(BASE)?;
    let idle = parse(&format!("{BASE}{}", schedule(1.5)))?;
    let active = parse(&format!("{BASE}{}", schedule(0.0)))?;
    let mut truth = collect(&none).map_err(|e| e.to_string())?;
    truth.truncate(1000);
    let cases = [
        ("no faults", &none),
        ("4 sensor faults, none active", &idle),
        ("4 sensor faults, one active (gyro bias step)", &active),
    ];
    let mut best = [f64::INFINITY; 3];
    let start = Instant::now();
    while best[0].is_infinite() || start.elapsed() < min_wall {
        for (b, (_, scene)) in best.iter_mut().zip(&cases) {
            *b = b.min(time_once(scene, &truth)?);
        }
    }
    Ok(cases
        .iter()
        .zip(best)
        .map(|((case, _), ns_per_sample)| FaultRow {
            case,
            ns_per_sample,
        })
        .collect())
}
