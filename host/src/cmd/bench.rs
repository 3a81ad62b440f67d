//! `margemu bench …`: speed against error, measured here and now.

use anyhow::Result;
use margemu::perf::{integrator_sweep, mode_costs};
use margemu::scene::{builtin, Method, MotionMode, Scene};
use std::path::{Path, PathBuf};
use std::time::Duration;

const KINEMATIC: &str = "name = \"figure3-kinematic\"\nduration = 3.0\nrate = 1000.0\nseed = 1\n\
motion = \"kinematic\"\n[bench]\ninitial = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]\n\
[joints.x]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 1.0\noffset = 1.0\n\
[joints.roll]\ntype = \"sine\"\namplitude = 0.4\nfrequency = 2.0\n\
[joints.pitch]\ntype = \"sine\"\namplitude = 0.6\nfrequency = 0.5\n\
[joints.yaw]\ntype = \"sine\"\namplitude = 0.3\nfrequency = 5.0\n";

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Error and speed of each integrator and step on a bench scene (default: Figure 3).
    Integrators {
        /// A bench scene instead of the built-in Figure 3 scene.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Least wall time spent timing each row (s).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
    },
    /// Cost per output sample of a static, a kinematic and a bench scene at 1 kHz.
    Modes {
        /// Least wall time spent timing each row (s).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
    },
    /// Each chip family's sampling chain per output sample: no vibration, and a vibration
    /// scene on the output path and on the internal-rate path, with the error skipping the
    /// internal path costs.
    Chain {
        /// Least wall time spent timing each row (s).
        #[arg(long, default_value_t = 0.5)]
        seconds: f64,
    },
    /// What a schedule of four sensor faults costs per sample of the host's sensor model, idle
    /// and with one active, against no faults (target: under 5 % when none is active).
    Faults {
        /// Least wall time spent timing the three rows, interleaved (s).
        #[arg(long, default_value_t = 3.0)]
        seconds: f64,
    },
    /// What writing `run.mcap` costs per sample against the CSV files (truth + MARG, written
    /// to memory), in time and bytes.
    Mcap {
        /// Least wall time spent timing each format (s).
        #[arg(long, default_value_t = 1.0)]
        seconds: f64,
    },
    /// Real-time streaming through a PTY pair to the firmware's link handler: samples served
    /// byte for byte and lost at each rate, pacing jitter, link efficiency and the rates a UART
    /// carries.
    Stream(super::bench_stream::Cmd),
}

fn inline(text: &str, name: &str) -> Result<Scene> {
    Ok(Scene::parse_str(text, Path::new(name))?)
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        match self {
            Cmd::Integrators { scene, seconds } => {
                let scene = match scene {
                    Some(p) => super::load_scene(&p)?,
                    None => builtin::load("figure3")?,
                };
                if scene.spec.motion != MotionMode::Bench {
                    anyhow::bail!(
                        "{}: `bench integrators` needs a bench scene (motion = \"bench\"); {:?} scenes integrate nothing",
                        scene.path.display(),
                        scene.spec.motion
                    );
                }
                let configs = [
                    (Method::Rk4, 0.001),
                    (Method::Rk4, 0.0005),
                    (Method::Rk4, 0.00025),
                    (Method::SemiImplicitEuler, 0.001),
                    (Method::SemiImplicitEuler, 0.0005),
                    (Method::SemiImplicitEuler, 0.0001),
                    (Method::SemiImplicitEuler, 0.00001),
                ];
                let reference_step = 1e-6;
                println!(
                    "scene {} ({} s at {} Hz, bench dynamics + ground truth, no file output);",
                    scene.path.display(),
                    scene.spec.duration,
                    scene.clock.hz()
                );
                println!("errors are maxima over all samples against RK4 with a {reference_step} s step\n");
                println!(
                    "| integrator | step (s) | max attitude error (rad) | max position error (m) | simulated s / wall s |"
                );
                println!("|---|---|---|---|---|");
                let rows = integrator_sweep(
                    &scene,
                    &configs,
                    reference_step,
                    Duration::from_secs_f64(seconds),
                )?;
                for r in rows {
                    println!(
                        "| {:?} | {} | {:.3e} | {:.3e} | {:.0} |",
                        r.method,
                        r.step,
                        r.max_attitude_error,
                        r.max_position_error,
                        r.realtime_factor
                    );
                }
            }
            Cmd::Stream(cmd) => cmd.run()?,
            Cmd::Faults { seconds } => {
                println!(
                    "host cost per output sample of the sensor model with a sensor-fault schedule \
                     (1 kHz static scene, white noise on every sensor; the fastest of interleaved \
                     1000-sample passes over {seconds} s)\n"
                );
                println!("| case | ns per sample | against no faults |");
                println!("|---|---|---|");
                let rows = margemu::perf_faults::fault_costs(Duration::from_secs_f64(seconds))
                    .map_err(anyhow::Error::msg)?;
                let base = rows[0].ns_per_sample;
                for r in &rows {
                    println!(
                        "| {} | {:.1} | {:+.1} % |",
                        r.case,
                        r.ns_per_sample,
                        (r.ns_per_sample / base - 1.0) * 100.0
                    );
                }
            }
            Cmd::Chain { seconds } => {
                println!(
                    "host cost per output sample of the sensor model behind each chip's sampling \
                     chain (1 s static scenes, white noise; vibration: 4 motors 9000→15000 rpm × \
                     2 harmonics, a PSD 20–2000 Hz, one 11 ms shock)\n"
                );
                println!(
                    "| chip | rate (Hz) | case | ns per sample | error of skipping: accel RMS (m/s²) | gyro RMS (rad/s) |"
                );
                println!("|---|---|---|---|---|---|");
                let rows = margemu::perf_chain::chain_costs(Duration::from_secs_f64(seconds))
                    .map_err(anyhow::Error::msg)?;
                for r in rows {
                    let (a, g) = match r.skip_error {
                        Some([a, g]) => (format!("{a:.3}"), format!("{g:.4}")),
                        None => (String::new(), String::new()),
                    };
                    println!(
                        "| {} | {} | {} | {:.0} | {a} | {g} |",
                        r.chip, r.rate_hz, r.case, r.ns_per_sample
                    );
                }
            }
            Cmd::Mcap { seconds } => {
                let scene = inline(KINEMATIC, "kinematic sines")?;
                println!(
                    "{} samples of a kinematic scene at {} Hz: truth + MARG written to memory as \
                     simulate writes them\n",
                    scene.samples(),
                    scene.clock.hz()
                );
                println!("| files | ns per sample | bytes per sample |");
                println!("|---|---|---|");
                let rows =
                    margemu::perf_mcap::output_costs(&scene, Duration::from_secs_f64(seconds))
                        .map_err(anyhow::Error::msg)?;
                for r in &rows {
                    println!(
                        "| {} | {:.0} | {:.0} |",
                        r.format, r.ns_per_sample, r.bytes_per_sample
                    );
                }
                let [csv, mcap] = &rows;
                println!(
                    "\nMCAP / CSV: {:.2}× the time, {:.2}× the bytes",
                    mcap.ns_per_sample / csv.ns_per_sample,
                    mcap.bytes_per_sample / csv.bytes_per_sample
                );
            }
            Cmd::Modes { seconds } => {
                let scenes = [
                    builtin::load("static")?,
                    inline(
                        &builtin::get("static")
                            .expect("built in")
                            .replace("rate = 200.0", "rate = 1000.0"),
                        "builtin:static at 1 kHz",
                    )?,
                    inline(KINEMATIC, "kinematic sines")?,
                    builtin::load("figure3")?,
                ];
                println!(
                    "| scene | mode | output rate (Hz) | ns per sample | simulated s / wall s |"
                );
                println!("|---|---|---|---|---|");
                let rows = mode_costs(&scenes, Duration::from_secs_f64(seconds))?;
                for (r, s) in rows.iter().zip(&scenes) {
                    println!(
                        "| {} | {} | {} | {:.1} | {:.0} |",
                        s.path.display(),
                        r.mode,
                        s.clock.hz(),
                        r.ns_per_sample,
                        r.realtime_factor
                    );
                }
            }
        }
        Ok(())
    }
}
