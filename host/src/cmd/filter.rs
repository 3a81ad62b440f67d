//! `margemu filter --filter ecf|gda|ekf INPUT -o FILE`: run a reference filter offline over a
//! recording and write its estimates (library: `margemu::offline`).

use anyhow::{bail, Context, Result};
use margemu::offline::{self, AttitudeStart, FilterKind, FilterParams, Initial};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args)]
pub struct Cmd {
    /// A `simulate` run directory (marg.csv, meta.toml) or a CSV recording
    /// `t_s,ax,ay,az,gx,gy,gz,mx,my,mz`.
    input: PathBuf,
    /// The filter: ecf (eq. 24), gda (eq. 25) or ekf (eq. 26).
    #[arg(long)]
    filter: FilterKind,
    /// A parameters file (as `margemu tune --write-params` writes it); its `[ecf]`, `[gda]` or
    /// `[ekf]` table sets the filter's parameters.
    #[arg(long)]
    params: Option<PathBuf>,
    /// NAME=VALUE, after --params (ecf: kp, ki; gda: beta; ekf: gyro_noise, gyro_bias_walk,
    /// accel_noise, mag_noise). Repeatable.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    param: Vec<String>,
    /// World magnetic reference x,y,z (default: the run's scene, or (0.5, 0, -0.83) for a CSV).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    mag_reference: Option<Vec<f64>>,
    /// Where the filter starts: first-sample (TRIAD on the first sample) or truth (the true
    /// attitude at the first sample, from a run directory's truth.csv).
    #[arg(long, default_value = "first-sample")]
    attitude_start: AttitudeStart,
    /// The estimates file: t_s,qw,qx,qy,qz,roll,pitch,yaw.
    #[arg(short, long)]
    output: PathBuf,
}

impl Cmd {
    pub fn run(self) -> Result<()> {
        let mut params = match &self.params {
            Some(path) => {
                let text = margemu::input_file::read_to_string(path)?;
                FilterParams::from_toml(&text, path, self.filter)?
            }
            None => FilterParams::defaults(self.filter),
        };
        for assignment in &self.param {
            params
                .set_assignment(assignment)
                .with_context(|| format!("--param {assignment}"))?;
        }
        let reference = match self.mag_reference.as_deref() {
            None => None,
            Some(&[x, y, z]) => Some([x, y, z]),
            Some(other) => bail!("--mag-reference needs three numbers, not {other:?}"),
        };
        let initial = match self.attitude_start {
            AttitudeStart::FirstSample => Initial::FirstSample,
            AttitudeStart::Truth => Initial::Attitude(offline::first_true_attitude(&self.input)?),
        };
        let start = Instant::now();
        let run = offline::filter_to_file(&params, &self.input, reference, initial, &self.output)?;
        let elapsed = start.elapsed();
        for warning in run.warnings() {
            eprintln!("warning: {warning}");
        }
        let values: Vec<String> = params
            .iter()
            .map(|(p, v)| format!("{}={v}", p.name))
            .collect();
        println!(
            "{} ({}) over {} samples of {} in {:.3} s (reading and writing included); wrote {}",
            self.filter,
            values.join(", "),
            run.samples,
            run.source,
            elapsed.as_secs_f64(),
            self.output.display()
        );
        Ok(())
    }
}
