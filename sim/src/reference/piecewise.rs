//! Piecewise references: stair steps, waypoints, random setpoints and random sine segments.
//!
//! A piecewise reference is a list of segments, each a held value or a sine that starts at
//! phase 0 at its segment's start. Finite lists (steps, waypoints) are built up front; cyclic
//! waypoints and random sources generate segments lazily as time advances. Segment starts are
//! whole nanoseconds accumulated as integers, so a long run never drifts.

use super::Derivatives;
use crate::scene::SourceSpec;
use margemu_model::rng::{stream, uniform, StreamRng};
use margemu_model::time::nanos_from_seconds;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    Hold(f64),
    /// `offset + amplitude · sin(ω (t − start))`.
    Sine {
        amplitude: f64,
        omega: f64,
        offset: f64,
    },
}

#[derive(Clone, Copy, Debug)]
struct Segment {
    start_ns: u64,
    shape: Shape,
}

#[derive(Clone, Debug)]
enum Generator {
    /// Nothing more to generate: the last segment lasts forever.
    Done,
    /// Waypoints `[value, hold]` repeated from `next`.
    Cycle { points: Vec<[f64; 2]>, next: usize },
    RandomSetpoints {
        rng: Box<StreamRng>,
        range: [f64; 2],
        hold: [f64; 2],
    },
    RandomSine {
        rng: Box<StreamRng>,
        amplitude: [f64; 2],
        frequency: [f64; 2],
        segment: [f64; 2],
        offset: f64,
    },
}

/// A piecewise reference with a forward-moving cursor.
#[derive(Clone, Debug)]
pub(super) struct Piecewise {
    segments: Vec<Segment>,
    /// Start of the segment the generator makes next.
    end_ns: u64,
    generator: Generator,
    cursor: usize,
}

fn ns(s: f64) -> u64 {
    // Validated scenes have finite, non-negative times; saturate anything else.
    nanos_from_seconds(s).unwrap_or(u64::MAX)
}

impl Piecewise {
    pub(super) fn new(spec: &SourceSpec, joint: &str, initial: f64, seed: u64) -> Self {
        let rng = || Box::new(stream(seed, &format!("reference/{joint}")));
        let mut p = Self {
            segments: Vec::new(),
            end_ns: 0,
            generator: Generator::Done,
            cursor: 0,
        };
        match spec {
            SourceSpec::Steps { points, .. } => {
                p.push(0, Shape::Hold(initial));
                for &[t, v] in points {
                    let start = ns(t);
                    if start == 0 {
                        p.segments.clear();
                    }
                    p.push(start, Shape::Hold(v));
                }
            }
            SourceSpec::Waypoints { points, repeat, .. } => {
                if *repeat {
                    p.generator = Generator::Cycle {
                        points: points.clone(),
                        next: 0,
                    };
                } else {
                    let mut start = 0;
                    for &[v, hold] in points {
                        p.push(start, Shape::Hold(v));
                        start = start.saturating_add(ns(hold));
                    }
                }
            }
            SourceSpec::RandomSetpoints { range, hold, .. } => {
                p.generator = Generator::RandomSetpoints {
                    rng: rng(),
                    range: *range,
                    hold: *hold,
                };
            }
            SourceSpec::RandomSine {
                amplitude,
                frequency,
                segment,
                offset,
            } => {
                p.generator = Generator::RandomSine {
                    rng: rng(),
                    amplitude: *amplitude,
                    frequency: *frequency,
                    segment: *segment,
                    offset: *offset,
                };
            }
            _ => p.push(0, Shape::Hold(initial)),
        }
        if p.segments.is_empty() {
            p.generate();
        }
        p
    }

    fn push(&mut self, start_ns: u64, shape: Shape) {
        self.segments.push(Segment { start_ns, shape });
        self.end_ns = start_ns;
    }

    /// Appends the next segment; returns false when the generator is exhausted.
    fn generate(&mut self) -> bool {
        let start = if self.segments.is_empty() {
            0
        } else {
            self.end_ns
        };
        let (shape, length_ns) = match &mut self.generator {
            Generator::Done => return false,
            Generator::Cycle { points, next } => {
                let [v, hold] = points[*next % points.len()];
                *next += 1;
                (Shape::Hold(v), ns(hold))
            }
            Generator::RandomSetpoints { rng, range, hold } => {
                let v = uniform(rng, range[0], range[1]);
                (Shape::Hold(v), ns(uniform(rng, hold[0], hold[1])))
            }
            Generator::RandomSine {
                rng,
                amplitude,
                frequency,
                segment,
                offset,
            } => {
                let a = uniform(rng, amplitude[0], amplitude[1]);
                let f = uniform(rng, frequency[0], frequency[1]);
                let length = uniform(rng, segment[0], segment[1]);
                // Whole half periods: the segment starts and ends at its offset.
                let half_periods = libm::round(length * 2.0 * f).max(1.0);
                let shape = Shape::Sine {
                    amplitude: a,
                    omega: 2.0 * core::f64::consts::PI * f,
                    offset: *offset,
                };
                (shape, ns(half_periods / (2.0 * f)))
            }
        };
        self.segments.push(Segment {
            start_ns: start,
            shape,
        });
        self.end_ns = start.saturating_add(length_ns.max(1));
        true
    }

    /// The segment in force at `t_ns`, generating segments up to it.
    fn segment_at(&mut self, t_ns: f64) -> Segment {
        // Fast path: time moves forward in small steps, so the cursor's segment usually holds.
        let here = self.segments[self.cursor];
        if here.start_ns as f64 <= t_ns && t_ns < self.next_start() {
            return here;
        }
        while !matches!(self.generator, Generator::Done) && self.end_ns as f64 <= t_ns {
            if !self.generate() {
                break;
            }
        }
        while self.cursor + 1 < self.segments.len()
            && self.segments[self.cursor + 1].start_ns as f64 <= t_ns
        {
            self.cursor += 1;
        }
        while self.cursor > 0 && self.segments[self.cursor].start_ns as f64 > t_ns {
            self.cursor -= 1;
        }
        self.segments[self.cursor]
    }

    /// Where the cursor's segment ends (as far as it is generated yet).
    fn next_start(&self) -> f64 {
        match self.segments.get(self.cursor + 1) {
            Some(next) => next.start_ns as f64,
            None if matches!(self.generator, Generator::Done) => f64::INFINITY,
            None => self.end_ns as f64,
        }
    }

    /// `[value(t0), value(tm), value_before(t1)]` for `t0 ≤ tm ≤ t1`, `t0 < t1`, when one
    /// segment covers `[t0, t1]` (then the last is `value(t1)` too); `None` when a segment
    /// starts in `(t0, t1]`. `at_t0` is `value(t0)` if the caller knows it.
    pub(super) fn span_values(
        &mut self,
        t0: f64,
        tm: f64,
        t1: f64,
        at_t0: Option<f64>,
    ) -> Option<[f64; 3]> {
        let seg = self.segment_at(t0);
        if t1 >= self.next_start() {
            return None;
        }
        let value = |t: f64| Self::evaluate(seg, t)[0];
        Some([at_t0.unwrap_or_else(|| value(t0)), value(tm), value(t1)])
    }

    pub(super) fn value(&mut self, t_ns: f64) -> f64 {
        self.derivatives(t_ns)[0]
    }

    /// The value just before `t_ns` (differs from [`Self::value`] only at a segment start).
    pub(super) fn value_before(&mut self, t_ns: f64) -> f64 {
        let seg = self.segment_at(t_ns);
        if seg.start_ns as f64 == t_ns && self.cursor > 0 {
            let previous = self.segments[self.cursor - 1];
            let start = previous.start_ns as f64;
            Self::evaluate(previous, t_ns.max(start))[0]
        } else {
            Self::evaluate(seg, t_ns)[0]
        }
    }

    pub(super) fn derivatives(&mut self, t_ns: f64) -> Derivatives {
        let seg = self.segment_at(t_ns);
        Self::evaluate(seg, t_ns)
    }

    fn evaluate(seg: Segment, t_ns: f64) -> Derivatives {
        match seg.shape {
            Shape::Hold(v) => [v, 0.0, 0.0],
            Shape::Sine {
                amplitude,
                omega,
                offset,
            } => {
                let t = (t_ns - seg.start_ns as f64) * 1e-9;
                let (s, c) = libm::sincos(omega * t);
                [
                    offset + amplitude * s,
                    amplitude * omega * c,
                    -amplitude * omega * omega * s,
                ]
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_switch_at_their_exact_instant() {
        let spec = SourceSpec::Steps {
            points: vec![[0.3, 1.0], [0.7, -2.0]],
            smoothing: None,
        };
        let mut p = Piecewise::new(&spec, "x", 0.5, 1);
        assert_eq!(p.value(0.0), 0.5);
        assert_eq!(p.value(299_999_999.5), 0.5);
        assert_eq!(p.value(300_000_000.0), 1.0);
        assert_eq!(p.value(700_000_000.0), -2.0);
        assert_eq!(p.value_before(700_000_000.0), 1.0);
        assert_eq!(p.value_before(700_000_001.0), -2.0);
        assert_eq!(p.value_before(0.0), 0.5);
        assert_eq!(p.value(1e12), -2.0);
        // Going back in time is answered too.
        assert_eq!(p.value(100.0), 0.5);
    }

    #[test]
    fn waypoints_hold_and_repeat() {
        let spec = SourceSpec::Waypoints {
            points: vec![[1.0, 0.5], [2.0, 0.25]],
            repeat: true,
            smoothing: None,
        };
        let mut p = Piecewise::new(&spec, "y", 0.0, 1);
        let at = |p: &mut Piecewise, s: f64| p.value(s * 1e9);
        assert_eq!(at(&mut p, 0.0), 1.0);
        assert_eq!(at(&mut p, 0.6), 2.0);
        assert_eq!(at(&mut p, 0.75), 1.0);
        assert_eq!(at(&mut p, 100.0 * 0.75 + 0.5), 2.0);
    }

    #[test]
    fn random_setpoints_stay_in_range_and_repeat_with_the_seed() {
        let spec = SourceSpec::RandomSetpoints {
            range: [-0.2, 0.3],
            hold: [0.5, 1.5],
            smoothing: None,
        };
        let mut a = Piecewise::new(&spec, "x", 0.0, 9);
        let mut b = Piecewise::new(&spec, "x", 0.0, 9);
        let mut c = Piecewise::new(&spec, "y", 0.0, 9);
        let mut differs = false;
        for k in 0..2000 {
            let t = k as f64 * 1e7;
            let v = a.value(t);
            assert!((-0.2..0.3).contains(&v));
            assert_eq!(v, b.value(t));
            differs |= v != c.value(t);
        }
        assert!(differs, "streams of different joints must differ");
        let holds: Vec<u64> = a
            .segments
            .windows(2)
            .map(|w| w[1].start_ns - w[0].start_ns)
            .collect();
        assert!(
            holds
                .iter()
                .all(|&h| (500_000_000..=1_500_000_000).contains(&h)),
            "{holds:?}"
        );
    }

    #[test]
    fn random_sine_segments_are_continuous() {
        let spec = SourceSpec::RandomSine {
            amplitude: [0.1, 1.0],
            frequency: [0.5, 5.0],
            segment: [0.5, 2.0],
            offset: 0.2,
        };
        let mut p = Piecewise::new(&spec, "roll", 0.0, 3);
        let mut last = p.value(0.0);
        for k in 1..200_000 {
            let v = p.value(k as f64 * 1e5);
            // |dv/dt| ≤ 2π·5·1 rad/s, so 0.1 ms steps move at most ~3.2 mrad.
            assert!((v - last).abs() < 3.3e-3, "jump at {k}: {last} -> {v}");
            last = v;
        }
    }
}
