//! A filter run from a recording on disk to an estimates file, one sample at a time: memory
//! does not grow with the recording (the first [`FIRST_STEP_WINDOW`]` + 1` samples are held
//! to find the first sample's time step, as [`run`](super::run) does), and the estimates are
//! those [`run`](super::run) gives for the same samples. The estimates file is created once the
//! recording has a first sample, and removed when a later row turns out bad.
//!
//! Input that is legal but likely wrong is reported as warnings: every accelerometer sample
//! zero (no gravity to level on), every magnetometer sample zero (no heading).

use super::input::{open, InputError, Sample};
use super::{write_estimate, FilterParams, ParamError, ESTIMATE_COLUMNS};
use crate::evaluate::{first_step_s, FIRST_STEP_WINDOW};
use crate::frame::Frame;
use margemu_filters::Initial;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Samples parsed per batch handed from the reading thread to the filtering one.
const BATCH: usize = 4096;

/// A filter run that could not be done.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum FilterError {
    /// {0}
    Input(#[from] InputError),
    /// {0}
    Params(#[from] ParamError),
    /// {path}: cannot write: {error}
    Write {
        /// The estimates file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
}

/// What a filter run read.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterRun {
    /// Samples filtered (one estimate each).
    pub samples: usize,
    /// Samples whose accelerometer vector is exactly zero.
    pub zero_acc: usize,
    /// Samples whose magnetometer vector is exactly zero.
    pub zero_mag: usize,
    /// What was read.
    pub source: String,
}

impl FilterRun {
    /// Warnings about input that is legal but likely wrong.
    pub fn warnings(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.zero_acc == self.samples {
            out.push(format!(
                "{}: every accelerometer sample is zero: the filter has no gravity to level on (a recording without an accelerometer, or its columns misnamed?)",
                self.source
            ));
        }
        if self.zero_mag == self.samples {
            out.push(format!(
                "{}: every magnetometer sample is zero: the filter has no heading reference (a chip without a magnetometer, or its columns misnamed?)",
                self.source
            ));
        }
        out
    }
}

/// Runs the filter `params` describes over the recording at `input` (see
/// [`open`](super::input::open) for `mag_reference`), started as `initial` says, and writes its
/// estimates to `output` (see the module docs).
pub fn filter_to_file(
    params: &FilterParams,
    input: &Path,
    mag_reference: Option<[f64; 3]>,
    initial: Initial,
    output: &Path,
) -> Result<FilterRun, FilterError> {
    filter_to_file_in(params, input, mag_reference, initial, output, Frame::Nwu)
}

/// [`filter_to_file`] for a recording in `frame` ([`crate::frame`]): its IMU columns are
/// converted into margemu's axes as they are read and the estimates written back in `frame`;
/// `mag_reference` and `initial` are already margemu's (NWU).
pub fn filter_to_file_in(
    params: &FilterParams,
    input: &Path,
    mag_reference: Option<[f64; 3]>,
    initial: Initial,
    output: &Path,
    frame: Frame,
) -> Result<FilterRun, FilterError> {
    let mut samples = open(input, mag_reference)?;
    let first = samples.first_sample()?;
    let mut filter = params.build(samples.mag_reference, initial)?;
    let mut head: Vec<Sample> = vec![first];
    while head.len() <= FIRST_STEP_WINDOW {
        match samples.next_sample()? {
            Some(s) => head.push(s),
            None => break,
        }
    }
    let times: Vec<u64> = head.iter().map(|s| s.0).collect();
    let first_step = first_step_s(&times);
    let write_err = |error| FilterError::Write {
        path: output.to_path_buf(),
        error,
    };
    let file = std::fs::File::create(output).map_err(write_err)?;
    let mut out = BufWriter::with_capacity(1 << 16, file);
    let mut run = FilterRun {
        samples: 0,
        zero_acc: 0,
        zero_mag: 0,
        source: samples.source.clone(),
    };
    let mut float = ryu::Buffer::new();
    let mut previous: Option<u64> = None;
    let mut step = |s: Sample, out: &mut BufWriter<std::fs::File>| {
        let (t_ns, acc, gyro, mag) = s;
        let (acc, gyro, mag) = (frame.body_in(acc), frame.body_in(gyro), frame.body_in(mag));
        let dt = previous.map_or(first_step, |p| (t_ns - p) as f64 * 1e-9);
        previous = Some(t_ns);
        run.samples += 1;
        run.zero_acc += usize::from(acc == [0.0; 3]);
        run.zero_mag += usize::from(mag == [0.0; 3]);
        filter.update(&margemu_filters::Imu { gyro, acc, mag }, dt);
        write_estimate(out, &mut float, t_ns, frame.quat_out(filter.quaternion()))
    };
    let result = std::thread::scope(|scope| {
        // Parsing on a second thread, in batches (a few in flight), while this one filters and
        // writes: the two take about as long each.
        let (tx, rx) = std::sync::mpsc::sync_channel::<Result<Vec<Sample>, InputError>>(4);
        scope.spawn(move || loop {
            let mut batch = Vec::with_capacity(BATCH);
            while batch.len() < BATCH {
                match samples.next_sample() {
                    Ok(Some(s)) => batch.push(s),
                    Ok(None) => break,
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        return;
                    }
                }
            }
            let last = batch.len() < BATCH;
            if tx.send(Ok(batch)).is_err() || last {
                return;
            }
        });
        writeln!(out, "{}", ESTIMATE_COLUMNS.join(",")).map_err(write_err)?;
        for s in head {
            step(s, &mut out).map_err(write_err)?;
        }
        for batch in rx {
            for s in batch? {
                step(s, &mut out).map_err(write_err)?;
            }
        }
        out.flush().map_err(write_err)
    });
    match result {
        Ok(()) => Ok(run),
        Err(e) => {
            drop(out);
            let _ = std::fs::remove_file(output);
            Err(e)
        }
    }
}
