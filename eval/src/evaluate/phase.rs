//! Splitting a run into phases, so each can be scored on its own: static, dynamic and magnetic
//! perturbation (the conditions the paper's Figures 8–10 show in their last two rows).
//!
//! Rules, per truth instant, from three magnitudes ([`PhaseSample`]):
//!
//! 1. **magnetic**: the field deviates from its reference by more than
//!    [`PhaseRules::magnetic_fraction`] of the reference's norm at some instant within half a
//!    [`PhaseRules::window_ns`] (a burst's waveform passes through zero inside the burst, and a
//!    filter feels it beyond its edges);
//! 2. else **static**: the body rate is below [`PhaseRules::static_rate`] *and* the external
//!    acceleration below [`PhaseRules::static_accel`];
//! 3. else **dynamic**.
//!
//! Where the magnitudes come from is the caller's business ([`super::run`], [`super::signals`]): the truth's
//! body rate and external acceleration when there is a truth; the perturbation a simulation
//! added (`perturbation.csv`), or the measured field minus the true field, or (for an external
//! recording) the measured field's norm minus its median norm. Measured signals are noisy, so
//! they are averaged over [`PhaseRules::window_ns`] (each axis, or the signed norm deviation)
//! before the magnitude is taken ([`moving_mean`]).

/// The phase of one instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Phase {
    /// At rest: slow rotation and no external acceleration.
    Static,
    /// Moving.
    Dynamic,
    /// Under a magnetic perturbation (whatever the motion).
    Magnetic,
}

impl Phase {
    /// All phases, in report order.
    pub const ALL: [Self; 3] = [Self::Static, Self::Dynamic, Self::Magnetic];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Static => "static",
            Self::Dynamic => "dynamic",
            Self::Magnetic => "magnetic",
        }
    }
}

/// Thresholds of the phase rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhaseRules {
    /// Body rate below which the plate may be static (rad/s).
    pub static_rate: f64,
    /// External acceleration below which the plate may be static (m/s²).
    pub static_accel: f64,
    /// Field deviation, as a fraction of the reference norm, above which the field is perturbed.
    pub magnetic_fraction: f64,
    /// Averaging window of measured (noisy) signals (ns).
    pub window_ns: u64,
}

impl Default for PhaseRules {
    /// 0.05 rad/s, 0.1 m/s², 10 % of the field, 100 ms.
    fn default() -> Self {
        Self {
            static_rate: 0.05,
            static_accel: 0.1,
            magnetic_fraction: 0.1,
            window_ns: 100_000_000,
        }
    }
}

/// The magnitudes the rules look at, for one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseSample {
    /// Body rate (rad/s).
    pub rate: f64,
    /// External acceleration (m/s²).
    pub accel: f64,
    /// Field deviation as a fraction of the reference norm.
    pub field: f64,
}

/// What the rules see of one instant, before the window: whether its field is perturbed and
/// whether it is quiet (slow and unaccelerated). One byte per instant, for long runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Marks {
    /// The field deviation is above the threshold.
    pub perturbed: bool,
    /// Body rate and external acceleration are below theirs.
    pub quiet: bool,
}

impl Marks {
    /// The marks of `sample` under `rules`.
    pub fn of(sample: &PhaseSample, rules: &PhaseRules) -> Self {
        Self {
            perturbed: sample.field > rules.magnetic_fraction,
            quiet: sample.rate < rules.static_rate && sample.accel < rules.static_accel,
        }
    }
}

/// The phase of every sample, `step_ns` apart.
pub fn classify(samples: &[PhaseSample], rules: &PhaseRules, step_ns: u64) -> Vec<Phase> {
    let marks: Vec<Marks> = samples.iter().map(|s| Marks::of(s, rules)).collect();
    classify_marks(&marks, rules, step_ns)
}

/// The phase of every instant from its marks, `step_ns` apart: magnetic when some instant
/// within half a window is perturbed (a count of perturbed instants slid along), else static
/// when quiet, else dynamic.
pub fn classify_marks(marks: &[Marks], rules: &PhaseRules, step_ns: u64) -> Vec<Phase> {
    let half = (rules.window_ns / 2 / step_ns.max(1)) as usize;
    let n = marks.len();
    let perturbed = |i: usize| usize::from(marks[i].perturbed);
    let mut near = (0..half.min(n)).map(perturbed).sum::<usize>();
    (0..n)
        .map(|i| {
            if let Some(k) = i.checked_add(half).filter(|&k| k < n) {
                near += perturbed(k);
            }
            if i > half {
                near -= perturbed(i - half - 1);
            }
            if near > 0 {
                Phase::Magnetic
            } else if marks[i].quiet {
                Phase::Static
            } else {
                Phase::Dynamic
            }
        })
        .collect()
}

/// Centred moving mean of each component over `2·half + 1` samples (fewer at the ends).
pub fn moving_mean<const N: usize>(values: &[[f64; N]], half: usize) -> Vec<[f64; N]> {
    let mut prefix = vec![[0.0; N]; values.len() + 1];
    for (i, v) in values.iter().enumerate() {
        prefix[i + 1] = core::array::from_fn(|j| prefix[i][j] + v[j]);
    }
    (0..values.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(values.len()));
            core::array::from_fn(|j| (prefix[hi][j] - prefix[lo][j]) / (hi - lo) as f64)
        })
        .collect()
}

/// Runs of equal phase: `(phase, first index, last index)`.
pub fn runs(phases: &[Phase]) -> Vec<(Phase, usize, usize)> {
    let mut out: Vec<(Phase, usize, usize)> = Vec::new();
    for (i, &p) in phases.iter().enumerate() {
        match out.last_mut() {
            Some(run) if run.0 == p => run.2 = i,
            _ => out.push((p, i, i)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magnetic_wins_then_static_needs_both_quiet() {
        let rules = PhaseRules::default();
        let s = |rate, accel, field| PhaseSample { rate, accel, field };
        let samples = [
            s(0.0, 0.0, 0.0),
            s(0.2, 0.0, 0.0),
            s(0.0, 0.5, 0.0),
            s(0.0, 0.0, 0.3),
        ];
        // Samples 1 s apart: the 100 ms window reaches no neighbour.
        let phases = classify(&samples, &rules, 1_000_000_000);
        use Phase::*;
        assert_eq!(phases, [Static, Dynamic, Dynamic, Magnetic]);
        assert_eq!(
            runs(&phases),
            [(Static, 0, 0), (Dynamic, 1, 2), (Magnetic, 3, 3)]
        );
        // 20 ms apart: the perturbation at sample 3 marks the two before it too.
        let phases = classify(&samples, &rules, 20_000_000);
        assert_eq!(phases, [Static, Magnetic, Magnetic, Magnetic]);
    }

    #[test]
    fn the_sliding_count_marks_what_a_window_mean_marks() {
        // Perturbed instants in a pattern with runs and gaps of several lengths.
        let marks: Vec<Marks> = (0..200u32)
            .map(|i| Marks {
                perturbed: (i * 7919) % 23 < 2 || (90..95).contains(&i),
                quiet: i % 3 == 0,
            })
            .collect();
        let flags: Vec<[f64; 1]> = marks
            .iter()
            .map(|m| [f64::from(u8::from(m.perturbed))])
            .collect();
        let rules = PhaseRules::default();
        for step_ns in [1_000_000_000, 50_000_000, 10_000_000, 3_000_000, 1_000_000] {
            let half = (rules.window_ns / 2 / step_ns) as usize;
            let expected: Vec<Phase> = moving_mean(&flags, half)
                .iter()
                .zip(&marks)
                .map(|(near, m)| match (near[0] > 0.0, m.quiet) {
                    (true, _) => Phase::Magnetic,
                    (false, true) => Phase::Static,
                    (false, false) => Phase::Dynamic,
                })
                .collect();
            assert_eq!(
                classify_marks(&marks, &rules, step_ns),
                expected,
                "{step_ns}"
            );
        }
    }

    #[test]
    fn moving_mean_averages_a_centred_window() {
        let v: Vec<[f64; 1]> = [1.0, 2.0, 3.0, 4.0, 5.0].iter().map(|&x| [x]).collect();
        let m = moving_mean(&v, 1);
        assert_eq!(m, [[1.5], [2.0], [3.0], [4.0], [4.5]]);
    }
}
