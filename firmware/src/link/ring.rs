//! The device's sample buffer: a fixed window of `N` consecutive sample indices.
//!
//! The window starts at `base`, the oldest index the device still holds or will serve next;
//! indices `base .. base + N` each have one slot (`index % N`), filled or not, so a batch that
//! arrives after a lost one is kept and the hole becomes an underrun when its instant passes.
//! [`SampleRing::limit`] is the credit limit of `docs/spec/link.md` §7, and
//! [`SampleRing::next_index`] the first index not yet received contiguously.
//!
//! ```
//! use margemu_firmware::link::{Insert, SampleRing};
//! let mut ring = SampleRing::<u8, 4>::new();
//! assert_eq!(ring.insert(0, 10), Insert::Stored);
//! assert_eq!(ring.insert(2, 12), Insert::Stored); // 1 missing
//! assert_eq!((ring.next_index(), ring.level(), ring.limit()), (1, 2, 4));
//! assert_eq!(ring.insert(4, 14), Insert::Overrun);
//! assert_eq!(ring.take(0), Some(10));
//! assert_eq!(ring.take(1), None); // the hole: an underrun
//! assert_eq!((ring.next_index(), ring.limit()), (3, 6));
//! ```

/// What [`SampleRing::insert`] did with a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insert {
    /// Kept.
    Stored,
    /// Below the window (already served or skipped), or already held: ignored.
    Stale,
    /// At or beyond [`SampleRing::limit`]: dropped (an overrun).
    Overrun,
}

/// A window of `N` sample slots (see the module docs). Never panics, `N = 0` included (every
/// sample is then an overrun).
#[derive(Clone, Debug)]
pub struct SampleRing<T: Copy, const N: usize> {
    slots: [Option<T>; N],
    base: u64,
    next_index: u64,
    level: usize,
}

impl<T: Copy, const N: usize> Default for SampleRing<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Copy, const N: usize> SampleRing<T, N> {
    /// An empty window starting at index 0.
    pub const fn new() -> Self {
        Self {
            slots: [None; N],
            base: 0,
            next_index: 0,
            level: 0,
        }
    }

    /// Empties the window and moves it to start at `base`.
    pub fn reset(&mut self, base: u64) {
        self.slots = [None; N];
        self.base = base;
        self.next_index = base;
        self.level = 0;
    }

    fn slot(index: u64) -> Option<usize> {
        let n = u64::try_from(N).ok()?;
        usize::try_from(index.checked_rem(n)?).ok()
    }

    /// The credit limit: samples with index `< limit` fit.
    pub fn limit(&self) -> u64 {
        self.base.saturating_add(N as u64)
    }

    /// The oldest index held or to be served next.
    pub fn base(&self) -> u64 {
        self.base
    }

    /// Every index below this one was received (or its instant has passed).
    pub fn next_index(&self) -> u64 {
        self.next_index
    }

    /// Samples held now.
    pub fn level(&self) -> usize {
        self.level
    }

    /// Stores sample `index`.
    pub fn insert(&mut self, index: u64, value: T) -> Insert {
        if index >= self.limit() {
            return Insert::Overrun;
        }
        if index < self.base {
            return Insert::Stale;
        }
        let Some(slot) = Self::slot(index).and_then(|i| self.slots.get_mut(i)) else {
            return Insert::Overrun;
        };
        if slot.is_some() {
            return Insert::Stale;
        }
        *slot = Some(value);
        self.level += 1;
        self.extend_contiguous();
        Insert::Stored
    }

    fn extend_contiguous(&mut self) {
        while self.next_index < self.limit() {
            match Self::slot(self.next_index).and_then(|i| self.slots.get(i)) {
                Some(Some(_)) => self.next_index += 1,
                _ => break,
            }
        }
    }

    /// Drops every sample below `index` and moves the window to start there (no-op if it
    /// already starts at or after it).
    pub fn advance_to(&mut self, index: u64) {
        if index <= self.base {
            return;
        }
        let count = (index - self.base).min(N as u64);
        for i in 0..count {
            if let Some(slot) = Self::slot(self.base + i).and_then(|s| self.slots.get_mut(s)) {
                if slot.take().is_some() {
                    self.level = self.level.saturating_sub(1);
                }
            }
        }
        self.base = index;
        self.next_index = self.next_index.max(index);
        self.extend_contiguous();
    }

    /// The sample at `index`, if held, without removing it.
    pub fn get(&self, index: u64) -> Option<T> {
        if index < self.base || index >= self.limit() {
            return None;
        }
        Self::slot(index).and_then(|i| self.slots.get(i).copied().flatten())
    }

    /// Drops everything below `index`, then removes and returns sample `index` (the window then
    /// starts after it).
    pub fn take(&mut self, index: u64) -> Option<T> {
        self.advance_to(index);
        let value = self.get(index);
        self.advance_to(index.saturating_add(1));
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wraps_and_counts() {
        let mut r = SampleRing::<u32, 3>::new();
        for i in 0..10u64 {
            assert_eq!(r.insert(i, i as u32), Insert::Stored);
            assert_eq!(r.insert(i, 0), Insert::Stale);
            assert_eq!(r.take(i), Some(i as u32));
            assert_eq!((r.level(), r.next_index(), r.limit()), (0, i + 1, i + 4));
        }
        r.insert(11, 11);
        r.advance_to(1_000_000);
        assert_eq!((r.level(), r.next_index()), (0, 1_000_000));
    }

    #[test]
    fn zero_capacity() {
        let mut r = SampleRing::<u8, 0>::new();
        assert_eq!(r.insert(0, 1), Insert::Overrun);
        assert_eq!(r.take(0), None);
    }
}
