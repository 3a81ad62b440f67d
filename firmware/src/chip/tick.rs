//! [`Tick`]: a rate divider on a chip's clock, for a sensor slower than the samples served
//! (the BMI270's and the BMI088's accelerometer at its own ODR below the gyro's, the BMI270's
//! temperature and FIFO down-sampling).

/// A rate divider on the chip's clock: it fires at the first latch of each of its periods,
/// the periods being the multiples of the period from time 0 (so a stream of latches at the
/// gyro ODR gives a slower sensor every n-th latch, always the same ones).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Tick {
    /// Where the next period begins; `None`: the next latch fires.
    next_ns: Option<u64>,
}

impl Tick {
    /// Whether a latch at `now_ns` is the first of a period of `period_ns`; the period is then
    /// used up.
    pub(crate) fn take(&mut self, now_ns: u64, period_ns: u64) -> bool {
        if self.next_ns.is_some_and(|next| now_ns < next) {
            return false;
        }
        let period = period_ns.max(1);
        self.next_ns = Some((now_ns / period).saturating_add(1).saturating_mul(period));
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tick_fires_once_per_period_on_the_grid() {
        let mut t = Tick::default();
        let fired = (0..9u64).map(|k| t.take(k * 312_500, 1_250_000));
        let expected = [true, false, false, false, true, false, false, false, true];
        assert!(fired.eq(expected));
        let mut t = Tick::default();
        assert!(t.take(7, 10)); // the first latch fires wherever it falls
        assert!(!t.take(9, 10));
        assert!(t.take(10, 10));
        assert!(t.take(u64::MAX, 0)); // no panic at the ends
    }
}
