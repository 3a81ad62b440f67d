//! [`Window`]: the newest `span` entries of an indexed stream, so that what a session keeps per
//! sample (images to resend, write times, predicted CRCs) never grows with the scene's length.
//!
//! Entries are appended in index order; appending beyond `span` forgets the oldest. An index
//! below [`Window::start`] is *forgotten*, one at or above [`Window::end`] *not yet known*:
//! [`Window::get`] answers `None` for both, and the caller says which it was.
//!
//! ```
//! use margemu_hil::stream::window::Window;
//! let mut w = Window::new(3);
//! for v in [10, 11, 12, 13] {
//!     w.push(v);
//! }
//! assert_eq!((w.start(), w.end()), (1, 4)); // index 0 forgotten
//! assert_eq!((w.get(0), w.get(1), w.get(3), w.get(4)), (None, Some(&11), Some(&13), None));
//! ```

use std::collections::VecDeque;

/// The newest `span` entries of a stream indexed from 0 (see the module docs).
#[derive(Clone, Debug)]
pub struct Window<T> {
    entries: VecDeque<T>,
    start: u64,
    span: usize,
}

impl<T> Window<T> {
    /// An empty window keeping at most `span` entries (at least one).
    pub fn new(span: usize) -> Self {
        Self {
            entries: VecDeque::new(),
            start: 0,
            span: span.max(1),
        }
    }

    /// Most entries kept.
    pub fn span(&self) -> usize {
        self.span
    }

    /// The oldest index still kept (the next to be appended when empty).
    pub fn start(&self) -> u64 {
        self.start
    }

    /// The index the next [`Window::push`] gets.
    pub fn end(&self) -> u64 {
        self.start + self.entries.len() as u64
    }

    /// Appends the entry of index [`Window::end`], forgetting the oldest beyond `span`.
    pub fn push(&mut self, entry: T) {
        if self.entries.len() == self.span {
            self.entries.pop_front();
            self.start += 1;
        }
        self.entries.push_back(entry);
    }

    /// Forgets everything below `index` and, when `index` is beyond the end, moves the (then
    /// empty) window there.
    pub fn forget_below(&mut self, index: u64) {
        let drop = index.saturating_sub(self.start);
        if drop >= self.entries.len() as u64 {
            self.entries.clear();
            self.start = self.start.max(index);
        } else {
            self.entries.drain(..drop as usize);
            self.start += drop;
        }
    }

    /// The entry of `index`, if kept.
    pub fn get(&self, index: u64) -> Option<&T> {
        let i = usize::try_from(index.checked_sub(self.start)?).ok()?;
        self.entries.get(i)
    }

    /// The entry of `index`, if kept, to change.
    pub fn get_mut(&mut self, index: u64) -> Option<&mut T> {
        let i = usize::try_from(index.checked_sub(self.start)?).ok()?;
        self.entries.get_mut(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forgetting_moves_the_start_and_never_the_entries_kept() {
        let mut w = Window::new(4);
        (0..3).for_each(|v| w.push(v));
        w.forget_below(1);
        assert_eq!((w.start(), w.end(), w.get(1)), (1, 3, Some(&1)));
        w.forget_below(10);
        assert_eq!((w.start(), w.end(), w.get(2)), (10, 10, None));
        w.push(7);
        assert_eq!(w.get(10), Some(&7));
        *w.get_mut(10).unwrap() = 8;
        assert_eq!(w.get(10), Some(&8));
        assert_eq!(Window::<u8>::new(0).span(), 1);
    }
}
