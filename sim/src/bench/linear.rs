//! The exact step map of a linear joint ([`LinearStep`]), precomputed once per joint, method and
//! step length by [`super::joint::Joint::prepare`], and its reduced form for a joint without
//! setpoint smoothing ([`PlainRows`]).

use super::joint::{State, I, Q, RF, RFD, V};
use crate::scene::Method;

/// The step map of a linear joint for one method and step length.
///
/// Without stiction and without an effort limit a joint is linear and time-invariant,
/// `ẋ = A x + b r(t)`, and one RK4 (or semi-implicit Euler) step is exactly linear in the state
/// and the three reference samples: `x₁ = Φ x₀ + g₀ r₀ + g_m r_m + g₁ r₁`. The matrices are
/// found by running the general step on unit inputs, so the fast path is the same method, not
/// an approximation of it; only the rounding differs.
///
/// A joint without setpoint smoothing never moves its smoothed-setpoint states: the map's rows
/// for them are the identity and their columns in the other rows are `+0.0`, so only the
/// position, velocity and integral rows are computed ([`PlainRows`]), with the same result.
#[derive(Clone, Debug)]
pub(super) struct LinearStep {
    pub(super) method: Method,
    pub(super) h: f64,
    pub(super) phi: [State; 5],
    pub(super) g: [State; 3],
    pub(super) plain: Option<PlainRows>,
}

/// The position, velocity and integral rows of a [`LinearStep`] whose smoothed-setpoint states
/// stand still (checked bit for bit by [`PlainRows::of`]).
///
/// A full row is `((((a₀ + a₁) + a₂) + a₃) + a₄) + b₀ + b₁ + b₂` with `aⱼ = Φᵢⱼ xⱼ` and
/// `bₖ = gₖᵢ rₖ`. Here `Φᵢ₃` is a zero and `x₃ = q₀` finite, so `a₃` is a zero; `x₄ = +0` and
/// `Φᵢ₄` is finite and not negative, so `a₄ = +0`. Adding both leaves a non-zero partial sum as
/// it is and turns a zero one into `+0` (a sum of zeros is `−0` only if every term is), which is
/// exactly `p + 0.0`. The setpoint rows likewise give `x₃ + 0.0` (the identity but for the sign
/// of a zero) and `x₄` itself.
#[derive(Clone, Debug)]
pub(super) struct PlainRows {
    phi: [[f64; 3]; 3],
    g: [[f64; 3]; 3],
}

impl PlainRows {
    /// The rows of `phi` and `g` if the setpoint states stand still under them for state `x`.
    pub(super) fn of(phi: &[State; 5], g: &[State; 3], x: &State) -> Option<Self> {
        let zero = |v: f64| v == 0.0;
        // Times x₄ = +0 this gives +0 (the semi-implicit map has Φ₃₄ = h).
        let keeps_plus_zero = |v: f64| v.is_finite() && v.is_sign_positive();
        let setpoint_rows = [(RF, phi[RF]), (RFD, phi[RFD])].iter().all(|&(k, row)| {
            (0..5).all(|j| match j {
                _ if j == k => row[j] == 1.0,
                RFD => keeps_plus_zero(row[j]),
                _ => zero(row[j]),
            })
        });
        let still = setpoint_rows
            && (Q..=I).all(|i| zero(phi[i][RF]) && keeps_plus_zero(phi[i][RFD]))
            && g.iter().all(|gk| zero(gk[RF]) && zero(gk[RFD]))
            && x[RF].is_finite()
            && x[RFD].to_bits() == 0;
        still.then(|| Self {
            phi: std::array::from_fn(|i| [phi[i][Q], phi[i][V], phi[i][I]]),
            g: std::array::from_fn(|i| [g[0][i], g[1][i], g[2][i]]),
        })
    }

    #[inline]
    pub(super) fn apply(&self, x: &State, r: [f64; 3]) -> State {
        let row = |i: usize| {
            let (p, g) = (&self.phi[i], &self.g[i]);
            (p[0] * x[Q] + p[1] * x[V] + p[2] * x[I] + 0.0)
                + g[0] * r[0]
                + g[1] * r[1]
                + g[2] * r[2]
        };
        [row(Q), row(V), row(I), x[RF] + 0.0, x[RFD]]
    }
}

impl LinearStep {
    #[inline]
    pub(super) fn apply(&self, x: &State, r: [f64; 3]) -> State {
        if let Some(plain) = &self.plain {
            return plain.apply(x, r);
        }
        std::array::from_fn(|i| {
            let row = &self.phi[i];
            row[0] * x[0]
                + row[1] * x[1]
                + row[2] * x[2]
                + row[3] * x[3]
                + row[4] * x[4]
                + self.g[0][i] * r[0]
                + self.g[1][i] * r[1]
                + self.g[2][i] * r[2]
        })
    }

    /// The general product, whatever the structure of the map (the oracle of the tests).
    #[cfg(test)]
    pub(super) fn apply_full(&self, x: &State, r: [f64; 3]) -> State {
        Self {
            plain: None,
            ..self.clone()
        }
        .apply(x, r)
    }
}
