//! Reference sources: what each joint is asked to do over time.
//!
//! A [`Reference`] is built from a scene's [`SourceSpec`] and answers the value at a time, or
//! the value with its first and second time derivatives (kinematic mode). Times are passed as
//! nanoseconds in an `f64` (exact up to 104 days, and exact at RK4's half steps), so a step
//! scheduled at 0.3 s switches at exactly 300 000 000 ns; seconds for formulas are derived
//! from that.
//!
//! Random sources draw from the stream `reference/<joint>` of the scene seed, lazily and in
//! time order, so a longer run extends a shorter one and never changes its beginning.
//!
//! ```
//! use margemu_sim::reference::Reference;
//! use margemu_sim::scene::SourceSpec;
//! let spec = SourceSpec::Sine { amplitude: 2.0, frequency: 0.25, phase: 0.0, offset: 1.0 };
//! let mut r = Reference::build(&spec, "roll", 0.0, 7, std::path::Path::new("."), false).unwrap();
//! assert!((r.value(1e9) - 3.0).abs() < 1e-12); // sin(π/2) at 1 s
//! ```

mod piecewise;
mod table;

use crate::scene::{Scene, SourceSpec, JOINT_NAMES};
use piecewise::Piecewise;
use std::path::{Path, PathBuf};
pub use table::{Table, TableError};

/// Value, first and second derivative (per second, per second²).
pub type Derivatives = [f64; 3];

/// A scene's motion that could not be produced: a joint reference that could not be built, or
/// a value that went non-finite while the motion ran.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum ReferenceError {
    /// {at}: joint `{joint}`: {problem}
    Table {
        /// The scene's `file:line:col` of the source's `file` key.
        at: String,
        /// Joint name.
        joint: String,
        /// The CSV problem (its text is part of the message, so it is not a `source`).
        problem: Box<TableError>,
    },
    /// {0}
    NonFinite(Box<crate::guard::NonFinite>),
}

/// One joint's reference signal.
#[derive(Clone, Debug)]
pub struct Reference {
    kind: Kind,
    memo: (f64, f64),
}

#[derive(Clone, Debug)]
enum Kind {
    Constant(f64),
    Sine {
        amplitude: f64,
        omega: f64,
        phase: f64,
        offset: f64,
    },
    Polynomial(Vec<f64>),
    Piecewise(Piecewise),
    Linear(Table),
    Spline(Table),
}

impl Reference {
    /// Builds joint `joint`'s reference. `initial` is the joint's value before the first step,
    /// `base` the folder CSV paths resolve against, and `smooth` asks for a twice
    /// differentiable interpolation of CSV data (kinematic mode) instead of a linear one.
    pub fn build(
        spec: &SourceSpec,
        joint: &str,
        initial: f64,
        seed: u64,
        base: &Path,
        smooth: bool,
    ) -> Result<Self, TableError> {
        let kind = match spec {
            SourceSpec::Constant { value } => Kind::Constant(*value),
            SourceSpec::Sine {
                amplitude,
                frequency,
                phase,
                offset,
            } => Kind::Sine {
                amplitude: *amplitude,
                omega: 2.0 * core::f64::consts::PI * frequency,
                phase: *phase,
                offset: *offset,
            },
            SourceSpec::Polynomial { coefficients } => Kind::Polynomial(coefficients.clone()),
            SourceSpec::Csv { file, column, .. } => {
                let path: PathBuf = base.join(file);
                let table = Table::load(&path, column)?;
                if smooth {
                    Kind::Spline(table.into_spline())
                } else {
                    Kind::Linear(table)
                }
            }
            other => Kind::Piecewise(Piecewise::new(other, joint, initial, seed)),
        };
        Ok(Self {
            kind,
            memo: (f64::NAN, 0.0),
        })
    }

    /// Joint `i`'s reference in `scene` (its source, or its initial value held), with CSV
    /// problems located at the scene's `joints.<name>.file`. `smooth` as for [`Self::build`].
    pub fn of_joint(scene: &Scene, i: usize, smooth: bool) -> Result<Self, ReferenceError> {
        let (spec, name) = (&scene.spec, JOINT_NAMES[i]);
        let initial = spec.bench.initial[i];
        match spec.joints.get(name) {
            None => Ok(Self::constant(initial)),
            Some(source) => Self::build(source, name, initial, spec.seed, scene.base_dir(), smooth)
                .map_err(|problem| ReferenceError::Table {
                    at: scene.location(&["joints", name, "file"]),
                    joint: name.into(),
                    problem: Box::new(problem),
                }),
        }
    }

    /// For a CSV source, the file and rows in force at `t_ns` (see [`Table::rows_at`]).
    pub fn rows_at(&self, t_ns: f64) -> Option<String> {
        match &self.kind {
            Kind::Linear(t) | Kind::Spline(t) => t.rows_at(seconds(t_ns)),
            _ => None,
        }
    }

    /// A constant reference.
    pub fn constant(value: f64) -> Self {
        Self {
            kind: Kind::Constant(value),
            memo: (f64::NAN, 0.0),
        }
    }

    /// The value at `t_ns` nanoseconds (repeated queries at one time are answered from a memo).
    pub fn value(&mut self, t_ns: f64) -> f64 {
        if self.memo.0 == t_ns {
            return self.memo.1;
        }
        let v = match &mut self.kind {
            Kind::Constant(c) => *c,
            Kind::Sine {
                amplitude,
                omega,
                phase,
                offset,
            } => *offset + *amplitude * libm::sin(*omega * seconds(t_ns) + *phase),
            Kind::Polynomial(c) => horner(c, seconds(t_ns)),
            Kind::Piecewise(p) => p.value(t_ns),
            Kind::Linear(t) => t.linear(seconds(t_ns)),
            Kind::Spline(t) => t.spline(seconds(t_ns))[0],
        };
        self.memo = (t_ns, v);
        v
    }

    /// The left limit of the value at `t_ns`: for a step scheduled exactly at `t_ns`, the value
    /// before it. An integration step that ends on a switch must see the old value at its end,
    /// or the switch leaks one step early and the integrator drops to first order.
    pub fn value_before(&mut self, t_ns: f64) -> f64 {
        match &mut self.kind {
            Kind::Piecewise(p) => p.value_before(t_ns),
            _ => self.value(t_ns),
        }
    }

    /// `[value(t0), value(½(t0 + t1)), value_before(t1)]`, the three samples an RK4 step from
    /// `t0` to `t1 > t0` takes, with the same results; a held stretch of a piecewise source is
    /// looked up once for all three.
    pub fn step_values(&mut self, t0: f64, t1: f64) -> [f64; 3] {
        let mid = 0.5 * (t0 + t1);
        if let Kind::Piecewise(p) = &mut self.kind {
            let known = (self.memo.0 == t0).then_some(self.memo.1);
            if let Some(values) = p.span_values(t0, mid, t1, known) {
                self.memo = (t1, values[2]);
                return values;
            }
        }
        [self.value(t0), self.value(mid), self.value_before(t1)]
    }

    /// The value and its first two time derivatives at `t_ns` (kinematic mode).
    ///
    /// Held setpoints report zero derivatives; a linear CSV reports its slope.
    pub fn derivatives(&mut self, t_ns: f64) -> Derivatives {
        let t = seconds(t_ns);
        match &mut self.kind {
            Kind::Constant(c) => [*c, 0.0, 0.0],
            Kind::Sine {
                amplitude,
                omega,
                phase,
                offset,
            } => {
                let (s, c) = libm::sincos(*omega * t + *phase);
                let a = *amplitude;
                [*offset + a * s, a * *omega * c, -a * *omega * *omega * s]
            }
            Kind::Polynomial(c) => polynomial_derivatives(c, t),
            Kind::Piecewise(p) => p.derivatives(t_ns),
            Kind::Linear(table) => [table.linear(t), table.slope(t), 0.0],
            Kind::Spline(table) => table.spline(t),
        }
    }
}

fn seconds(t_ns: f64) -> f64 {
    t_ns * 1e-9
}

fn horner(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * t + ci)
}

fn polynomial_derivatives(c: &[f64], t: f64) -> Derivatives {
    let (mut p, mut dp, mut ddp) = (0.0, 0.0, 0.0);
    for &ci in c.iter().rev() {
        ddp = ddp * t + 2.0 * dp;
        dp = dp * t + p;
        p = p * t + ci;
    }
    [p, dp, ddp]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn step_values_are_the_three_separate_queries() {
        let specs = [
            SourceSpec::Steps {
                points: vec![[0.1, 1.5], [0.1005, 1.0], [0.25, -2.0]],
                smoothing: None,
            },
            SourceSpec::RandomSetpoints {
                range: [-1.0, 1.0],
                hold: [0.01, 0.03],
                smoothing: None,
            },
            SourceSpec::RandomSine {
                amplitude: [0.1, 0.9],
                frequency: [0.5, 9.0],
                segment: [0.01, 0.05],
                offset: 0.2,
            },
            SourceSpec::Sine {
                amplitude: 0.4,
                frequency: 2.0,
                phase: 0.3,
                offset: 0.0,
            },
        ];
        for spec in &specs {
            let build = || Reference::build(spec, "x", 0.5, 3, Path::new("."), false).unwrap();
            let (mut fused, mut separate) = (build(), build());
            // Steps of 0.5 ms landing on the switches at 0.1 s and 0.1005 s, then uneven ones
            // that land on the one at 0.25 s every other step.
            let mut t0 = 0u64;
            for k in 0..700u64 {
                let t1 = t0
                    + match k {
                        0..400 => 500_000,
                        _ if k % 2 == 0 => 300_000,
                        _ => 200_000,
                    };
                let (a, b) = (t0 as f64, t1 as f64);
                let want = [
                    separate.value(a),
                    separate.value(0.5 * (a + b)),
                    separate.value_before(b),
                ];
                let got = fused.step_values(a, b);
                assert_eq!(
                    got.map(f64::to_bits),
                    want.map(f64::to_bits),
                    "{spec:?} at {t0}"
                );
                // The value at the step's end, as the bench samples it.
                assert_eq!(fused.value(b).to_bits(), separate.value(b).to_bits());
                t0 = t1;
            }
        }
    }

    #[test]
    fn polynomial_derivatives_are_exact() {
        // 1 + 2t + 3t² + 4t³ at t = 2: 49, 2 + 12 + 48 = 62, 6 + 48 = 54.
        assert_eq!(
            polynomial_derivatives(&[1.0, 2.0, 3.0, 4.0], 2.0),
            [49.0, 62.0, 54.0]
        );
        assert_eq!(horner(&[1.0, 2.0, 3.0, 4.0], 2.0), 49.0);
    }

    #[test]
    fn sine_derivatives_are_analytic() {
        let spec = SourceSpec::Sine {
            amplitude: 0.5,
            frequency: 2.0,
            phase: 0.3,
            offset: 0.1,
        };
        let mut r = Reference::build(&spec, "roll", 0.0, 1, Path::new("."), true).unwrap();
        let t = 0.123;
        let w = 4.0 * core::f64::consts::PI;
        let d = r.derivatives(t * 1e9);
        assert_relative_eq!(d[0], 0.1 + 0.5 * (w * t + 0.3).sin(), epsilon = 1e-12);
        assert_relative_eq!(d[1], 0.5 * w * (w * t + 0.3).cos(), epsilon = 1e-12);
        assert_relative_eq!(d[2], -0.5 * w * w * (w * t + 0.3).sin(), epsilon = 1e-10);
    }
}
