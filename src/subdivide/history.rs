//! Per-dart link histories ([`super::LinkChange`]) in one pool: 4 bytes per dart slot up to the
//! highest slot that ever got a change (the head of its list) plus 12 bytes per recorded change,
//! instead of one heap vector per dart. Most darts have no change at all, and a bulk refinement
//! records one change per old dart without an allocation each; the darts it creates have none,
//! so the heads do not grow over them (slots past the end of `head` have an empty history).

use super::LinkChange;

/// No entry.
const NONE: u32 = u32::MAX;

/// One recorded change and the index of the dart's next one.
#[derive(Clone, Copy, Debug)]
struct Entry {
    change: LinkChange,
    next: u32,
}

/// The link histories of every dart slot: dart d's changes, in the order they were made
/// (non-decreasing level), are the list starting at `head[d]`, or empty when d ≥ `head.len()`.
#[derive(Clone, Debug, Default)]
pub(super) struct LinkHistory {
    head: Vec<u32>,
    pool: Vec<Entry>,
}

impl LinkHistory {
    /// Empty histories, with heads allocated for `darts` slots (the slots that may get a change
    /// first; any slot may). O(darts).
    pub(super) fn new(darts: usize) -> Self {
        LinkHistory { head: vec![NONE; darts], pool: Vec::new() }
    }

    /// Allocates the heads of slots `0..darts` at once (exactly, no doubling), for a bulk pass
    /// that records changes on those slots. O(new slots).
    pub(super) fn cover(&mut self, darts: usize) {
        if darts > self.head.len() {
            self.head.reserve_exact(darts - self.head.len());
            self.head.resize(darts, NONE);
        }
    }

    /// The changes of dart slot `d`, in the order they were made. O(1) per item.
    pub(super) fn of(&self, d: usize) -> impl Iterator<Item = LinkChange> + '_ {
        let mut at = self.head.get(d).copied().unwrap_or(NONE);
        std::iter::from_fn(move || {
            if at == NONE {
                return None;
            }
            let e = self.pool[at as usize];
            at = e.next;
            Some(e.change)
        })
    }

    /// Appends a change to dart slot `d`'s list. O(changes of d), plus amortized O(1) per slot
    /// when d is past the allocated heads.
    #[inline]
    pub(super) fn push(&mut self, d: usize, change: LinkChange) {
        if d >= self.head.len() {
            self.head.resize(d + 1, NONE);
        }
        let index = self.pool.len() as u32;
        self.pool.push(Entry { change, next: NONE });
        if self.head[d] == NONE {
            self.head[d] = index;
            return;
        }
        let mut at = self.head[d] as usize;
        // Each step follows one of d's own entries: bounded by the pool length.
        for _ in 0..self.pool.len() {
            match self.pool[at].next {
                NONE => break,
                next => at = next as usize,
            }
        }
        self.pool[at].next = index;
    }

    /// Reserves room for `additional` more changes. O(1) amortized.
    pub(super) fn reserve(&mut self, additional: usize) {
        self.pool.reserve(additional);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_keep_their_order_per_dart() {
        let mut h = LinkHistory::new(3);
        let c = |level, old| LinkChange { level, j: 0, old };
        h.push(1, c(1, 10));
        h.push(2, c(1, 20));
        h.push(1, c(2, 11));
        h.push(5, c(3, 50)); // past the allocated heads: they grow
        h.cover(8);
        h.push(3, c(3, 30));
        h.push(1, c(3, 12));
        let of = |d| h.of(d).map(|x| x.old).collect::<Vec<_>>();
        assert_eq!((of(0), of(1), of(2), of(3)), (vec![], vec![10, 11, 12], vec![20], vec![30]));
        assert_eq!((of(4), of(5), of(7), of(100)), (vec![], vec![50], vec![], vec![]));
    }
}
