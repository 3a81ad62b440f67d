//! Aligning a device's output with the truth: its latency, and its clock against the host's.
//!
//! **Latency** ([`estimate_latency`]): the shift `L` of the estimates' time stamps that
//! minimises the mean squared geodesic error `c(L) = mean_j g(q(t_j − L), q̂_j)²`, with the
//! truth interpolated as in [`score`](mod@super::score). The truth is noise-free, so `c` is smooth
//! in `L` and a fractional shift does not average the estimates' noise away (interpolating
//! noisy estimates would favour half-sample shifts). A coarse scan covers
//! `[−max_lag, +max_lag]` in steps of the truth's sample period, on at most about 2000
//! estimates (and only at lags where at least half as many overlap as at the best overlapping
//! lag); a golden-section search over the two steps around the coarse minimum, on every
//! estimate up to [`FINE_POINTS`] (evenly spaced ones beyond: the cost is a smooth mean, and
//! those estimates with the truth around them fit in memory), refines it to 100 ns. Files are
//! read once for the scan and once to gather the refinement's estimates, with only a window of
//! the truth in memory. `L` is the whole delay from the instant a sample
//! describes to the time stamp its estimate carries: transport, the filter's processing and its
//! own phase lag alike. Motion is what makes `L` observable: when the lowest cost is not at least
//! 20 % below the median cost of the scan (a plate at rest, say), the estimate is reported as
//! not observable and callers use 0. Keep `max_lag` below half the period of any periodic motion,
//! or a whole period's shift fits as well as the true one.
//!
//! **Clock** ([`fit_clock`]): when the device stamps its output with its own clock, the line
//! `host_ns = offset + rate · device_time_us` under the (device time, host arrival time) pairs
//! (their lower envelope: arrivals are late by the link's delay and by host stalls, never
//! early) gives the device clock's offset (the host time, on the scene's origin, at which the
//! device clock read 0, plus the link's shortest delay), its drift `(rate/1000 − 1)·10⁶` ppm,
//! and the residual (how late the arrivals are against the line).

use super::quat::geodesic;
use super::run::EvalError;
use super::score::{after_warmup, locate, Estimates, Reference, Sample, ScoreOptions};
use super::series::Series;
use super::walk::Walk;

/// Where and how finely the latency is searched.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LatencySearch {
    /// Largest lag tried either way (ns).
    pub max_lag_ns: u64,
    /// Coarse step (ns); `None`: the truth's median sample period.
    pub step_ns: Option<u64>,
    /// Warm-up and largest interpolation gap, as in scoring (`latency_ns` is ignored).
    pub score: ScoreOptions,
}

impl Default for LatencySearch {
    fn default() -> Self {
        Self {
            max_lag_ns: 500_000_000,
            step_ns: None,
            score: ScoreOptions::default(),
        }
    }
}

/// The result of a latency search.
#[derive(Clone, Debug, PartialEq)]
pub struct Latency {
    /// The best lag (ns): estimates stamped `t` describe the truth at `t − lag_ns`.
    pub lag_ns: i64,
    /// Mean squared geodesic error at that lag (rad²).
    pub cost: f64,
    /// `1 − cost / median cost of the scan`: how sharply the motion pins the lag.
    pub contrast: f64,
    /// Whether the contrast is at least [`MIN_CONTRAST`] and the minimum is inside the range.
    pub observable: bool,
    /// Whether the coarse minimum sat at an end of the range (raise the range).
    pub at_edge: bool,
    /// The coarse scan: `(lag ns, cost rad²)`.
    pub curve: Vec<(i64, f64)>,
}

/// Smallest contrast for which a latency estimate is trusted.
pub const MIN_CONTRAST: f64 = 0.2;

/// Estimates used by the coarse scan, at most about this many.
const COARSE_POINTS: usize = 2000;

/// The latency of `estimates` against `reference` (see the module docs); `None` when no lag
/// in the range overlaps the truth at all.
pub fn estimate_latency(
    reference: &Reference,
    estimates: &Estimates,
    search: &LatencySearch,
) -> Option<Latency> {
    let truth = TruthFacts {
        first_ns: reference.samples()[0].0,
        median_step_ns: reference.median_step_ns(),
    };
    let (truth_series, estimate_series) = (
        Series::Memory(reference.samples().to_vec()),
        Series::Memory(estimates.samples().to_vec()),
    );
    // In-memory series read without fault.
    latency_of_series(
        &truth_series,
        &truth,
        &estimate_series,
        estimates.len(),
        search,
    )
    .ok()
    .flatten()
}

/// What alignment needs to know of the truth before reading it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct TruthFacts {
    /// Its first instant (ns).
    pub(super) first_ns: u64,
    /// Its median sample spacing (ns).
    pub(super) median_step_ns: u64,
}

impl TruthFacts {
    /// The largest spacing interpolated across, by `opts` or by default.
    pub(super) fn max_gap_ns(&self, opts: &ScoreOptions) -> u64 {
        opts.max_gap_ns.unwrap_or(4 * self.median_step_ns)
    }
}

/// [`estimate_latency`] over series read from their start for each pass (see the module docs):
/// the coarse scan in one pass, the estimates of the refinement (every one up to
/// [`FINE_POINTS`], evenly spaced beyond) with the truth around them in a second.
pub(super) fn latency_of_series(
    truth: &Series,
    facts: &TruthFacts,
    estimates: &Series,
    count: usize,
    search: &LatencySearch,
) -> Result<Option<Latency>, EvalError> {
    let step = search.step_ns.unwrap_or(facts.median_step_ns).max(1) as i64;
    let max = search.max_lag_ns as i64;
    let n_steps = max / step;
    let lags: Vec<i64> = (-n_steps..=n_steps).map(|i| i * step).collect();
    let max_gap = facts.max_gap_ns(&search.score);
    let first = facts.first_ns;
    let stride = count.div_ceil(COARSE_POINTS).max(1);
    let mut sums = vec![(0.0f64, 0usize); lags.len()];
    let mut walk = Walk::new(truth)?;
    for (j, estimate) in estimates.read()?.enumerate() {
        let (stamp, q) = estimate?;
        if j % stride != 0 {
            continue;
        }
        let t = stamp as i64;
        let (window, base) = walk.cover(t - n_steps * step, t + n_steps * step, &mut |_, _| {})?;
        for (sum, lag) in sums.iter_mut().zip(&lags) {
            let aligned = t - lag;
            if !after_warmup(aligned, first, &search.score) {
                continue;
            }
            if let Some(truth) = locate(window, base, aligned, max_gap) {
                let g = geodesic(&truth.q, &q);
                sum.0 += g * g;
                sum.1 += 1;
            }
        }
    }
    let scan: Vec<(i64, f64, usize)> = lags
        .iter()
        .zip(&sums)
        .filter(|(_, s)| s.1 > 0)
        .map(|(&lag, s)| (lag, s.0 / s.1 as f64, s.1))
        .collect();
    let Some(most) = scan.iter().map(|s| s.2).max() else {
        return Ok(None);
    };
    let curve: Vec<(i64, f64)> = scan
        .iter()
        .filter(|s| 2 * s.2 >= most)
        .map(|s| (s.0, s.1))
        .collect();
    let Some((best_i, &(coarse, _))) = curve
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
    else {
        return Ok(None);
    };
    let at_edge = best_i == 0 || best_i + 1 == curve.len();
    let fine = Refinement::gather(truth, estimates, count, (coarse - step, coarse + step))?;
    let full = |lag: i64| fine.cost(lag, first, max_gap, &search.score);
    let refined = golden_min(
        |lag| full(lag.round() as i64),
        (coarse - step) as f64,
        (coarse + step) as f64,
        100.0,
    )
    .round() as i64;
    let Some((lag_ns, best)) = [(refined, full(refined)), (coarse, full(coarse))]
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return Ok(None);
    };
    let mut costs: Vec<f64> = curve.iter().map(|c| c.1).collect();
    costs.sort_by(f64::total_cmp);
    let median = costs[costs.len() / 2];
    let contrast = if median > 0.0 {
        1.0 - best / median
    } else {
        0.0
    };
    Ok(Some(Latency {
        lag_ns,
        cost: best,
        contrast,
        observable: contrast >= MIN_CONTRAST && !at_edge,
        at_edge,
        curve,
    }))
}

/// Estimates the refinement uses: all of them up to this many, evenly spaced beyond (about
/// 20 MB with the truth around them), so the refinement's many passes run in memory.
pub const FINE_POINTS: usize = 100_000;

/// The refinement's estimates, each with the truth samples its aligned instants can fall
/// between over the refinement's lag range.
struct Refinement {
    truth: Vec<Sample>,
    /// An estimate, where its truth starts in `truth`, how many, and the index in the truth of
    /// the first.
    estimates: Vec<(Sample, usize, usize, usize)>,
}

impl Refinement {
    fn gather(
        truth: &Series,
        estimates: &Series,
        count: usize,
        (lo, hi): (i64, i64),
    ) -> Result<Self, EvalError> {
        let stride = count.div_ceil(FINE_POINTS).max(1);
        let mut out = Self {
            truth: Vec::new(),
            estimates: Vec::new(),
        };
        let mut walk = Walk::new(truth)?;
        for (j, estimate) in estimates.read()?.enumerate() {
            let estimate = estimate?;
            if j % stride != 0 {
                continue;
            }
            let t = estimate.0 as i64;
            let (window, base) = walk.cover(t - hi, t - lo, &mut |_, _| {})?;
            out.estimates
                .push((estimate, out.truth.len(), window.len(), base));
            out.truth.extend_from_slice(window);
        }
        Ok(out)
    }

    /// Mean squared geodesic error at `lag` (infinite when no estimate is scored).
    fn cost(&self, lag: i64, first: u64, max_gap: u64, opts: &ScoreOptions) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for &((stamp, q), start, len, base) in &self.estimates {
            let aligned = stamp as i64 - lag;
            if !after_warmup(aligned, first, opts) {
                continue;
            }
            if let Some(truth) = locate(&self.truth[start..start + len], base, aligned, max_gap) {
                let g = geodesic(&truth.q, &q);
                sum += g * g;
                n += 1;
            }
        }
        if n == 0 {
            f64::INFINITY
        } else {
            sum / n as f64
        }
    }
}

/// The minimiser of `f` on `[lo, hi]` to within `tol`, by golden-section search.
fn golden_min(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, tol: f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while hi - lo > tol {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        }
    }
    (lo + hi) / 2.0
}

/// A device clock against the host's (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClockFit {
    /// Host time (ns, scene origin) at which the device clock read 0.
    pub offset_ns: f64,
    /// Host nanoseconds per device microsecond (1000 for a perfect clock).
    pub rate: f64,
    /// `(rate / 1000 − 1) · 10⁶`: how fast the host clock runs against the device's (ppm);
    /// positive when the device clock is slow.
    pub drift_ppm: f64,
    /// RMS of the host times about the line (ns).
    pub residual_rms_ns: f64,
    /// Largest distance of a host time from the line (ns).
    pub residual_max_ns: f64,
    /// Pairs fitted.
    pub points: usize,
}

impl ClockFit {
    /// The host time (ns, scene origin) of a device time (µs).
    pub fn host_ns(&self, device_us: f64) -> f64 {
        self.offset_ns + self.rate * device_us
    }
}

/// The line under `(device time µs, host time ns)` pairs: a message arrives no earlier than
/// the device stamped it plus the link's shortest delay, and on a loaded host some arrive
/// tens of milliseconds late, so the device clock is the lower envelope of the pairs, not
/// their mean. Of the lines on or below every pair, the one with the least total distance to
/// them (the linear-programming skew estimator of Moon, Skelly and Towsley, 1999): an edge of
/// the pairs' lower convex hull, the one spanning their mean device time. Late arrivals,
/// however many and however clustered in time, move it only where they are the lowest pairs.
/// `None` with fewer than two distinct device times (non-finite pairs are ignored).
pub fn fit_clock(pairs: &[(f64, f64)]) -> Option<ClockFit> {
    let finite: Vec<(f64, f64)> = pairs
        .iter()
        .copied()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let mut points = finite.clone();
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    points.dedup_by(|later, first| later.0 == first.0); // the earliest arrival of a device time
    let hull = lower_hull(&points);
    if hull.len() < 2 {
        return None;
    }
    let n = finite.len() as f64;
    let mean_d = points.iter().map(|p| p.0).sum::<f64>() / points.len() as f64;
    let edge = hull
        .windows(2)
        .find(|w| w[1].0 >= mean_d)
        .unwrap_or(&hull[hull.len() - 2..]);
    let (a, b) = (edge[0], edge[1]);
    let rate = (b.1 - a.1) / (b.0 - a.0);
    let fit = ClockFit {
        offset_ns: a.1 - rate * a.0,
        rate,
        drift_ppm: (rate / 1000.0 - 1.0) * 1e6,
        residual_rms_ns: 0.0,
        residual_max_ns: 0.0,
        points: finite.len(),
    };
    let residuals = finite.iter().map(|p| p.1 - fit.host_ns(p.0));
    let sum_sq: f64 = residuals.clone().map(|r| r * r).sum();
    Some(ClockFit {
        residual_rms_ns: (sum_sq / n).sqrt(),
        residual_max_ns: residuals.fold(0.0, |m, r| m.max(r.abs())),
        ..fit
    })
}

/// The lower convex hull of points sorted by x with distinct x (Andrew's monotone chain).
fn lower_hull(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(points.len().min(64));
    for &p in points {
        while let [.., o, a] = hull[..] {
            // Drop `a` unless o → a → p turns left (counter-clockwise).
            let cross = (a.0 - o.0) * (p.1 - o.1) - (a.1 - o.1) * (p.0 - o.0);
            if cross > 0.0 {
                break;
            }
            hull.pop();
        }
        hull.push(p);
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn golden_section_finds_a_parabola_minimum() {
        let x = golden_min(|x| (x - 3.7e6).powi(2), 0.0, 1e7, 10.0);
        assert!((x - 3.7e6).abs() < 10.0, "{x}");
    }

    #[test]
    fn clock_fit_recovers_offset_and_drift() {
        let pairs: Vec<(f64, f64)> = (0..1000)
            .map(|k| {
                let d = 5e6 + k as f64 * 1000.0;
                (d, -2.5e9 + d * 1000.0 * (1.0 + 80e-6))
            })
            .collect();
        let fit = fit_clock(&pairs).unwrap();
        assert!((fit.drift_ppm - 80.0).abs() < 1e-6, "{fit:?}");
        assert!((fit.offset_ns + 2.5e9).abs() < 1e-3, "{fit:?}");
        assert!(fit.residual_max_ns < 1e-3);
        assert!(fit_clock(&[(1.0, 2.0)]).is_none());
        assert!(fit_clock(&[(1.0, 2.0), (1.0, 3.0)]).is_none());
        assert!(fit_clock(&[(1.0, 2.0), (f64::NAN, 3.0), (2.0, f64::INFINITY)]).is_none());
        assert!(fit_clock(&[]).is_none());
        let mut with_nan = pairs.clone();
        with_nan.push((f64::NAN, 1.0));
        let fit = fit_clock(&with_nan).unwrap();
        assert_eq!(fit.points, pairs.len(), "the non-finite pair is left out");
        assert!(fit.residual_max_ns < 1e-3, "{fit:?}");
    }

    #[test]
    fn clock_fit_ignores_late_arrivals_clustered_in_time() {
        // 2 ms of link delay; a host stall delays the last fifth by 5-45 ms, and every 7th
        // message by up to 3 ms: a least squares line would tilt and shift by milliseconds.
        let pairs: Vec<(f64, f64)> = (0..1000u32)
            .map(|k| {
                let d = f64::from(k) * 5000.0;
                let mut late = 2e6 + f64::from(k % 13) * 1e4;
                if k >= 800 {
                    late += 5e6 + f64::from(k % 40) * 1e6;
                }
                if k % 7 == 0 {
                    late += 3e6;
                }
                (d, 1e9 + d * 1000.0 + late)
            })
            .collect();
        let fit = fit_clock(&pairs).unwrap();
        assert!(fit.drift_ppm.abs() < 1.0, "{fit:?}");
        assert!((fit.offset_ns - (1e9 + 2e6)).abs() < 1e3, "{fit:?}");
        let below = pairs
            .iter()
            .filter(|p| p.1 < fit.host_ns(p.0) - 1e-3)
            .count();
        assert_eq!(below, 0, "no arrival before the line");
    }
}
