//! `margemu scene check SCENE`: validate a scene (its CSV sources too), print its warnings (to
//! stderr), its run, its size and the derived PID gains.

use anyhow::Result;
use margemu::bench::{designs, masses_and_loads};
use margemu::scene::JOINT_NAMES;
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Validate a scene and print its run and the PID gains derived from Table 2.
    Check {
        /// The scene: a file (TOML) or a built-in scene's name (`margemu scenes`).
        scene: PathBuf,
    },
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let Cmd::Check { scene } = self;
        let scene = super::load_scene(&scene)?;
        let spec = &scene.spec;
        println!(
            "ok: {}: {} samples at {} Hz over {} s, motion {:?}, {:?} integrator with {} s steps, seed {}",
            scene.path.display(),
            scene.samples(),
            scene.clock.hz(),
            spec.duration,
            spec.motion,
            spec.integrator.method,
            spec.integrator.step,
            spec.seed
        );
        let size = margemu::scene::size::estimate(&scene);
        println!("size: {size}");
        if size.is_large() {
            println!(
                "beyond the limit of {} samples and {} of output: simulate, loopback and stream \
                 need --allow-large",
                margemu::scene::size::MAX_SAMPLES,
                margemu::scene::size::bytes(margemu::scene::size::MAX_OUTPUT_BYTES)
            );
        }
        if spec.motion != margemu::scene::MotionMode::Bench {
            println!("no dynamics in {:?} mode: no PID gains", spec.motion);
            return Ok(());
        }
        let (masses, _) = masses_and_loads(&scene);
        if let Some(gains) = &spec.control.gains {
            println!(
                "{:<6} {:>12} {:>12} {:>12}   (explicit gains)",
                "joint", "Kp", "Ki", "Kd"
            );
            for (name, g) in JOINT_NAMES.iter().zip(gains) {
                println!("{name:<6} {:>12.6} {:>12.6} {:>12.6}", g[0], g[1], g[2]);
            }
            return Ok(());
        }
        println!(
            "{:<6} {:>10} {:>6} {:>7} {:>6} {:>7} {:>8} {:>12} {:>12} {:>12} {:>9} {:>9}",
            "joint",
            "M",
            "ζ eq11",
            "ωn eq11",
            "ζ",
            "ωn",
            "T (s)",
            "Kp",
            "Ki",
            "Kd",
            "overshoot",
            "settling"
        );
        for (i, d) in designs(&scene).iter().enumerate() {
            let d = d.as_ref().expect("synthesised");
            println!(
                "{:<6} {:>10.4e} {:>6.3} {:>7.3} {:>6.3} {:>7.3} {:>8.5} {:>12.6e} {:>12.6e} {:>12.6e} {:>8.1}% {:>7.3} s",
                JOINT_NAMES[i],
                masses[i],
                d.initial.0,
                d.initial.1,
                d.tuned.0,
                d.tuned.1,
                d.time_constant,
                d.gains.kp,
                d.gains.ki,
                d.gains.kd,
                d.predicted_overshoot * 100.0,
                d.predicted_settling
            );
        }
        println!(
            "requirements: overshoot {:?}, settling {:?} s; retune {} (margin {}), pole ratio {}",
            spec.control.overshoot,
            spec.control.settling_time,
            spec.control.retune,
            spec.control.retune_margin,
            spec.control.pole_ratio
        );
        Ok(())
    }
}
