//! `margemu filter --filter ecf|gda|ekf INPUT -o FILE`: run a reference filter offline over a
//! recording and write its estimates (library: `margemu::offline`).

use anyhow::{bail, Context, Result};
use margemu::frame::Frame;
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
    /// NAME=VALUE, after --params (ecf: kp, ki; gda: beta, normalization=gradient|residual|xio;
    /// ekf: gyro_noise, gyro_bias_walk, accel_noise, mag_noise, initial_attitude_std,
    /// initial_bias_std); NAME may carry the filter as a prefix (gda.beta). Repeatable.
    #[arg(long = "param", value_name = "NAME=VALUE")]
    param: Vec<String>,
    /// World magnetic reference `X,Y,Z` (spaces after commas allowed), or `auto`: estimated
    /// from the CSV recording's first rest phase (the default for a CSV; a run directory's
    /// default is its scene's).
    #[arg(long, allow_hyphen_values = true, value_name = "X,Y,Z|auto")]
    mag_reference: Option<String>,
    /// Where the filter starts: first-sample (TRIAD on the first sample) or truth (the true
    /// attitude at the first sample: a run directory's truth.csv, or a CSV recording's
    /// reference columns qw,qx,qy,qz on its first row).
    #[arg(long, default_value = "first-sample")]
    attitude_start: AttitudeStart,
    /// The world frame of a CSV recording, of --mag-reference and of the estimates written:
    /// nwu (margemu's), enu, or ned (body FRD); see the evaluation guide.
    #[arg(long, default_value = "nwu")]
    frame: Frame,
    /// The estimates file: t_s,qw,qx,qy,qz,roll,pitch,yaw.
    #[arg(short, long)]
    output: PathBuf,
}

/// The magnetic reference estimated from the recording at `input`, printed with its rows; when
/// the estimate fails and it was not asked for (`explicit`), the default, with a note.
fn estimated(input: &std::path::Path, frame: Frame, explicit: bool) -> Result<Option<[f64; 3]>> {
    match offline::mag_estimate::estimate_in(input, frame) {
        Ok(e) => {
            println!("{e}");
            Ok(Some(e.reference))
        }
        Err(e) if explicit => Err(anyhow::anyhow!("--mag-reference auto: {e}")),
        Err(e) => {
            println!("note: {e}; using the default reference instead");
            Ok(None)
        }
    }
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
            Some("auto") if self.input.is_dir() => {
                bail!("--mag-reference auto: estimation applies to a CSV recording; a run directory's reference is its scene's")
            }
            Some("auto") => estimated(&self.input, self.frame, true)?,
            Some(text) => Some(
                self.frame
                    .world_in(super::parse_vector3("--mag-reference", text)?),
            ),
            None if self.input.is_file() => estimated(&self.input, self.frame, false)?,
            None => None,
        };
        let initial = match self.attitude_start {
            AttitudeStart::FirstSample => Initial::FirstSample,
            AttitudeStart::Truth => {
                Initial::Attitude(offline::first_true_attitude_in(&self.input, self.frame)?)
            }
        };
        let start = Instant::now();
        if self.frame != Frame::Nwu && self.input.is_dir() {
            bail!("--frame {}: a run directory is margemu's own (nwu); the frame applies to a CSV recording", self.frame);
        }
        let run = offline::filter_to_file_in(
            &params,
            &self.input,
            reference,
            initial,
            &self.output,
            self.frame,
        )?;
        if self.frame != Frame::Nwu {
            println!(
                "frame {}: the recording's IMU columns and --mag-reference read in it, the estimates written in it (evaluate them with --frame {})",
                self.frame, self.frame
            );
        }
        let elapsed = start.elapsed();
        for warning in run.warnings() {
            eprintln!("warning: {warning}");
        }
        let values = params.assignments();
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
