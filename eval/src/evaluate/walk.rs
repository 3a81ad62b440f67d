//! Walking the truth alongside time-ordered estimates with only a window of it in memory: for
//! each estimate, the truth samples its aligned instants can fall between (every lag of the
//! range asked for), so alignment and scoring run in memory bounded by the lag range, not by
//! the length of the run.

use super::run::EvalError;
use super::score::Sample;
use super::series::{Reader, Series};
use std::collections::{HashMap, VecDeque};

/// A window on the truth that moves forward only.
pub(super) struct Walk<'a> {
    truth: Reader<'a>,
    window: VecDeque<Sample>,
    /// Index in the truth of `window[0]`.
    base: usize,
    /// Samples read so far.
    read: usize,
    exhausted: bool,
}

impl<'a> Walk<'a> {
    /// A walk from the truth's first sample.
    pub(super) fn new(truth: &'a Series) -> Result<Self, EvalError> {
        Ok(Self {
            truth: truth.read()?,
            window: VecDeque::new(),
            base: 0,
            read: 0,
            exhausted: false,
        })
    }

    fn pull(&mut self, on_read: &mut impl FnMut(usize, &Sample)) -> Result<bool, EvalError> {
        match self.truth.next() {
            None => {
                self.exhausted = true;
                Ok(false)
            }
            Some(sample) => {
                let sample = sample?;
                on_read(self.read, &sample);
                self.read += 1;
                self.window.push_back(sample);
                Ok(true)
            }
        }
    }

    /// The truth samples around `[lower, upper]` (ns): the last at or before `lower`, those
    /// between, and the first at or after `upper` (each where the truth has one), with the
    /// index of the first. `lower` must not decrease from call to call. `on_read` sees every
    /// truth sample once, in order, as it is read.
    pub(super) fn cover(
        &mut self,
        lower: i64,
        upper: i64,
        on_read: &mut impl FnMut(usize, &Sample),
    ) -> Result<(&[Sample], usize), EvalError> {
        while !self.exhausted && self.window.back().is_none_or(|b| (b.0 as i64) < upper) {
            self.pull(on_read)?;
        }
        while self.window.len() >= 2 && (self.window[1].0 as i64) <= lower {
            self.window.pop_front();
            self.base += 1;
        }
        Ok((self.window.make_contiguous(), self.base))
    }

    /// Reads the rest of the truth through `on_read`.
    pub(super) fn drain(
        &mut self,
        on_read: &mut impl FnMut(usize, &Sample),
    ) -> Result<(), EvalError> {
        self.window.clear();
        while !self.exhausted {
            if self.pull(on_read)? {
                self.window.clear();
            }
        }
        Ok(())
    }
}

/// The median of the steps between consecutive instants, gathered one instant at a time in
/// memory proportional to the number of distinct steps (a few for a sampled run).
#[derive(Debug, Default)]
pub(super) struct MedianStep {
    last: Option<u64>,
    counts: HashMap<u64, usize>,
    steps: usize,
}

impl MedianStep {
    /// Adds the next instant (ns, increasing).
    pub(super) fn add(&mut self, t_ns: u64) {
        if let Some(last) = self.last {
            *self.counts.entry(t_ns - last).or_default() += 1;
            self.steps += 1;
        }
        self.last = Some(t_ns);
    }

    /// The step at position `steps / 2` of the sorted steps (0 without any step).
    pub(super) fn median(&self) -> u64 {
        let mut distinct: Vec<(u64, usize)> = self.counts.iter().map(|(&s, &n)| (s, n)).collect();
        distinct.sort_unstable();
        let mut seen = 0;
        for (step, n) in distinct {
            seen += n;
            if seen > self.steps / 2 {
                return step;
            }
        }
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    #[test]
    fn the_window_brackets_the_range_and_sees_every_sample_once() {
        let truth = Series::Memory(
            (0..10u64)
                .map(|k| (k * 10, UnitQuaternion::identity()))
                .collect(),
        );
        let mut walk = Walk::new(&truth).unwrap();
        let mut seen = Vec::new();
        let mut on_read = |i: usize, s: &Sample| seen.push((i, s.0));
        let (w, base) = walk.cover(25, 41, &mut on_read).unwrap();
        assert_eq!(
            (w.iter().map(|s| s.0).collect::<Vec<_>>(), base),
            (vec![20, 30, 40, 50], 2)
        );
        let (w, base) = walk.cover(30, 30, &mut on_read).unwrap();
        assert_eq!(
            (w.iter().map(|s| s.0).collect::<Vec<_>>(), base),
            (vec![30, 40, 50], 3)
        );
        let (w, _) = walk.cover(95, 120, &mut on_read).unwrap();
        assert_eq!(w.iter().map(|s| s.0).collect::<Vec<_>>(), vec![90]);
        walk.drain(&mut on_read).unwrap();
        assert_eq!(
            seen,
            (0..10).map(|k| (k, k as u64 * 10)).collect::<Vec<_>>()
        );
    }

    #[test]
    fn the_median_step_is_that_of_the_sorted_steps() {
        let times = [0u64, 10, 20, 50, 51, 61, 71, 171];
        let mut m = MedianStep::default();
        times.iter().for_each(|&t| m.add(t));
        let mut steps: Vec<u64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_unstable();
        assert_eq!(m.median(), steps[steps.len() / 2]);
        assert_eq!(MedianStep::default().median(), 0);
    }
}
