//! `--vfc ecf|gda|ekf [--vfc-params FILE] [--vfc-rate HZ|every]` of `margemu loopback`: a
//! virtual flight controller on the emulated chip (library: `margemu::vfc`), and what is printed
//! about it at the end.

use anyhow::{Context, Result};
use margemu::dut::DutSummary;
use margemu::offline::{FilterKind, FilterParams};
use margemu::scene::Scene;
use margemu::vfc::{FcOutcome, OutputRate, VfcConfig};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct VfcArgs {
    /// Run a virtual flight controller with this filter on the emulated chip: its driver over
    /// the virtual bus (`mpu9250` on the MPU-9250; `icm426xx` on the ICM-42688-P, which has no
    /// magnetometer: heading from the gyroscope alone, compare roll and pitch; on a rig, its
    /// IST8310 or QMC5883L compass over I2C gives the heading), MAVLink
    /// ATTITUDE/ATTITUDE_QUATERNION read back through a second PTY pair into dut_*.csv and
    /// scored at the end.
    #[arg(long, conflicts_with = "dut", value_name = "ecf|gda|ekf")]
    pub vfc: Option<FilterKind>,
    /// The filter's parameters (TOML: [ecf] kp, ki; [gda] beta; [ekf] gyro_noise,
    /// gyro_bias_walk, accel_noise, mag_noise); absent keys keep the defaults.
    #[arg(long, requires = "vfc", value_name = "FILE")]
    pub vfc_params: Option<PathBuf>,
    /// Attitude output rate of the flight controller: Hz on its clock, or `every` sample.
    #[arg(long, requires = "vfc", default_value = "50", value_name = "HZ|every")]
    pub vfc_rate: OutputRate,
}

impl VfcArgs {
    /// The flight controller's configuration on `scene`, or `None` without `--vfc`.
    pub fn config(&self, scene: &Scene) -> Result<Option<VfcConfig>> {
        let Some(kind) = self.vfc else {
            return Ok(None);
        };
        let filter = match &self.vfc_params {
            Some(path) => {
                let text = margemu::input_file::read_to_string(path)?;
                FilterParams::from_toml(&text, path, kind)?
            }
            None => FilterParams::defaults(kind),
        };
        Ok(Some(VfcConfig {
            output: self.vfc_rate,
            ..VfcConfig::for_scene(scene, filter)
        }))
    }
}

/// Prints what the flight controller did and checks that its frames arrived; then scores its
/// attitude against the truth (report.md and errors.csv in `dir`).
pub fn report(fc: &FcOutcome, dut: &DutSummary, dir: &Path) -> Result<()> {
    println!("virtual flight controller: {}", fc.fc);
    fc.check_delivery(dut)
        .map_err(|e| anyhow::anyhow!("the flight controller's MAVLink did not all arrive: {e}"))?;
    println!(
        "every frame the flight controller sent was decoded ({} frames, {} bytes)",
        fc.uart.frames, fc.uart.bytes
    );
    let eval = margemu::vfc_score::evaluate_session(dir)
        .with_context(|| format!("evaluating {}", dir.display()))?;
    print!("{}", margemu::evaluate::report::summary(&eval));
    margemu::evaluate::report::write(&eval, dir, false)?;
    println!(
        "wrote {0}/report.md and {0}/errors.csv; figures: margemu evaluate {0} --message ATTITUDE_QUATERNION",
        dir.display()
    );
    Ok(())
}
