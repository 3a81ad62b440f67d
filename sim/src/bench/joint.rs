//! One joint of the bench. The paper's bench is fully decoupled (eq. 3: diagonal mass matrix;
//! eq. 9: gravity acts on joint 3 only), so each joint is integrated on its own:
//!
//! `M q̈ = τ_a − τ_f − V`, with `τ_a = sat(K_P e + K_I ∫e − K_D q̇ + V)` (eq. 14),
//!
//! where `e = q_d − q`, `V` is the joint's constant gravity load (eq. 9: `(m_b + m_j3) g` on
//! joint 3) and the feed-forward `+V` cancels it (eq. 14 prints `−V`; with eq. 9's sign
//! convention the compensating term is `+V`, which is what eq. 15 assumes). The net effort
//! `u = τ_a − V` is what moves the joint; stiction compares `|u|` with `τ_s`, so a joint 3 held
//! against gravity is not counted as pushing.
//!
//! **Friction (eq. 5–8).** A joint starts stuck. It slips when `|u| > τ_s`; while sliding,
//! viscous friction `f q̇` acts; it sticks again, with `q̇ := 0`, when `|u| ≤ τ_s` and the
//! velocity crossed (or reached) zero during the last step. Stuck, it neither moves nor
//! accelerates, and the PID integrator keeps integrating, so a stuck joint breaks away once the
//! integral has built enough effort. The mode is decided between steps, never inside one, so it
//! cannot chatter within a step; a joint with `τ_s = 0` skips the state machine altogether.
//!
//! **Effort limit and anti-windup.** The commanded effort is clipped to `±limit`; while it is
//! clipped and the error pushes further into the limit, the integrator holds (conditional
//! integration).
//!
//! **Setpoint smoothing.** Optionally `q_d` is the output of `r̈_f = ωn² (r − r_f) − 2ζωn ṙ_f`
//! driven by the raw reference `r`, integrated with the joint.

use super::linear::{LinearStep, PlainRows};
use super::pid::Gains;
use crate::scene::Method;

/// Physical and control parameters of one joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointParams {
    /// Mass or moment of inertia `M_i` (kg or kg·m²).
    pub mass: f64,
    /// Viscous friction `f_i`.
    pub viscous: f64,
    /// Static friction threshold `τ_s,i`; 0 disables stiction.
    pub stiction: f64,
    /// Constant generalized gravity load `V_i`.
    pub load: f64,
    /// Largest actuator effort (∞ for none).
    pub limit: f64,
    /// PID gains.
    pub gains: Gains,
    /// Setpoint smoothing `(ωn, ζ)`, if any.
    pub smoothing: Option<(f64, f64)>,
}

pub(super) const Q: usize = 0;
pub(super) const V: usize = 1;
pub(super) const I: usize = 2;
pub(super) const RF: usize = 3;
pub(super) const RFD: usize = 4;

/// Integrated state: position, velocity, error integral, smoothed setpoint and its rate.
pub type State = [f64; 5];

/// A friction mode change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrictionChange {
    /// Static friction was overcome.
    Slip,
    /// The joint came to rest under static friction.
    Stick,
}

/// One joint: its parameters, its state and its friction mode.
#[derive(Clone, Debug)]
pub struct Joint {
    params: JointParams,
    state: State,
    stuck: bool,
    linear: Option<LinearStep>,
}

/// Efforts at one state.
struct Effort {
    error: f64,
    /// Net effort after the limit, gravity load removed: `τ_a − V`.
    net: f64,
    /// Whether the integrator must hold (clipped and pushing further in).
    hold_integral: bool,
}

impl Joint {
    /// A joint at rest at `q0` (its smoothed setpoint too), stuck if it has static friction.
    pub fn new(params: JointParams, q0: f64) -> Self {
        let state = [q0, 0.0, 0.0, q0, 0.0];
        Self {
            params,
            state,
            stuck: params.stiction > 0.0,
            linear: None,
        }
    }

    /// Whether the joint is linear (no stiction, no effort limit).
    pub fn is_linear(&self) -> bool {
        self.params.stiction == 0.0 && self.params.limit == f64::INFINITY
    }

    /// Precomputes the step map for `method` and steps of `h` seconds, if the joint is linear.
    /// Steps of that length then cost one small matrix product.
    pub fn prepare(&mut self, method: Method, h: f64) {
        if !self.is_linear() {
            return;
        }
        let probe = |x: State, r: [f64; 3]| {
            let j = Joint {
                state: x,
                linear: None,
                ..self.clone()
            };
            j.advance(method, h, r)
        };
        let unit = |i: usize| -> State { std::array::from_fn(|k| if k == i { 1.0 } else { 0.0 }) };
        let columns: [State; 5] = std::array::from_fn(|j| probe(unit(j), [0.0; 3]));
        let phi = std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]));
        let g = std::array::from_fn(|k| {
            let r: [f64; 3] = std::array::from_fn(|m| if m == k { 1.0 } else { 0.0 });
            probe([0.0; 5], r)
        });
        let plain = if self.params.smoothing.is_none() {
            PlainRows::of(&phi, &g, &self.state)
        } else {
            None
        };
        self.linear = Some(LinearStep {
            method,
            h,
            phi,
            g,
            plain,
        });
    }

    /// The joint's parameters.
    pub fn params(&self) -> &JointParams {
        &self.params
    }

    /// Position.
    pub fn position(&self) -> f64 {
        self.state[Q]
    }

    /// Velocity.
    pub fn velocity(&self) -> f64 {
        self.state[V]
    }

    /// Whether static friction holds the joint.
    pub fn is_stuck(&self) -> bool {
        self.stuck
    }

    /// The setpoint the PID tracks for raw reference `r`.
    pub fn setpoint(&self, r: f64) -> f64 {
        if self.params.smoothing.is_some() {
            self.state[RF]
        } else {
            r
        }
    }

    /// Acceleration at the current state with raw reference `r`.
    pub fn acceleration(&self, r: f64) -> f64 {
        self.accel(&self.state, self.effort(&self.state, r).net)
    }

    /// Net actuator effort `τ_a − V` at the current state with raw reference `r`.
    pub fn net_effort(&self, r: f64) -> f64 {
        self.effort(&self.state, r).net
    }

    fn effort(&self, s: &State, r: f64) -> Effort {
        let p = &self.params;
        let qd = if p.smoothing.is_some() { s[RF] } else { r };
        let error = qd - s[Q];
        let pid = p.gains.kp * error + p.gains.ki * s[I] - p.gains.kd * s[V];
        let commanded = pid + p.load;
        let applied = commanded.clamp(-p.limit, p.limit);
        Effort {
            error,
            net: applied - p.load,
            hold_integral: applied != commanded && error * (commanded - applied) > 0.0,
        }
    }

    /// `q̈` at state `s` under net effort `net` (zero while stuck).
    fn accel(&self, s: &State, net: f64) -> f64 {
        if self.stuck {
            0.0
        } else {
            (net - self.params.viscous * s[V]) / self.params.mass
        }
    }

    fn deriv(&self, s: &State, r: f64) -> State {
        let p = &self.params;
        let effort = self.effort(s, r);
        let dq = if self.stuck { 0.0 } else { s[V] };
        let dv = self.accel(s, effort.net);
        let di = if effort.hold_integral {
            0.0
        } else {
            effort.error
        };
        let (drf, drfd) = match p.smoothing {
            Some((wn, zeta)) => (s[RFD], wn * wn * (r - s[RF]) - 2.0 * zeta * wn * s[RFD]),
            None => (0.0, 0.0),
        };
        [dq, dv, di, drf, drfd]
    }

    /// Advances by `h` seconds with the raw reference at the start, middle and end of the step.
    /// Returns the friction mode change, if any.
    #[inline]
    pub fn step(&mut self, method: Method, h: f64, r: [f64; 3]) -> Option<FrictionChange> {
        // A prepared linear joint has no stiction, so no friction mode to decide.
        if let Some(l) = &self.linear {
            if l.h == h && l.method == method {
                self.state = l.apply(&self.state, r);
                return None;
            }
        }
        self.step_general(method, h, r)
    }

    /// [`Self::step`] for a joint that may stick, or a step of another length.
    fn step_general(&mut self, method: Method, h: f64, r: [f64; 3]) -> Option<FrictionChange> {
        let stiction = self.params.stiction;
        let mut change = None;
        if self.stuck && self.effort(&self.state, r[0]).net.abs() > stiction {
            self.stuck = false;
            change = Some(FrictionChange::Slip);
        }
        let v_before = self.state[V];
        self.state = self.advance(method, h, r);
        if stiction > 0.0 && !self.stuck {
            let v = self.state[V];
            let crossed = v_before * v < 0.0 || v == 0.0;
            if crossed && self.effort(&self.state, r[2]).net.abs() <= stiction {
                self.stuck = true;
                self.state[V] = 0.0;
                change = Some(FrictionChange::Stick);
            }
        }
        change
    }

    /// The state after one step of the general (possibly nonlinear) method.
    fn advance(&self, method: Method, h: f64, r: [f64; 3]) -> State {
        match method {
            Method::Rk4 => self.rk4(h, r),
            Method::SemiImplicitEuler => self.semi_implicit_euler(h, r[0]),
        }
    }

    fn rk4(&self, h: f64, r: [f64; 3]) -> State {
        let s = self.state;
        let k1 = self.deriv(&s, r[0]);
        let k2 = self.deriv(&axpy(&s, h / 2.0, &k1), r[1]);
        let k3 = self.deriv(&axpy(&s, h / 2.0, &k2), r[1]);
        let k4 = self.deriv(&axpy(&s, h, &k3), r[2]);
        std::array::from_fn(|i| s[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// Velocities first, then positions with the new velocities (symplectic Euler).
    fn semi_implicit_euler(&self, h: f64, r: f64) -> State {
        let s = self.state;
        let d = self.deriv(&s, r);
        let v = s[V] + h * d[V];
        let rfd = s[RFD] + h * d[RFD];
        let q = if self.stuck { s[Q] } else { s[Q] + h * v };
        [q, v, s[I] + h * d[I], s[RF] + h * rfd, rfd]
    }
}

fn axpy(s: &State, h: f64, k: &State) -> State {
    std::array::from_fn(|i| s[i] + h * k[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(stiction: f64) -> JointParams {
        JointParams {
            mass: 2.0,
            viscous: 1.0,
            stiction,
            load: 0.0,
            limit: f64::INFINITY,
            gains: Gains {
                kp: 0.0,
                ki: 10.0,
                kd: 0.0,
            },
            smoothing: None,
        }
    }

    #[test]
    fn a_stuck_joint_breaks_away_only_past_the_threshold() {
        // Pure integral control on a unit error: the effort is 10·t, so with τ_s = 5 the joint
        // must stay put until t = 0.5 s and slide from the first step after.
        let mut j = Joint::new(params(5.0), 0.0);
        let h = 1e-3;
        let mut slipped_at = None;
        for k in 0..1000 {
            if j.step(Method::Rk4, h, [1.0; 3]) == Some(FrictionChange::Slip) {
                slipped_at = Some(k);
                break;
            }
            assert_eq!(j.position(), 0.0);
            assert_eq!(j.velocity(), 0.0);
        }
        let k = slipped_at.expect("never slipped");
        assert!((500..=501).contains(&k), "slipped at step {k}");
    }

    #[test]
    fn without_stiction_the_state_machine_is_off() {
        let mut j = Joint::new(params(0.0), 0.0);
        assert!(!j.is_stuck());
        for _ in 0..100 {
            assert_eq!(j.step(Method::Rk4, 1e-3, [1.0; 3]), None);
        }
        assert!(j.position() > 0.0);
    }

    #[test]
    fn the_linear_step_map_is_the_same_method() {
        let mut p = params(0.0);
        p.gains = Gains {
            kp: 30.0,
            ki: 40.0,
            kd: 5.0,
        };
        p.smoothing = Some((46.0, 0.869));
        for method in [Method::Rk4, Method::SemiImplicitEuler] {
            let mut general = Joint::new(p, 0.1);
            let mut fast = general.clone();
            fast.prepare(method, 1e-3);
            assert!(fast.linear.is_some());
            for k in 0..5000 {
                let t = k as f64 * 1e-3;
                let r = [t.sin(), (t + 5e-4).sin(), (t + 1e-3).sin()];
                general.step(method, 1e-3, r);
                fast.step(method, 1e-3, r);
            }
            for i in 0..5 {
                let (a, b) = (general.state[i], fast.state[i]);
                assert!(
                    (a - b).abs() <= 1e-12 * (1.0 + a.abs()),
                    "{method:?} state {i}: {a} vs {b}"
                );
            }
            // A nonlinear joint keeps the general path.
            let mut stuck = Joint::new(params(1.0), 0.0);
            stuck.prepare(method, 1e-3);
            assert!(stuck.linear.is_none());
        }
    }

    #[test]
    fn the_plain_rows_give_the_full_product_bit_for_bit() {
        let mut p = params(0.0);
        p.gains = Gains {
            kp: 5e5,
            ki: 1.7e6,
            kd: 5e4,
        };
        for (method, q0) in [
            (Method::Rk4, 0.0),
            (Method::Rk4, -0.0),
            (Method::Rk4, 1.0),
            (Method::SemiImplicitEuler, -2.5),
        ] {
            let mut j = Joint::new(p, q0);
            j.prepare(method, 1e-3);
            let map = j.linear.clone().expect("a linear joint");
            assert!(map.plain.is_some(), "{method:?}: no plain rows");
            // Zeros of both signs, tiny and large values, in every state and input slot.
            let values = [0.0, -0.0, 1e-300, -3.5, 0.25, 7e12, -1e-9];
            let mut x = j.state;
            for k in 0..2000usize {
                let pick = |n: usize| values[(k * 7 + n * 3 + k / 7) % values.len()];
                let (x_q, x_v, x_i) = (pick(0), pick(1), pick(2));
                let r = [pick(3), pick(4), pick(5)];
                let probe = [x_q, x_v, x_i, x[RF], x[RFD]];
                let (fast, full) = (map.apply(&probe, r), map.apply_full(&probe, r));
                assert_eq!(
                    fast.map(f64::to_bits),
                    full.map(f64::to_bits),
                    "{probe:?} {r:?}"
                );
                x = full;
            }
        }
        // A smoothed joint moves its setpoint states, so it keeps the full product.
        p.smoothing = Some((46.0, 0.869));
        let mut j = Joint::new(p, 0.0);
        j.prepare(Method::Rk4, 1e-3);
        assert!(j.linear.expect("a linear joint").plain.is_none());
    }

    #[test]
    fn a_clipped_effort_holds_the_integrator() {
        let mut p = params(0.0);
        p.limit = 1.0;
        let mut j = Joint::new(p, 0.0);
        for _ in 0..1000 {
            j.step(Method::SemiImplicitEuler, 1e-3, [1.0; 3]);
        }
        // The integral stops at the value whose effort reaches the limit: K_I ∫e = 1.
        assert!(j.state[I] * 10.0 <= 1.0 + 10.0 * 1e-3, "{}", j.state[I]);
    }
}
