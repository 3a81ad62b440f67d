//! The paper's 6-DOF bench in closed loop: three prismatic and three revolute joints, each with
//! the dynamics of eq. 9–10, the friction of eq. 5–8 and a PID of eq. 14 designed from Table 2.
//!
//! [`Bench::advance_to`] integrates up to an instant. Internal steps are at most the scene's
//! `integrator.step`, lie on the grid of its multiples, and also land exactly on every instant
//! asked for, so the output rate never changes the integration (a 3 kHz output with a 1 ms step
//! integrates the same trajectory as a 1 kHz one, with extra landings).
//!
//! ```
//! use margemu_sim::{bench::Bench, scene::Scene};
//! let scene = Scene::parse_str(
//!     "duration = 1.0\nrate = 100.0\nseed = 1\n[joints.x]\ntype = \"constant\"\nvalue = 0.1\n",
//!     std::path::Path::new("doc.toml"),
//! ).unwrap();
//! let mut bench = Bench::new(&scene).unwrap();
//! bench.advance_to(1_000_000_000);
//! assert!((bench.sample().q[0] - 0.1).abs() < 0.01);
//! ```

pub mod joint;
mod linear;
pub mod pid;
mod pid_table;

use crate::reference::{Reference, ReferenceError};
use crate::scene::{Method, Scene, JOINT_NAMES};
use joint::{FrictionChange, Joint, JointParams};
use margemu_model::time::Nanos;
use pid::{Design, Gains, Requirement};

/// Joint positions, velocities and accelerations at one instant (generalized coordinates).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointSample {
    /// `q = (x, y, z, φ, θ, ψ)` (m, rad).
    pub q: [f64; 6],
    /// `q̇`.
    pub qd: [f64; 6],
    /// `q̈`.
    pub qdd: [f64; 6],
}

/// A friction mode change of one joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrictionEvent {
    /// When (end of the step that decided it).
    pub t_ns: Nanos,
    /// Joint index 0–5.
    pub joint: usize,
    /// Slip or stick.
    pub change: FrictionChange,
}

/// The bench: six joints, their references and the integrator.
#[derive(Clone, Debug)]
pub struct Bench {
    joints: [Joint; 6],
    references: [Reference; 6],
    designs: [Option<Design>; 6],
    method: Method,
    step_ns: Nanos,
    t_ns: Nanos,
    friction_log: Vec<FrictionEvent>,
}

/// Mass-matrix diagonal of eq. 3 and gravity loads of eq. 9 for a scene.
pub fn masses_and_loads(scene: &Scene) -> ([f64; 6], [f64; 6]) {
    let b = &scene.spec.bench;
    let mb = b.plate_mass;
    let masses = [
        b.link_mass[0] + mb,
        b.link_mass[1] + mb,
        b.link_mass[2] + mb,
        b.plate_inertia[0],
        b.plate_inertia[1],
        b.plate_inertia[2],
    ];
    let loads = [0.0, 0.0, (mb + b.link_mass[2]) * b.gravity, 0.0, 0.0, 0.0];
    (masses, loads)
}

/// The PID design of every joint: synthesised from Table 2, or `None` where the scene gives
/// explicit gains.
pub fn designs(scene: &Scene) -> [Option<Design>; 6] {
    let c = &scene.spec.control;
    if c.gains.is_some() {
        return [None; 6];
    }
    let (masses, _) = masses_and_loads(scene);
    let friction = scene.spec.bench.viscous_friction;
    std::array::from_fn(|i| {
        let req = Requirement {
            overshoot: c.overshoot[i],
            settling_time: c.settling_time[i],
        };
        Some(pid::synthesize(
            masses[i],
            friction[i],
            req,
            c.pole_ratio,
            c.retune.then_some(c.retune_margin),
        ))
    })
}

impl Bench {
    /// Builds the bench of a scene, at rest at `bench.initial`.
    pub fn new(scene: &Scene) -> Result<Self, ReferenceError> {
        let spec = &scene.spec;
        let (masses, loads) = masses_and_loads(scene);
        let designs = designs(scene);
        let mut references = Vec::with_capacity(6);
        for i in 0..JOINT_NAMES.len() {
            references.push(Reference::of_joint(scene, i, false)?);
        }
        let references: [Reference; 6] = references.try_into().expect("six joints");
        let joints = std::array::from_fn(|i| {
            let gains = match (&spec.control.gains, &designs[i]) {
                (Some(g), _) => Gains {
                    kp: g[i][0],
                    ki: g[i][1],
                    kd: g[i][2],
                },
                (None, Some(d)) => d.gains,
                (None, None) => unreachable!("designs exist when gains are not given"),
            };
            let smoothing = spec
                .joints
                .get(JOINT_NAMES[i])
                .and_then(|s| s.smoothing())
                .map(|s| (s.natural_frequency, s.damping));
            let params = JointParams {
                mass: masses[i],
                viscous: spec.bench.viscous_friction[i],
                stiction: spec.bench.static_friction[i],
                load: loads[i],
                limit: spec.bench.effort_limit.map_or(f64::INFINITY, |l| l[i]),
                gains,
                smoothing,
            };
            let q0 = spec.bench.initial[i];
            let mut joint = Joint::new(params, q0);
            joint.prepare(spec.integrator.method, scene.step_ns as f64 * 1e-9);
            joint
        });
        Ok(Self {
            joints,
            references,
            designs,
            method: spec.integrator.method,
            step_ns: scene.step_ns,
            t_ns: 0,
            friction_log: Vec::new(),
        })
    }

    /// The PID designs (`None` for joints with explicit gains).
    pub fn designs(&self) -> &[Option<Design>; 6] {
        &self.designs
    }

    /// The joints.
    pub fn joints(&self) -> &[Joint; 6] {
        &self.joints
    }

    /// Current time.
    pub fn time(&self) -> Nanos {
        self.t_ns
    }

    /// Every friction mode change so far.
    pub fn friction_log(&self) -> &[FrictionEvent] {
        &self.friction_log
    }

    /// Joint `i`'s reference source.
    pub fn reference_of(&self, i: usize) -> &Reference {
        &self.references[i]
    }

    /// The raw reference of joint `i` at the current time.
    pub fn reference(&mut self, i: usize) -> f64 {
        self.references[i].value(self.t_ns as f64)
    }

    /// Integrates up to `target` (no-op if already there or past).
    pub fn advance_to(&mut self, target: Nanos) {
        while self.t_ns < target {
            let next_grid = (self.t_ns / self.step_ns + 1).saturating_mul(self.step_ns);
            let end = next_grid.min(target);
            self.step(end);
        }
    }

    fn step(&mut self, end: Nanos) {
        let (t0, t1) = (self.t_ns as f64, end as f64);
        let h = (end - self.t_ns) as f64 * 1e-9;
        for (i, (joint, reference)) in self.joints.iter_mut().zip(&mut self.references).enumerate()
        {
            let r = match self.method {
                Method::Rk4 => reference.step_values(t0, t1),
                Method::SemiImplicitEuler => [reference.value(t0); 3],
            };
            if let Some(change) = joint.step(self.method, h, r) {
                self.friction_log.push(FrictionEvent {
                    t_ns: end,
                    joint: i,
                    change,
                });
            }
        }
        self.t_ns = end;
    }

    /// Positions, velocities and accelerations at the current time.
    pub fn sample(&mut self) -> JointSample {
        let t = self.t_ns as f64;
        let mut s = JointSample::default();
        for (i, (joint, reference)) in self.joints.iter().zip(&mut self.references).enumerate() {
            s.q[i] = joint.position();
            s.qd[i] = joint.velocity();
            s.qdd[i] = joint.acceleration(reference.value(t));
        }
        s
    }
}
