//! Spare lists: the emptied `Vec`s of a dropped report, kept by one thread for the next report
//! of the same kind, so that a loop of small topological operations (cut, sew back, cut…)
//! allocates nothing for its reports in the steady state.
//!
//! Each report type that uses it owns one thread-local slot of its lists
//! ([`crate::gmap::CellChanges`], [`crate::mechanics::TouchedCells`]; not
//! [`crate::cut::Dissociation`], whose fields users move out). Its `Drop` gives its lists back
//! with [`give_back`]; its constructor takes them with [`take`]. When two reports
//! meet in the slot, each list keeps the larger of the two buffers; lists grown past
//! [`CAPACITY_LIMIT`] are freed rather than kept (a bulk operation's report would otherwise hold
//! its memory for the thread's lifetime). Costs O(1) per list: the elements are plain data.
//!
//! None of this changes a report's contents: a list taken from the slot is empty.

use std::cell::Cell;
use std::thread::LocalKey;

/// Buffers with more room than this many elements are not kept.
pub(crate) const CAPACITY_LIMIT: usize = 1 << 12;

/// Lists that a slot can hold: a `Vec`, or a pair of such (nested for more), merged list by
/// list.
pub(crate) trait Lists: Default {
    /// Empties each list (freeing any over [`CAPACITY_LIMIT`]).
    fn emptied(self) -> Self;
    /// List by list, the one of `self` and `other` with the larger capacity (the other freed).
    fn larger(self, other: Self) -> Self;
}

impl<T> Lists for Vec<T> {
    fn emptied(mut self) -> Self {
        if self.capacity() > CAPACITY_LIMIT {
            return Vec::new();
        }
        self.clear();
        self
    }
    fn larger(self, other: Self) -> Self {
        if self.capacity() >= other.capacity() {
            self
        } else {
            other
        }
    }
}

impl<A: Lists, B: Lists> Lists for (A, B) {
    fn emptied(self) -> Self {
        (self.0.emptied(), self.1.emptied())
    }
    fn larger(self, other: Self) -> Self {
        (self.0.larger(other.0), self.1.larger(other.1))
    }
}

/// The slot's lists (or fresh empty ones), leaving the slot empty. O(1).
pub(crate) fn take<L: Lists + 'static>(slot: &'static LocalKey<Cell<Option<L>>>) -> L {
    slot.try_with(Cell::take).ok().flatten().unwrap_or_default()
}

/// Puts `lists`, emptied, into the slot, merged with what it holds. After the thread's locals are
/// gone (a report dropped during thread exit) they are simply freed. O(1).
pub(crate) fn give_back<L: Lists + 'static>(slot: &'static LocalKey<Cell<Option<L>>>, lists: L) {
    let lists = lists.emptied();
    let _ = slot.try_with(|s| {
        let kept = match s.take() {
            None => lists,
            Some(old) => old.larger(lists),
        };
        s.set(Some(kept));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    thread_local! {
        static SLOT: Cell<Option<(Vec<u32>, Vec<u64>)>> = const { Cell::new(None) };
    }

    #[test]
    fn a_slot_hands_back_empty_lists_keeping_the_larger_buffers() {
        assert_eq!(take(&SLOT), (Vec::new(), Vec::new()));
        let a = (Vec::<u32>::with_capacity(40), vec![7u64; 3]);
        let b = (vec![1u32, 2, 3], Vec::<u64>::with_capacity(100));
        give_back(&SLOT, a);
        give_back(&SLOT, b);
        let (x, y) = take(&SLOT);
        assert!(x.is_empty() && y.is_empty());
        assert!(x.capacity() >= 40 && y.capacity() >= 100);
        assert_eq!(take(&SLOT).0.capacity(), 0); // the slot was emptied by the take
    }

    #[test]
    fn lists_over_the_limit_are_freed_not_kept() {
        give_back(&SLOT, (Vec::<u32>::with_capacity(CAPACITY_LIMIT + 1), Vec::<u64>::with_capacity(8)));
        let (x, y) = take(&SLOT);
        assert_eq!(x.capacity(), 0);
        assert!(y.capacity() >= 8);
    }
}
