//! The search: argmin's Nelder–Mead over the natural logarithms of a filter's parameters, inside
//! the box `[ln lower, ln upper]` of each [`ParamSpec`], under a budget of evaluations.
//!
//! - **Log space.** Gains and noise statistics are scale parameters (a factor of 2 matters the
//!   same at 0.01 as at 10), and the logarithm keeps every candidate positive.
//! - **Bounds.** A vertex outside the box is evaluated at its projection onto the box (clamped
//!   per coordinate), and its cost is multiplied by `1 + d²`, `d` the Euclidean distance
//!   outside the box in log units. So the simplex is pushed back, the cost stays continuous,
//!   and a projection that was already evaluated is not run again (a cache keyed by the
//!   projected point). A parameter that may be off (`zero_at_lower`, the ECF's `ki`) is 0 at
//!   its lower bound.
//! - **Start.** The simplex is the start point and, per coordinate, one vertex a factor of 4
//!   above it (below it when that leaves the box).
//! - **Stop.** Nelder–Mead stops when the standard deviation of the simplex's costs falls below
//!   `1e-5` of the best cost at the run's start, or the budget is spent (checked after each iteration, so it
//!   may be passed by up to `n + 1` evaluations: a shrink). After a converged run it restarts
//!   from the best point with a fresh simplex a factor of 2 wide, while the budget lasts and
//!   the last restart improved the best cost by more than `1e-3` of it (restarts undo a
//!   collapsed simplex).
//!
//! The cost function is called in order and must be deterministic; then so is the search.

use crate::offline::{FilterKind, FilterParams, ParamSpec};
use argmin::core::{
    CostFunction, Error, Executor, IterState, Problem, Solver, State, TerminationReason,
    TerminationStatus, KV,
};
use argmin::solver::neldermead::NelderMead;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// A Nelder–Mead run has converged when the standard deviation of its simplex's costs is below
/// this fraction of the best cost at its start.
const RELATIVE_TOLERANCE: f64 = 1e-5;

/// Cost reported for a candidate the objective could not score.
pub const FAILED_COST: f64 = 1e6;

/// What a search found.
#[derive(Clone, Debug, PartialEq)]
pub struct SearchOutcome {
    /// The best parameters evaluated.
    pub best: FilterParams,
    /// Their cost.
    pub cost: f64,
    /// Calls of the cost function (the optimiser's evaluations).
    pub evaluations: usize,
    /// Distinct candidates run (the rest came from the cache).
    pub distinct: usize,
    /// Nelder–Mead runs (1 + restarts).
    pub runs: usize,
    /// Why it stopped.
    pub stop: String,
}

/// The candidate at log-space point `x`: the projected parameters and the squared distance
/// outside the box.
fn candidate(kind: FilterKind, x: &[f64]) -> (FilterParams, f64) {
    let mut params = FilterParams::defaults(kind);
    let mut outside = 0.0;
    for (spec, &xi) in kind.params().iter().zip(x) {
        let (lo, hi) = (spec.lower.ln(), spec.upper.ln());
        let clamped = xi.clamp(lo, hi);
        outside += (xi - clamped).powi(2);
        let value = if spec.zero_at_lower && clamped <= lo {
            0.0
        } else {
            clamped.exp()
        };
        params
            .set(spec.name, value)
            .expect("a value inside the box");
    }
    (params, outside)
}

/// The log-space point of `params`, projected onto the box (0 maps to the lower bound).
fn point(params: &FilterParams) -> Vec<f64> {
    params
        .iter()
        .map(|(spec, v)| v.clamp(spec.lower, spec.upper).ln())
        .collect()
}

/// The start simplex around `x0`, vertices `step` (log units) along each axis.
fn simplex(specs: &[ParamSpec], x0: &[f64], step: f64) -> Vec<Vec<f64>> {
    let mut out = vec![x0.to_vec()];
    for (i, spec) in specs.iter().enumerate() {
        let mut v = x0.to_vec();
        v[i] += if x0[i] + step <= spec.upper.ln() {
            step
        } else {
            -step
        };
        out.push(v);
    }
    out
}

/// Costs of the candidates run so far (keyed by their parameters' bits) and the calls made,
/// across Nelder–Mead runs.
#[derive(Default)]
struct Tally {
    cache: Mutex<HashMap<Vec<u64>, f64>>,
    calls: AtomicUsize,
}

/// The cost function argmin sees.
#[derive(Clone, Copy)]
struct Objective<'a> {
    kind: FilterKind,
    f: &'a (dyn Fn(&FilterParams) -> f64 + Sync),
    progress: &'a (dyn Fn(usize) + Sync),
    tally: &'a Tally,
}

impl CostFunction for Objective<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        let (params, outside) = candidate(self.kind, x);
        let key: Vec<u64> = params.values().iter().map(|v| v.to_bits()).collect();
        let cache = &self.tally.cache;
        let cached = cache.lock().map_or(None, |c| c.get(&key).copied());
        let inside = match cached {
            Some(c) => c,
            None => {
                let c = (self.f)(&params);
                let c = if c.is_finite() { c } else { FAILED_COST };
                if let Ok(mut cache) = cache.lock() {
                    cache.insert(key, c);
                }
                c
            }
        };
        let calls = self.tally.calls.fetch_add(1, Ordering::Relaxed) + 1;
        (self.progress)(calls);
        Ok(inside * (1.0 + outside))
    }
}

/// Nelder–Mead that also stops once the tally has counted `max_evals` calls.
struct Budgeted<'a> {
    inner: NelderMead<Vec<f64>, f64>,
    tally: &'a Tally,
    max_evals: usize,
}

type NmState = IterState<Vec<f64>, (), (), (), (), f64>;

impl<O: CostFunction<Param = Vec<f64>, Output = f64>> Solver<O, NmState> for Budgeted<'_> {
    fn name(&self) -> &str {
        "Nelder-Mead with an evaluation budget"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: NmState,
    ) -> Result<(NmState, Option<KV>), Error> {
        self.inner.init(problem, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: NmState,
    ) -> Result<(NmState, Option<KV>), Error> {
        self.inner.next_iter(problem, state)
    }

    fn terminate(&mut self, state: &NmState) -> TerminationStatus {
        if self.tally.calls.load(Ordering::Relaxed) >= self.max_evals {
            return TerminationStatus::Terminated(TerminationReason::SolverExit(
                "evaluation budget spent".into(),
            ));
        }
        Solver::<O, NmState>::terminate(&mut self.inner, state)
    }
}

/// Minimises `f` over the parameters of `start.kind()` from `start`, with at most about
/// `max_evals` evaluations; `progress(calls)` after each. See the module docs.
pub fn minimize(
    start: &FilterParams,
    max_evals: usize,
    f: &(dyn Fn(&FilterParams) -> f64 + Sync),
    progress: &(dyn Fn(usize) + Sync),
) -> Result<SearchOutcome, Error> {
    let kind = start.kind();
    let specs = kind.params();
    let tally = Tally::default();
    let objective = Objective {
        kind,
        f,
        progress,
        tally: &tally,
    };
    let mut best = point(start);
    let mut best_cost = objective.cost(&best)?;
    let (mut runs, mut step) = (0, 4f64.ln());
    let mut stop: String;
    loop {
        let used = tally.calls.load(Ordering::Relaxed);
        if used + specs.len() + 2 > max_evals {
            stop = "evaluation budget spent".into();
            break;
        }
        let tolerance = RELATIVE_TOLERANCE * best_cost.max(f64::MIN_POSITIVE);
        let solver = Budgeted {
            inner: NelderMead::new(simplex(specs, &best, step)).with_sd_tolerance(tolerance)?,
            tally: &tally,
            max_evals,
        };
        let result = Executor::new(objective, solver).run()?;
        runs += 1;
        let state = result.state();
        let reason = state.get_termination_reason();
        stop = reason.map_or("stopped".into(), |r| r.text().to_owned());
        let previous = best_cost;
        if let Some(p) = state.get_best_param() {
            if state.get_best_cost() < best_cost {
                best_cost = state.get_best_cost();
                best = p.clone();
            }
        }
        let converged = matches!(reason, Some(TerminationReason::SolverConverged));
        if !converged || (runs > 1 && previous - best_cost <= 1e-3 * previous) {
            break;
        }
        step = 2f64.ln();
    }
    let distinct = tally.cache.lock().map_or(0, |c| c.len());
    Ok(SearchOutcome {
        best: candidate(kind, &best).0,
        cost: best_cost,
        evaluations: tally.calls.load(Ordering::Relaxed),
        distinct,
        runs,
        stop,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_minimum_of_a_bowl_in_log_space_and_respects_the_box() {
        // Minimum at kp = 2, ki = 0.05 (inside the box).
        let bowl = |p: &FilterParams| {
            let (kp, ki) = (p.get("kp").unwrap(), p.get("ki").unwrap().max(1e-12));
            1.0 + (kp / 2.0).ln().powi(2) + (ki / 0.05).ln().powi(2)
        };
        let start = FilterParams::defaults(FilterKind::Ecf);
        let out = minimize(&start, 300, &bowl, &|_| {}).unwrap();
        assert!(
            (out.best.get("kp").unwrap() / 2.0 - 1.0).abs() < 0.02,
            "{out:?}"
        );
        assert!(
            (out.best.get("ki").unwrap() / 0.05 - 1.0).abs() < 0.05,
            "{out:?}"
        );
        assert!(out.evaluations <= 300 + 3, "{out:?}");
        // Minimum beyond the upper bound of beta (10): the search ends on the bound.
        let ramp = |p: &FilterParams| 1.0 / p.get("beta").unwrap();
        let start = FilterParams::defaults(FilterKind::Gda);
        let out = minimize(&start, 200, &ramp, &|_| {}).unwrap();
        assert!(
            (out.best.get("beta").unwrap() - 10.0).abs() < 1e-6,
            "{out:?}"
        );
    }

    #[test]
    fn the_lower_bound_of_an_optional_gain_is_zero() {
        let (p, outside) = candidate(FilterKind::Ecf, &[0.0, 1e-4f64.ln() - 1.0]);
        assert_eq!(p.get("ki"), Some(0.0));
        assert!((outside - 1.0).abs() < 1e-12);
        assert_eq!(p.get("kp"), Some(1.0));
    }
}
