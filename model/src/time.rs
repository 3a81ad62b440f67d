//! Time as an integer count of nanoseconds from the scene start, and exact sample clocks.
//!
//! Never accumulate time in a float: a [`SampleClock`] holds the sample period as the exact
//! rational `num / den` nanoseconds, and sample `k` is latched at `floor(k · num / den)` ns,
//! computed in 128-bit integers. Rates that do not divide 10⁹ (333.33 Hz, 3 kHz) therefore
//! produce instants that never drift, and the seconds a formula needs are derived from ticks.
//!
//! ```
//! use margemu_model::time::SampleClock;
//! let clock = SampleClock::from_hz(3000.0).unwrap();
//! assert_eq!(clock.instant(1), 333_333);
//! assert_eq!(clock.instant(3), 1_000_000);
//! assert_eq!(clock.count_before(1_000_000_000), 3000);
//! ```

/// Nanoseconds from the scene start.
pub type Nanos = u64;

/// Nanoseconds in one second.
pub const NANOS_PER_SECOND: u64 = 1_000_000_000;

/// Converts a tick count to seconds (for formulas; never accumulate the result).
pub fn seconds(t: Nanos) -> f64 {
    t as f64 * 1e-9
}

/// Converts seconds to the nearest whole nanosecond, or `None` if negative, not finite or out of
/// range.
pub fn nanos_from_seconds(s: f64) -> Option<Nanos> {
    let ns = s * 1e9;
    if !ns.is_finite() || ns < 0.0 || ns >= u64::MAX as f64 {
        return None;
    }
    Some(libm::round(ns) as u64)
}

/// A clock that latches samples at exact instants: sample `k` at `floor(k · num / den)` ns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleClock {
    num: u64,
    den: u64,
}

impl SampleClock {
    /// A clock with the period `num / den` nanoseconds, or `None` if either part is zero.
    pub fn from_period(num: u64, den: u64) -> Option<Self> {
        (num > 0 && den > 0).then_some(Self { num, den })
    }

    /// A clock at `hz` samples per second, resolved to a millihertz, or `None` if the rate is not
    /// finite, below 1 mHz, or above 1 GHz.
    pub fn from_hz(hz: f64) -> Option<Self> {
        if !hz.is_finite() || !(0.001..=1e9).contains(&hz) {
            return None;
        }
        let millihertz = libm::round(hz * 1000.0) as u64;
        let (num, den) = reduce(NANOS_PER_SECOND * 1000, millihertz);
        Self::from_period(num, den)
    }

    /// The rate in hertz (for formulas and reports).
    pub fn hz(&self) -> f64 {
        self.den as f64 * 1e9 / self.num as f64
    }

    /// The instant at which sample `k` is latched.
    pub fn instant(&self, k: u64) -> Nanos {
        ((k as u128 * self.num as u128) / self.den as u128) as Nanos
    }

    /// How many samples are latched strictly before `t` (the samples of a run of length `t`).
    pub fn count_before(&self, t: Nanos) -> u64 {
        // Smallest k with k·num/den ≥ t, i.e. ceil(t·den / num).
        let scaled = t as u128 * self.den as u128;
        scaled.div_ceil(self.num as u128) as u64
    }

    /// Whether the period is a whole number of nanoseconds.
    pub fn is_integral(&self) -> bool {
        self.num.is_multiple_of(self.den)
    }
}

fn reduce(a: u64, b: u64) -> (u64, u64) {
    let g = gcd(a, b);
    match (a.checked_div(g), b.checked_div(g)) {
        (Some(x), Some(y)) => (x, y),
        _ => (a, b),
    }
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_rates_have_exact_instants() {
        let clock = SampleClock::from_hz(200.0).unwrap();
        assert!(clock.is_integral());
        assert_eq!(clock.instant(0), 0);
        assert_eq!(clock.instant(1), 5_000_000);
        assert_eq!(clock.instant(4000), 20 * NANOS_PER_SECOND);
        assert_eq!(clock.count_before(20 * NANOS_PER_SECOND), 4000);
    }

    #[test]
    fn fractional_periods_do_not_drift() {
        // 300 Hz: period 10/3 ms, not a whole number of nanoseconds.
        let clock = SampleClock::from_period(10_000_000, 3).unwrap();
        assert!(!clock.is_integral());
        assert_eq!(clock.instant(1), 3_333_333);
        assert_eq!(clock.instant(3), 10_000_000);
        // After 3·10^9 samples (115 days) the instant is still exact.
        assert_eq!(clock.instant(3_000_000_000), 10_000_000_000_000_000);
        assert_eq!(SampleClock::from_hz(300.0), Some(clock));
        // Rates resolve to a millihertz.
        assert!((SampleClock::from_hz(1000.0 / 3.0).unwrap().hz() - 333.333).abs() < 1e-9);
    }

    #[test]
    fn degenerate_rates_are_refused() {
        assert!(SampleClock::from_hz(0.0).is_none());
        assert!(SampleClock::from_hz(f64::NAN).is_none());
        assert!(SampleClock::from_hz(-5.0).is_none());
        assert!(SampleClock::from_period(0, 1).is_none());
        assert!(nanos_from_seconds(-1.0).is_none());
        assert!(nanos_from_seconds(f64::INFINITY).is_none());
        assert_eq!(nanos_from_seconds(0.3), Some(300_000_000));
    }

    #[test]
    fn count_before_is_the_inverse_of_instant() {
        let clock = SampleClock::from_hz(3000.0).unwrap();
        for k in [0u64, 1, 2, 3, 999, 1000, 123_457] {
            let t = clock.instant(k);
            assert_eq!(clock.count_before(t), k, "k = {k}");
            assert_eq!(clock.count_before(t + 1), k + 1, "k = {k}");
        }
    }
}
