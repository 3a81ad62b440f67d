//! The session's time, injected: a [`Clock`] gives monotonic nanoseconds since the session's
//! origin (host time 0 of its logs). Every deadline the streaming core sets (pacing, credit,
//! resend, Stop, timeouts) and every host time it logs is read from the clock it was given, never
//! from the operating system directly, so the same core runs on [`SystemClock`] against a real
//! port and on a [`VirtualClock`] that a test advances by hand (as smoltcp's `poll(timestamp)`
//! and embassy-time's mock driver do).
//!
//! ```
//! use margemu_hil::stream::clock::{Clock, VirtualClock};
//! let clock = VirtualClock::new();
//! let shared = clock.clone();
//! clock.advance(1_500);
//! assert_eq!(shared.now_ns(), 1_500); // clones share one time
//! clock.set(1_000); // never backwards
//! assert_eq!(clock.now_ns(), 1_500);
//! ```

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Monotonic host time, nanoseconds since the session's origin.
pub trait Clock: Send + Sync {
    /// Now, ns since the origin; never decreases.
    fn now_ns(&self) -> u64;
}

/// The host's monotonic clock ([`Instant`]), counted from an origin.
#[derive(Clone, Copy, Debug)]
pub struct SystemClock {
    origin: Instant,
}

impl SystemClock {
    /// Time 0 is now.
    pub fn new() -> Self {
        Self::with_origin(Instant::now())
    }

    /// Time 0 is `origin`.
    pub fn with_origin(origin: Instant) -> Self {
        Self { origin }
    }

    /// The instant `ns` after the origin.
    pub fn instant(&self, ns: u64) -> Instant {
        self.origin + std::time::Duration::from_nanos(ns)
    }
}

impl Default for SystemClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for SystemClock {
    fn now_ns(&self) -> u64 {
        self.origin.elapsed().as_nanos() as u64
    }
}

/// A clock that moves only when told to; clones share the same time.
#[derive(Clone, Debug, Default)]
pub struct VirtualClock {
    now: Arc<AtomicU64>,
}

impl VirtualClock {
    /// At time 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves to `ns`, or stays if that is in the past.
    pub fn set(&self, ns: u64) {
        self.now.fetch_max(ns, Ordering::SeqCst);
    }

    /// Moves on by `ns`.
    pub fn advance(&self, ns: u64) {
        self.now.fetch_add(ns, Ordering::SeqCst);
    }
}

impl Clock for VirtualClock {
    fn now_ns(&self) -> u64 {
        self.now.load(Ordering::SeqCst)
    }
}
