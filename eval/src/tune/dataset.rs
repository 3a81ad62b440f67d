//! The runs a tuner scores every candidate on: one scene simulated with several seeds, each
//! seed's truth and MARG samples computed once and kept.
//!
//! Seed `i` (from 0) runs the scene with `seed + i`, so seed 0 is the scene itself; the seed
//! drives everything random in the scene (random setpoints and sines, sensor noise, magnetic
//! bursts). Seeds are simulated in parallel (rayon) and scored in parallel; results are
//! collected in seed order, so they do not depend on the number of threads.

use super::{AttitudeStart, TuneError};
use crate::evaluate::input::Imu;
use crate::evaluate::{Estimates, Reference, ScoreError, ScoreOptions, Scores};
use crate::offline::{self, FilterParams, Initial, ParamError};
use margemu_sim::marg::MargSim;
use margemu_sim::run::RunError;
use margemu_sim::scene::Scene;
use rayon::prelude::*;

/// One seed's run.
#[derive(Clone, Debug)]
pub struct SeedRun {
    /// The scene seed it ran with.
    pub seed: u64,
    /// The truth, ready to score against.
    pub reference: Reference,
    /// The MARG samples the sensor model gave (`f32`, widened).
    pub imu: Imu,
    /// The true attitude at the first sample.
    pub first_attitude: [f64; 4],
}

/// A scene run with several seeds.
#[derive(Clone, Debug)]
pub struct Dataset {
    /// The scene's file, for reports.
    pub scene: String,
    /// Output rate (Hz).
    pub rate_hz: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// World magnetic reference of the scene.
    pub mag_reference: [f64; 3],
    /// One run per seed, in seed order.
    pub runs: Vec<SeedRun>,
}

/// Why a candidate could not be scored.
#[derive(Debug, Clone, PartialEq, thiserror::Error, docsplay::Display)]
pub enum CandidateError {
    /// {0}
    Params(ParamError),
    /// seed {seed}: {reason}
    Score {
        /// The seed.
        seed: u64,
        /// Why.
        reason: ScoreError,
    },
}

impl Dataset {
    /// Simulates `scene` with seeds `scene.spec.seed + i`, `i` in `0..seeds`.
    pub fn simulate(scene: &Scene, seeds: usize) -> Result<Self, TuneError> {
        if seeds == 0 {
            return Err(TuneError::NoSeeds);
        }
        let runs = (0..seeds as u64)
            .into_par_iter()
            .map(|i| simulate_seed(scene, scene.spec.seed.wrapping_add(i)))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            scene: scene.path.display().to_string(),
            rate_hz: scene.clock.hz(),
            duration_s: scene.spec.duration,
            mag_reference: scene.spec.field.reference,
            runs,
        })
    }

    /// The seeds, in order.
    pub fn seeds(&self) -> Vec<u64> {
        self.runs.iter().map(|r| r.seed).collect()
    }

    /// The scores of the filter `params`, started as `start` says, on every seed, in seed
    /// order.
    pub fn score(
        &self,
        params: &FilterParams,
        start: AttitudeStart,
        opts: &ScoreOptions,
    ) -> Result<Vec<Scores>, CandidateError> {
        self.runs
            .par_iter()
            .map(|run| {
                let initial = match start {
                    AttitudeStart::FirstSample => Initial::FirstSample,
                    AttitudeStart::Truth => Initial::Attitude(run.first_attitude),
                };
                let estimates = offline::run(params, &run.imu, self.mag_reference, initial)
                    .map_err(CandidateError::Params)?;
                let scored = Estimates::new(&estimates)
                    .and_then(|e| run.reference.score(&e, opts))
                    .map_err(|reason| CandidateError::Score {
                        seed: run.seed,
                        reason,
                    })?;
                Ok(scored)
            })
            .collect()
    }
}

fn simulate_seed(scene: &Scene, seed: u64) -> Result<SeedRun, TuneError> {
    let mut scene = scene.clone();
    scene.spec.seed = seed;
    let mut marg = MargSim::new(&scene).map_err(|e| TuneError::Run(RunError::Model(e)))?;
    let n = scene.samples() as usize;
    let mut truth = Vec::with_capacity(n);
    let mut imu = Imu {
        t_ns: Vec::with_capacity(n),
        acc: Vec::with_capacity(n),
        gyr: Vec::with_capacity(n),
        mag: Vec::with_capacity(n),
    };
    let widen = |v: [f32; 3]| v.map(f64::from);
    margemu_sim::run::for_each(&scene, |t| {
        let s = marg.sample(t).sample;
        truth.push((t.t_ns, t.quaternion));
        imu.t_ns.push(t.t_ns);
        imu.acc.push(widen(s.acc));
        imu.gyr.push(widen(s.gyr));
        imu.mag.push(widen(s.mag));
    })
    .map_err(|e| TuneError::Run(RunError::Reference(e)))?;
    let reference = Reference::new(&truth).map_err(|reason| TuneError::Truth { seed, reason })?;
    Ok(SeedRun {
        seed,
        reference,
        first_attitude: truth[0].1,
        imu,
    })
}
