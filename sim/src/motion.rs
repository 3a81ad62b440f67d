//! Where the plate's motion comes from; a scene pays only for the mode it names.
//!
//! - [`Motion::Static`]: the plate rests at `bench.initial`; nothing is computed per sample.
//! - [`Motion::Kinematic`]: each joint's source prescribes position, velocity and acceleration
//!   analytically (or by a C² spline through CSV rows); no dynamics, no PID.
//! - [`Motion::Bench`]: the closed-loop bench of the paper ([`crate::bench`]).

use crate::bench::{Bench, JointSample};
use crate::reference::{Reference, ReferenceError};
use crate::scene::{MotionMode, Scene, JOINT_NAMES};
use margemu_model::time::Nanos;

/// The plate's motion source.
#[derive(Clone, Debug)]
pub enum Motion {
    /// A fixed pose.
    Static(JointSample),
    /// Prescribed joint trajectories.
    Kinematic(Box<[Reference; 6]>),
    /// The simulated bench.
    Bench(Box<Bench>),
}

impl Motion {
    /// The motion source a scene asks for.
    pub fn new(scene: &Scene) -> Result<Self, ReferenceError> {
        let spec = &scene.spec;
        Ok(match spec.motion {
            MotionMode::Static => Motion::Static(JointSample {
                q: spec.bench.initial,
                ..JointSample::default()
            }),
            MotionMode::Kinematic => {
                let mut refs = Vec::with_capacity(6);
                for i in 0..JOINT_NAMES.len() {
                    refs.push(Reference::of_joint(scene, i, true)?);
                }
                Motion::Kinematic(Box::new(refs.try_into().expect("six joints")))
            }
            MotionMode::Bench => Motion::Bench(Box::new(Bench::new(scene)?)),
        })
    }

    /// Joint positions, velocities and accelerations at `t_ns` (times must not decrease for
    /// the bench, which integrates forward).
    pub fn sample_at(&mut self, t_ns: Nanos) -> JointSample {
        match self {
            Motion::Static(pose) => *pose,
            Motion::Kinematic(refs) => {
                let mut s = JointSample::default();
                for (i, r) in refs.iter_mut().enumerate() {
                    [s.q[i], s.qd[i], s.qdd[i]] = r.derivatives(t_ns as f64);
                }
                s
            }
            Motion::Bench(bench) => {
                bench.advance_to(t_ns);
                bench.sample()
            }
        }
    }

    /// Joint `i`'s reference (none for a static plate).
    pub fn reference(&self, i: usize) -> Option<&Reference> {
        match self {
            Motion::Static(_) => None,
            Motion::Kinematic(refs) => Some(&refs[i]),
            Motion::Bench(bench) => Some(bench.reference_of(i)),
        }
    }

    /// The bench, in bench mode.
    pub fn bench(&self) -> Option<&Bench> {
        match self {
            Motion::Bench(b) => Some(b),
            _ => None,
        }
    }
}
