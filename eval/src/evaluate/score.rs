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
//! Heading and inclination errors, as the BROAD benchmark defines them (Laidig et al., "BROAD —
//! A Benchmark for Robust Inertial Orientation Estimation", Data 6(7) 72, 2021, section 4; its
//! evaluation code `example_code/broad_utils.py`, `calculateErrorQuatEarth`,
//! `calculateHeadingError`, `calculateInclinationError`): the error quaternion expressed in the
//! world (reference) frame, `q_e = q̂ ⊗ q⁻¹` (estimate times inverse truth, both body-to-world),
//! split into a rotation about the vertical (world z, up) and the remaining tilt. The heading
//! error is `2·atan(|z_e / w_e|)` and the inclination error `2·acos(√(w_e² + z_e²))`; here both
//! come from `atan2` (`2·atan2(|z_e|, |w_e|)` and `2·atan2(√(x_e² + y_e²), √(w_e² + z_e²))`,
//! equal for a unit quaternion, exact for small angles), so `q` and `−q` score the same. Their
//! RMS (`√(Σh²/N)`, `√(Σι²/N)`) and largest values are reported beside the geodesic.
//!
//! Latency: an estimate stamped `t` is taken to describe the truth at `t − latency`.
//!
//! ```
//! use margemu_eval::evaluate::{score, ScoreOptions};
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
use margemu_sim::truth::wrap_angle;
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

/// An instant (ns) and a unit attitude: one sample of a validated series.
pub(super) type Sample = (u64, UnitQuaternion<f64>);

/// `samples` checked (times strictly increasing, quaternions non-zero and finite) and normalised.
pub(super) fn validated(
    samples: &[Stamped],
    what: &'static str,
) -> Result<Vec<Sample>, ScoreError> {
    if samples.is_empty() {
        return Err(ScoreError::Empty { what });
    }
    let mut out = Vec::with_capacity(samples.len());
    for (index, &(t_ns, raw)) in samples.iter().enumerate() {
        if index > 0 && t_ns <= samples[index - 1].0 {
            return Err(ScoreError::NotIncreasing { what, index, t_ns });
        }
        let q = normalize(raw).ok_or(ScoreError::BadQuaternion {
            what,
            index,
            q: raw,
        })?;
        out.push((t_ns, q));
    }
    Ok(out)
}

/// Validated, time-ordered attitudes with unit quaternions.
#[derive(Clone, Debug)]
struct Track {
    samples: Vec<Sample>,
}

impl Track {
    fn new(samples: &[Stamped], what: &'static str) -> Result<Self, ScoreError> {
        Ok(Self {
            samples: validated(samples, what)?,
        })
    }

    fn len(&self) -> usize {
        self.samples.len()
    }

    fn span(&self, shift_ns: i64) -> Span {
        Span {
            start_ns: self.samples[0].0 as i64 - shift_ns,
            end_ns: self.samples.last().map_or(0, |s| s.0) as i64 - shift_ns,
        }
    }

    fn median_step_ns(&self) -> u64 {
        let mut steps: Vec<u64> = self.samples.windows(2).map(|w| w[1].0 - w[0].0).collect();
        steps.sort_unstable();
        steps.get(steps.len() / 2).copied().unwrap_or(0)
    }
}

/// Where an instant falls in a series of truth samples.
pub(super) struct Located {
    /// The index of the nearest sample.
    pub(super) nearest: usize,
    /// Whether the instant is that sample's own.
    pub(super) exact: bool,
    /// The attitude there, interpolated.
    pub(super) q: UnitQuaternion<f64>,
}

/// The attitude at `t_ns` in consecutive samples `samples` of a series whose first is its
/// sample number `base`, or `None` outside them or across a gap over `max_gap_ns`. The caller
/// includes the samples on either side of `t_ns` whenever the series has them.
pub(super) fn locate(
    samples: &[Sample],
    base: usize,
    t_ns: i64,
    max_gap_ns: u64,
) -> Option<Located> {
    let after = samples.partition_point(|s| (s.0 as i64) < t_ns);
    if after < samples.len() && samples[after].0 as i64 == t_ns {
        return Some(Located {
            nearest: base + after,
            exact: true,
            q: samples[after].1,
        });
    }
    if after == 0 || after == samples.len() {
        return None;
    }
    let ((t0, q0), (t1, q1)) = (samples[after - 1], samples[after]);
    if t1 - t0 > max_gap_ns {
        return None;
    }
    let s = (t_ns - t0 as i64) as f64 / (t1 - t0) as f64;
    Some(Located {
        nearest: base + if s < 0.5 { after - 1 } else { after },
        exact: false,
        q: interpolate(&q0, &q1, s),
    })
}

/// The scored comparison of an estimate `(stamp, q, its Euler angles)` with the truth found
/// at its aligned instant (`truth_euler`: the truth's Euler angles there).
pub(super) fn compared(
    located: &Located,
    truth_euler: [f64; 3],
    estimate: (u64, &UnitQuaternion<f64>, [f64; 3]),
    latency_ns: i64,
) -> Compared {
    let (stamp, q, e) = estimate;
    Compared {
        index: located.nearest,
        t_ns: (stamp as i64 - latency_ns) as u64,
        truth: truth_euler,
        estimate: e,
        error: [0, 1, 2].map(|i| wrap_angle(truth_euler[i] - e[i])),
        geodesic: geodesic(&located.q, q),
        heading_inclination: heading_inclination(&located.q, q),
    }
}

/// The heading and inclination errors (rad) of `estimate` against `truth`, as BROAD defines
/// them (see the module docs): the error quaternion `estimate ⊗ truth⁻¹` in the world frame,
/// its rotation about world z and its remaining tilt.
pub fn heading_inclination(
    truth: &UnitQuaternion<f64>,
    estimate: &UnitQuaternion<f64>,
) -> [f64; 2] {
    let e = estimate * truth.inverse();
    let (w, x, y, z) = (e.w, e.i, e.j, e.k);
    let heading = 2.0 * z.abs().atan2(w.abs());
    let inclination = 2.0 * (x * x + y * y).sqrt().atan2((w * w + z * z).sqrt());
    [heading, inclination]
}

/// Whether an estimate's aligned instant is late enough to score (after the warm-up).
pub(super) fn after_warmup(aligned_ns: i64, first_truth_ns: u64, opts: &ScoreOptions) -> bool {
    aligned_ns >= first_truth_ns.saturating_add(opts.warmup_ns) as i64
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
        let euler = track.samples.iter().map(|s| euler(&s.1)).collect();
        Ok(Self { track, euler })
    }

    /// Number of estimates.
    pub fn len(&self) -> usize {
        self.track.len()
    }

    /// Whether there are none (never: [`Estimates::new`] refuses that).
    pub fn is_empty(&self) -> bool {
        self.track.samples.is_empty()
    }

    /// The validated samples.
    pub(super) fn samples(&self) -> &[Sample] {
        &self.track.samples
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
    /// Heading and inclination errors `[h, ι]` (rad, BROAD's split; see the module docs).
    pub heading_inclination: [f64; 2],
}

impl Reference {
    /// Checks `truth` (times strictly increasing, quaternions non-zero and finite).
    pub fn new(truth: &[Stamped]) -> Result<Self, ScoreError> {
        let track = Track::new(truth, "truth")?;
        let euler = track.samples.iter().map(|s| euler(&s.1)).collect();
        let median_step_ns = track.median_step_ns();
        Ok(Self {
            track,
            euler,
            median_step_ns,
        })
    }

    /// The validated samples.
    pub(super) fn samples(&self) -> &[Sample] {
        &self.track.samples
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

    /// The truth at the aligned instant of an estimate stamped `stamp_ns`, if it is scored.
    fn truth_at(&self, stamp_ns: u64, opts: &ScoreOptions) -> Option<Located> {
        let aligned = stamp_ns as i64 - opts.latency_ns;
        if !after_warmup(aligned, self.track.samples[0].0, opts) {
            return None;
        }
        let max_gap = opts.max_gap_ns.unwrap_or(4 * self.median_step_ns);
        locate(&self.track.samples, 0, aligned, max_gap)
    }

    fn compare_at(&self, j: usize, est: &Estimates, opts: &ScoreOptions) -> Option<Compared> {
        let (stamp, q) = &est.track.samples[j];
        let located = self.truth_at(*stamp, opts)?;
        let truth = if located.exact {
            self.euler[located.nearest]
        } else {
            euler(&located.q)
        };
        Some(compared(
            &located,
            truth,
            (*stamp, q, est.euler[j]),
            opts.latency_ns,
        ))
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
