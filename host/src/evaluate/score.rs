//! Scores of an attitude estimate against ground truth (paper section 3.2, eq. 27).
//!
//! The truth is interpolated onto the estimates' instants (spherical linear interpolation
//! between the two truth samples around each instant), not the other way round: the truth is
//! noise-free and dense, so interpolating it adds no error worth the name, whereas interpolating
//! noisy estimates would average neighbouring errors and flatter the estimator (by up to half
//! the error variance midway between samples). Each estimate is one scored instant, so `N` of
//! eq. 27 is the number of estimates scored; an offline filter run on the truth's own instants
//! is compared sample for sample, with no interpolation at all. An estimate is scored when its
//! aligned instant lies within the truth, at least `warmup` after the first truth instant, and
//! between two truth samples no further apart than `max_gap` (truth dropouts are not bridged).
//!
//! Per scored instant `k`, with `(φ, θ, ψ)` the ZYX Euler angles of the truth and of the
//! estimate: `e_k = wrap(true − estimate)` per angle into (−π, π] (so 179° against −179° is a
//! 2° error), and the geodesic angle `g_k = 2·acos|⟨q, q̂⟩|` (computed with `atan2`; `q` and
//! `−q` score the same). Per angle: mean, `MSE = Σe²/N`, `STD` = the standard deviation of `e`
//! about its mean (population form, `√(MSE − mean²)`), and the largest `|e|`.
//! `F = ∛(MSE_φ·MSE_θ·MSE_ψ)` (eq. 27, rad²); the geodesic RMS is `√(Σg²/N)`.
//!
//! Latency: an estimate stamped `t` is taken to describe the truth at `t − latency`.
//!
//! ```
//! use margemu::evaluate::{score, ScoreOptions};
//! let truth: Vec<(u64, [f64; 4])> = (0..100).map(|k| (k * 5_000_000, [1.0, 0.0, 0.0, 0.0])).collect();
//! let rolled = [0.9998750026041124, 0.015811, 0.0, 0.0]; // ≈ 1.8° of roll, normalised inside
//! let estimate: Vec<(u64, [f64; 4])> = truth.iter().map(|&(t, _)| (t, rolled)).collect();
//! let s = score(&truth, &estimate, &ScoreOptions::default()).unwrap();
//! assert_eq!(s.count, 100);
//! assert!((s.angles[0].mse.sqrt() - 0.031623).abs() < 1e-5);
//! assert!(s.f < 1e-12); // pitch and yaw are exact, so their MSE is 0
//! ```

use super::quat::{euler, geodesic, interpolate, normalize, Quat};
pub use super::stats::{AngleStats, Scores};
use crate::truth::wrap_angle;
use nalgebra::UnitQuaternion;
use std::fmt;

/// A time stamp (ns) and an attitude quaternion `[w, x, y, z]` (any non-zero norm).
pub type Stamped = (u64, Quat);

/// How estimates are compared with the truth.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScoreOptions {
    /// The estimate stamped `t` describes the truth at `t − latency_ns`.
    pub latency_ns: i64,
    /// Truth instants earlier than the first one plus this are not scored.
    pub warmup_ns: u64,
    /// Truth samples further apart than this are not interpolated across; `None`: four times
    /// their median spacing.
    pub max_gap_ns: Option<u64>,
}

/// Input the scoring functions refuse.
#[derive(Debug, Clone, PartialEq, thiserror::Error, docsplay::Display)]
pub enum ScoreError {
    /// {what} sample {index}: time {t_ns} ns does not increase
    NotIncreasing {
        /// `truth` or `estimate`.
        what: &'static str,
        /// 0-based sample index.
        index: usize,
        /// Its time.
        t_ns: u64,
    },
    /// {what} sample {index}: quaternion {q:?} has no direction (zero or not finite)
    BadQuaternion {
        /// `truth` or `estimate`.
        what: &'static str,
        /// 0-based sample index.
        index: usize,
        /// The quaternion.
        q: Quat,
    },
    /// {what} has no samples
    Empty {
        /// `truth` or `estimate`.
        what: &'static str,
    },
    /// no truth instant to score: the truth spans {truth}, the estimates (shifted by the latency) span {estimate}, warm-up {warmup_s} s
    NoOverlap {
        /// Truth span.
        truth: Span,
        /// Estimate span after the latency shift.
        estimate: Span,
        /// Warm-up (s).
        warmup_s: f64,
    },
}

/// A time interval, printed in seconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    /// First instant (ns).
    pub start_ns: i64,
    /// Last instant (ns).
    pub end_ns: i64,
}

impl fmt::Display for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let s = |ns: i64| ns as f64 * 1e-9;
        write!(f, "{:.3} s to {:.3} s", s(self.start_ns), s(self.end_ns))
    }
}

/// Validated, time-ordered attitudes with unit quaternions.
#[derive(Clone, Debug)]
struct Track {
    t_ns: Vec<u64>,
    q: Vec<UnitQuaternion<f64>>,
}

impl Track {
    fn new(samples: &[Stamped], what: &'static str) -> Result<Self, ScoreError> {
        if samples.is_empty() {
            return Err(ScoreError::Empty { what });
        }
        let mut q = Vec::with_capacity(samples.len());
        for (index, &(t_ns, raw)) in samples.iter().enumerate() {
            if index > 0 && t_ns <= samples[index - 1].0 {
                return Err(ScoreError::NotIncreasing { what, index, t_ns });
            }
            q.push(normalize(raw).ok_or(ScoreError::BadQuaternion {
                what,
                index,
                q: raw,
            })?);
        }
        Ok(Self {
            t_ns: samples.iter().map(|s| s.0).collect(),
            q,
        })
    }

    fn span(&self, shift_ns: i64) -> Span {
        Span {
            start_ns: self.t_ns[0] as i64 - shift_ns,
            end_ns: *self.t_ns.last().unwrap_or(&0) as i64 - shift_ns,
        }
    }
}

/// Where an instant falls in a track.
struct Located {
    /// The nearest sample.
    nearest: usize,
    /// Whether the instant is that sample's own.
    exact: bool,
    /// The attitude there, interpolated.
    q: UnitQuaternion<f64>,
}

impl Track {
    fn median_step_ns(&self) -> u64 {
        let mut steps: Vec<u64> = self.t_ns.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_unstable();
        steps.get(steps.len() / 2).copied().unwrap_or(0)
    }

    /// The attitude at `t_ns`, or `None` outside the track or across a gap over `max_gap_ns`.
    fn at(&self, t_ns: i64, max_gap_ns: u64) -> Option<Located> {
        let t = &self.t_ns;
        let after = t.partition_point(|&s| (s as i64) < t_ns);
        if after < t.len() && t[after] as i64 == t_ns {
            let q = self.q[after];
            return Some(Located {
                nearest: after,
                exact: true,
                q,
            });
        }
        if after == 0 || after == t.len() || t[after] - t[after - 1] > max_gap_ns {
            return None;
        }
        let (t0, t1) = (t[after - 1], t[after]);
        let s = (t_ns - t0 as i64) as f64 / (t1 - t0) as f64;
        Some(Located {
            nearest: if s < 0.5 { after - 1 } else { after },
            exact: false,
            q: interpolate(&self.q[after - 1], &self.q[after], s),
        })
    }
}

/// The estimates of one run, validated once, with their Euler angles.
#[derive(Clone, Debug)]
pub struct Estimates {
    track: Track,
    euler: Vec<[f64; 3]>,
}

impl Estimates {
    /// Checks `samples` (times strictly increasing, quaternions non-zero and finite).
    pub fn new(samples: &[Stamped]) -> Result<Self, ScoreError> {
        let track = Track::new(samples, "estimate")?;
        let euler = track.q.iter().map(euler).collect();
        Ok(Self { track, euler })
    }

    /// Number of estimates.
    pub fn len(&self) -> usize {
        self.track.t_ns.len()
    }

    /// Whether there are none (never: [`Estimates::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.track.t_ns.is_empty()
    }
}

/// The truth of one run with its Euler angles computed once, to score many estimates against
/// (a tuner scores hundreds of filter settings against one truth).
#[derive(Clone, Debug)]
pub struct Reference {
    track: Track,
    euler: Vec<[f64; 3]>,
    median_step_ns: u64,
}

/// One scored estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Compared {
    /// Index of the truth sample nearest to its aligned instant (for its phase).
    pub index: usize,
    /// Its aligned instant: its stamp minus the latency (ns, on the truth's axis).
    pub t_ns: u64,
    /// Euler angles of the truth there `[roll, pitch, yaw]` (rad).
    pub truth: [f64; 3],
    /// Euler angles of the estimate (rad).
    pub estimate: [f64; 3],
    /// `wrap(true − estimate)` per angle (rad).
    pub error: [f64; 3],
    /// Geodesic angle between truth and estimate (rad).
    pub geodesic: f64,
}

impl Reference {
    /// Checks `truth` (times strictly increasing, quaternions non-zero and finite).
    pub fn new(truth: &[Stamped]) -> Result<Self, ScoreError> {
        let track = Track::new(truth, "truth")?;
        let euler = track.q.iter().map(euler).collect();
        let median_step_ns = track.median_step_ns();
        Ok(Self {
            track,
            euler,
            median_step_ns,
        })
    }

    /// Truth instants (ns).
    pub fn t_ns(&self) -> &[u64] {
        &self.track.t_ns
    }

    /// Truth Euler angles `[roll, pitch, yaw]` per instant (rad).
    pub fn euler(&self) -> &[[f64; 3]] {
        &self.euler
    }

    /// The truth's median sample spacing (ns).
    pub fn median_step_ns(&self) -> u64 {
        self.median_step_ns
    }

    /// Every scored estimate, in order.
    pub fn compare(
        &self,
        estimates: &Estimates,
        opts: &ScoreOptions,
    ) -> Result<Vec<Compared>, ScoreError> {
        let compared: Vec<Compared> = (0..estimates.len())
            .filter_map(|j| self.compare_at(j, estimates, opts))
            .collect();
        if compared.is_empty() {
            return Err(ScoreError::NoOverlap {
                truth: self.track.span(0),
                estimate: estimates.track.span(opts.latency_ns),
                warmup_s: opts.warmup_ns as f64 * 1e-9,
            });
        }
        Ok(compared)
    }

    /// The scores of `estimates`.
    pub fn score(&self, estimates: &Estimates, opts: &ScoreOptions) -> Result<Scores, ScoreError> {
        let compared = self.compare(estimates, opts)?;
        Ok(Scores::from_compared(compared.iter()).expect("compare returns at least one"))
    }

    /// Mean squared geodesic error (rad²) over every `stride`-th estimate that is scored, and
    /// how many it covers; `None` when none is.
    pub fn geodesic_cost(
        &self,
        estimates: &Estimates,
        opts: &ScoreOptions,
        stride: usize,
    ) -> Option<(f64, usize)> {
        let (mut sum, mut n) = (0.0, 0usize);
        for j in (0..estimates.len()).step_by(stride.max(1)) {
            if let Some(truth) = self.truth_at(estimates.track.t_ns[j], opts) {
                let g = geodesic(&truth.q, &estimates.track.q[j]);
                sum += g * g;
                n += 1;
            }
        }
        (n > 0).then(|| (sum / n as f64, n))
    }

    /// The truth at the aligned instant of an estimate stamped `stamp_ns`, if it is scored.
    fn truth_at(&self, stamp_ns: u64, opts: &ScoreOptions) -> Option<Located> {
        let aligned = stamp_ns as i64 - opts.latency_ns;
        let first = self.track.t_ns[0].saturating_add(opts.warmup_ns);
        if aligned < first as i64 {
            return None;
        }
        let max_gap = opts.max_gap_ns.unwrap_or(4 * self.median_step_ns);
        self.track.at(aligned, max_gap)
    }

    fn compare_at(&self, j: usize, est: &Estimates, opts: &ScoreOptions) -> Option<Compared> {
        let stamp = est.track.t_ns[j];
        let located = self.truth_at(stamp, opts)?;
        let truth = if located.exact {
            self.euler[located.nearest]
        } else {
            euler(&located.q)
        };
        let estimate = est.euler[j];
        Some(Compared {
            index: located.nearest,
            t_ns: (stamp as i64 - opts.latency_ns) as u64,
            truth,
            estimate,
            error: [0, 1, 2].map(|i| wrap_angle(truth[i] - estimate[i])),
            geodesic: geodesic(&located.q, &est.track.q[j]),
        })
    }
}

/// Scores `estimate` against `truth` in one call (see the module docs).
pub fn score(
    truth: &[Stamped],
    estimate: &[Stamped],
    opts: &ScoreOptions,
) -> Result<Scores, ScoreError> {
    Reference::new(truth)?.score(&Estimates::new(estimate)?, opts)
}
