//! What writing MCAP costs beside the CSV files: `margemu bench mcap`. One scene's truth and
//! MARG samples are computed once, then written again and again, as `simulate` writes them, to
//! memory (no disk): as `truth.csv` + `marg.csv` ([`TruthWriter`], [`MargWriter`]) and as
//! `run.mcap` ([`McapLog`]: six messages per sample). The figures are wall time per sample and
//! bytes per sample of each.

use margemu_sim::marg::{MargSample, MargSim, MargWriter};
use margemu_sim::mcap::{McapLog, McapSetup, PLATE_FRAME};
use margemu_sim::output::TruthWriter;
use margemu_sim::run::{collect, reading};
use margemu_sim::scene::Scene;
use margemu_sim::truth::Truth;
use std::io::{self, Cursor};
use std::time::{Duration, Instant};

/// One output format's cost.
#[derive(Clone, Debug)]
pub struct OutputCost {
    /// Which files.
    pub format: &'static str,
    /// Wall time per sample (ns).
    pub ns_per_sample: f64,
    /// Bytes written per sample.
    pub bytes_per_sample: f64,
}

/// The cost of the CSV files and of `run.mcap` for `scene`, each timed for at least `min_wall`.
pub fn output_costs(scene: &Scene, min_wall: Duration) -> Result<[OutputCost; 2], String> {
    let truths = collect(scene).map_err(|e| e.to_string())?;
    let mut marg = MargSim::new(scene).map_err(|e| e.to_string())?;
    let samples: Vec<MargSample> = truths
        .iter()
        .map(|t| marg.try_sample(scene, t).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let mut buf = Vec::with_capacity(2000 * truths.len());
    let csv = time(&truths, min_wall, &mut buf, |buf| {
        write_csv(&truths, &samples, buf)
    })
    .map_err(|e| e.to_string())?;
    let setup = McapSetup {
        scene: scene.stem(),
        seed: scene.spec.seed,
        field_unit: scene.spec.field.unit,
        ut_per_unit: margemu_sim::mcap::ut_per_unit(scene.spec.field.unit),
        devices: vec![(scene.chip_name.clone(), PLATE_FRAME.to_string())],
        clock: "scene time".to_string(),
    };
    let mcap = time(&truths, min_wall, &mut buf, |buf| {
        let mut log = McapLog::new(Cursor::new(buf), &setup)?;
        for (t, s) in truths.iter().zip(&samples) {
            log.truth(t)?;
            log.marg(0, &reading(scene, s))?;
        }
        log.finish().map(drop)
    })
    .map_err(|e| e.to_string())?;
    Ok([
        OutputCost {
            format: "CSV (truth.csv + marg.csv)",
            ns_per_sample: csv.0,
            bytes_per_sample: csv.1,
        },
        OutputCost {
            format: "MCAP (run.mcap)",
            ns_per_sample: mcap.0,
            bytes_per_sample: mcap.1,
        },
    ])
}

fn write_csv(truths: &[Truth], samples: &[MargSample], buf: &mut Vec<u8>) -> io::Result<()> {
    // Both files into one buffer: what counts is the bytes and the time, not the files.
    let mut marg_buf = Vec::with_capacity(100 * samples.len());
    let mut truth = TruthWriter::new(&mut *buf)?;
    let mut marg = MargWriter::new(&mut marg_buf, None)?;
    for (t, s) in truths.iter().zip(samples) {
        truth.write(t)?;
        marg.write(s)?;
    }
    truth.finish()?;
    marg.finish()?;
    buf.extend_from_slice(&marg_buf);
    Ok(())
}

/// `(ns per sample, bytes per sample)` of `write`, run into a cleared `buf` until `min_wall`
/// has passed (at least once).
fn time(
    truths: &[Truth],
    min_wall: Duration,
    buf: &mut Vec<u8>,
    mut write: impl FnMut(&mut Vec<u8>) -> io::Result<()>,
) -> io::Result<(f64, f64)> {
    let n = truths.len().max(1) as f64;
    let start = Instant::now();
    let mut passes = 0u32;
    loop {
        buf.clear();
        write(buf)?;
        passes += 1;
        if start.elapsed() >= min_wall {
            break;
        }
    }
    let wall = start.elapsed().as_secs_f64();
    Ok((wall * 1e9 / (n * f64::from(passes)), buf.len() as f64 / n))
}
