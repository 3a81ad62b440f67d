//! Waiting for a send instant through the session's injected clock ([`crate::stream::clock`]):
//! a [`Pacer`] is a [`Clock`] that can also wait until one of its own instants. On the
//! [`SystemClock`] it sleeps, then busy-waits the last stretch (as the streaming core's
//! `Port::spin_until` does); on a [`VirtualClock`] waiting is moving the clock there, so a test's
//! every send time is exact whatever the machine's load.
//!
//! ```
//! use margemu_hil::hitl::pace::Pacer;
//! use margemu_hil::stream::clock::{Clock, VirtualClock};
//! let clock = VirtualClock::new();
//! clock.wait_until(2_500);
//! assert_eq!(clock.now_ns(), 2_500);
//! ```

use crate::stream::clock::{Clock, SystemClock, VirtualClock};
use std::time::Duration;

/// The last stretch before an instant that [`SystemClock`] busy-waits (ns).
pub const SPIN_NS: u64 = 200_000;

/// A clock that can wait for its own instants.
pub trait Pacer: Clock {
    /// Returns at host time `deadline_ns` or later (at once if that has passed).
    fn wait_until(&self, deadline_ns: u64);
}

impl Pacer for SystemClock {
    fn wait_until(&self, deadline_ns: u64) {
        let now = self.now_ns();
        if deadline_ns > now + SPIN_NS {
            std::thread::sleep(Duration::from_nanos(deadline_ns - now - SPIN_NS));
        }
        while self.now_ns() < deadline_ns {
            std::hint::spin_loop();
        }
    }
}

impl Pacer for VirtualClock {
    fn wait_until(&self, deadline_ns: u64) {
        self.set(deadline_ns);
    }
}
